// Output sized to the geometry: a dual contour has a vertex per gray cell, so a flat face or a
// straight crease costs one vertex per finest cell along it. Flat regions are merged first
// without moving the surface (merge_flat.h); then edge collapses merge the vertices left: both
// ends move to the point nearest their planes (on a crease, onto its line), allowed where every
// vertex of the original contour that the two stars answer for (the merged mesh's vertices and
// those the merge took away) stays within the tolerance, less the merge's share, of the new
// star. Original points, not original triangles' planes, are the measure: a triangle spanning a
// crease between vertices a tenth of a cell off its line has a plane tilted across the crease,
// which would stop every collapse along it. Each collapse is checked locally (the link
// condition keeps the mesh closed and 2-manifold; the turned triangles keep their orientation
// and do not become needles), and the whole result is checked for crossings before it replaces
// the contour.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "contour/simplify.h"
#include "contour/blocks.h"
#include "contour/edge_collapse.h"
#include "contour/merge_flat.h"
#include "contour/triangle_shape.h"
#include "geometry/lattice.h"
#include "geometry/mesh_distance.h"
#include "geometry/qef.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"
#include "pic/contour.h"
#include "pic/measure.h"

namespace pic {

namespace {

using detail::cross3;
using detail::dot3;
using detail::norm3;
using detail::kKeptNormalCosine;
using detail::kMinTriangleQuality;
using detail::BlockGrid;
using detail::kGrids;
using detail::triangle_normal;
using detail::triangle_quality;

/// The share of the tolerance the flat regions' merge may move the surface.
constexpr double kFlatMergeShare = 1e-3;

/// A symmetric 4x4 quadric: the sum of squared distances to a set of planes.
struct Quadric {
  std::array<double, 10> q{};  // xx xy xz xw yy yz yw zz zw ww
  void add_plane(const Vec3& n, double d) {
    const double a = n[0], b = n[1], c = n[2];
    const double v[10] = {a * a, a * b, a * c, a * d, b * b, b * c, b * d, c * c, c * d, d * d};
    for (int i = 0; i < 10; ++i) q[i] += v[i];
    ++count;
  }
  void add(const Quadric& o) {
    for (int i = 0; i < 10; ++i) q[i] += o.q[i];
    count += o.count;
  }
  /// The mean squared distance: no plane is nearer than that on the whole.
  double mean_at(const Vec3& p) const { return count ? at(p) / count : 0; }
  double count = 0;
  /// The point nearest the planes from `seed`: seed + A+ (b - A seed), with A+ the
  /// pseudo-inverse truncated below a fraction of A's largest eigenvalue, so the point moves
  /// only across the planes and stays at the seed along the directions they leave free.
  Vec3 minimum_near(const Vec3& seed) const {
    detail::Qef e;
    e.a = {q[0], q[1], q[2], q[4], q[5], q[7]};
    e.b = {-q[3], -q[6], -q[8]};
    e.c = q[9];
    e.weight = 1;
    return e.solve(seed).position;
  }
  double at(const Vec3& p) const {
    const double x = p[0], y = p[1], z = p[2];
    return q[0] * x * x + 2 * q[1] * x * y + 2 * q[2] * x * z + 2 * q[3] * x + q[4] * y * y + 2 * q[5] * y * z +
           2 * q[6] * y + q[7] * z * z + 2 * q[8] * z + q[9];
  }
};

double dist2(const Vec3& a, const Vec3& b) {
  const double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
  return x * x + y * y + z * z;
}

/// A candidate for merging a vertex: the neighbour v, where both go, and the planes' error there.
struct Candidate {
  double error;
  uint32_t v;
  Vec3 x;
};
/// An original point handed to a triangle of the star a collapse leaves.
struct MovedPoint {
  uint32_t point, triangle;
  double near;  // at most this far from it
};
/// What trying one collapse needs for itself; each block (and the last pass) has its own.
struct Scratch {
  std::vector<uint32_t> ring_u, ring_v;
  std::vector<Candidate> candidates;
  // The star a collapse under test leaves (triangle, corners, how far its moving corner goes,
  // how far from the original it was found) and, per original point of the two stars, a
  // triangle of that star within the tolerance of it.
  std::vector<uint32_t> star;
  std::vector<std::array<Vec3, 3>> star_corners;
  std::vector<double> star_shift, new_off;
  std::vector<MovedPoint> moved_points;
  std::vector<uint32_t> new_near_raw;  // per triangle of that star: where the original was found
  bool left_block = false;  // the last vertex tried had a collapse refused for leaving the block
  double worst_u = 1;       // the worst shape in the star of the vertex tried
  bool log_moves = false;
  std::vector<uint32_t> moved_log;  // every original point the collapses moved, if log_moves
};

class Simplifier {
 public:
  /// `frozen`: per vertex of `mesh`, whether it must stay where it is (empty: none).
  /// `surface`: the distance to `mesh`. `more`: original points besides `mesh`'s vertices (the
  /// raw vertices a flat merge took away), each answered for by the triangle of `mesh` in
  /// `more_on` at that distance; they are numbered after the vertices.
  Simplifier(const TriMesh& mesh, const detail::MeshDistance& surface, double tolerance,
             const std::vector<uint8_t>& frozen, const std::vector<Vec3>& more,
             const std::vector<detail::Nearest>& more_on)
      : pos_(mesh.positions), original_(with(mesh.positions, more)), original_surface_(surface), tris_(mesh.triangles),
        tol_(tolerance), quadric_(pos_.size()), faces_(pos_.size()), first_point_(tris_.size(), kNoPoint),
        next_point_(original_.size(), kNoPoint), near_(original_.size(), 0.0), alive_(tris_.size(), 1),
        off_(tris_.size(), 0.0), near_raw_(tris_.size()), merged_into_(pos_.size()), frozen_(frozen), grid_(pos_),
        deferred_(pos_.size(), 0), logged_(original_.size(), 0) {
    for (uint32_t f = 0; f < tris_.size(); ++f) near_raw_[f] = surface.hint_of(f);
    std::iota(merged_into_.begin(), merged_into_.end(), 0u);
    frozen_.resize(pos_.size(), 0);
    for (uint32_t f = 0; f < tris_.size(); ++f) {
      const auto& t = tris_[f];
      const Vec3 n = triangle_normal(pos_[t[0]], pos_[t[1]], pos_[t[2]]);
      const double len = norm3(n);
      for (int k = 0; k < 3; ++k) faces_[t[k]].push_back(f);
      if (!(len > 0)) continue;
      const Vec3 u{n[0] / len, n[1] / len, n[2] / len};
      const double d = -dot3(u, pos_[t[0]]);
      for (int k = 0; k < 3; ++k) quadric_[t[k]].add_plane(u, d);
    }
    // Each original vertex is answered for by one triangle of its star (it is that
    // triangle's corner: at distance 0).
    for (uint32_t v = 0; v < pos_.size(); ++v)
      if (!faces_[v].empty()) answer_for(v, faces_[v][0]);
    for (size_t i = 0; i < more.size(); ++i) {
      const uint32_t p = uint32_t(pos_.size() + i);
      answer_for(p, more_on[i].triangle);
      near_[p] = more_on[i].distance;
    }
  }

