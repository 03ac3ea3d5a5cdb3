// Rounding a mesh to the 32-bit floats STL and GLB files hold, without making it cross itself.
//
// The contour is free of self-intersections in double precision, but its construction may put
// a vertex within a float's step of another triangle (a face point on a cell face beside
// another sheet's triangle, a vertex an inset away from a cell border); rounding each
// coordinate to the nearest float then folds a few such pairs through each other (spot: 7 of
// 148,722 triangles, a CSG result with flush faces: 827 of 64,478). Each coordinate has two
// floats around it; where the nearest makes a crossing, the vertices of the crossing triangles
// try the other combinations and keep the one with the fewest crossings around them (then, for
// what is left, floats up to three steps out: a point can sit so close beside a triangle that
// no choice of the two nearest floats keeps it off). Every test is exact on the rounded values.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

#include <tbb/parallel_sort.h>

#include "geometry/box_tree.h"
#include "geometry/predicates.h"
#include "measure/self_intersect.h"
#include "pic/measure.h"
#include "pic/types.h"

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

/// The floats a coordinate x may take: the one at or below it and the one at or above it
/// (`wide`: two more steps out on each side).
std::vector<double> float_choices(double x, bool wide) {
  constexpr float kUp = std::numeric_limits<float>::infinity();
  float f = static_cast<float>(x);
  asm volatile("" : "+x"(f));
  float lo = double(f) <= x ? f : std::nextafter(f, -kUp), hi = double(f) >= x ? f : std::nextafter(f, kUp);
  std::vector<double> out;
  if (wide) {
    const float l2 = std::nextafter(lo, -kUp), h2 = std::nextafter(hi, kUp);
    out = {std::nextafter(l2, -kUp), l2, lo, hi, h2, std::nextafter(h2, kUp)};
  } else {
    out = {lo, hi};
  }
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
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

/// The vertices that may move, their triangles, and every triangle near those: the only part
/// of the mesh the choices look at.
struct Neighbourhood {
  std::vector<std::vector<uint32_t>> around;  // per vertex: its triangles (moving ones only)
  std::vector<uint32_t> near;                 // mesh triangle of each box in `tree`
  std::vector<uint32_t> slot;                 // mesh triangle -> its box, or none
  std::vector<Box> boxes;
  BoxTree tree{{}};

  Neighbourhood(const TriMesh& m, const std::vector<Vec3>& r, const std::vector<uint32_t>& verts, double slack)
      : around(m.positions.size()), slot(m.triangles.size(), ~uint32_t{0}) {
    std::vector<char> moving(m.positions.size(), 0);
    for (uint32_t v : verts) moving[v] = 1;
    std::vector<Box> reach;
    for (uint32_t t = 0; t < m.triangles.size(); ++t)
      for (uint32_t v : m.triangles[t])
        if (moving[v]) {
          around[v].push_back(t);
          reach.push_back(box_of(r, m.triangles[t], 2 * slack));
        }
    const BoxTree reach_tree(reach);
    for (uint32_t t = 0; t < m.triangles.size(); ++t) {
      const Box b = box_of(r, m.triangles[t], slack);
      bool hit = false;
      reach_tree.query(b, [&](uint32_t) { hit = true; });
      if (!hit) continue;
      slot[t] = uint32_t(near.size());
      near.push_back(t);
      boxes.push_back(b);
    }
    tree = BoxTree(boxes);
  }
  /// Calls f(u) for each triangle u that triangle t (a triangle at a moving vertex) crosses.
  /// By index: the rounded positions are all distinct, as the doubles were, unless a choice
  /// makes two equal — then their triangles count as crossing, so no choice merges vertices.
  template <class F>
  void crossings_of(const TriMesh& m, const std::vector<Vec3>& r, uint32_t t, F&& f) const {
    const Tri& a = m.triangles[t];
    tree.query(boxes[slot[t]], [&](uint32_t k) {
      const uint32_t u = near[k];
      if (u != t && !degenerate(r, m.triangles[u]) && detail::triangles_intersect(r, a, m.triangles[u])) f(u);
    });
  }
  size_t count_at(const TriMesh& m, const std::vector<Vec3>& r, uint32_t v) const {
    size_t count = 0;
    for (uint32_t t : around[v]) {
      if (degenerate(r, m.triangles[t])) count += 4;  // flattening a triangle is worse than most crossings
      else crossings_of(m, r, t, [&](uint32_t) { ++count; });
    }
    return count;
  }
};

/// Chooses, vertex by vertex, the rounding direction of each coordinate of `verts` in the
/// rounded positions `r` (of `m`'s) for the fewest crossings around it. A crossing left brings
/// the vertices of both its triangles into the next round. Only triangles at the vertices
/// moved can cross anew, so counting around them answers for the whole mesh.
void choose_roundings(const TriMesh& m, std::vector<Vec3>& r, std::vector<uint32_t> verts) {
  // A vertex moves by at most three float steps: boxes grown by four steps of the largest
  // coordinate cover every choice.
  double big = 0;
  for (const Vec3& p : r)
    for (double c : p) big = std::max(big, std::abs(c));
  const double slack = 4 * big * 0x1p-23;
  for (int round = 0; round < 4; ++round) {
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
    const Neighbourhood nb(m, r, verts, slack);
    // First the two floats around each coordinate; where that leaves a crossing, up to three
    // steps out (a vertex a hair's breadth beside another triangle may need the room).
    const bool wide = round > 0;
    for (uint32_t v : verts) {
      std::array<std::vector<double>, 3> choice;
      for (int k = 0; k < 3; ++k) choice[k] = float_choices(m.positions[v][k], wide);
      Vec3 best = r[v];
      size_t best_count = nb.count_at(m, r, v);
      for (double x : choice[0])
        for (double y : choice[1])
          for (double z : choice[2]) {
            if (best_count == 0) break;
            r[v] = {x, y, z};
            if (r[v] == best) continue;
            const size_t count = nb.count_at(m, r, v);
            if (count < best_count) best_count = count, best = r[v];
          }
      r[v] = best;
    }
    size_t left = 0;
    const size_t before = verts.size();
    for (size_t i = 0; i < before; ++i)
      for (uint32_t t : nb.around[verts[i]]) {
        if (degenerate(r, m.triangles[t])) {
          ++left;
          continue;
        }
        nb.crossings_of(m, r, t, [&](uint32_t u) {
          ++left;
          verts.insert(verts.end(), m.triangles[t].begin(), m.triangles[t].end());
          verts.insert(verts.end(), m.triangles[u].begin(), m.triangles[u].end());
        });
      }
    if (left == 0) return;
  }
}

}  // namespace

bool holds_floats(const TriMesh& mesh) {
  return std::all_of(mesh.positions.begin(), mesh.positions.end(), [](const Vec3& p) {
    return nearest_float(p[0]) == p[0] && nearest_float(p[1]) == p[1] && nearest_float(p[2]) == p[2];
  });
}

TriMesh round_to_float32(const TriMesh& mesh) {
  // Already floats (rounded before, or read from an STL): nothing moves, nothing to check.
  if (holds_floats(mesh)) return mesh;
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
