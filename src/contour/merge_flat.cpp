// Flat regions merged without moving the surface. A vertex whose star lies in one plane goes
// onto a neighbour: when every triangle of the fan from that neighbour keeps the plane's
// orientation, the fan covers the same polygon the star did, so the surface as a point set
// does not change (up to the star's distance from its plane). On a dual contour most vertices
// are such (a flat face has a vertex per cell); merging them this way costs a star's
// orientations, where the simplification proper checks every original point of two stars
// against the new one.
#include "contour/merge_flat.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>

#include "contour/blocks.h"
#include "contour/edge_collapse.h"
#include "contour/triangle_shape.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"

namespace pic::detail {

namespace {

class FlatMerger {
 public:
  FlatMerger(TriMesh& mesh, double drift, const std::vector<uint8_t>* keep)
      : keep_(keep), pos_(mesh.positions), tris_(mesh.triangles), faces_(pos_.size()), alive_(tris_.size(), 1),
        moved_(pos_.size(), 0.0), drift_(drift), deferred_(pos_.size(), 1) {
    std::vector<uint32_t> degree(pos_.size(), 0);
    for (const auto& t : tris_)
      for (uint32_t w : t) ++degree[w];
    for (uint32_t w = 0; w < pos_.size(); ++w) faces_[w].reserve(degree[w]);
    for (uint32_t f = 0; f < tris_.size(); ++f)
      for (uint32_t w : tris_[f]) faces_[w].push_back(f);
    had_triangles_.resize(pos_.size());
    for (uint32_t u = 0; u < pos_.size(); ++u) had_triangles_[u] = !faces_[u].empty();
  }

  /// The blocks of the first two grids, each grid's in parallel, then what they left over the
  /// whole mesh (the merges are short-ranged: on example004 the second grid tries 5 % of the
  /// vertices, the last pass 1 %). The blocks do not depend on the thread count, so neither
  /// does the result.
  void run() {
    const BlockGrid grid(pos_);
    for (size_t g = 0; g < 2; ++g) {
      membership_.assign(pos_.size(), kNoBlock);
      std::vector<std::vector<uint32_t>> members(kGrids[g].count());
      for (uint32_t u = 0; u < pos_.size(); ++u)
        if (!faces_[u].empty()) {
          membership_[u] = grid.block(pos_[u], kGrids[g]);
          members[membership_[u]].push_back(u);
        }
      tbb::parallel_for(size_t{0}, members.size(), [&](size_t b) {
        std::vector<uint8_t> dirty(members[b].size());
        for (size_t i = 0; i < dirty.size(); ++i) dirty[i] = std::exchange(deferred_[members[b][i]], 0);
        passes(members[b], std::move(dirty), int(b));
      });
    }
    std::vector<uint32_t> all(pos_.size());
    std::iota(all.begin(), all.end(), 0u);
    std::vector<uint8_t> dirty(deferred_.begin(), deferred_.end());
    passes(all, std::move(dirty), kAnyBlock);
  }

  size_t removed() const { return size_t(std::count(alive_.begin(), alive_.end(), 0)); }

  /// The vertices merged onto a neighbour (not those that never had a triangle).
  void merged_away(std::vector<Vec3>& out) const {
    out.clear();
    for (uint32_t u = 0; u < pos_.size(); ++u)
      if (faces_[u].empty() && had_triangles_[u]) out.push_back(pos_[u]);
  }

  TriMesh result() const { return live_mesh(pos_, tris_, alive_); }

 private:
  static constexpr uint32_t kNone = UINT32_MAX;
  const std::vector<uint8_t>* keep_;  // per vertex: its star stays as it is (none: all may merge)
  const std::vector<Vec3>& pos_;
  std::vector<std::array<uint32_t, 3>>& tris_;
  std::vector<std::vector<uint32_t>> faces_;  // per vertex: its live triangles
  std::vector<uint8_t> alive_, had_triangles_;
  // Per vertex: how far the surface around it may have moved (every live triangle lies within
  // the largest of its corners' bounds of the input, and the input there within it of them).
  std::vector<double> moved_;
  double drift_;
  std::vector<uint8_t> deferred_;      // per vertex: to be tried again in the next grid
  // A triangle of the star of the vertex being tried, read once: its corners and positions.
  struct StarTriangle {
    std::array<uint32_t, 3> v;
    std::array<Vec3, 3> p;
  };
  // What trying one vertex needs for itself (each block has its own).
  struct Scratch {
    std::vector<uint32_t> ring, v_ring;
    std::vector<StarTriangle> star;
  };
  std::vector<uint16_t> membership_;  // per live vertex: its block of the grid in use
  static constexpr uint16_t kNoBlock = UINT16_MAX;
  static constexpr int kAnyBlock = -1;

