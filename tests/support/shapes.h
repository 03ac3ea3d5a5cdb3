// Closed, outward-oriented (counter-clockwise seen from outside), welded test meshes.
#pragma once

#include <cmath>
#include <numbers>

#include "pic/pic.h"

namespace pic {

/// Axis-aligned box: 8 vertices, 12 triangles.
inline TriMesh make_box(Vec3 min, Vec3 max) {
  TriMesh m;
  for (int k = 0; k < 8; ++k)
    m.positions.push_back({k & 1 ? max[0] : min[0], k >> 1 & 1 ? max[1] : min[1],
                           k >> 2 & 1 ? max[2] : min[2]});
  // Vertex k sits at corner (k&1, k>>1&1, k>>2&1); each quad is counter-clockwise from outside.
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

/// Latitude/longitude sphere: `nu` segments around the z axis, `nv` bands pole to pole,
/// single pole vertices.
inline TriMesh make_uv_sphere(Vec3 c, double r, int nu, int nv) {
  const double pi = std::numbers::pi;
  TriMesh m;
  m.positions.push_back({c[0], c[1], c[2] + r});
  for (int j = 1; j < nv; ++j) {
    double th = pi * j / nv;
    for (int i = 0; i < nu; ++i) {
      double ph = 2 * pi * i / nu;
      m.positions.push_back({c[0] + r * std::sin(th) * std::cos(ph),
                             c[1] + r * std::sin(th) * std::sin(ph), c[2] + r * std::cos(th)});
    }
  }
  const uint32_t south = uint32_t(m.positions.size());
  m.positions.push_back({c[0], c[1], c[2] - r});
  auto ring = [&](int j, int i) { return uint32_t(1 + (j - 1) * nu + (i % nu)); };
  for (int i = 0; i < nu; ++i) {
    m.triangles.push_back({0, ring(1, i), ring(1, i + 1)});
    for (int j = 1; j + 1 < nv; ++j) {
      uint32_t a = ring(j, i), b = ring(j, i + 1), cc = ring(j + 1, i + 1), d = ring(j + 1, i);
      m.triangles.push_back({a, d, cc});
      m.triangles.push_back({a, cc, b});
    }
    m.triangles.push_back({south, ring(nv - 1, i + 1), ring(nv - 1, i)});
  }
  return m;
}

/// Cylinder along +z from `base` (centre of the bottom cap), `n` segments, capped by fans.
inline TriMesh make_cylinder(Vec3 base, double r, double height, int n) {
  const double pi = std::numbers::pi;
  TriMesh m;
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < n; ++i) {
      double ph = 2 * pi * i / n;
      m.positions.push_back(
          {base[0] + r * std::cos(ph), base[1] + r * std::sin(ph), base[2] + k * height});
    }
  const uint32_t bc = uint32_t(m.positions.size()), tc = bc + 1;
  m.positions.push_back(base);
  m.positions.push_back({base[0], base[1], base[2] + height});
  auto bot = [&](int i) { return uint32_t(i % n); };
  auto top = [&](int i) { return uint32_t(n + i % n); };
  for (int i = 0; i < n; ++i) {
    m.triangles.push_back({bot(i), bot(i + 1), top(i + 1)});
    m.triangles.push_back({bot(i), top(i + 1), top(i)});
    m.triangles.push_back({tc, top(i), top(i + 1)});
    m.triangles.push_back({bc, bot(i + 1), bot(i)});
  }
  return m;
}

/// Torus around the z axis: major radius `big_r`, tube radius `small_r`.
inline TriMesh make_torus(Vec3 c, double big_r, double small_r, int nu, int nv) {
  const double pi = std::numbers::pi;
  TriMesh m;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      double u = 2 * pi * i / nu, v = 2 * pi * j / nv;
      double rr = big_r + small_r * std::cos(v);
      m.positions.push_back({c[0] + rr * std::cos(u), c[1] + rr * std::sin(u),
                             c[2] + small_r * std::sin(v)});
    }
  auto at = [&](int i, int j) { return uint32_t((i % nu) * nv + (j % nv)); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      uint32_t a = at(i, j), b = at(i + 1, j), cc = at(i + 1, j + 1), d = at(i, j + 1);
      m.triangles.push_back({a, b, cc});
      m.triangles.push_back({a, cc, d});
    }
  return m;
}

}  // namespace pic