  static std::vector<Vec3> with(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
    std::vector<Vec3> all(a);
    all.insert(all.end(), b.begin(), b.end());
    return all;
  }

  static constexpr uint16_t kNoBlock = UINT16_MAX;

  /// What a later round takes over from this round's blocks: the merges and where each
  /// original point is answered for, and the vertices and triangles still alive.
  struct BlocksState {
    // Per vertex and original point (the same numbers; the points besides the vertices come
    // after them): their merge, the next point on their triangle's list, how near it, whether
    // deferred; for all, or (a later grid's phase) only for those it touched (its blocks'
    // vertices, the points it moved), in `touched`'s order.
    std::vector<uint32_t> touched;
    bool partial = false;
    std::vector<uint32_t> merged_into, next_point;
    std::vector<double> near;
    std::vector<uint8_t> deferred;
    std::vector<uint8_t> alive;  // per triangle
    std::vector<uint32_t> live_vertices;  // and per live vertex:
    std::vector<Vec3> pos;
    std::vector<Quadric> quadric;
    std::vector<std::vector<uint32_t>> faces;
    std::vector<uint32_t> live_triangles;  // and per live triangle:
    std::vector<std::array<uint32_t, 3>> tris;
    std::vector<double> off;
    std::vector<uint32_t> first_point, near_raw;
  };
  /// One grid's phase of a round: each live vertex's block when it began, the state at its end.
  struct PhaseRecord {
    std::vector<uint16_t> membership;
    BlocksState after;
  };

  /// The grids' blocks one grid after another, each grid's in parallel: first each block of the
  /// first grid on its own, collapsing only where both stars lie in the block; then the blocks
  /// of the other grids, from the vertices whose collapses left their block before (phase);
  /// then the whole mesh from those the last grid left (finish). The blocks do not depend on
  /// the thread count, so neither does the result.
  ///
  /// Grid g's phase. `previous`: the same phase of the last round (none in the first), whose
  /// blocks are taken over where no vertex of theirs, then or now, may have changed
  /// (`changed`, per vertex; the vertices of the blocks run here are added to it): a block's
  /// collapses touch only its own vertices, the triangles whose corners all lie in it and the
  /// original points those answer for, so it would come out the same.
  /// `record_it`: whether a later round may take this phase over (its record is returned).
  PhaseRecord phase(size_t g, const PhaseRecord* previous, std::vector<uint8_t>& changed, bool record_it) {
    PhaseRecord record;
    const std::vector<std::vector<uint32_t>> members = members_of(g, record.membership);
    std::vector<uint8_t> run(members.size(), previous == nullptr);
    if (previous)
      for (uint32_t u = 0; u < pos_.size(); ++u)
        if (changed[u])
          for (uint16_t b : {record.membership[u], previous->membership[u]})
            if (b != kNoBlock) run[b] = 1;
    std::vector<uint32_t> touched = previous ? adopt(previous->after, record.membership, run) : std::vector<uint32_t>{};
    current_ = record.membership;
    run_blocks(g, members, run, touched);
    for (uint32_t u = 0; u < pos_.size(); ++u)
      if (record.membership[u] != kNoBlock && run[record.membership[u]]) changed[u] = 1, touched.push_back(u);
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    if (record_it) record.after = state(g == 0 ? nullptr : &touched);
    return record;
  }

