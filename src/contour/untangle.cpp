// Triangulating the dual polygons of the whole contour without self-intersections.
//
// Dual contouring's plain rule (split each quad along the diagonal that folds most) leaves a
// few triangles crossing their neighbours: fold-overs of nearly coplanar slivers and long
// triangles of the two faces meeting at a sharp crease. Each dual polygon has three ways to
// become triangles: the preferred two-triangle split, the other diagonal, and — after Ju and
// Udeshi 2006, "Intersection-free contouring on an octree grid" — a fan around a point
// strictly inside its minimal edge (each fan triangle (x, v_k, v_k+1) lies in the tetrahedron
// spanned by the edge and v_k, v_k+1, which on a uniform grid is disjoint from every other
// polygon's tetrahedra). On an adaptive octree that containment argument does not hold
// everywhere (a segment between a big and a small cell's vertices need not cross their
// common face), so the choice is made by the exact test itself: starting from the plain
// split, every polygon that has a triangle in an intersecting pair takes the option with the
// fewest exact intersections against its neighbours (ties keep the current, then the cheaper
// option), and this repeats until no pair is left or nothing changes. Only polygons near a
// crossing change, so the triangle count grows by a few percent at most. What options cannot
// resolve, vertex moves try (within a finest cell, then along the vertex's own planes; a corner,
// whose every move leaves some of its planes, by one finest cell in all rounds together); then the
// sides where the containment fails are split at a point of their cells' common face
// (Untangler::split_sides); moves off the planes, up to 1/8 of the vertex's cell, come next,
// and anywhere in the vertex's cell last (kLastStage).
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <numeric>
#include <unordered_map>
#include <vector>

#include <Eigen/Dense>
#include <tbb/parallel_for.h>

#include "geometry/box_tree.h"
#include "contour/dual_walk.h"
#include "geometry/predicates.h"
#include "geometry/vec3.h"

namespace pic::detail {
namespace {

using Tri = std::array<uint32_t, 3>;
/// A polygon's triangles: a fan over a quad with its 4 sides split has 8.
constexpr int kMaxTris = 8;
using Tris = std::array<Tri, kMaxTris>;
constexpr uint32_t kNoSplit = UINT32_MAX;

/// Rounds of re-triangulation; each starts by re-testing the polygons the previous one changed.
/// A round changes options, or moves vertices, or changes pairs of polygons jointly.
constexpr int kMaxRounds = 16;
/// Largest vertex move, in finest cells. Moves are tried from 1/16 of it up and the least that
/// works is kept; measured on spot (1,117 crossings at depth 12), 1/4 of a cell leaves 48 and
/// 1/2 leaves 8, one cell none. The vertex stays inside its own cell either way.
constexpr double kMaxPull = 1.0;
/// How far (in finest cells) the other diagonal or a fan may move the surface of a polygon.
constexpr double kMaxDeviation = 0.25;
/// How far (in finest cells) vertices of different cells that coincide are moved apart.
constexpr double kSeparation = 1.0 / 64;
/// How far (in finest cells) a last-resort move of a coarse vertex beyond a finest cell may take
/// it off the planes of its triangles.
constexpr double kFarMoveDeviation = 0.25;
/// The last stage: what the others leave (a rotated box at depth 7, harness seed 74: 3 pairs
/// where a crease's finest triangles meet two 8-cell leaves' long ones, and no single move
/// within 1/8 of a cell undoes them) may move the crossing triangles' vertices anywhere in
/// their own cells, off their planes: a bounded dent is better than a file no tool accepts.
constexpr int kLastStage = 3;
/// Directions along which the planes of a vertex's triangles vary less than this (relative
/// eigenvalue of the sum of their normals' outer products) count as lying in all of them.
constexpr double kNullCutoff = 0.05;
/// A vertex whose triangles' planes spread in every direction (the least eigenvalue of the
/// same sum above this fraction of the largest) is a corner: a cone's apex, a box's corner.
/// Every move takes a corner off some of its planes by the whole move, so ordinary moves may
/// take it at most kMaxPull from where it started, in all rounds together (see move_vertex).
constexpr double kCornerSpread = 0.2;

// kSplitFan: the fan with some sides split at a point on their cells' common face (see
// Untangler::split_sides).
enum Option : uint8_t { kPreferred = 0, kOtherDiagonal = 1, kFan = 2, kSplitFan = 3 };

struct Polygons {
  const std::vector<MeshPolygon>& polys;
  std::vector<uint8_t> preferred_a;  // quads: split_quad chose diagonal v0 v2
  uint32_t fan_base;                 // vertex id of polygon i's fan point: fan_base + i
  // Sides split at a face point (vertex id; kNoSplit: not split): side k runs from v[k] to
  // v[k + 1]. Empty until a side is split.
  std::vector<std::array<uint32_t, 4>> split_at;