  /// Passes over `members` (ascending; `dirty` per member: to be tried) until a pass merges
  /// fewer than a thousandth of them; after the first, only vertices whose star changed are
  /// tried again. With a `block`, only vertices whose neighbours all lie in it; the others, and
  /// those whose star changed after their last try, are marked deferred_.
  void passes(const std::vector<uint32_t>& members, std::vector<uint8_t> dirty, int block) {
    std::vector<uint8_t> next(members.size(), 0);
    const auto local = [&](uint32_t w) {
      return block == kAnyBlock ? size_t(w) : size_t(std::lower_bound(members.begin(), members.end(), w) - members.begin());
    };
    Scratch s;
    bool stopped = false;
    for (int pass = 0; pass < 32; ++pass) {
      size_t done = 0;
      for (size_t i = 0; i < members.size(); ++i) {
        const uint32_t u = members[i];
        if (!dirty[i] || faces_[u].empty()) continue;
        bool left_block = false;
        double moved = 0;
        const uint32_t v = best_target(u, block, s, left_block, moved);
        deferred_[u] = left_block;
        if (v == kNone) continue;
        for (uint32_t w : s.ring) next[local(w)] = 1;
        collapse(u, v, moved);
        ++done;
      }
      if (done * 1000 < members.size()) {
        stopped = true;
        break;
      }
      dirty.swap(next);
      std::fill(next.begin(), next.end(), 0);
    }
    const std::vector<uint8_t>& untried = stopped ? next : dirty;
    for (size_t i = 0; i < members.size(); ++i)
      if (untried[i] && !faces_[members[i]].empty()) deferred_[members[i]] = 1;
  }

  /// The neighbour u may go onto without moving the surface, the one leaving the best-shaped
  /// triangles; kNone when u's star is not flat or no neighbour will do.
  uint32_t best_target(uint32_t u, int block, Scratch& s, bool& left_block, double& moved) {
    auto& ring = s.ring;
    ring.clear();
    s.star.clear();
    Vec3 n{0, 0, 0};
    for (uint32_t f : faces_[u]) {
      const auto& t = tris_[f];
      for (uint32_t w : t)
        if (w != u) ring.push_back(w);
      const StarTriangle& st = s.star.emplace_back(StarTriangle{t, {pos_[t[0]], pos_[t[1]], pos_[t[2]]}});
      n = add3(n, triangle_normal(st.p[0], st.p[1], st.p[2]));
    }
    if (block != kAnyBlock)
      for (uint32_t w : ring)
        if (membership_[w] != block) return left_block = true, kNone;
    if (keep_ && !keep_->empty()) {
      if ((*keep_)[u]) return kNone;
      for (uint32_t w : ring)
        if ((*keep_)[w]) return kNone;
    }
    const double len = norm3(n);
    if (!(len > 0)) return kNone;
    n = scale3(n, 1 / len);
    // Flat: every vertex of the star this near the plane through u, every triangle facing
    // the plane's way (no pleat). Most stars that are not flat stop here, first.
    double off = 0, bound = moved_[u];
    for (uint32_t w : ring) {
      off = std::max(off, std::abs(dot3(n, sub3(pos_[w], pos_[u]))));
      bound = std::max(bound, moved_[w]);
    }
    // The fan and the star both lie within `off` of the plane over the same polygon.
    bound += 2 * off;
    if (!(bound <= drift_)) return kNone;
    double worst_before = 1;
    for (const StarTriangle& t : s.star) {
      const Vec3 m = triangle_normal(t.p[0], t.p[1], t.p[2]);
      if (!(dot3(m, n) >= kKeptNormalCosine * norm3(m))) return kNone;
      worst_before = std::min(worst_before, triangle_quality(t.p[0], t.p[1], t.p[2]));
    }
    // A closed disk: the link is one cycle through every neighbour once (each on exactly two
    // triangles of the star).
    if (!one_cycle(u)) return kNone;
    std::sort(ring.begin(), ring.end());
    const double min_quality = std::min(kMinTriangleQuality, worst_before);
    uint32_t best = kNone;
    double best_quality = -1;
    for (size_t i = 0; i < ring.size(); i += 2) {
      const uint32_t v = ring[i];
      double q = 0;
      if (fan_keeps(u, v, s.star, n, std::max(min_quality, best_quality), q) && q > best_quality &&
          link_condition(u, v, ring, s.v_ring))
        best = v, best_quality = q;
    }
    moved = bound;
    return best;
  }