  /// The collapses the last grid's blocks left, over the whole mesh.
  void finish() {
    std::vector<uint32_t> all(pos_.size());
    std::iota(all.begin(), all.end(), 0u);
    std::vector<uint8_t> dirty(pos_.size(), 0);
    dirty.swap(deferred_);
    deferred_.assign(pos_.size(), 0);
    Scratch s;
    passes(all, std::move(dirty), s, kAnyBlock);
  }

  /// The input vertex that u was merged into, at last (u itself when it was kept).
  uint32_t survivor(uint32_t u) {
    uint32_t root = u;
    while (merged_into_[root] != root) root = merged_into_[root];
    while (merged_into_[u] != root) u = std::exchange(merged_into_[u], root);  // shorten the chain
    return root;
  }

  /// The simplified mesh; `kept[i]`: the vertex of the input that output vertex i is.
  TriMesh result(std::vector<uint32_t>& kept) const { return detail::live_mesh(pos_, tris_, alive_, &kept); }

 private:
  std::vector<Vec3> pos_;
  const std::vector<Vec3> original_;
  const detail::MeshDistance& original_surface_;
  std::vector<std::array<uint32_t, 3>> tris_;
  double tol_;
  std::vector<Quadric> quadric_;              // per vertex: its planes summed (where to merge)
  std::vector<std::vector<uint32_t>> faces_;  // per vertex: its live triangles
  // Per triangle, the original vertices it answers for: a list through next_point_.
  static constexpr uint32_t kNoPoint = UINT32_MAX;
  static constexpr uint32_t kNoTriangle = UINT32_MAX;
  std::vector<uint32_t> first_point_, next_point_;
  std::vector<double> near_;  // per original point: at most this far from its triangle
  std::vector<uint8_t> alive_;
  std::vector<double> off_;              // per triangle: how far from the original it was found
  std::vector<uint32_t> near_raw_;       // per triangle: where the original was found near it (a hint)
  std::vector<uint32_t> merged_into_;  // per input vertex: the vertex it was merged into, or itself
  std::vector<uint8_t> frozen_;
  BlockGrid grid_;
  std::vector<uint16_t> current_;               // per vertex: its block of the grid in use
  std::vector<uint8_t> deferred_;  // per vertex: a collapse of it was refused for leaving its block
  std::vector<uint8_t> logged_;    // per original point: in a block's moved_log this phase
  static constexpr int kAnyBlock = -1;

  /// Grid g's blocks: each live vertex's (into `membership`, kNoBlock for the others) and
  /// each block's vertices, ascending.
  std::vector<std::vector<uint32_t>> members_of(size_t g, std::vector<uint16_t>& membership) const {
    membership.assign(pos_.size(), kNoBlock);
    std::vector<std::vector<uint32_t>> members(kGrids[g].count());
    for (uint32_t u = 0; u < pos_.size(); ++u)
      if (!faces_[u].empty()) {
        const uint16_t b = grid_.block(pos_[u], kGrids[g]);
        membership[u] = b;
        members[b].push_back(u);
      }
    return members;
  }

  /// The blocks `run` says, in parallel; the original points the later grids' collapses moved
  /// are added to `touched`.
  void run_blocks(size_t g, const std::vector<std::vector<uint32_t>>& members, const std::vector<uint8_t>& run,
                  std::vector<uint32_t>& touched) {
    std::vector<std::vector<uint32_t>> moved(members.size());
    tbb::parallel_for(size_t{0}, members.size(), [&](size_t b) {
      if (!run[b]) return;
      std::vector<uint8_t> dirty(members[b].size(), 1);
      if (g > 0)
        for (size_t i = 0; i < dirty.size(); ++i) dirty[i] = std::exchange(deferred_[members[b][i]], 0);
      Scratch s;
      s.log_moves = g > 0;
      passes(members[b], std::move(dirty), s, int(b));
      moved[b] = std::move(s.moved_log);
    });
    for (const auto& m : moved) {
      touched.insert(touched.end(), m.begin(), m.end());
      for (uint32_t p : m) logged_[p] = 0;
    }
  }

  /// The state now; with `touched`, the vertices' and points' only for those.
  BlocksState state(const std::vector<uint32_t>* touched) const {
    BlocksState st;
    if (touched) {
      st.partial = true;
      st.touched = *touched;
      for (uint32_t i : *touched) {
        const bool vertex = i < pos_.size();
        st.merged_into.push_back(vertex ? merged_into_[i] : i);
        st.next_point.push_back(next_point_[i]);
        st.near.push_back(near_[i]);
        st.deferred.push_back(vertex ? deferred_[i] : 0);
      }
    } else {
      st.merged_into = merged_into_, st.next_point = next_point_, st.near = near_, st.deferred = deferred_;
    }
    st.alive = alive_;
    for (uint32_t u = 0; u < pos_.size(); ++u)
      if (!faces_[u].empty()) {
        st.live_vertices.push_back(u);
        st.pos.push_back(pos_[u]);
        st.quadric.push_back(quadric_[u]);
        st.faces.push_back(faces_[u]);
      }
    for (uint32_t f = 0; f < tris_.size(); ++f)
      if (alive_[f]) {
        st.live_triangles.push_back(f);
        st.tris.push_back(tris_[f]);
        st.off.push_back(off_[f]);
        st.first_point.push_back(first_point_[f]);
        st.near_raw.push_back(near_raw_[f]);
      }
    return st;
  }