  /// The triangles of polygon i under option o, as vertex ids (fan point: fan_base + i).
  int triangles(size_t i, uint8_t o, Tris& out) const {
    const MeshPolygon& p = polys[i];
    const auto& v = p.v;
    if (o == kFan) {
      for (int k = 0; k < p.count; ++k) out[k] = {fan_base + uint32_t(i), v[k], v[(k + 1) % p.count]};
      return p.count;
    }
    if (o == kSplitFan) {
      int c = 0;
      for (int k = 0; k < p.count; ++k) {
        const uint32_t next = v[(k + 1) % p.count], mid = split_at[i][k];
        if (mid == kNoSplit) {
          out[c++] = {fan_base + uint32_t(i), v[k], next};
        } else {
          out[c++] = {fan_base + uint32_t(i), v[k], mid};
          out[c++] = {fan_base + uint32_t(i), mid, next};
        }
      }
      return c;
    }
    if (p.count == 3) {
      out[0] = {v[0], v[1], v[2]};
      return 1;
    }
    const bool a = (o == kPreferred) == bool(preferred_a[i]);
    if (a) {
      out[0] = {v[0], v[1], v[2]};
      out[1] = {v[0], v[2], v[3]};
    } else {
      out[0] = {v[0], v[1], v[3]};
      out[1] = {v[1], v[2], v[3]};
    }
    return 2;
  }
};

Box box_of(const std::vector<Vec3>& x, const Tri& t) {
  Box b{x[t[0]], x[t[0]]};
  for (int k = 1; k < 3; ++k)
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = std::min(b.lo[a], x[t[k]][a]);
      b.hi[a] = std::max(b.hi[a], x[t[k]][a]);
    }
  return b;
}

/// Options that keep the surface where it is, for a polygon with corners q[0..count) and fan
/// point f: the other diagonal only of a quad whose two splits lie within `limit` of each
/// other (the distance between its diagonals' lines) and that may take it (`other_ok`), the
/// fan only when f is that close to the current triangles' planes. A big non-planar quad
/// folded the other way moves the surface by up to its bulge.
std::vector<uint8_t> surface_keeping_options(const std::array<Vec3, 4>& q, int count, const Vec3& f, bool other_ok,
                                             double limit) {
  std::vector<uint8_t> o{kPreferred};
  auto plane_distance = [&](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& r) {
    const Vec3 n = cross3(sub3(b, a), sub3(c, a));
    const double l = norm3(n);
    return l > 0 ? std::abs(dot3(n, sub3(r, a))) / l : 0.0;
  };
  if (count == 3) {
    if (plane_distance(q[0], q[1], q[2], f) <= limit) o.push_back(kFan);
    return o;
  }
  const Vec3 n = cross3(sub3(q[2], q[0]), sub3(q[3], q[1]));
  const double l = norm3(n);
  const double bulge = l > 0 ? std::abs(dot3(n, sub3(q[1], q[0]))) / l : 0.0;
  if (bulge <= limit && other_ok) o.push_back(kOtherDiagonal);
  if (std::min(plane_distance(q[0], q[1], q[2], f), plane_distance(q[0], q[2], q[3], f)) <= limit &&
      std::min(plane_distance(q[0], q[1], q[3], f), plane_distance(q[1], q[2], q[3], f)) <= limit)
    o.push_back(kFan);
  return o;
}

/// Move targets for a vertex at `was` along the common null space of its triangles' planes
/// (m: the sum of their unit normals' outer products; a flat face's plane, a crease's line):
/// the existing targets projected onto it, and straight along it both ways (an in-plane fold
/// needs a sideways move), each reaching up to `along_reach`.
void add_targets_along_planes(const Eigen::Matrix3d& m, const Vec3& was, double along_reach,
                              std::vector<Vec3>& targets, std::vector<double>& scale) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
  const Eigen::Vector3d ev = eig.eigenvalues();
  for (size_t k = 0, c = targets.size(); k < c; ++k) {
    const Eigen::Vector3d d(targets[k][0] - was[0], targets[k][1] - was[1], targets[k][2] - was[2]);
    Eigen::Vector3d along = Eigen::Vector3d::Zero();
    for (int a = 0; a < 3; ++a)
      if (ev[a] < kNullCutoff * ev[2]) along += eig.eigenvectors().col(a) * eig.eigenvectors().col(a).dot(d);
    if (along.norm() > 0) {
      targets.push_back({was[0] + along[0], was[1] + along[1], was[2] + along[2]});
      scale.push_back(along_reach);
    }
  }
  for (int a = 0; a < 3; ++a)
    if (ev[a] < kNullCutoff * ev[2])
      for (double sgn : {-1.0, 1.0}) {
        const Eigen::Vector3d e = sgn * along_reach * eig.eigenvectors().col(a);
        targets.push_back({was[0] + e[0], was[1] + e[1], was[2] + e[2]});
        scale.push_back(along_reach);
      }
}

/// Vertex ids sorted by position (ties by id).
std::vector<uint32_t> sorted_by_position(const std::vector<Vec3>& x) {
  std::vector<uint32_t> perm(x.size());
  std::iota(perm.begin(), perm.end(), 0u);
  std::sort(perm.begin(), perm.end(), [&](uint32_t a, uint32_t b) { return x[a] < x[b] || (x[a] == x[b] && a < b); });
  return perm;
}

/// Two cells' vertices clamped to the same point (a corner or edge the cells share) are one
/// vertex to a reader that merges equal positions: a pinch, and neither could move later.
/// Each is moved a hair (kSeparation finest cells) toward its own cell's centre. Returns how
/// many moved.
size_t separate_coincident(std::vector<Vec3>& x, const std::vector<VertexCell>& cells, double finest) {
  const std::vector<uint32_t> perm = sorted_by_position(x);
  std::vector<uint32_t> shared;
  for (size_t k = 0; k < perm.size(); ++k)
    if ((k > 0 && x[perm[k]] == x[perm[k - 1]]) || (k + 1 < perm.size() && x[perm[k]] == x[perm[k + 1]]))
      shared.push_back(perm[k]);
  size_t moved = 0;
  for (uint32_t v : shared) {
    const Vec3 d = sub3(cells[v].center, x[v]);
    const double len = norm3(d);
    if (!(len > 0)) continue;
    const double f = std::min(0.5, kSeparation * finest / len);
    for (int a = 0; a < 3; ++a) x[v][a] += f * d[a];
    ++moved;
  }
  return moved;
}

/// Positions for the exact test: the vertices (bit-equal ones merged, as a reader of the file
/// sees them) followed by every polygon's candidate fan point.
struct MergedPositions {
  std::vector<Vec3> xm;
  std::vector<uint32_t> mid;     // vertex id (fan point of polygon i: nv + i) -> index in xm
  std::vector<uint32_t> copies;  // vertices at each merged position
};

