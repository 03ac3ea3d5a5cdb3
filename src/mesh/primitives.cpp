#include "pic/primitives.h"

#include <cmath>
#include <numbers>

namespace pic {
namespace {

// Local frame: `axis` becomes the third coordinate; (u, v, w) -> world.
Vec3 frame(const Vec3& c, int axis, double u, double v, double w) {
  Vec3 p;
  p[axis] = c[axis] + w;
  p[(axis + 1) % 3] = c[(axis + 1) % 3] + u;
  p[(axis + 2) % 3] = c[(axis + 2) % 3] + v;
  return p;
}

void check(bool ok, const char* what) {
  if (!ok) throw InvalidInput(what);
}

// A surface of revolution: `ring` radii/heights from bottom to top; r == 0 closes with a pole.
TriMesh revolve(const Vec3& c, int axis, const std::vector<std::array<double, 2>>& profile, int segments) {
  TriMesh m;
  std::vector<std::vector<uint32_t>> rings;
  for (const auto& [r, h] : profile) {
    std::vector<uint32_t> ids;
    if (r == 0) {
      ids.assign(segments, static_cast<uint32_t>(m.positions.size()));
      m.positions.push_back(frame(c, axis, 0, 0, h));
    } else {
      for (int s = 0; s < segments; ++s) {
        const double a = 2 * std::numbers::pi * s / segments;
        ids.push_back(static_cast<uint32_t>(m.positions.size()));
        m.positions.push_back(frame(c, axis, r * std::cos(a), r * std::sin(a), h));
      }
    }
    rings.push_back(ids);
  }
  for (size_t k = 0; k + 1 < rings.size(); ++k) {
    for (int s = 0; s < segments; ++s) {
      const int t = (s + 1) % segments;
      const uint32_t a = rings[k][s], b = rings[k][t], d = rings[k + 1][s], e = rings[k + 1][t];
      if (a != b) m.triangles.push_back({a, b, e});
      if (d != e) m.triangles.push_back({a, e, d});
    }
  }
  return m;
}

}  // namespace

TriMesh make_box(const Vec3& lo, const Vec3& hi) {
  check(lo[0] < hi[0] && lo[1] < hi[1] && lo[2] < hi[2], "box: min must be below max on every axis");
  TriMesh m;
  for (int c = 0; c < 8; ++c)
    m.positions.push_back({(c & 1) ? hi[0] : lo[0], (c & 2) ? hi[1] : lo[1], (c & 4) ? hi[2] : lo[2]});
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

TriMesh make_sphere(const Vec3& center, double radius, int segments) {
  check(radius > 0 && segments >= 4, "sphere: radius must be > 0 and segments >= 4");
  std::vector<std::array<double, 2>> prof;
  const int rings = segments / 2;
  for (int k = 0; k <= rings; ++k) {
    const double a = std::numbers::pi * k / rings;
    prof.push_back({k == 0 || k == rings ? 0 : radius * std::sin(a), -radius * std::cos(a)});
  }
  return revolve(center, 2, prof, segments);
}

TriMesh make_cylinder(const Vec3& center, double radius, double height, int axis, int segments) {
  check(radius > 0 && height > 0 && segments >= 3 && axis >= 0 && axis < 3, "cylinder: bad parameters");
  return revolve(center, axis, {{0, -height / 2}, {radius, -height / 2}, {radius, height / 2}, {0, height / 2}}, segments);
}

TriMesh make_cone(const Vec3& center, double radius, double height, int axis, int segments) {
  check(radius > 0 && height > 0 && segments >= 3 && axis >= 0 && axis < 3, "cone: bad parameters");
  return revolve(center, axis, {{0, -height / 2}, {radius, -height / 2}, {0, height / 2}}, segments);
}

TriMesh make_torus(const Vec3& center, double major, double minor, int axis, int segments, int tube_segments) {
  check(major > minor && minor > 0 && segments >= 3 && tube_segments >= 3, "torus: need major > minor > 0");
  TriMesh m;
  for (int s = 0; s < segments; ++s) {
    const double a = 2 * std::numbers::pi * s / segments;
    for (int t = 0; t < tube_segments; ++t) {
      const double b = 2 * std::numbers::pi * t / tube_segments;
      const double r = major + minor * std::cos(b);
      m.positions.push_back(frame(center, axis, r * std::cos(a), r * std::sin(a), minor * std::sin(b)));
    }
  }
  auto id = [&](int s, int t) { return static_cast<uint32_t>((s % segments) * tube_segments + (t % tube_segments)); };
  for (int s = 0; s < segments; ++s)
    for (int t = 0; t < tube_segments; ++t) {
      m.triangles.push_back({id(s, t), id(s + 1, t), id(s + 1, t + 1)});
      m.triangles.push_back({id(s, t), id(s + 1, t + 1), id(s, t + 1)});
    }
  return m;
}

TriMesh transformed(TriMesh mesh, const std::array<double, 9>& r, const Vec3& t) {
  for (Vec3& p : mesh.positions) {
    const Vec3 q = p;
    for (int k = 0; k < 3; ++k) p[k] = r[3 * k] * q[0] + r[3 * k + 1] * q[1] + r[3 * k + 2] * q[2] + t[k];
  }
  return mesh;
}

std::array<double, 9> rotation(const Vec3& axis, double radians) {
  const double l = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  check(l > 0, "rotation axis must be non-zero");
  const double x = axis[0] / l, y = axis[1] / l, z = axis[2] / l;
  const double c = std::cos(radians), s = std::sin(radians), C = 1 - c;
  return {x * x * C + c,     x * y * C - z * s, x * z * C + y * s,
          y * x * C + z * s, y * y * C + c,     y * z * C - x * s,
          z * x * C - y * s, z * y * C + x * s, z * z * C + c};
}

}  // namespace pic