  /// Takes from `done` the state of the blocks of `membership` that `run` leaves out: their
  /// vertices, the live triangles with every corner in one of them and the points those answer
  /// for. Returns the vertices and points a partial `done` changed there.
  std::vector<uint32_t> adopt(const BlocksState& done, const std::vector<uint16_t>& membership,
                              const std::vector<uint8_t>& run) {
    const auto adopted = [&](uint32_t u) { return u < pos_.size() && membership[u] != kNoBlock && !run[membership[u]]; };
    std::vector<uint8_t> taken(tris_.size(), 0), point_taken(done.partial ? original_.size() : 0, 0);
    for (uint32_t f = 0; f < tris_.size(); ++f) {
      const auto& t = tris_[f];
      if (!alive_[f] || !adopted(t[0]) || membership[t[1]] != membership[t[0]] || membership[t[2]] != membership[t[0]])
        continue;
      taken[f] = 1;
      for (uint32_t p = first_point_[f]; p != kNoPoint;) {
        const uint32_t next = next_point_[p];
        if (done.partial) {
          point_taken[p] = 1;
        } else {
          next_point_[p] = done.next_point[p];
          near_[p] = done.near[p];
        }
        p = next;
      }
      alive_[f] = done.alive[f];
      first_point_[f] = kNoPoint;
    }
    std::vector<uint32_t> changed_here;
    if (done.partial)
      for (size_t k = 0; k < done.touched.size(); ++k) {
        const uint32_t i = done.touched[k];
        const bool vertex = adopted(i), point = point_taken[i];
        if (vertex) merged_into_[i] = done.merged_into[k], deferred_[i] = done.deferred[k];
        if (point) next_point_[i] = done.next_point[k], near_[i] = done.near[k];
        if (vertex || point) changed_here.push_back(i);
      }
    for (size_t i = 0; i < done.live_triangles.size(); ++i) {
      const uint32_t f = done.live_triangles[i];
      if (!taken[f]) continue;
      tris_[f] = done.tris[i];
      off_[f] = done.off[i];
      first_point_[f] = done.first_point[i];
      near_raw_[f] = done.near_raw[i];
    }
    for (uint32_t u = 0; u < pos_.size(); ++u)
      if (adopted(u)) {
        if (!done.partial) merged_into_[u] = done.merged_into[u], deferred_[u] = done.deferred[u];
        faces_[u].clear();
      }
    for (size_t i = 0; i < done.live_vertices.size(); ++i) {
      const uint32_t u = done.live_vertices[i];
      if (!adopted(u)) continue;
      pos_[u] = done.pos[i];
      quadric_[u] = done.quadric[i];
      faces_[u] = done.faces[i];
    }
    return changed_here;
  }

  /// Passes over `members` (ascending vertex numbers, `dirty` per member), each vertex moving
  /// onto the neighbour that keeps the planes closest, until a pass collapses fewer than a
  /// thousandth of them; after the first, only vertices whose star changed are tried again.
  /// With a `block`, only collapses whose two stars lie in it.
  /// A vertex whose collapses were refused for leaving the block, or whose star changed after
  /// its last try, is marked deferred_ for the next grid.
  void passes(const std::vector<uint32_t>& members, std::vector<uint8_t> dirty, Scratch& s, int block) {
    bool stopped = false;
    std::vector<uint8_t> next(members.size(), 0);
    const auto local = [&](uint32_t w) {
      return block == kAnyBlock ? size_t(w) : size_t(std::lower_bound(members.begin(), members.end(), w) - members.begin());
    };
    for (int pass = 0; pass < 32; ++pass) {
      size_t done = 0;
      for (size_t i = 0; i < members.size(); ++i) {
        const uint32_t u = members[i];
        if (!dirty[i] || faces_[u].empty()) continue;
        const bool collapsed = collapse_cheapest(u, s, block);
        deferred_[u] = !collapsed && s.left_block;
        if (!collapsed) continue;
        for (uint32_t w : s.ring_u) next[local(w)] = 1;
        ++done;
      }
      if (done * 1000 < members.size()) {
        stopped = true;
        break;
      }
      dirty.swap(next);
      std::fill(next.begin(), next.end(), 0);
    }
    // Not tried since their star changed: `next` when the passes stopped, else (out of passes)
    // the last swap's `dirty`.
    const std::vector<uint8_t>& untried = stopped ? next : dirty;
    for (size_t i = 0; i < members.size(); ++i)
      if (untried[i]) deferred_[members[i]] |= !faces_[members[i]].empty();
  }

