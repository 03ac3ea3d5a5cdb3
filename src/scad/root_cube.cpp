// The root cube of an evaluated model: around where its result can lie, not around every leaf,
// when that saves a level of the octree (a part cut in half by a box ten times its size, or
// sectioned by a big intersecting block, keeps the resolution of the part).
#include <algorithm>
#include <array>

#include "geometry/convex_hull.h"
#include "geometry/tolerances.h"
#include "pic/sample.h"
#include "scad/lower.h"

namespace pic::detail::scad {

namespace {

using Box = std::array<Vec3, 2>;

Box nothing() { return {Vec3{kHuge, kHuge, kHuge}, Vec3{-kHuge, -kHuge, -kHuge}}; }
bool is_empty(const Box& b) { return b[0][0] > b[1][0] || b[0][1] > b[1][1] || b[0][2] > b[1][2]; }
void grow(Box& b, const Box& o) {
  for (int k = 0; k < 3; ++k) b[0][k] = std::min(b[0][k], o[0][k]), b[1][k] = std::max(b[1][k], o[1][k]);
}
bool within(const Box& b, const Box& outer) {
  if (is_empty(b)) return true;
  for (int k = 0; k < 3; ++k)
    if (b[0][k] < outer[0][k] || b[1][k] > outer[1][k]) return false;
  return true;
}

Box leaves_box(const Solid& s) {
  Box b = nothing();
  size_t leaves = 0, triangles = 0;
  solid_bounds(s, b[0], b[1], leaves, triangles);
  return b;
}

/// Where the result of `s` can lie: a difference within its first operand, an intersection
/// within the common part of its operands' boxes, a union within all of theirs; a hull or a
/// Minkowski sum wherever its leaves (grown by the body) reach.
Box result_box(const Solid& s) {
  switch (s.kind) {
    case Solid::Kind::Empty: return nothing();
    case Solid::Kind::Mesh: return box_of(s.mesh.positions);
    case Solid::Kind::Union: {
      Box b = nothing();
      for (const Solid& c : s.children) grow(b, result_box(c));
      return b;
    }
    case Solid::Kind::Intersect: {
      Box b = result_box(s.children[0]);
      for (size_t i = 1; i < s.children.size(); ++i) {
        const Box c = result_box(s.children[i]);
        for (int k = 0; k < 3; ++k) b[0][k] = std::max(b[0][k], c[0][k]), b[1][k] = std::min(b[1][k], c[1][k]);
      }
      return b;
    }
    case Solid::Kind::Difference: return result_box(s.children[0]);
    case Solid::Kind::Hull:
    case Solid::Kind::RoundSum: return leaves_box(s);
  }
  return nothing();
}

/// A convex leaf cut to `keep`: the hull of its part inside; Empty when nothing of it is.
void cut_convex(Solid& leaf, const Box& keep) {
  TriMesh part = leaf.mesh;
  for (int k = 0; k < 3; ++k)
    for (const bool high : {false, true}) {
      Plane p{{0, 0, 0}, high ? keep[1][k] : -keep[0][k]};
      p.n[k] = high ? 1 : -1;
      const Box b = box_of(part.positions);
      if (high ? b[1][k] <= keep[1][k] : b[0][k] >= keep[0][k]) continue;  // not crossed
      const std::vector<Vec3> inside = clip_convex(part, p, false, 0);
      part = inside.empty() ? TriMesh{} : convex_hull(inside);
      if (part.triangles.empty()) {
        leaf = Solid{};
        return;
      }
    }
  leaf.mesh = std::move(part);
}

/// Cuts the leaves of `s` that reach out of `keep` to their parts inside. Inside a box, a
/// union, intersection or difference depends only on its operands' parts inside it; a hull or
/// a sum does not, and a leaf that is not convex would need a Boolean to be cut: false when
/// one of those reaches out (`s` then partly cut: the caller keeps its own copy).
bool cut_to(Solid& s, const Box& keep) {
  if (within(leaves_box(s), keep)) return true;
  switch (s.kind) {
    case Solid::Kind::Mesh:
      if (!is_convex(s.mesh)) return false;
      cut_convex(s, keep);
      return true;
    case Solid::Kind::Union:
    case Solid::Kind::Intersect:
    case Solid::Kind::Difference:
      return std::all_of(s.children.begin(), s.children.end(), [&](Solid& c) { return cut_to(c, keep); });
    default: return false;
  }
}

}  // namespace

Cube root_cube(Solid& model) {
  const Box all = leaves_box(model);
  const Cube around_all = bounding_cube(TriMesh{{all[0], all[1]}, {}});
  const Box result = result_box(model);
  if (is_empty(result)) return around_all;
  const double extent = std::max({result[1][0] - result[0][0], result[1][1] - result[0][1], result[1][2] - result[0][2]});
  if (!(extent > 0)) return around_all;
  const Cube around_result = bounding_cube(TriMesh{{result[0], result[1]}, {}});
  if (around_result.size * 2 > around_all.size) return around_all;
  // Inside the root cube's margin: a cut leaf's new faces lie strictly inside the cube.
  Box keep = result;
  for (int k = 0; k < 3; ++k) keep[0][k] -= extent / 64, keep[1][k] += extent / 64;
  Solid cut = model;
  if (!cut_to(cut, keep)) return around_all;
  model = std::move(cut);
  return around_result;
}

}  // namespace pic::detail::scad