MergedPositions merge_positions(const std::vector<Vec3>& x, const std::vector<MeshPolygon>& polys) {
  const auto nv = static_cast<uint32_t>(x.size());
  const size_t n = polys.size();
  MergedPositions m;
  m.mid.resize(size_t(nv) + n);
  const std::vector<uint32_t> perm = sorted_by_position(x);
  for (size_t k = 0; k < perm.size(); ++k) {
    if (k == 0 || x[perm[k]] != x[perm[k - 1]]) m.xm.push_back(x[perm[k]]);
    m.mid[perm[k]] = uint32_t(m.xm.size() - 1);
  }
  m.copies.assign(m.xm.size(), 0);
  for (uint32_t v = 0; v < nv; ++v) ++m.copies[m.mid[v]];
  for (size_t i = 0; i < n; ++i) {
    const MeshPolygon& p = polys[i];
    std::array<Vec3, 4> q;
    for (int k = 0; k < p.count; ++k) q[k] = x[p.v[k]];
    m.mid[nv + i] = uint32_t(m.xm.size());
    m.xm.push_back(fan_point(q, p.count, p.e0, p.e1));
  }
  return m;
}

/// Whether each quad may take its other diagonal: not when that is an edge the mesh has (or
/// may have) elsewhere — a polygon's side or another quad's diagonal would become an edge of
/// four triangles.
std::vector<uint8_t> other_diagonal_allowed(const std::vector<MeshPolygon>& polys) {
  auto key = [](uint32_t a, uint32_t b) { return uint64_t(std::min(a, b)) << 32 | std::max(a, b); };
  std::vector<uint64_t> pairs_used;
  for (const auto& p : polys) {
    for (int k = 0; k < p.count; ++k) pairs_used.push_back(key(p.v[k], p.v[(k + 1) % p.count]));
    if (p.count == 4) {
      pairs_used.push_back(key(p.v[0], p.v[2]));
      pairs_used.push_back(key(p.v[1], p.v[3]));
    }
  }
  std::sort(pairs_used.begin(), pairs_used.end());
  auto uses = [&](uint64_t k) {
    return std::upper_bound(pairs_used.begin(), pairs_used.end(), k) - std::lower_bound(pairs_used.begin(), pairs_used.end(), k);
  };
  std::vector<uint8_t> ok(polys.size(), 0);
  for (size_t i = 0; i < polys.size(); ++i)
    if (polys[i].count == 4) {
      const auto& v = polys[i].v;
      ok[i] = uses(key(v[0], v[2])) == 1 && uses(key(v[1], v[3])) == 1;
    }
  return ok;
}

/// The polygons around each vertex v: around[first[v] .. first[v + 1]).
struct PolygonsAround {
  std::vector<uint32_t> first, around;
};

PolygonsAround polygons_around(const std::vector<MeshPolygon>& polys, uint32_t nv) {
  PolygonsAround r;
  r.first.assign(size_t(nv) + 1, 0);
  for (const auto& p : polys)
    for (int k = 0; k < p.count; ++k) ++r.first[p.v[k] + 1];
  for (size_t v = 0; v < nv; ++v) r.first[v + 1] += r.first[v];
  r.around.resize(r.first[nv]);
  std::vector<uint32_t> fill(r.first.begin(), r.first.end() - 1);
  for (uint32_t i = 0; i < polys.size(); ++i)
    for (int k = 0; k < polys[i].count; ++k) r.around[fill[polys[i].v[k]]++] = i;
  return r;
}

/// The search for a triangulation without crossings (see the top of this file): rounds of
/// re-testing what changed, then trying each crossing polygon's options, then moving the
/// vertices of crossing triangles, then changing crossing pairs of polygons jointly, with
/// ever larger moves when nothing else is left. Positions are tested as a reader of the file
/// sees them (bit-equal vertices merged); `x` receives every vertex move.
class Untangler {
 public:
  Untangler(std::vector<Vec3>& x, const std::vector<VertexCell>& cells, Polygons& polygons, double finest,
            std::vector<uint8_t>& opt, TriangulationStats& st)
      : x_(x), cells_(cells), polys_(polygons.polys), polygons_(polygons), finest_(finest), opt_(opt), st_(st),
        n_(polys_.size()), nv_(static_cast<uint32_t>(x.size())) {
    st_.moved_vertices += separate_coincident(x_, cells_, finest_);
    merged_ = merge_positions(x_, polys_);
    boxes_.resize(n_);
    // The first whole-mesh test needs no room for moves: a tighter tree, 3x fewer candidates.
    build_tree(0);
    other_ok_ = other_diagonal_allowed(polys_);
    star_ = polygons_around(polys_, nv_);
    crossing_.resize(n_);
    self_hits_.assign(n_, 0);
    is_dirty_.assign(n_, 1);
    settled_.assign(n_, 0);
    joint_settled_.assign(n_, 0);
    vertex_settled_.assign(nv_, 0);
    dirty_.resize(n_);
    std::iota(dirty_.begin(), dirty_.end(), 0u);
  }

  /// Runs the rounds; returns each polygon's fan point.
  std::vector<Vec3> run() {
    std::vector<Vec3>& xm = merged_.xm;
    bool moved = false;
    for (int round = 0;; ++round) {
      if (moved) build_tree(kMaxPull * finest_);
      moved = false;
      update_crossings();
      if (round == 0) build_tree(kMaxPull * finest_);
      size_t total = 0;
      std::vector<uint32_t> bad;
      for (uint32_t i = 0; i < n_; ++i) {
        total += self_hits_[i];
        for (const auto& e : crossing_[i]) total += e.first > i ? e.second : 0;
        if (self_hits_[i] || !crossing_[i].empty()) bad.push_back(i);
      }
      if (round == 0) st_.initial_intersections = total;
      st_.remaining_intersections = total;
      st_.rounds = round;
      if (total == 0 || round == kMaxRounds) break;
      if (try_options(bad)) continue;
      if (move_vertices(bad)) {
        moved = true;
        continue;
      }
      if (try_joint_options(bad)) continue;
      if (last_resort_ == 1 && !split_tried_) {
        split_tried_ = true;
        if (split_sides(bad)) {
          moved = true;  // the polygons' boxes grow by their face points
          std::fill(settled_.begin(), settled_.end(), 0);
          std::fill(joint_settled_.begin(), joint_settled_.end(), 0);
          std::fill(vertex_settled_.begin(), vertex_settled_.end(), 0);
          continue;
        }
      }
      if (last_resort_ == kLastStage) break;
      // What is left: let the vertices of coarse cells move further, and try everything once
      // more (only the few polygons still crossing are tried).
      ++last_resort_;
      moved = true;  // the tree needs the larger room
      std::fill(settled_.begin(), settled_.end(), 0);
      std::fill(joint_settled_.begin(), joint_settled_.end(), 0);
      std::fill(vertex_settled_.begin(), vertex_settled_.end(), 0);
    }
    const ptrdiff_t fans = merged_.mid[nv_];  // the fan points follow the vertices in xm
    return std::vector<Vec3>(xm.begin() + fans, xm.begin() + fans + ptrdiff_t(n_));
  }