  /// Whether every vertex of `ring` lies in `block` of the grid in use (always, for kAnyBlock).
  bool in_block(const std::vector<uint32_t>& ring, int block) const {
    if (block == kAnyBlock) return true;
    for (uint32_t w : ring)
      if (current_[w] != block) return false;
    return true;
  }

  /// Triangle f answers for original point p from now on.
  void answer_for(uint32_t p, uint32_t f) {
    next_point_[p] = first_point_[f];
    first_point_[f] = p;
  }

  void ring(uint32_t v, std::vector<uint32_t>& out) const {
    out.clear();
    for (uint32_t f : faces_[v])
      for (uint32_t w : tris_[f])
        if (w != v) out.push_back(w);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  /// Where u and v merge (q: their planes summed): the point nearest their planes (least
  /// squares, truncated along the directions they leave free, from the edge's middle) when it
  /// stays near the edge, else the edge's middle. `error`: the root mean squared distance to
  /// the planes there (the order in which neighbours are tried).
  Vec3 merged_position(uint32_t u, uint32_t v, const Quadric& q, double& error) const {
    const Vec3 &a = pos_[u], &b = pos_[v];
    const Vec3 mid{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
    Vec3 x = q.minimum_near(mid);
    // Keep to the edge's neighbourhood: a far optimum of nearly parallel planes is no merge.
    if (!(dist2(x, mid) <= dist2(a, b))) x = mid;
    error = std::sqrt(std::max(0.0, q.mean_at(x)));
    return x;
  }

  /// Merges u with the neighbour that keeps the planes closest, among those that may take it:
  /// both at the planes' point, or u onto the neighbour where it stands.
  bool collapse_cheapest(uint32_t u, Scratch& s, int block) {
    s.left_block = false;
    if (frozen_[u]) return false;
    ring(u, s.ring_u);
    if (!in_block(s.ring_u, block)) return s.left_block = true, false;
    s.worst_u = worst_shape(u);
    s.candidates.clear();
    double error = 0;
    for (uint32_t v : s.ring_u)
      if (!frozen_[v]) {
        Quadric q = quadric_[u];
        q.add(quadric_[v]);
        const Vec3 x = merged_position(u, v, q, error);
        s.candidates.push_back({error, v, x});
        // u onto v where it stands: on a flat region the planes leave the middle free, and
        // a fan from v may keep shapes that one from the middle does not.
        if (x != pos_[v]) s.candidates.push_back({std::sqrt(std::max(0.0, q.mean_at(pos_[v]))), v, pos_[v]});
      }
    std::sort(s.candidates.begin(), s.candidates.end(),
              [](const Candidate& a, const Candidate& b) { return a.error < b.error || (a.error == b.error && a.v < b.v); });
    for (const Candidate& c : s.candidates)
      if (can_collapse(u, c.v, c.x, s, block)) {
        collapse(u, c.v, c.x, s);
        return true;
      }
    return false;
  }

  /// The link condition (the vertices next to both u and v are exactly the two across the
  /// edge uv), every triangle of u or v that survives keeps its orientation and its shape
  /// when both move to x, and the original points stay within the tolerance.
  bool can_collapse(uint32_t u, uint32_t v, const Vec3& x, Scratch& s, int block) {
    int shared = 0;
    std::array<uint32_t, 2> across{};
    for (uint32_t f : faces_[u]) {
      const auto& t = tris_[f];
      if (t[0] != v && t[1] != v && t[2] != v) continue;
      if (shared == 2) return false;
      for (uint32_t w : t)
        if (w != u && w != v) across[shared] = w;
      ++shared;
    }
    if (shared != 2 || across[0] == across[1]) return false;
    ring(v, s.ring_v);
    if (!in_block(s.ring_v, block)) return s.left_block = true, false;
    size_t common = 0;
    for (uint32_t w : s.ring_u)
      if (std::binary_search(s.ring_v.begin(), s.ring_v.end(), w)) ++common;
    if (common != 2) return false;
    // A closed mesh of 4 vertices (a tetrahedron) would fold flat.
    if (s.ring_u.size() <= 3 && s.ring_v.size() <= 3) return false;
    return keeps_shape(u, v, x, s.worst_u) && keeps_shape(v, u, x, worst_shape(v)) && keeps_points(u, v, x, s) &&
           near_original(x, s);
  }

  /// Whether every original point the stars of u and v answer for lies within the tolerance
  /// of the star both leave at x; records a triangle there that answers for it (moved).
  bool keeps_points(uint32_t u, uint32_t v, const Vec3& x, Scratch& s) {
    auto& star = s.star;
    auto& corners = s.star_corners;
    auto& shift = s.star_shift;
    auto& moved = s.moved_points;
    star.clear();
    corners.clear();
    shift.clear();
    moved.clear();
    const double shift_u = std::sqrt(dist2(x, pos_[u])), shift_v = std::sqrt(dist2(x, pos_[v]));
    for (uint32_t w : {u, v})
      for (uint32_t f : faces_[w]) {
        const auto& t = tris_[f];
        const bool gone = (t[0] == u || t[1] == u || t[2] == u) && (t[0] == v || t[1] == v || t[2] == v);
        if (gone || (w == v && (t[0] == u || t[1] == u || t[2] == u))) continue;
        std::array<Vec3, 3> c;
        for (int k = 0; k < 3; ++k) c[k] = t[k] == u || t[k] == v ? x : pos_[t[k]];
        star.push_back(f);
        corners.push_back(c);
        shift.push_back(w == u ? shift_u : shift_v);
      }
    const double tol2 = tol_ * tol_;
    auto distance2 = [&](uint32_t p, size_t k) {
      const auto& c = corners[k];
      return detail::point_triangle_distance2(original_[p], c[0], c[1], c[2]);
    };
    // Any triangle of the new star within the tolerance answers for a point: its own first
    // (where it stays), then the others. A triangle that one corner leaves by s moves no
    // point of it farther than s: a point that was near enough before and still is by that
    // bound (`near_`) needs no new distance.
    size_t last = star.size();
    auto check = [&](uint32_t f) {
      const size_t own = size_t(std::find(star.begin(), star.end(), f) - star.begin());
      for (uint32_t p = first_point_[f]; p != kNoPoint; p = next_point_[p]) {
        if (own < star.size() && near_[p] + shift[own] <= tol_) {
          moved.push_back({p, f, near_[p] + shift[own]});
          continue;
        }
        size_t at = star.size();
        double d2 = 0;
        if (own < star.size() && (d2 = distance2(p, own)) <= tol2) at = own;
        // The triangle the last point moved to first: the points of one triangle lie close.
        if (at == star.size() && last != own && last < star.size() && (d2 = distance2(p, last)) <= tol2) at = last;
        for (size_t k = 0; k < star.size() && at == star.size(); ++k)
          if (k != own && k != last && (d2 = distance2(p, k)) <= tol2) at = k;
        if (at != own) last = at;
        if (at == star.size()) return false;
        moved.push_back({p, star[at], std::sqrt(d2)});
      }
      return true;
    };
    for (uint32_t f : faces_[u])
      if (!check(f)) return false;
    for (uint32_t f : faces_[v]) {
      const auto& t = tris_[f];
      if (t[0] != u && t[1] != u && t[2] != u && !check(f)) return false;
    }
    return true;
  }

  /// Whether the new star (keeps_points left it in `s`) lies within the tolerance of the
  /// original surface (the other way round): its vertex x, and each triangle's centroid (a
  /// long triangle across a fold) and side from x. A point near the triangle it lies on before
  /// the collapse is as near the original as that triangle (`off_`: how far each triangle was
  /// found from it at such points, 0 for one no collapse has changed); else the original
  /// surface is searched, which the point must then reach. The bounds found go to the new
  /// star (new_off).
  bool near_original(const Vec3& x, Scratch& s) {
    const auto& star = s.star;
    const auto& corners = s.star_corners;
    auto& new_off = s.new_off;
    auto bound_by = [&](const Vec3& m, uint32_t f) {
      const auto& t = tris_[f];
      return off_[f] + std::sqrt(detail::point_triangle_distance2(m, pos_[t[0]], pos_[t[1]], pos_[t[2]]));
    };
    // `own`: the triangle whose new shape the point lies on, tried first (the nearest, mostly).
    // Within half the tolerance it will do: the bound stays low enough for the next collapse.
    // Else the original surface is asked, from where that triangle found it last (`near_raw_`:
    // its neighbourhood holds the answer mostly), and the nearer triangle found sets the bound.
    auto bound = [&](const Vec3& m, uint32_t own, uint32_t& hint) {
      const double by_own = bound_by(m, own);
      if (by_own <= tol_ / 2) return by_own;
      double found = 0;
      return original_surface_.within(m, tol_, &hint, &found) ? std::min(found, by_own) : detail::kHuge;
    };
    double at_x = 0;
    uint32_t hint = star.empty() ? 0 : near_raw_[star[0]];
    if (!original_surface_.within(x, tol_, &hint, &at_x)) return false;
    new_off.clear();
    s.new_near_raw.clear();
    for (size_t i = 0; i < star.size(); ++i) {
      const auto& c = corners[i];
      const Vec3 m{(c[0][0] + c[1][0] + c[2][0]) / 3, (c[0][1] + c[1][1] + c[2][1]) / 3, (c[0][2] + c[1][2] + c[2][2]) / 3};
      // And the middle of the side that leaves x towards the next corner (each such side of
      // the star once): a side across a valley of the original stays in reach of it.
      const int k = c[0] == x ? 0 : c[1] == x ? 1 : 2;
      const Vec3& y = c[(k + 1) % 3];
      const Vec3 e{(x[0] + y[0]) / 2, (x[1] + y[1]) / 2, (x[2] + y[2]) / 2};
      uint32_t near = near_raw_[star[i]];
      const double at_m = bound(m, star[i], near);
      if (at_m > tol_) return false;
      const double at_e = bound(e, star[i], near);
      if (at_e > tol_) return false;
      new_off.push_back(std::max({at_x, at_m, at_e}));
      s.new_near_raw.push_back(near);
    }
    return true;
  }

  /// The worst shape among the triangles of a's star.
  double worst_shape(uint32_t a) const {
    double worst = 1;
    for (uint32_t f : faces_[a]) {
      const auto& t = tris_[f];
      worst = std::min(worst, triangle_quality(pos_[t[0]], pos_[t[1]], pos_[t[2]]));
    }
    return worst;
  }

  /// Whether the triangles of `a` without `b` keep orientation and shape with `a` at x
  /// (`worst_before`: a's worst_shape): no worse than the floor, or than they were.
  bool keeps_shape(uint32_t a, uint32_t b, const Vec3& x, double worst_before) const {
    const double min_quality = std::min(kMinTriangleQuality, worst_before);
    for (uint32_t f : faces_[a]) {
      const auto& t = tris_[f];
      if (t[0] == b || t[1] == b || t[2] == b) continue;
      std::array<Vec3, 3> p;
      for (int k = 0; k < 3; ++k) p[k] = t[k] == a ? x : pos_[t[k]];
      const Vec3 before = triangle_normal(pos_[t[0]], pos_[t[1]], pos_[t[2]]);
      const Vec3 after = triangle_normal(p[0], p[1], p[2]);
      const double lb = norm3(before), la = norm3(after);
      // Turned by less than about 25 degrees: the new fan covers the old star, folding nothing.
      if (!(la > 0) || !(lb > 0) || dot3(before, after) < kKeptNormalCosine * lb * la) return false;
      if (triangle_quality(p[0], p[1], p[2]) < min_quality) return false;
    }
    return true;
  }

  /// Carries out the collapse keeps_points() last accepted (of u into v at x).
  void collapse(uint32_t u, uint32_t v, const Vec3& x, Scratch& s) {
    for (uint32_t w : {u, v})
      for (uint32_t f : faces_[w]) first_point_[f] = kNoPoint;
    for (const MovedPoint& m : s.moved_points) {
      answer_for(m.point, m.triangle);
      near_[m.point] = m.near;
      // Each point once a phase: a block's points are its own, so the flags do not race.
      if (s.log_moves && !std::exchange(logged_[m.point], 1)) s.moved_log.push_back(m.point);
    }
    for (size_t k = 0; k < s.star.size(); ++k) off_[s.star[k]] = s.new_off[k], near_raw_[s.star[k]] = s.new_near_raw[k];
    pos_[v] = x;
    merged_into_[u] = v;
    detail::hand_star_over(u, v, tris_, faces_, alive_);
    quadric_[v].add(quadric_[u]);
  }
};

/// The boxes of the crossing pairs whose two triangles are `mesh`'s own, unchanged
/// (`kept`: the vertex of `mesh` that each vertex of `out` is): no round can undo those.
std::vector<std::array<Vec3, 2>> crossings_of_the_input(const TriMesh& out, const std::vector<uint32_t>& kept,
                                                        const TriMesh& mesh,
                                                        const std::vector<std::pair<uint32_t, uint32_t>>& crossings) {
  std::vector<std::array<uint32_t, 3>> input(mesh.triangles);
  for (auto& t : input) std::sort(t.begin(), t.end());
  std::sort(input.begin(), input.end());
  const auto unchanged = [&](uint32_t f) {
    std::array<uint32_t, 3> t;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = out.triangles[f][k];
      if (out.positions[v] != mesh.positions[kept[v]]) return false;
      t[k] = kept[v];
    }
    std::sort(t.begin(), t.end());
    return std::binary_search(input.begin(), input.end(), t);
  };
  std::vector<std::array<Vec3, 2>> boxes;
  for (const auto& [a, b] : crossings) {
    if (!unchanged(a) || !unchanged(b)) continue;
    std::array<Vec3, 2> box{out.positions[out.triangles[a][0]], out.positions[out.triangles[a][0]]};
    for (uint32_t f : {a, b})
      for (uint32_t v : out.triangles[f])
        for (int k = 0; k < 3; ++k) {
          box[0][k] = std::min(box[0][k], out.positions[v][k]);
          box[1][k] = std::max(box[1][k], out.positions[v][k]);
        }
    boxes.push_back(box);
  }
  return boxes;
}

/// The collapses that check original points, in rounds; false (and `mesh` as it was) when
/// none could be taken. `merged_away`: more points of the original surface (near `mesh`'s
/// triangles) that the result keeps within `tolerance` as it keeps `mesh`'s vertices.
/// `input_crossings`: where `mesh` itself crosses, when that is why none could be taken.
bool collapse_in_rounds(TriMesh& mesh, double tolerance, bool take_over, const std::vector<Vec3>& merged_away,
                        std::vector<std::array<Vec3, 2>>& input_crossings) {
  // The local checks keep the mesh closed and 2-manifold; a crossing between parts that are
  // not neighbours (two sheets a fraction of a cell apart) is found on the result. Then the
  // input vertices merged into the crossing triangles stay as they are, and the rest is
  // simplified again (a few rounds; none taken when crossings remain).
  constexpr int kRounds = 6;
  std::vector<uint8_t> frozen(mesh.positions.size(), 0), frozen_before;
  const detail::MeshDistance surface(mesh, detail::Pruning::Boxes);
  // Each point merged away is answered for by the triangle it lies on (within the merge's drift).
  std::vector<detail::Nearest> on(merged_away.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, merged_away.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    uint32_t hint = 0;
    for (size_t i = r.begin(); i < r.end(); ++i) on[i] = surface.nearest(merged_away[i], &hint);
  });
  // Each phase of a round as it ended: the next round redoes only the blocks where vertices
  // were frozen since, and those their changes reach in the later grids.
  std::vector<Simplifier::PhaseRecord> last;
  for (int round = 0; round < kRounds; ++round) {
    Simplifier s(mesh, surface, tolerance, frozen, merged_away, on);
    std::vector<uint8_t> changed(mesh.positions.size(), 0);
    if (round > 0)
      for (uint32_t u = 0; u < frozen.size(); ++u) changed[u] = frozen[u] != frozen_before[u];
    std::vector<Simplifier::PhaseRecord> now;
    // Records only where a later round may take them over.
    const bool record = take_over && round + 1 < kRounds;
    for (size_t g = 0; g < std::size(kGrids); ++g) {
      now.push_back(s.phase(g, last.empty() ? nullptr : &last[g], changed, record));
      if (!last.empty()) last[g] = {};  // its memory before the next phase's record
    }
    if (record)
      last = std::move(now);
    else
      last.clear();
    frozen_before = frozen;
    s.finish();
    std::vector<uint32_t> kept;
    TriMesh out = s.result(kept);
    if (out.triangles.size() == mesh.triangles.size()) return false;
    const auto crossings = self_intersecting_pairs(out);
    if (crossings.empty()) {
      mesh = std::move(out);
      return true;
    }
    input_crossings = crossings_of_the_input(out, kept, mesh, crossings);
    if (!input_crossings.empty()) return false;
    // The vertices of the crossing triangles, and from the second round on their neighbours
    // too: keeping only the crossing triangles raw can make the next collapses beside them
    // cross again, and a wider raw patch settles in fewer rounds.
    std::vector<uint8_t> at_crossing(out.positions.size(), 0);
    for (const auto& [a, b] : crossings)
      for (uint32_t t : {a, b})
        for (uint32_t v : out.triangles[t]) at_crossing[v] = 1;
    if (round > 0) {
      std::vector<uint8_t> grown = at_crossing;
      for (const auto& t : out.triangles)
        if (at_crossing[t[0]] || at_crossing[t[1]] || at_crossing[t[2]]) grown[t[0]] = grown[t[1]] = grown[t[2]] = 1;
      at_crossing.swap(grown);
    }
    std::vector<uint8_t> input_at(mesh.positions.size(), 0);
    for (uint32_t v = 0; v < out.positions.size(); ++v)
      if (at_crossing[v]) input_at[kept[v]] = 1;
    for (uint32_t u = 0; u < mesh.positions.size(); ++u)
      if (input_at[s.survivor(u)]) frozen[u] = 1;
  }
  return false;
}

}  // namespace

size_t simplify(TriMesh& mesh, double tolerance) { return detail::simplify_in_rounds(mesh, tolerance, true); }

size_t detail::simplify_in_rounds(TriMesh& mesh, double tolerance, bool take_over) {
  if (!(tolerance > 0) || mesh.triangles.empty()) return 0;
  // Flat regions first, moving the surface by a small share of the tolerance: the collapses
  // then start from far fewer vertices. Two sheets closer than that
  // share may cross once merged; then the merge is redone with the input kept as it is around
  // the crossing (a few times; then the input is written).
  constexpr int kMergeAttempts = 3;
  const double drift = tolerance * kFlatMergeShare;
  std::vector<uint8_t> keep(mesh.positions.size(), 0);
  for (int attempt = 0; attempt < kMergeAttempts; ++attempt) {
    TriMesh merged = mesh;
    std::vector<Vec3> merged_away;
    const size_t flat = merge_flat(merged, drift, &merged_away, &keep);
    std::vector<std::array<Vec3, 2>> merged_crossings;
    if (collapse_in_rounds(merged, tolerance - drift, take_over, merged_away, merged_crossings) ||
        (merged_crossings.empty() && flat > 0 && self_intersecting_pairs(merged).empty())) {
      const size_t removed = mesh.triangles.size() - merged.triangles.size();
      mesh = std::move(merged);
      return removed;
    }
    if (merged_crossings.empty()) return 0;
    // A fan triangle was made by merging a vertex whose neighbours include its corners, and
    // no vertex next to a kept one merges: keeping every input vertex in the crossing
    // triangles' boxes undoes them. When none is newly kept, the input itself crosses there.
    bool more = false;
    for (uint32_t u = 0; u < mesh.positions.size(); ++u)
      for (const auto& [lo, hi] : merged_crossings) {
        bool inside = !keep[u];
        for (int k = 0; k < 3 && inside; ++k)
          inside = mesh.positions[u][k] >= lo[k] - drift && mesh.positions[u][k] <= hi[k] + drift;
        if (inside) keep[u] = 1, more = true;
      }
    if (!more) return 0;
  }
  return 0;
}

}  // namespace pic
