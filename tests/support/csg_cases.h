// Random CSG cases for the randomized harness (bench/csg_fuzz.cpp) and the regression tests
// that keep its worst finds (tests/csg_regression_test.cpp): a case is a pure function of its
// seed, so a seed names it everywhere.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "pic/pic.h"
#include "pic/primitives.h"

namespace pic {

inline constexpr const char* kModels[] = {"cad_part", "fandisk", "spot", "suzanne", "teapot"};

/// A small deterministic generator (the same numbers on every standard library).
struct Rng {
  uint64_t s;
  uint64_t next() {
    s += 0x9E3779B97F4A7C15ull;
    uint64_t z = s;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * double(next() >> 11) * 0x1.0p-53; }
  int below(int n) { return int(next() % uint64_t(n)); }
};

inline TriMesh normalized(TriMesh m) {
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const auto& p : m.positions)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  const double ext = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  for (auto& p : m.positions)
    for (int k = 0; k < 3; ++k) p[k] = (p[k] - (lo[k] + hi[k]) / 2) / ext;
  return m;
}

/// One random operand, inside [0.1, 0.9]^3: a primitive or a data mesh, scaled (not
/// uniformly), rotated about a random axis, moved.
inline TriMesh random_operand(Rng& r, const std::vector<TriMesh>& models, std::string& what) {
  const int kind = r.below(6);
  TriMesh m;
  const Vec3 o{0, 0, 0};
  switch (kind) {
    case 0: m = make_box({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}); what = "box"; break;
    case 1: m = make_sphere(o, 0.5, 48); what = "sphere"; break;
    case 2: m = make_cylinder(o, 0.5, 1, 2, 48); what = "cylinder"; break;
    case 3: m = make_torus(o, 0.35, 0.15, 2, 48, 24); what = "torus"; break;
    case 4: m = make_cone(o, 0.5, 1, 2, 48); what = "cone"; break;
    default: {
      const int k = r.below(int(models.size()));
      m = models[k];
      what = kModels[k];
    }
  }
  const double size = r.uniform(0.3, 0.6);
  const Vec3 scale{size * r.uniform(0.5, 1), size * r.uniform(0.5, 1), size * r.uniform(0.5, 1)};
  for (auto& p : m.positions)
    for (int k = 0; k < 3; ++k) p[k] *= scale[k];
  Vec3 axis{r.uniform(-1, 1), r.uniform(-1, 1), r.uniform(-1, 1)};
  const double n = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]) + 1e-12;
  for (double& x : axis) x /= n;
  const Vec3 at{r.uniform(0.35, 0.65), r.uniform(0.35, 0.65), r.uniform(0.35, 0.65)};
  m = transformed(std::move(m), rotation(axis, r.uniform(0, 2 * std::numbers::pi)), at);
  // Shrunk about its centre where it would leave [0.03, 0.97]^3 (the root cube is the unit cube).
  double reach = 0;
  for (const auto& p : m.positions)
    for (int k = 0; k < 3; ++k) reach = std::max(reach, std::abs(p[k] - at[k]) / (p[k] > at[k] ? 0.97 - at[k] : at[k] - 0.03));
  if (reach > 1)
    for (auto& p : m.positions)
      for (int k = 0; k < 3; ++k) p[k] = at[k] + (p[k] - at[k]) / reach;
  return m;
}

/// The data/ meshes the cases draw from, normalized.
inline std::vector<TriMesh> load_case_models(const std::string& data_dir) {
  std::vector<TriMesh> models;
  for (const char* name : kModels) models.push_back(normalized(read_mesh(data_dir + "/" + name + ".obj")));
  return models;
}

/// Operands (meshes in the unit cube), the operations combining them left to right, the depth.
struct CsgCase {
  int depth = 8;
  std::vector<TriMesh> inputs;
  std::vector<CsgOp> ops;
  std::string text;
};

/// Case `seed`: 2 operands, or (a third of the cases) a chain of 3-4; depth 7-9 unless fixed.
inline CsgCase make_case(uint64_t seed, int fixed_depth, const std::vector<TriMesh>& models) {
  Rng r{seed * 0x2545F4914F6CDD1Dull + 1};
  CsgCase k;
  k.depth = fixed_depth > 0 ? fixed_depth : 7 + r.below(3);
  const int operands = 2 + (r.below(3) == 0 ? 1 + r.below(2) : 0);
  for (int i = 0; i < operands; ++i) {
    std::string what;
    k.inputs.push_back(random_operand(r, models, what));
    if (i > 0) {
      k.ops.push_back(CsgOp(r.below(3)));
      k.text += " " + to_string(k.ops.back()) + " ";
    }
    k.text += what;
  }
  return k;
}

}  // namespace pic