  /// Positions of the face points (vertex ids fan_base + n + k), in order.
  std::vector<Vec3> face_points() const {
    std::vector<Vec3> r;
    for (size_t k = size_t(nv_) + n_; k < merged_.mid.size(); ++k) r.push_back(merged_.xm[merged_.mid[k]]);
    return r;
  }

 private:
  int merged_tris(size_t i, uint8_t o, Tris& t) const {
    const int c = polygons_.triangles(i, o, t);
    for (int k = 0; k < c; ++k)
      for (auto& v : t[k]) v = merged_.mid[v];
    return c;
  }

  // How far a vertex may move in one round: a finest cell; in the last resort, 1/8 of its own
  // cell's side when that is larger (the long triangles of a coarse cell's vertex cross a fine
  // neighbour's folds by more than a finest cell); in the last stage, half its cell's side.
  double reach(uint32_t v) const {
    if (last_resort_ == kLastStage) return std::max(finest_, cells_[v].half);
    return kMaxPull * (last_resort_ ? std::max(finest_, cells_[v].half / 4) : finest_);
  }
  // Moves along a vertex's planes (last resort) may cross its whole cell.
  double room_of(uint32_t v) const { return last_resort_ ? std::max(reach(v), cells_[v].half) : reach(v); }

  // Every option of polygon i, with its vertices moved by up to kMaxPull finest cells (in one
  // round), stays inside the box of its vertices and its edge grown by that much. Rebuilt
  // after a round that moved vertices.
  void build_tree(double room) {
    const std::vector<Vec3>& xm = merged_.xm;
    const std::vector<uint32_t>& mid = merged_.mid;
    tbb::parallel_for(size_t{0}, n_, [&](size_t i) {
      const MeshPolygon& p = polys_[i];
      Box b{p.e0, p.e0};
      auto grow = [&](const Vec3& q) {
        for (int a = 0; a < 3; ++a) {
          b.lo[a] = std::min(b.lo[a], q[a]);
          b.hi[a] = std::max(b.hi[a], q[a]);
        }
      };
      grow(p.e1);
      for (int k = 0; k < p.count; ++k) grow(xm[mid[p.v[k]]]);
      if (opt_[i] == kSplitFan)
        for (int k = 0; k < p.count; ++k)
          if (polygons_.split_at[i][k] != kNoSplit) grow(xm[mid[polygons_.split_at[i][k]]]);
      double r = 0;  // room for the vertex pulls below
      if (room > 0)
        for (int k = 0; k < p.count; ++k) r = std::max(r, room_of(p.v[k]));
      for (int a = 0; a < 3; ++a) {
        b.lo[a] -= r;
        b.hi[a] += r;
      }
      boxes_[i] = b;
    });
    // The hierarchy of the first build serves every later one: vertices move by a cell at
    // most, so refitting the boxes keeps the queries exact and costs no sorting.
    if (tree_)
      tree_->refit(boxes_);
    else
      tree_ = std::make_unique<BoxTree>(boxes_);
  }

  // Exact intersections of polygon i's triangles under its current option with its
  // neighbours' current triangles and with each other; a degenerate triangle rules the
  // option out. `except`: a neighbour left out (counted once by the caller).
  size_t cost(uint32_t i, uint32_t except) const {
    const std::vector<Vec3>& xm = merged_.xm;
    Tris t;
    const int c = merged_tris(i, opt_[i], t);
    std::array<Box, kMaxTris> tb;
    for (int k = 0; k < c; ++k) {
      if (projection_axis(xm[t[k][0]], xm[t[k][1]], xm[t[k][2]]) < 0) return size_t{1} << 40;
      tb[k] = box_of(xm, t[k]);
    }
    size_t hits = 0;
    for (int a = 0; a < c; ++a)
      for (int b = a + 1; b < c; ++b) hits += triangles_intersect(xm, t[a], t[b]);
    for (int a = 0; a < c; ++a)
      tree_->query(tb[a], [&](uint32_t j) {
        if (j == i || j == except) return;
        Tris u;
        const int cu = merged_tris(j, opt_[j], u);
        for (int b = 0; b < cu; ++b)
          if (overlap(tb[a], box_of(xm, u[b]))) hits += triangles_intersect(xm, t[a], u[b]);
      });
    return hits;
  }

  // Crossings between polygon i under option oi and polygon j under option oj.
  size_t mutual(uint32_t i, uint8_t oi, uint32_t j, uint8_t oj) const {
    const std::vector<Vec3>& xm = merged_.xm;
    Tris t, u;
    const int c = merged_tris(i, oi, t), cu = merged_tris(j, oj, u);
    size_t hits = 0;
    for (int a = 0; a < c; ++a) {
      const Box ta = box_of(xm, t[a]);
      for (int b = 0; b < cu; ++b)
        if (overlap(ta, box_of(xm, u[b]))) hits += triangles_intersect(xm, t[a], u[b]);
    }
    return hits;
  }

  // The polygons around vertex v, counted together (a crossing between two of them twice).
  size_t vertex_cost(uint32_t v) const {
    size_t c = 0;
    for (uint32_t k = star_.first[v]; k < star_.first[v + 1]; ++k) c += cost(star_.around[k], uint32_t(-1));
    return c;
  }

