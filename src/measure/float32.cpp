// Rounding a mesh to the 32-bit floats STL and GLB files hold, without making it cross itself.
//
// The contour is free of self-intersections in double precision, but its construction may put
// a vertex within a float's step of another triangle (a face point on a cell face beside
// another sheet's triangle, a vertex an inset away from a cell border); rounding each
// coordinate to the nearest float then folds a few such pairs through each other (spot: 7 of
// 148,722 triangles, a CSG result with flush faces: 827 of 64,478). Each coordinate has two
// floats around it; where the nearest makes a crossing, the vertices of the crossing triangles
// try the other combinations and keep the one with the fewest crossings around them. Every
// test is exact on the rounded values.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include <tbb/parallel_sort.h>

#include "geometry/box_tree.h"
#include "geometry/predicates.h"
#include "measure/self_intersect.h"
#include "pic/pic.h"

namespace pic {
namespace {

using detail::Box;
using detail::BoxTree;
using Tri = std::array<uint32_t, 3>;

/// x rounded to the nearest float. The barrier keeps g++ 12 -O3 from dropping the rounding:
/// in a loop over positions it left the last few unrounded (its vectorizer's epilogue).
double nearest_float(double x) {
  float f = static_cast<float>(x);
  asm volatile("" : "+x"(f));
  return f;
}

/// The float at or below x and the float at or above it (equal when x is a float).
std::array<double, 2> float_neighbours(double x) {
  float f = static_cast<float>(x);
  asm volatile("" : "+x"(f));
  const double d = f;
  if (d == x) return {d, d};
  if (d < x) return {d, double(std::nextafter(f, std::numeric_limits<float>::infinity()))};
  return {double(std::nextafter(f, -std::numeric_limits<float>::infinity())), d};
}

Box box_of(const std::vector<Vec3>& x, const Tri& t, double slack) {
  Box b;
  for (int k = 0; k < 3; ++k) {
    b.lo[k] = std::min({x[t[0]][k], x[t[1]][k], x[t[2]][k]}) - slack;
    b.hi[k] = std::max({x[t[0]][k], x[t[1]][k], x[t[2]][k]}) + slack;
  }
  return b;
}

bool degenerate(const std::vector<Vec3>& x, const Tri& t) {
  return t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || detail::projection_axis(x[t[0]], x[t[1]], x[t[2]]) < 0;
}

/// Repairs the crossings of `pairs` in the rounded positions `r` (of `m`'s positions) by
/// choosing, vertex by vertex, the rounding direction of each coordinate. Returns the crossings
/// left: only triangles at the vertices it may move can cross anew, so counting around them
/// answers for the whole mesh.
size_t choose_roundings(const TriMesh& m, std::vector<Vec3>& r, std::vector<uint32_t> verts) {
  const size_t n = m.triangles.size();
  // A vertex moves by less than a float's step: boxes grown by two steps of the largest
  // coordinate cover every choice.
  double big = 0;
  for (const Vec3& p : r)
    for (double c : p) big = std::max(big, std::abs(c));
  const double slack = 2 * big * 0x1p-23;
  std::sort(verts.begin(), verts.end());
  verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
  std::vector<char> moving(m.positions.size(), 0);
  for (uint32_t v : verts) moving[v] = 1;
  // The triangles at the vertices that may move, and every triangle near them: the only ones
  // the tests below look at (a handful of the mesh's).
  std::vector<std::vector<uint32_t>> around(m.positions.size());
  std::vector<Box> reach;
  for (uint32_t t = 0; t < n; ++t)
    for (uint32_t v : m.triangles[t])
      if (moving[v]) {
        around[v].push_back(t);
        reach.push_back(box_of(r, m.triangles[t], 2 * slack));
      }
  const BoxTree reach_tree(reach);
  std::vector<uint32_t> near;  // mesh triangle of each box below
  std::vector<Box> boxes;
  std::vector<uint32_t> slot(n, ~uint32_t{0});
  for (uint32_t t = 0; t < n; ++t) {
    const Box b = box_of(r, m.triangles[t], slack);
    bool hit = false;
    reach_tree.query(b, [&](uint32_t) { hit = true; });
    if (!hit) continue;
    slot[t] = uint32_t(near.size());
    near.push_back(t);
    boxes.push_back(b);
  }
  const BoxTree tree(boxes);
  // Crossings of triangle t with the triangles near it (by index: the rounded positions are
  // all distinct, as the doubles were, unless a choice makes two equal — then the two
  // triangles count as crossing, so no choice merges two vertices).
  auto crossings_of = [&](uint32_t t) {
    const Tri& a = m.triangles[t];
    if (degenerate(r, a)) return size_t{4};  // flattening a triangle is worse than most crossings
    size_t count = 0;
    tree.query(boxes[slot[t]], [&](uint32_t k) {
      const uint32_t u = near[k];
      if (u != t && !degenerate(r, m.triangles[u])) count += detail::triangles_intersect(r, a, m.triangles[u]);
    });
    return count;
  };
  auto crossings_at = [&](uint32_t v) {
    size_t count = 0;
    for (uint32_t t : around[v]) count += crossings_of(t);
    return count;
  };
  for (int round = 0; round < 3; ++round) {
    for (uint32_t v : verts) {
      std::array<std::array<double, 2>, 3> choice;
      for (int k = 0; k < 3; ++k) choice[k] = float_neighbours(m.positions[v][k]);
      Vec3 best = r[v];
      size_t best_count = crossings_at(v);
      for (int c = 0; c < 8 && best_count > 0; ++c) {
        r[v] = {choice[0][c & 1], choice[1][(c >> 1) & 1], choice[2][(c >> 2) & 1]};
        if (r[v] == best) continue;
        const size_t count = crossings_at(v);
        if (count < best_count) best_count = count, best = r[v];
      }
      r[v] = best;
    }
    // Each crossing counted from both triangles when both are at moved vertices: any left?
    std::vector<uint32_t> tris;
    for (uint32_t v : verts) tris.insert(tris.end(), around[v].begin(), around[v].end());
    std::sort(tris.begin(), tris.end());
    tris.erase(std::unique(tris.begin(), tris.end()), tris.end());
    size_t left = 0;
    for (uint32_t t : tris) left += crossings_of(t);
    if (left == 0) return 0;
    if (round == 2) return left;
  }
  return 0;
}

}  // namespace

TriMesh round_to_float32(const TriMesh& mesh) {
  TriMesh out = mesh;
  for (Vec3& p : out.positions)
    for (double& c : p) c = nearest_float(c);
  // Rounding can only add crossings where the doubles come within a float's step: nothing to
  // do when the rounded mesh has none, else choices at the crossings' vertices.
  std::vector<uint32_t> verts;
  // Distinct positions that became one: a reader would merge them (the copies of a split
  // vertex sit a 1/1024 step apart, often less than a float's).
  std::vector<uint32_t> order(out.positions.size());
  std::iota(order.begin(), order.end(), 0u);
  tbb::parallel_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return out.positions[a] < out.positions[b]; });
  bool distinct = true;
  for (size_t i = 1; i < order.size(); ++i)
    if (out.positions[order[i]] == out.positions[order[i - 1]]) {
      distinct = false;
      if (mesh.positions[order[i]] != mesh.positions[order[i - 1]]) verts.insert(verts.end(), {order[i], order[i - 1]});
    }
  // Triangles the rounding flattened.
  for (const Tri& t : out.triangles)
    if (degenerate(out.positions, t) && !degenerate(mesh.positions, t)) verts.insert(verts.end(), t.begin(), t.end());
  const auto pairs = distinct ? detail::intersecting_pairs_of_distinct(out) : self_intersecting_pairs(out);
  for (const auto& [a, b] : pairs)
    for (uint32_t t : {a, b}) verts.insert(verts.end(), out.triangles[t].begin(), out.triangles[t].end());
  if (!verts.empty()) choose_roundings(mesh, out.positions, std::move(verts));
  return out;
}

}  // namespace pic