  /// Whether u's star is a disk: following each triangle's side opposite u from one end to
  /// the other (they keep the star's orientation) goes once round every triangle.
  bool one_cycle(uint32_t u) const {
    const auto& star = faces_[u];
    if (star.size() < 4) return false;  // a valence-3 vertex: the tetrahedron's, kept
    const auto side = [&](uint32_t f) {
      const auto& t = tris_[f];
      const int k = t[0] == u ? 0 : t[1] == u ? 1 : 2;
      return std::pair{t[(k + 1) % 3], t[(k + 2) % 3]};
    };
    uint32_t at = side(star[0]).second;
    for (size_t step = 1; step < star.size(); ++step) {
      size_t next = 0, found = 0;
      for (size_t i = 0; i < star.size(); ++i)
        if (side(star[i]).first == at) next = i, ++found;
      if (found != 1 || next == 0) return false;
      at = side(star[next]).second;
    }
    return at == side(star[0]).first;
  }

  /// Whether u's triangles (`star`) without v, once u stands at v, all face the plane's way
  /// (n) and are shaped at least `floor`; `worst` is set to the worst shape among them.
  bool fan_keeps(uint32_t u, uint32_t v, const std::vector<StarTriangle>& star, const Vec3& n, double floor,
                 double& worst) const {
    worst = 1;
    const Vec3& at = pos_[v];
    for (const StarTriangle& t : star) {
      if (t.v[0] == v || t.v[1] == v || t.v[2] == v) continue;
      std::array<Vec3, 3> p = t.p;
      for (int k = 0; k < 3; ++k)
        if (t.v[k] == u) p[k] = at;
      const Vec3 m = triangle_normal(p[0], p[1], p[2]);
      const double along = dot3(m, n);
      if (!(along > 0 && along * along >= kKeptNormalCosine * kKeptNormalCosine * dot3(m, m))) return false;
      worst = std::min(worst, triangle_quality(p[0], p[1], p[2]));
      if (worst < floor) return false;
    }
    return true;
  }

  /// The link condition: the edge uv lies on exactly two triangles, and u and v share
  /// exactly the two neighbours across it (`ring`: u's, sorted; `v_ring`: scratch).
  bool link_condition(uint32_t u, uint32_t v, const std::vector<uint32_t>& ring, std::vector<uint32_t>& v_ring) const {
    size_t shared = 0;
    for (uint32_t f : faces_[u]) {
      const auto& t = tris_[f];
      shared += t[0] == v || t[1] == v || t[2] == v;
    }
    if (shared != 2) return false;
    v_ring.clear();
    for (uint32_t f : faces_[v])
      for (uint32_t w : tris_[f])
        if (w != v && w != u) v_ring.push_back(w);
    std::sort(v_ring.begin(), v_ring.end());
    v_ring.erase(std::unique(v_ring.begin(), v_ring.end()), v_ring.end());
    size_t common = 0;
    for (uint32_t w : v_ring) common += std::binary_search(ring.begin(), ring.end(), w);
    return common == 2;
  }

  /// u onto v; every vertex of u's star may have moved by `moved` since the input.
  void collapse(uint32_t u, uint32_t v, double moved) {
    for (uint32_t f : faces_[u])
      for (uint32_t w : tris_[f]) moved_[w] = std::max(moved_[w], moved);
    hand_star_over(u, v, tris_, faces_, alive_);
  }
};

}  // namespace

size_t merge_flat(TriMesh& mesh, double drift, std::vector<Vec3>* merged_away, const std::vector<uint8_t>* keep) {
  if (merged_away) merged_away->clear();
  if (!(drift > 0) || mesh.triangles.empty()) return 0;
  FlatMerger m(mesh, drift, keep);
  m.run();
  const size_t removed = m.removed();
  if (merged_away) m.merged_away(*merged_away);
  if (removed) mesh = m.result();
  return removed;
}

}  // namespace pic::detail