  // Crossings of polygon i with the polygons `keep` accepts (and among its own triangles);
  // zero-area triangles are skipped, as in the whole-mesh test.
  template <class Keep>
  void crossings_of(uint32_t i, Keep&& keep, std::vector<std::pair<uint32_t, uint32_t>>& out, uint32_t& self) const {
    const std::vector<Vec3>& xm = merged_.xm;
    out.clear();
    self = 0;
    Tris t;
    const int c = merged_tris(i, opt_[i], t);
    std::array<Box, kMaxTris> tb;
    std::array<bool, kMaxTris> ok{};
    for (int k = 0; k < c; ++k) {
      ok[k] = projection_axis(xm[t[k][0]], xm[t[k][1]], xm[t[k][2]]) >= 0;
      tb[k] = box_of(xm, t[k]);
    }
    for (int a = 0; a < c; ++a)
      for (int b = a + 1; b < c; ++b) self += ok[a] && ok[b] && triangles_intersect(xm, t[a], t[b]);
    for (int a = 0; a < c; ++a) {
      if (!ok[a]) continue;
      tree_->query(tb[a], [&](uint32_t j) {
        if (j == i || !keep(j)) return;
        Tris u;
        const int cu = merged_tris(j, opt_[j], u);
        uint32_t hits = 0;
        for (int b = 0; b < cu; ++b)
          if (overlap(tb[a], box_of(xm, u[b])) && projection_axis(xm[u[b][0]], xm[u[b][1]], xm[u[b][2]]) >= 0)
            hits += triangles_intersect(xm, t[a], u[b]);
        if (!hits) return;
        auto it = std::find_if(out.begin(), out.end(), [&](const auto& e) { return e.first == j; });
        if (it == out.end())
          out.push_back({j, hits});
        else
          it->second += hits;
      });
    }
  }

