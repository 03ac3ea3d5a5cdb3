// OpenSCAD's tessellation rules (OpenSCAD 2021.01, src/calc.cc, src/primitives.cc,
// src/GeometryEvaluator.cc), re-implemented so that a `$fn = 6` cylinder is the same hexagonal
// prism here as there: fragment counts, sphere rings, circle vertex angles, extrusion slices.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "pic/measure.h"
#include "geometry/vec3.h"
#include "scad/scad_detail.h"

namespace pic::detail::scad {
namespace {

constexpr double kPi = std::numbers::pi;
double rad(double deg) { return deg * kPi / 180; }

// OpenSCAD's linear_extrude: two diagonals of a side quad whose lengths differ by less than
// their mean over this count as equal (10 ppm).
constexpr double kDiagonalTieRatio = 1e5;

double cross(const P2& o, const P2& a, const P2& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

// Drops repeated consecutive points (and a closing point equal to the first).
Ring cleaned(const Ring& ring) {
  Ring out;
  for (const P2& p : ring)
    if (out.empty() || p[0] != out.back()[0] || p[1] != out.back()[1]) out.push_back(p);
  while (out.size() > 1 && out.front()[0] == out.back()[0] && out.front()[1] == out.back()[1]) out.pop_back();
  return out;
}

// Flips every triangle when the mesh came out inside-out (negative volume); callers build
// one consistent orientation and let this pick the outward one.
void orient_outward(TriMesh& m) {
  if (volume(m) < 0)
    for (auto& t : m.triangles) std::swap(t[1], t[2]);
}

}  // namespace

double cos_degrees(double deg) {
  if (!std::isfinite(deg)) return std::nan("");
  double x = deg - 360 * std::floor(deg / 360);  // [0, 360)
  bool negative = false;
  if (x >= 180) x -= 180, negative = true;
  if (x > 90) x = 180 - x, negative = !negative;
  double c;
  if (x == 0) c = 1;
  else if (x == 30) c = std::sqrt(3.0) / 2;
  else if (x == 45) c = std::sqrt(0.5);
  else if (x == 60) c = 0.5;
  else if (x == 90) c = 0;
  else c = std::cos(rad(x));
  return negative ? -c : c;
}

int fragments_from_r(double r, double fn, double fs, double fa) {
  if (r < kGridFine || std::isinf(fn) || std::isnan(fn)) return 3;
  if (fn > 0.0) return static_cast<int>(fn >= 3 ? fn : 3);
  return static_cast<int>(std::ceil(std::fmax(std::fmin(360.0 / fa, r * 2 * kPi / fs), 5)));
}

Ring circle_ring(double r, int n) {
  Ring out(n);
  for (int i = 0; i < n; ++i) {
    const double phi = rad(360.0 * i / n);
    out[i] = {r * std::cos(phi), r * std::sin(phi)};
  }
  return out;
}

TriMesh sphere_mesh(double r, int n) {
  TriMesh m;
  const int rings = (n + 1) / 2;
  for (int i = 0; i < rings; ++i) {
    const double phi = rad(180.0 * (i + 0.5) / rings);
    const double rr = r * std::sin(phi), z = r * std::cos(phi);
    for (const P2& p : circle_ring(rr, n)) m.positions.push_back({p[0], p[1], z});
  }
  auto at = [&](int ring, int j) { return static_cast<uint32_t>(ring * n + (j % n)); };
  // Top and bottom caps are the flat polygons of the first and last ring (fans).
  for (int j = 1; j + 1 < n; ++j) {
    m.triangles.push_back({at(0, 0), at(0, j), at(0, j + 1)});
    m.triangles.push_back({at(rings - 1, 0), at(rings - 1, j + 1), at(rings - 1, j)});
  }
  for (int i = 0; i + 1 < rings; ++i)
    for (int j = 0; j < n; ++j) {
      const uint32_t a = at(i + 1, j), b = at(i + 1, j + 1), c = at(i, j + 1), d = at(i, j);
      m.triangles.push_back({a, b, c});
      m.triangles.push_back({a, c, d});
    }
  orient_outward(m);
  return m;
}

TriMesh cylinder_mesh(double r1, double r2, double z1, double z2, int n) {
  TriMesh m;
  std::vector<uint32_t> lo, hi;
  auto ring = [&](double r, double z, std::vector<uint32_t>& ids) {
    if (r <= 0) {
      ids.assign(n, static_cast<uint32_t>(m.positions.size()));
      m.positions.push_back({0, 0, z});
      return;
    }
    for (const P2& p : circle_ring(r, n)) {
      ids.push_back(static_cast<uint32_t>(m.positions.size()));
      m.positions.push_back({p[0], p[1], z});
    }
  };
  ring(r1, z1, lo);
  ring(r2, z2, hi);
  for (int j = 0; j < n; ++j) {
    const int k = (j + 1) % n;
    if (lo[j] != lo[k]) m.triangles.push_back({lo[j], lo[k], hi[k]});
    if (hi[j] != hi[k]) m.triangles.push_back({lo[j], hi[k], hi[j]});
  }
  for (int j = 1; j + 1 < n; ++j) {
    if (r1 > 0) m.triangles.push_back({lo[0], lo[j + 1], lo[j]});
    if (r2 > 0) m.triangles.push_back({hi[0], hi[j], hi[j + 1]});
  }
  orient_outward(m);
  return m;
}

double signed_area(const Ring& ring) {
  double a = 0;
  for (size_t i = 0, n = ring.size(); i < n; ++i) {
    const P2& p = ring[i];
    const P2& q = ring[(i + 1) % n];
    a += p[0] * q[1] - q[0] * p[1];
  }
  return a / 2;
}

std::vector<std::array<uint32_t, 3>> triangulate(const Ring& ring) {
  std::vector<std::array<uint32_t, 3>> out;
  std::vector<uint32_t> idx(ring.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<uint32_t>(i);
  // Ear clipping, O(n^2): a convex corner whose triangle holds no other vertex is cut off.
  // Collinear corners are dropped without a triangle (zero area).
  size_t k = 0, since_cut = 0;
  while (idx.size() > 3) {
    const size_t n = idx.size();
    if (since_cut > n) {
      // No ear (numerically degenerate input): drop the flattest corner and go on.
      size_t best = 0;
      double best_c = INFINITY;
      for (size_t i = 0; i < n; ++i) {
        const double c = std::abs(cross(ring[idx[(i + n - 1) % n]], ring[idx[i]], ring[idx[(i + 1) % n]]));
        if (c < best_c) best_c = c, best = i;
      }
      idx.erase(idx.begin() + static_cast<long>(best));
      since_cut = 0;
      continue;
    }
    k %= n;
    const uint32_t a = idx[(k + n - 1) % n], b = idx[k], c = idx[(k + 1) % n];
    const double cr = cross(ring[a], ring[b], ring[c]);
    bool ear = cr > 0;
    if (cr == 0) {  // collinear: remove without a triangle
      idx.erase(idx.begin() + static_cast<long>(k));
      since_cut = 0;
      continue;
    }
    for (size_t i = 0; ear && i < n; ++i) {
      const uint32_t v = idx[i];
      if (v == a || v == b || v == c) continue;
      const P2& p = ring[v];
      if ((p[0] == ring[a][0] && p[1] == ring[a][1]) || (p[0] == ring[c][0] && p[1] == ring[c][1])) continue;
      if (cross(ring[a], ring[b], p) >= 0 && cross(ring[b], ring[c], p) >= 0 && cross(ring[c], ring[a], p) >= 0)
        ear = false;
    }
    if (ear) {
      out.push_back({a, b, c});
      idx.erase(idx.begin() + static_cast<long>(k));
      since_cut = 0;
    } else {
      ++k;
      ++since_cut;
    }
  }
  if (idx.size() == 3 && cross(ring[idx[0]], ring[idx[1]], ring[idx[2]]) > 0) out.push_back({idx[0], idx[1], idx[2]});
  return out;
}

TriMesh extrude_linear(Ring ring, const LinearExtrude& e) {
  TriMesh m;
  ring = cleaned(ring);
  if (ring.size() < 3 || e.height <= 0 || signed_area(ring) == 0) return m;
  if (signed_area(ring) < 0) std::reverse(ring.begin(), ring.end());
  const auto tris = triangulate(ring);
  const int slices = std::max(1, e.slices);
  const size_t n = ring.size();
  const double z0 = e.center ? -e.height / 2 : 0;
  const bool apex = e.scale[0] <= 0 && e.scale[1] <= 0;
  std::vector<std::vector<uint32_t>> ids(slices + 1);
  for (int j = 0; j <= slices; ++j) {
    const double t = double(j) / slices;
    const double rot = rad(-e.twist * t);
    const double sx = 1 + (e.scale[0] - 1) * t, sy = 1 + (e.scale[1] - 1) * t;
    const double z = z0 + e.height * t, c = std::cos(rot), s = std::sin(rot);
    if (j == slices && apex) {
      ids[j].assign(n, static_cast<uint32_t>(m.positions.size()));
      m.positions.push_back({0, 0, z});
      continue;
    }
    for (const P2& p : ring) {
      ids[j].push_back(static_cast<uint32_t>(m.positions.size()));
      m.positions.push_back({sx * (c * p[0] - s * p[1]), sy * (s * p[0] + c * p[1]), z});
    }
  }
  // Each side quad is split along its shorter diagonal measured in the plane, as OpenSCAD 2021
  // does; diagonals within 10 ppm of each other count as equal (an edge on a line through the
  // axis, a centred shape scaled unevenly), and then a twist to the left (positive) takes p1-c2
  // and any other extrusion c1-p2 -- measured on its output for outer rings and holes alike.
  // Deciding a tie by rounding instead moved a twisted rectangle's volume by 0.7 %.
  const bool ties_first = e.twist > 0;
  auto shorter_first = [&](uint32_t p1, uint32_t c1, uint32_t p2, uint32_t c2) {
    const auto planar = [&](uint32_t a, uint32_t b) {
      return std::hypot(m.positions[a][0] - m.positions[b][0], m.positions[a][1] - m.positions[b][1]);
    };
    const double first = planar(p1, c2), second = planar(c1, p2);
    if (std::abs(first - second) * kDiagonalTieRatio < (first + second) / 2) return ties_first;
    return first < second;
  };
  for (int j = 0; j < slices; ++j)
    for (size_t i = 0; i < n; ++i) {
      const size_t k = (i + 1) % n;
      const uint32_t p1 = ids[j][i], c1 = ids[j][k], p2 = ids[j + 1][i], c2 = ids[j + 1][k];
      if (shorter_first(p1, c1, p2, c2)) {
        m.triangles.push_back({p1, c1, c2});
        if (p2 != c2) m.triangles.push_back({p1, c2, p2});
      } else {
        if (p2 != c2) m.triangles.push_back({c1, c2, p2});
        m.triangles.push_back({p1, c1, p2});
      }
    }
  for (const auto& t : tris) {
    m.triangles.push_back({ids[0][t[0]], ids[0][t[2]], ids[0][t[1]]});
    if (!apex) m.triangles.push_back({ids[slices][t[0]], ids[slices][t[1]], ids[slices][t[2]]});
  }
  orient_outward(m);
  return m;
}

TriMesh extrude_rotate(Ring ring, double angle, int fragments) {
  TriMesh m;
  // Only the x >= 0 part revolves (a subtracted shape may reach across the axis): clip the
  // ring to that half plane (Sutherland-Hodgman); pieces joined along the axis collapse there.
  Ring clipped;
  for (size_t i = 0, n = ring.size(); i < n; ++i) {
    const P2& a = ring[i];
    const P2& b = ring[(i + 1) % n];
    if (a[0] >= 0) clipped.push_back(a);
    if ((a[0] >= 0) != (b[0] >= 0)) {
      const double t = a[0] / (a[0] - b[0]);
      clipped.push_back({0, a[1] + t * (b[1] - a[1])});
    }
  }
  ring = cleaned(clipped);
  if (ring.size() < 3 || signed_area(ring) == 0 || angle == 0) return m;
  if (signed_area(ring) < 0) std::reverse(ring.begin(), ring.end());
  angle = std::clamp(angle, -360.0, 360.0);
  const bool full = std::abs(angle) >= 360;
  const int f = std::max(1, fragments);
  const int steps = full ? f : f + 1;
  const size_t n = ring.size();
  // A profile vertex on the axis is one vertex for every angle (keeps the mesh manifold).
  std::vector<std::vector<uint32_t>> ids(n, std::vector<uint32_t>(steps));
  for (size_t i = 0; i < n; ++i) {
    const double x = ring[i][0], y = ring[i][1];
    if (x <= 0) {
      std::fill(ids[i].begin(), ids[i].end(), static_cast<uint32_t>(m.positions.size()));
      m.positions.push_back({0, 0, y});
      continue;
    }
    for (int k = 0; k < steps; ++k) {
      // OpenSCAD: a full turn starts on the -x axis ("legacy support"), a partial one on +x.
      const double theta = full ? rad(180.0 + 360.0 * k / f) : rad(angle * k / f);
      ids[i][k] = static_cast<uint32_t>(m.positions.size());
      m.positions.push_back({x * std::cos(theta), x * std::sin(theta), y});
    }
  }
  for (size_t i = 0; i < n; ++i) {
    const size_t j = (i + 1) % n;
    for (int k = 0; k < f; ++k) {
      const int l = full ? (k + 1) % f : k + 1;
      const uint32_t a = ids[i][k], b = ids[j][k], c = ids[j][l], d = ids[i][l];
      if (a != c && c != b && a != b) m.triangles.push_back({a, c, b});
      if (a != d && d != c && a != c) m.triangles.push_back({a, d, c});
    }
  }
  if (!full) {
    for (const auto& t : triangulate(ring)) {
      m.triangles.push_back({ids[t[0]][0], ids[t[1]][0], ids[t[2]][0]});
      m.triangles.push_back({ids[t[0]][f], ids[t[2]][f], ids[t[1]][f]});
    }
  }
  orient_outward(m);
  return m;
}

}  // namespace pic::detail::scad