  // Re-tests the dirty polygons against their neighbours (the first round: every polygon) and
  // unsettles everything near them.
  void update_crossings() {
    std::sort(dirty_.begin(), dirty_.end());
    dirty_.erase(std::unique(dirty_.begin(), dirty_.end()), dirty_.end());
    for (uint32_t i : dirty_) is_dirty_[i] = 1;
    for (uint32_t i : dirty_) {
      for (const auto& [j, h] : crossing_[i])
        if (!is_dirty_[j]) std::erase_if(crossing_[j], [&](const auto& e) { return e.first == i; });
      crossing_[i].clear();
    }
    std::vector<std::vector<std::pair<uint32_t, uint32_t>>> found(dirty_.size());
    std::vector<uint32_t> found_self(dirty_.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, dirty_.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t k = r.begin(); k < r.end(); ++k) {
        const uint32_t i = dirty_[k];
        crossings_of(i, [&](uint32_t j) { return !is_dirty_[j] || j > i; }, found[k], found_self[k]);
      }
    });
    for (size_t k = 0; k < dirty_.size(); ++k) {
      const uint32_t i = dirty_[k];
      self_hits_[i] = found_self[k];
      for (const auto& [j, h] : found[k]) {
        crossing_[i].push_back({j, h});
        crossing_[j].push_back({i, h});
      }
    }
    const bool all = dirty_.size() == n_;  // nothing was settled yet
    for (uint32_t i : dirty_) {
      is_dirty_[i] = 0;
      if (!all)
        tree_->query(boxes_[i], [&](uint32_t j) {
          settled_[j] = joint_settled_[j] = 0;
          for (int k = 0; k < polys_[j].count; ++k) vertex_settled_[polys_[j].v[k]] = 0;
        });
    }
    dirty_.clear();
  }

  std::vector<uint8_t> options(uint32_t i) const {
    const std::vector<Vec3>& xm = merged_.xm;
    const std::vector<uint32_t>& mid = merged_.mid;
    const MeshPolygon& p = polys_[i];
    if (opt_[i] == kSplitFan) return {kSplitFan};
    std::array<Vec3, 4> q;
    for (int k = 0; k < p.count; ++k) q[k] = xm[mid[p.v[k]]];
    return surface_keeping_options(q, p.count, xm[mid[nv_ + i]], other_ok_[i], kMaxDeviation * finest_);
  }

  // Each crossing polygon not yet settled takes its option with the fewest crossings (ties
  // keep the current one). Returns how many changed.
  size_t try_options(const std::vector<uint32_t>& bad) {
    size_t changed = 0;
    for (uint32_t i : bad) {
      if (settled_[i]) continue;
      settled_[i] = 1;
      const uint8_t was = opt_[i];
      uint8_t best = was;
      size_t best_cost = cost(i, uint32_t(-1));
      for (uint8_t o : options(i)) {
        if (o == was || best_cost == 0) continue;
        opt_[i] = o;
        const size_t c = cost(i, uint32_t(-1));
        if (c < best_cost) {
          best = o;
          best_cost = c;
        }
      }
      opt_[i] = best;
      if (best != was) {
        ++changed;
        dirty_.push_back(i);
      }
    }
    return changed;
  }

  // Only a vertex of a crossing triangle can undo the crossing (moving any other leaves both
  // triangles as they are): the vertices of the bad polygons' crossing triangles, sorted.
  std::vector<uint32_t> crossing_vertices(const std::vector<uint32_t>& bad) const {
    const std::vector<Vec3>& xm = merged_.xm;
    std::vector<uint32_t> verts;
    for (uint32_t i : bad) {
      Tris t, raw;
      const int c = merged_tris(i, opt_[i], t);
      polygons_.triangles(i, opt_[i], raw);
      std::array<bool, kMaxTris> ok{}, hit{};
      for (int k = 0; k < c; ++k) ok[k] = projection_axis(xm[t[k][0]], xm[t[k][1]], xm[t[k][2]]) >= 0;
      for (int a = 0; a < c; ++a)
        for (int b = a + 1; b < c; ++b)
          if (ok[a] && ok[b] && triangles_intersect(xm, t[a], t[b])) hit[a] = hit[b] = true;
      for (const auto& [j, h] : crossing_[i]) {
        Tris u;
        const int cu = merged_tris(j, opt_[j], u);
        for (int a = 0; a < c; ++a) {
          if (!ok[a] || hit[a]) continue;
          const Box ta = box_of(xm, t[a]);
          for (int b = 0; b < cu && !hit[a]; ++b)
            hit[a] = overlap(ta, box_of(xm, u[b])) && projection_axis(xm[u[b][0]], xm[u[b][1]], xm[u[b][2]]) >= 0 &&
                     triangles_intersect(xm, t[a], u[b]);
        }
      }
      for (int a = 0; a < c; ++a)
        if (hit[a])
          for (uint32_t v : raw[a])
            if (v < nv_) verts.push_back(v);
    }
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
    return verts;
  }

  // No choice of triangulation resolves what is left: the polygons' vertices themselves
  // cross (a sliver folded over its neighbour, a crease vertex on the wrong side). Move a
  // vertex of a crossing pair a little — toward its cell's centre or toward the mean of its
  // polygon neighbours, by 1/16 up to 1 finest cell, staying inside its cell — taking the
  // least move that removes the most crossings around it. Returns how many moved.
  size_t move_vertices(const std::vector<uint32_t>& bad) {
    size_t changed = 0;
    for (uint32_t v : crossing_vertices(bad)) {
      // A position shared by two vertices stays put.
      if (merged_.copies[merged_.mid[v]] != 1 || vertex_settled_[v]) continue;
      vertex_settled_[v] = 1;
      if (move_vertex(v)) ++changed;
    }
    return changed;
  }

  // Where vertex v (at `was`) may move: toward its cell's centre and toward the mean of its
  // polygon neighbours, each by up to reach(v). Moves further than a finest cell (coarse
  // vertices in the last resort) must keep the surface where it is: they go along the planes
  // of v's triangles (their common null space: a flat face's plane, a crease's line) and are
  // taken only if v stays within kFarMoveDeviation of every one of those planes (`normals`).
  struct MoveTargets {
    std::vector<Vec3> targets;
    std::vector<double> scale;  // the largest move toward each target
    std::vector<Vec3> normals;  // unit normals of v's triangles (last resort only)
  };
  MoveTargets move_targets(uint32_t v, const Vec3& was) const {
    const std::vector<uint32_t>& first = star_.first;
    const std::vector<uint32_t>& around = star_.around;
    Vec3 ring{0, 0, 0};
    double count = 0;
    for (uint32_t k = first[v]; k < first[v + 1]; ++k) {
      const MeshPolygon& p = polys_[around[k]];
      for (int j = 0; j < p.count; ++j)
        if (p.v[j] != v) {
          for (int a = 0; a < 3; ++a) ring[a] += x_[p.v[j]][a];
          ++count;
        }
    }
    for (double& r : ring) r /= count > 0 ? count : 1;
    MoveTargets mt{{cells_[v].center, ring}, {reach(v), reach(v)}, {}};
    if (!last_resort_) return mt;
    // Moves along the planes keep the surface where it is, so they may cross the whole cell.
    add_targets_along_planes(plane_spread(v, &mt.normals), was, room_of(v), mt.targets, mt.scale);
    return mt;
  }

  // The sum of the outer products of the unit normals of v's triangles (its planes' spread:
  // null directions lie in all of them); `normals` (if given) receives the normals.
  Eigen::Matrix3d plane_spread(uint32_t v, std::vector<Vec3>* normals) const {
    const std::vector<Vec3>& xm = merged_.xm;
    const uint32_t at = merged_.mid[v];
    Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
    for (uint32_t k = star_.first[v]; k < star_.first[v + 1]; ++k) {
      Tris t;
      const int c = merged_tris(star_.around[k], opt_[star_.around[k]], t);
      for (int a = 0; a < c; ++a) {
        if (t[a][0] != at && t[a][1] != at && t[a][2] != at) continue;
        const Vec3 nn = cross3(sub3(xm[t[a][1]], xm[t[a][0]]), sub3(xm[t[a][2]], xm[t[a][0]]));
        const double l = norm3(nn);
        if (!(l > 0)) continue;
        const Eigen::Vector3d e(nn[0] / l, nn[1] / l, nn[2] / l);
        if (normals) normals->push_back({e[0], e[1], e[2]});
        m += e * e.transpose();
      }
    }
    return m;
  }

  // Where corner v started (see kCornerSpread), or null if v is no corner; decided when v is
  // first tried (nothing has moved it before).
  const Vec3* corner_start(uint32_t v, const Vec3& was) {
    auto [it, first] = corner_start_.try_emplace(v);
    if (first) {
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(plane_spread(v, nullptr), Eigen::EigenvaluesOnly);
      const Eigen::Vector3d ev = eig.eigenvalues();
      it->second = {was, ev[2] > 0 && ev[0] > kCornerSpread * ev[2]};
    }
    return it->second.second ? &it->second.first : nullptr;
  }

  // Moves vertex v to the best of its candidate positions; whether it moved.
  bool move_vertex(uint32_t v) {
    std::vector<Vec3>& xm = merged_.xm;
    const std::vector<uint32_t>& mid = merged_.mid;
    const std::vector<uint32_t>& first = star_.first;
    const std::vector<uint32_t>& around = star_.around;
    const Vec3 was = xm[mid[v]];
    const size_t before = vertex_cost(v);
    if (before == 0) return false;
    Vec3 best = was;
    size_t best_cost = before;
    const MoveTargets mt = move_targets(v, was);
    const std::vector<Vec3>& targets = mt.targets;
    const std::vector<double>& scale = mt.scale;
    const std::vector<Vec3>& normals = mt.normals;
    // A corner's ordinary moves add up to at most kMaxPull in all rounds (each round could
    // take another cell: the apex of the CSG harness case 250's cone, a 128-cell leaf's vertex,
    // went 2 cells into the cone in two rounds and cut its tip). Its neighbours' moves or the
    // last resort take what that leaves; only the last resort's later stages may move it further.
    const Vec3* start = last_resort_ < 2 ? corner_start(v, was) : nullptr;
    double best_deviation = 0;
    auto deviation = [&](const Vec3& q) {
      double w = 0;
      for (const Vec3& nn : normals) w = std::max(w, std::abs(dot3(nn, sub3(q, was))));
      return w;
    };
    for (double step : {kMaxPull / 16, kMaxPull / 8, kMaxPull / 4, kMaxPull / 2, kMaxPull}) {
      for (size_t ti = 0; ti < targets.size(); ++ti) {
        const Vec3 d = sub3(targets[ti], was);
        const double len = norm3(d);
        if (!(len > 0)) continue;
        const double f = std::min(1.0, step * scale[ti] / len);
        Vec3 q;
        bool inside = true;
        for (int k = 0; k < 3; ++k) {
          q[k] = was[k] + f * d[k];
          inside = inside && std::abs(q[k] - cells_[v].center[k]) <= cells_[v].half;
        }
        if (!inside || (start && norm3(sub3(q, *start)) > kMaxPull * finest_)) continue;
        const double dv = deviation(q);
        // Stage 1 keeps every far move on the planes; stage 2 still the moves along them
        // (which may go further than reach(v) only because they keep the surface).
        const bool far = f * len > (last_resort_ == 1 ? kMaxPull * finest_ : reach(v));
        if (far && dv > kFarMoveDeviation * finest_ && last_resort_ < kLastStage) continue;
        xm[mid[v]] = q;
        const size_t c = vertex_cost(v);
        if (c < best_cost || (last_resort_ >= 2 && c == best_cost && best != was && dv < best_deviation)) {
          best = q;
          best_cost = c;
          best_deviation = dv;
        }
      }
      if (best_cost == 0 && (last_resort_ != 2 || best_deviation <= kFarMoveDeviation * finest_)) break;
    }
    xm[mid[v]] = best;
    if (best == was) return false;
    x_[v] = best;
    for (uint32_t k = first[v]; k < first[v + 1]; ++k) dirty_.push_back(around[k]);
    ++st_.moved_vertices;
    return true;
  }

  // Ju and Udeshi's fan keeps each triangle (x, v_k, v_k+1) inside the cells of v_k and
  // v_k+1 when the segment v_k v_k+1 crosses their common face. Beside a much smaller cell it
  // need not: a coarse vertex near one corner of its cell reaches a fine neighbour at the other
  // end of its face through the cells between (suzanne at depth 12: a 32-cell leaf's vertex
  // and 4- and 8-cell neighbours 16 cells away, whose segments cross the face inside a 16-cell
  // neighbour, through that neighbour's fan). Splitting such a side at a point of the common
  // face restores the containment: (x, v_k, p) lies in v_k's cell and (x, p, v_k+1) in
  // v_k+1's, so they cannot cross triangles that stay in other cells. The side is split in
  // both polygons that share it, and each polygon with a split side becomes a fan around its
  // edge point over its corners and face points. Only sides of polygons still crossing are
  // split. Returns whether any was.
  bool split_sides(const std::vector<uint32_t>& bad) {
    std::vector<Vec3>& xm = merged_.xm;
    const std::vector<uint32_t>& mid = merged_.mid;
    if (polygons_.split_at.empty()) polygons_.split_at.resize(n_);
    std::vector<uint32_t> changed;
    for (uint32_t i : bad) {
      const MeshPolygon& p = polys_[i];
      for (int k = 0; k < p.count; ++k) {
        const uint32_t a = p.v[k], b = p.v[(k + 1) % p.count];
        if (a == b || (opt_[i] == kSplitFan && polygons_.split_at[i][k] != kNoSplit)) continue;
        Vec3 f;
        if (!face_point(a, b, third_corner(i, k), f)) continue;
        const auto id = static_cast<uint32_t>(mid.size());
        merged_.mid.push_back(static_cast<uint32_t>(xm.size()));
        xm.push_back(f);
        // Every polygon with side (a, b) or (b, a): two on a manifold.
        for (uint32_t s = star_.first[a]; s < star_.first[a + 1]; ++s) {
          const uint32_t j = star_.around[s];
          const MeshPolygon& q = polys_[j];
          for (int m = 0; m < q.count; ++m) {
            const uint32_t u = q.v[m], w = q.v[(m + 1) % q.count];
            if (!((u == a && w == b) || (u == b && w == a))) continue;
            if (opt_[j] != kSplitFan) polygons_.split_at[j].fill(kNoSplit);
            polygons_.split_at[j][m] = id;
            opt_[j] = kSplitFan;
            changed.push_back(j);
          }
        }
      }
    }
    dirty_.insert(dirty_.end(), changed.begin(), changed.end());
    return !changed.empty();
  }

  // The corner of polygon i's current triangle on side k that is not on the side.
  Vec3 third_corner(uint32_t i, int k) const {
    const MeshPolygon& p = polys_[i];
    const uint32_t a = p.v[k], b = p.v[(k + 1) % p.count];
    Tris t;
    const int c = polygons_.triangles(i, opt_[i], t);
    for (int m = 0; m < c; ++m)
      for (int e = 0; e < 3; ++e)
        if ((t[m][e] == a && t[m][(e + 1) % 3] == b) || (t[m][e] == b && t[m][(e + 1) % 3] == a))
          return merged_.xm[merged_.mid[t[m][(e + 2) % 3]]];
    return merged_.xm[merged_.mid[polygons_.fan_base + i]];
  }

  bool face_point(uint32_t a, uint32_t b, const Vec3& c, Vec3& f) const {
    return detail::face_point(cells_[a], cells_[b], merged_.xm[merged_.mid[a]], merged_.xm[merged_.mid[b]], c, f);
  }

  // Two polygons that cross may need to change together: try every pair of options with each
  // partner. Last resort before giving up (after the vertex moves): it costs up to 9
  // evaluations per partner. Returns how many options changed.
  size_t try_joint_options(const std::vector<uint32_t>& bad) {
    size_t changed = 0;
    // `crossing_` stays as the round began until the next update_crossings, so each bad
    // polygon's partners are those it crossed then, tried in increasing order.
    for (uint32_t i : bad) {
      if (joint_settled_[i]) continue;
      joint_settled_[i] = 1;
      std::vector<uint32_t> partners;
      for (const auto& e : crossing_[i]) partners.push_back(e.first);
      std::sort(partners.begin(), partners.end());
      // Options depend on positions only, which the joint pass does not move.
      const std::vector<uint8_t> opts_i = options(i);
      // The pair's cost under (oi, oj) is i's crossings with everything but j, j's with
      // everything but i, and their mutual ones: single costs (each against the other's
      // current option) corrected by the mutual counts, which need no neighbour search.
      for (const uint32_t j : partners) {
        const uint8_t oi0 = opt_[i], oj0 = opt_[j];
        const std::vector<uint8_t> opts_j = options(j);
        std::array<size_t, 4> ci{}, cj{};
        for (uint8_t o : opts_i) {
          opt_[i] = o;
          ci[o] = cost(i, j);
        }
        opt_[i] = oi0;
        for (uint8_t o : opts_j) {
          opt_[j] = o;
          cj[o] = cost(j, i);
        }
        opt_[j] = oj0;
        auto joint = [&](uint8_t oi, uint8_t oj) { return ci[oi] + cj[oj] + mutual(i, oi, j, oj); };
        size_t best_joint = joint(oi0, oj0);
        uint8_t bi = oi0, bj = oj0;
        for (uint8_t oi : opts_i)
          for (uint8_t oj : opts_j) {
            if ((oi == oi0 && oj == oj0) || best_joint == 0) continue;
            const size_t c = joint(oi, oj);
            if (c < best_joint) {
              best_joint = c;
              bi = oi;
              bj = oj;
            }
          }
        opt_[i] = bi;
        opt_[j] = bj;
        changed += (bi != oi0) + (bj != oj0);
        if (bi != oi0) dirty_.push_back(i);
        if (bj != oj0) dirty_.push_back(j);
      }
    }
    return changed;
  }

  std::vector<Vec3>& x_;
  const std::vector<VertexCell>& cells_;
  const std::vector<MeshPolygon>& polys_;
  Polygons& polygons_;
  const double finest_;
  std::vector<uint8_t>& opt_;  // each polygon's option
  TriangulationStats& st_;
  const size_t n_;
  const uint32_t nv_;
  MergedPositions merged_;
  // 0: none yet; 1: far moves that keep v on its triangles' planes; 2: any far move, the one
  // that leaves those planes least among the ones that remove the most crossings.
  int last_resort_ = 0;
  bool split_tried_ = false;
  std::unique_ptr<BoxTree> tree_;
  std::vector<Box> boxes_;
  std::vector<uint8_t> other_ok_;
  PolygonsAround star_;
  // The crossings of the current triangulation, per polygon: partners with the number of
  // crossing triangle pairs (symmetric), and crossings among its own triangles. Round 0 tests
  // every polygon; later rounds only the polygons whose triangles changed (`dirty_`), against
  // their neighbours — the other polygons' pairs are unchanged.
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> crossing_;
  std::vector<uint32_t> self_hits_;
  std::vector<uint8_t> is_dirty_;
  // Polygons and vertices already tried whose neighbourhood has not changed since: trying
  // them again would give the same answer.
  std::vector<uint8_t> settled_, joint_settled_, vertex_settled_;
  // Vertices tried for a move: where each started and whether it is a corner.
  std::unordered_map<uint32_t, std::pair<Vec3, bool>> corner_start_;
  std::vector<uint32_t> dirty_;
};

}  // namespace

std::vector<std::array<uint32_t, 3>> triangulate_polygons(std::vector<Vec3>& x, const std::vector<VertexCell>& cells,
                                                          const std::vector<MeshPolygon>& polys, double finest,
                                                          bool intersection_free, TriangulationStats* stats) {
  const size_t n = polys.size();
  const auto nv = static_cast<uint32_t>(x.size());
  Polygons P{polys, std::vector<uint8_t>(n, 1), nv, {}};
  for (size_t i = 0; i < n; ++i)
    if (polys[i].count == 4) {
      const auto& v = polys[i].v;
      P.preferred_a[i] = split_quad({x[v[0]], x[v[1]], x[v[2]], x[v[3]]})[0][2] == 2;
    }
  std::vector<uint8_t> opt(n, kPreferred);
  std::vector<Vec3> fans_at;     // each polygon's fan point
  std::vector<Vec3> face_at;     // each split side's face point
  TriangulationStats st;
  if (intersection_free && n > 0) {
    Untangler u(x, cells, P, finest, opt, st);
    fans_at = u.run();
    face_at = u.face_points();
  }

  // Output: fan points and face points appended after the vertices, in polygon order (a face
  // point where the first of its two polygons needs it).
  std::vector<uint32_t> face_id(face_at.size(), kNoSplit);
  const uint32_t face_base = nv + static_cast<uint32_t>(n);
  std::vector<Tri> tris;
  tris.reserve(n * 2);
  for (size_t i = 0; i < n; ++i) {
    Tris t;
    const int c = P.triangles(i, opt[i], t);
    if (opt[i] == kFan || opt[i] == kSplitFan) {
      const auto id = static_cast<uint32_t>(x.size());
      x.push_back(fans_at[i]);
      for (int k = 0; k < c; ++k) {
        t[k][0] = id;
        for (int m = 1; m < 3; ++m) {
          if (t[k][m] < face_base) continue;
          uint32_t& f = face_id[t[k][m] - face_base];
          if (f == kNoSplit) {
            f = static_cast<uint32_t>(x.size());
            x.push_back(face_at[t[k][m] - face_base]);
          }
          t[k][m] = f;
        }
      }
      ++st.fans;
    } else if (opt[i] == kOtherDiagonal) {
      ++st.other_diagonal;
    }
    tris.insert(tris.end(), t.begin(), t.begin() + c);
  }
  if (stats) *stats = st;
  return tris;
}

}  // namespace pic::detail
