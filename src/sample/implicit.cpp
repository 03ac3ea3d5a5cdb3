// Sampling a solid given by a function of space (pic::ImplicitSolid): the paper's top-down
// rules with f in place of a mesh. Corner signs are f's sign at the lattice point, so one sign
// per point holds by construction; a cell whose corners agree is subdivided unless f's
// Lipschitz bound proves the surface out of reach, so no sign change hides in a coarse uniform
// leaf above the cap (no cracks for the settling to mend).
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <vector>

#include "geometry/lattice.h"
#include "geometry/memo.h"
#include "geometry/qef.h"
#include "geometry/root.h"
#include "geometry/stopwatch.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"
#include "octree/cell.h"
#include "octree/cell_vertex.h"
#include "octree/dual_walk.h"
#include "pic/sample.h"
#include "sample/rounded_edges.h"
#include "signs/invariants.h"
#include "signs/settle.h"

namespace pic {

namespace {

using namespace detail;
using Lat = std::array<int64_t, 3>;

Vec3 lattice_unit(const Lat& l) {
  constexpr double k = 1.0 / double(int64_t{1} << kMaxLevel);
  return {double(l[0]) * k, double(l[1]) * k, double(l[2]) * k};
}

/// A lattice point as one number, its coordinates' bits interleaved (21 bits each: kMaxLevel
/// is 20): sorted so, a batch of points goes along a space-filling curve, and each query of a
/// distance starts near the last one's answer.
uint64_t spread(uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffull;
  x = (x | x << 16) & 0x1f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  x = (x | x << 2) & 0x1249249249249249ull;
  return x;
}
uint64_t gather(uint64_t x) {
  x &= 0x1249249249249249ull;
  x = (x | x >> 2) & 0x10c30c30c30c30c3ull;
  x = (x | x >> 4) & 0x100f00f00f00f00full;
  x = (x | x >> 8) & 0x1f0000ff0000ffull;
  x = (x | x >> 16) & 0x1f00000000ffffull;
  x = (x | x >> 32) & 0x1fffff;
  return x;
}
uint64_t pack(const Lat& l) { return spread(uint64_t(l[0])) | spread(uint64_t(l[1])) << 1 | spread(uint64_t(l[2])) << 2; }
Lat unpack(uint64_t k) { return {int64_t(gather(k)), int64_t(gather(k >> 1)), int64_t(gather(k >> 2))}; }

constexpr uint32_t kNone = ~uint32_t{0};

/// The parallelogram law's lower bound on the distance to a set at a mean point c = sum w_k x_k
/// (weights summing to 1) of points x_k all on one side of its boundary: for any set,
/// d(c)^2 >= sum w_k d(x_k)^2 - sum w_k |x_k - c|^2. Takes both sums; 0 where they leave nothing.
double parallelogram_bound(double weighted_d2, double weighted_spread) {
  const double d2 = weighted_d2 - weighted_spread;
  return d2 > 0 ? std::sqrt(d2) : 0;
}

/// Numbers the distinct keys of `refs` (key, owner) by their first owner: each owner's
/// number goes to `id` (indexed by owner; owners not in `refs` keep kNone). Returns the
/// count. Numbering by first owner keeps a batch in the order the cells asked, near points
/// after near points (a distance query starts from the last one's answer).
size_t number_keys(std::vector<std::pair<uint64_t, uint32_t>>& refs, std::vector<uint32_t>& id, bool parallel) {
  std::fill(id.begin(), id.end(), kNone);
  if (parallel) tbb::parallel_sort(refs.begin(), refs.end());
  else std::sort(refs.begin(), refs.end());
  size_t n = 0;
  for (size_t i = 0; i < refs.size(); ++i) {
    if (i > 0 && refs[i].first != refs[i - 1].first) ++n;
    id[refs[i].second] = uint32_t(n);
  }
  const size_t count = refs.empty() ? 0 : n + 1;
  std::vector<uint32_t> renumber(count, kNone);
  uint32_t next = 0;
  for (uint32_t& x : id)
    if (x != kNone) {
      if (renumber[x] == kNone) renumber[x] = next++;
      x = renumber[x];
    }
  return count;
}

/// f at a lattice point, memoized per thread where f is asked one point at a time (up to
/// eight cells of a level share a point).
struct PointValue {
  Lat p;
  bool filled = false;
  double f = 0;
};
using PointMemo = ThreadMemo<PointValue, 16>;
/// The surface point on a cell edge and f's gradient there, memoized the same way (up to
/// four cells share an edge).
struct EdgeHermite {
  Lat a;
  int64_t span = 0;
  int axis = 0;
  bool filled = false;
  Vec3 x, g;
};
using EdgeMemo = ThreadMemo<EdgeHermite, 14>;
/// f at a gray leaf's vertex as stored (`at`: its unit position after rounding to the leaf's
/// float coordinates), asked at the unrounded position `slack` (world units) away, with the
/// site there (ImplicitSolid::value_site).
struct VertexValue {
  Vec3 at;
  double f;
  float slack;  // rounded up (widened by a millionth before rounding to a float)
  uint32_t site;
};
/// What a function asked one point at a time is memoized in, and what its vertex and octant
/// checks found for the polygons' check.
struct Memos {
  PointMemo points;
  EdgeMemo edges;
  tbb::enumerable_thread_specific<std::vector<VertexValue>> vertices;
  std::vector<VertexValue> vertices_sorted;  // those gathered so far, by position
  /// Surface points (unit space) the octant checks found in a leaf's cell away from its planes.
  tbb::enumerable_thread_specific<std::vector<Vec3>> unrepresented;
};

/// Leaves within this many levels of the cap are not asked whether they hide surface: a sheet
/// hidden in one moves the surface by less than its size, 4 finest cells, and asking them
/// doubled the values an offset takes (spot grown at depth 10: 2.15 M instead of 1.13 M) for
/// no change measured.
constexpr int kUncheckedLevels = 2;

/// Newton steps from an octant centre towards the surface, at most (a part hidden in a leaf).
constexpr int kSurfaceSteps = 6;

/// A cell waiting at its level, with f at its corners.
struct Job {
  Cell cell;
  uint32_t slot;
  std::array<double, 8> v;
};

/// A sign-changing cell edge, once per level (up to 4 cells share it): its ends in unit
/// space, f there, and the surface point on it with f's gradient.
struct Edge {
  Vec3 a, b;
  double fa = 0, fb = 0, size = 0;
  Vec3 x{}, g{};
};

class LevelSampler {
 public:
  /// `memo`: for a function asked one point at a time (none for a batched one).
  LevelSampler(const ImplicitSolid& f, const Cube& cube, int max_depth, double error, bool parallel, Memos* memo)
      : f_(f), cube_(cube), max_depth_(max_depth), error_(error), parallel_(parallel), memo_(memo) {}

  /// f at unit-space points, as one batch.
  std::vector<double> values(const std::vector<Vec3>& unit) {
    std::vector<double> out(unit.size());
    if (unit.empty()) return out;
    evaluations += unit.size();
    if (f_.values) {
      std::vector<Vec3> w(unit.size());
      for (size_t i = 0; i < unit.size(); ++i) w[i] = world(unit[i]);
      f_.values(w, out);
      if (out.size() != unit.size()) throw InvalidInput("the function must give one value per point");
    } else {
      for_each(unit.size(), [&](size_t i) { out[i] = f_.value(world(unit[i])); });
    }
    return out;
  }

  /// Samples `cell` (f at its corners: `v`) level by level into a tree rooted at node 0. A
  /// C++ function in parallel: the first levels over the whole cell, then each cell of level
  /// kSubtreeLevel on its own, the cells in parallel -- each one's batches stay small, near
  /// in memory as in space. A batched function sees each level whole.
  Builder run(const Cell& cell, const std::array<double, 8>& v, size_t& capped) {
    Builder out;
    out.nodes.resize(1);
    std::vector<Job> jobs{{cell, 0, v}};
    while (!jobs.empty()) {
      if (parallel_ && !f_.values && jobs.front().cell.level == kSubtreeLevel) {
        run_apart(jobs, out, capped);
        break;
      }
      std::vector<Job> split;
      settle_uniform(jobs, out, split);
      place_vertices(jobs, out, split, capped);
      jobs = subdivide(split, out);
    }
    return out;
  }

  size_t evaluations = 0;

  /// Splits every cell whose closed box holds one of the lattice points `p` down to the cap
  /// (with `to_corner`: until each point is a corner of the cells around it), whatever f says
  /// there: a leaf sampled again around points the settling would flip (refine_around), or
  /// whose finer neighbours sampled them with f's sign (then f's sign there is all it takes).
  void focus_on(std::vector<Lat> p, bool to_corner = false) {
    focus_ = std::move(p);
    to_corner_ = to_corner;
  }

 private:
  std::vector<Lat> focus_;
  bool to_corner_ = false;
  bool focused(const Cell& cell) const {
    return cell.level < max_depth_ && std::any_of(focus_.begin(), focus_.end(), [&](const Lat& p) {
             return cell.holds(p) && (!to_corner_ || cell.corner_index(p) < 0);
           });
  }

  const ImplicitSolid& f_;
  Cube cube_;
  int max_depth_;
  double error_;
  bool parallel_;
  Memos* memo_;

  double value_at(const Lat& p) {
    PointValue& e = memo_->points.slot(memo_slot(p, 0, PointMemo::kBits));
    if (!e.filled || e.p != p) {
      ++evaluations;
      e = {p, true, f_.value(world(lattice_unit(p)))};
    }
    return e.f;
  }

  static constexpr int kSubtreeLevel = 2;

  void run_apart(const std::vector<Job>& jobs, Builder& out, size_t& capped) {
    std::vector<Builder> subs(jobs.size());
    std::vector<size_t> caps(jobs.size()), evals(jobs.size());
    tbb::parallel_for(size_t{0}, jobs.size(), [&](size_t i) {
      LevelSampler one(f_, cube_, max_depth_, error_, false, memo_);
      subs[i] = one.run(jobs[i].cell, jobs[i].v, caps[i]);
      evals[i] = one.evaluations;
    });
    for (size_t i = 0; i < jobs.size(); ++i) {
      out.splice(jobs[i].slot, subs[i]);
      capped += caps[i];
      evaluations += evals[i];
    }
  }

  template <class F>
  void for_each(size_t n, F&& f) const {
    if (parallel_ && n > 256) {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i < r.end(); ++i) f(i);
      });
    } else {
      for (size_t i = 0; i < n; ++i) f(i);
    }
  }

  Vec3 world(const Vec3& unit) const {
    return {cube_.origin[0] + unit[0] * cube_.size, cube_.origin[1] + unit[1] * cube_.size,
            cube_.origin[2] + unit[2] * cube_.size};
  }

  static uint8_t signs_of(const std::array<double, 8>& v) {
    uint8_t signs = 0;
    for (int k = 0; k < 8; ++k) signs |= uint8_t(v[k] < 0) << k;
    return signs;
  }
  /// f's reach over a cell's diagonal, in world units.
  double diagonal(const Cell& cell) const { return f_.lipschitz * cell.size() * cube_.size * std::sqrt(3.0); }

  /// Uniform cells become leaves at the cap or where f's bound keeps the surface out of the
  /// whole cell: |f| at a corner beyond the diagonal, else at the centre beyond half of it
  /// (those centres asked in one batch) -- or, where f can say so, its box proven clear. The
  /// rest go to `split`.
  void settle_uniform(const std::vector<Job>& jobs, Builder& out, std::vector<Job>& split) {
    std::vector<size_t> open;
    std::vector<Vec3> centres;
    for (size_t i = 0; i < jobs.size(); ++i) {
      const Job& j = jobs[i];
      const uint8_t signs = signs_of(j.v);
      if (signs != 0 && signs != 0xff) continue;
      if (focused(j.cell)) {
        split.push_back(j);
        continue;
      }
      bool away = j.cell.level >= max_depth_;
      for (double x : j.v) away = away || std::abs(x) > diagonal(j.cell);
      if (away) {
        out.set_uniform(j.slot, signs != 0);
        continue;
      }
      open.push_back(i);
      if (f_.clear) continue;
      const Vec3 m = j.cell.min_unit();
      const double h = j.cell.size() / 2;
      centres.push_back({m[0] + h, m[1] + h, m[2] + h});
    }
    std::vector<char> clear(open.size(), 0);
    if (f_.clear) {
      evaluations += open.size();
      for_each(open.size(), [&](size_t k) {
        const Cell& c = jobs[open[k]].cell;
        clear[k] = f_.clear(world(c.min_unit()), world(c.max_unit()));
      });
    } else {
      const std::vector<double> fc = values(centres);
      for (size_t k = 0; k < open.size(); ++k) clear[k] = std::abs(fc[k]) > diagonal(jobs[open[k]].cell) / 2;
    }
    for (size_t k = 0; k < open.size(); ++k) {
      const Job& j = jobs[open[k]];
      if (clear[k]) out.set_uniform(j.slot, signs_of(j.v) != 0);
      else split.push_back(j);
    }
  }

  /// Gray cells at the cap or with one surface component get their QEF vertex from the
  /// crossings of their edges (each edge's found once, all in step); a vertex is kept when
  /// the planes fit, it lies in its cell and on the surface within the error (edge crossings
  /// alone take a rounded corner for the sharp one), or at the cap. The rest go to `split`.
  void place_vertices(const std::vector<Job>& jobs, Builder& out, std::vector<Job>& split, size_t& capped) {
    std::vector<size_t> cand;
    std::vector<std::array<uint32_t, 12>> cell_edges;  // first into `refs`, then into `edges`
    std::vector<Edge> found;                            // per ref
    std::vector<std::pair<uint64_t, uint32_t>> refs;    // (edge key, ref)
    std::vector<std::pair<Lat, int>> start;             // per ref: first corner and axis
    for (size_t i = 0; i < jobs.size(); ++i) {
      const Job& j = jobs[i];
      const uint8_t signs = signs_of(j.v);
      if (signs == 0 || signs == 0xff) continue;
      if (j.cell.level < max_depth_ && (!one_component(signs) || focused(j.cell))) {
        split.push_back(j);
        continue;
      }
      cand.push_back(i);
      std::array<uint32_t, 12> ids;
      ids.fill(kNone);
      const Vec3 m = j.cell.min_unit();
      const double s = j.cell.size();
      auto corner = [&](int k) { return Vec3{m[0] + (k & 1) * s, m[1] + ((k >> 1) & 1) * s, m[2] + ((k >> 2) & 1) * s}; };
      for (int e = 0; e < 12; ++e) {
        const int c0 = kEdgeCorners[e][0], c1 = kEdgeCorners[e][1];
        if (((signs >> c0) & 1) == ((signs >> c1) & 1)) continue;
        // An edge's key: its first corner and its axis (a level's edges share one length).
        if (!memo_) refs.push_back({pack(j.cell.corner(c0)) * 3 + uint64_t(edge_axis(e)), uint32_t(found.size())});
        ids[e] = uint32_t(found.size());
        found.push_back({corner(c0), corner(c1), j.v[c0], j.v[c1], s});
        start.push_back({j.cell.corner(c0), edge_axis(e)});
      }
      cell_edges.push_back(ids);
    }
    std::vector<Edge> edges;
    if (memo_) {
      // One point at a time: each edge through the memo, in cell order.
      edges = std::move(found);
      for (size_t r = 0; r < edges.size(); ++r) {
        const int64_t span = jobs[0].cell.span();
        EdgeHermite& h = memo_->edges.slot(edge_memo_slot(start[r].first, start[r].second, span, EdgeMemo::kBits));
        if (!h.filled || h.a != start[r].first || h.axis != start[r].second || h.span != span) {
          cross_one(edges[r]);
          h = {start[r].first, span, start[r].second, true, edges[r].x, edges[r].g};
        }
        edges[r].x = h.x, edges[r].g = h.g;
      }
    } else {
      std::vector<uint32_t> edge_of(found.size());
      edges.resize(number_keys(refs, edge_of, parallel_));
      for (size_t r = 0; r < found.size(); ++r) edges[edge_of[r]] = found[r];
      for (auto& ids : cell_edges)
        for (uint32_t& id : ids)
          if (id != kNone) id = edge_of[id];
      crossings(edges);
    }
    std::vector<Qef::Solution> sol(cand.size());
    for_each(cand.size(), [&](size_t k) {
      const Job& j = jobs[cand[k]];
      Qef q;
      for (uint32_t id : cell_edges[k]) {
        if (id == kNone) continue;
        const double len = norm3(edges[id].g);
        if (!(len > 0)) continue;
        const Vec3 n = scale3(edges[id].g, 1 / len);
        q.add_plane(n, dot3(n, edges[id].x), 1);
      }
      sol[k] = cell_vertex(q, j.cell, signs_of(j.v));
    });
    // f at the vertices that pass every other test (one batch): the last test.
    std::vector<size_t> fitting;
    std::vector<Vec3> at;
    for (size_t k = 0; k < cand.size(); ++k) {
      const Job& j = jobs[cand[k]];
      if (sol[k].error < error_ && inside_cell(sol[k].position, j.cell) && one_component(signs_of(j.v))) {
        fitting.push_back(k);
        at.push_back(sol[k].position);
      }
    }
    // With sites (ImplicitSolid::value_site), each vertex's site bounds f in its octants.
    std::vector<uint32_t> site(cand.size(), kNone);
    std::vector<double> fv;
    if (f_.value_site && !f_.values) {
      fv.resize(at.size());
      evaluations += at.size();
      for_each(at.size(), [&](size_t i) { fv[i] = f_.value_site(world(at[i]), site[fitting[i]]); });
    } else {
      fv = values(at);
    }
    std::vector<char> fits(cand.size(), 0);
    for (size_t i = 0; i < fitting.size(); ++i) {
      const double off = reach(fv[i]);
      fits[fitting[i]] = off * off < error_;
    }
    split_leaves_cutting_bends(jobs, cand, sol, fits);
    keep_only_whole_surfaces(jobs, cand, cell_edges, edges, site, fits);
    for (size_t k = 0; k < cand.size(); ++k) {
      const Job& j = jobs[cand[k]];
      const uint8_t signs = signs_of(j.v);
      const bool ok = fits[k];
      if (ok || j.cell.level >= max_depth_) {
        if (!ok) ++capped;
        out.set_gray(j.slot, j.cell, signs, sol[k].position, ok ? 0 : kFlagCapped);
      } else {
        split.push_back(j);
      }
    }
    // The kept leaves' vertex values, for the polygons' check.
    if (memo_ && f_.value_site && !f_.values) {
      std::vector<VertexValue>& kept = memo_->vertices.local();
      for (size_t i = 0; i < fitting.size(); ++i) {
        const size_t k = fitting[i];
        if (!fits[k]) continue;
        const Cell& cell = jobs[cand[k]].cell;
        const Vec3 stored = vertex_unit(cell, to_local(cell, sol[k].position));
        kept.push_back({stored, fv[i], float(norm3(sub3(stored, sol[k].position)) * cube_.size * (1 + 1e-6)), site[k]});
      }
    }
  }

  /// A leaf above the cap whose vertex lies off a bend of the surface that f reports in its
  /// cell (ImplicitSolid::bends: an offset's round of a sharp edge, between crossings that all
  /// land on the flat parts beside it) is split: its planes' corner would cut the round off.
  void split_leaves_cutting_bends(const std::vector<Job>& jobs, const std::vector<size_t>& cand,
                                  const std::vector<Qef::Solution>& sol, std::vector<char>& fits) {
    if (!f_.bends) return;
    const double tolerance = bend_tolerance(cube_, max_depth_, error_) / cube_.size;
    std::vector<size_t> leaf;  // per point asked
    std::vector<Vec3> points;  // unit coordinates
    std::vector<std::array<Vec3, 2>> found;
    for (size_t k = 0; k < cand.size(); ++k) {
      const Cell& c = jobs[cand[k]].cell;
      if (!fits[k] || c.level >= max_depth_) continue;
      found.clear();
      f_.bends(world(c.min_unit()), world(c.max_unit()), world(sol[k].position), found);
      for (const auto& [at, normal] : found) {
        const Vec3 p = scale3(sub3(at, cube_.origin), 1 / cube_.size);
        if (std::abs(dot3(sub3(sol[k].position, p), normal)) <= tolerance) continue;
        leaf.push_back(k);
        points.push_back(p);
      }
    }
    // Only where the bend is the surface: a nearer part of the solid may hide it.
    const std::vector<double> f = values(points);
    for (size_t i = 0; i < points.size(); ++i)
      if (reach(f[i]) <= tolerance) fits[leaf[i]] = 0;
  }

  /// A leaf above the cap may stand only for surface its planes (the crossings of its edges)
  /// account for. Its corners and edges can miss a part of the solid passing between them (a
  /// fandisk flange grown by a hair, inside a cell 30 finest cells wide), and two or three
  /// crossings always fit a line or a point, so a curved sheet can pass for a crease (a hole's
  /// offset cylinder meeting a face's offset plane in a cell 64 finest cells wide, its vertex
  /// on their crease and every test passed). Each octant of such a cell is asked at its centre
  /// c: c must lie on the side of the nearest plane that f says, unless near both; and |f(c)|,
  /// which bounds the distance from c to the surface from below, must not say the surface is
  /// nearer than every plane. Every point of the cell lies within an octant's half-diagonal of
  /// its centre, so a sheet anywhere in the cell shows in some octant's bound; a sheet the
  /// bound cannot tell from a plane lies about as near c as the plane does. Leaves within
  /// kUncheckedLevels of the cap are not asked. Where the leaf's polygons run, between its
  /// vertex and its neighbours', is asked once the tree is whole (refine_polygons_off_surface).
  void keep_only_whole_surfaces(const std::vector<Job>& jobs, const std::vector<size_t>& cand,
                                const std::vector<std::array<uint32_t, 12>>& cell_edges, const std::vector<Edge>& edges,
                                const std::vector<uint32_t>& site, std::vector<char>& fits) {
    std::vector<size_t> asked;
    for (size_t k = 0; k < cand.size(); ++k)
      if (fits[k] && jobs[cand[k]].cell.level + kUncheckedLevels < max_depth_) asked.push_back(k);
    octants_agree(jobs, cand, asked, cell_edges, edges, site, fits);
  }

  /// |f| as a lower bound on the distance to the surface, in unit-cube lengths.
  double reach(double value) const { return std::abs(value) / (f_.lipschitz * cube_.size); }

  /// The planes fit the crossings within sqrt(error): twice that is rounding, not a sheet.
  double sheet_tolerance() const { return 2 * std::sqrt(error_); }

  /// How a leaf's planes bound its solid (crease_of): the intersection of their inner sides (a
  /// convex corner or crease), their union (a concave one), or neither, as its corner signs say.
  enum class Crease { Convex, Concave, Other };
  /// Where a point lies among a leaf's planes (plane_distances).
  struct PlaneDistances {
    double nearest, side, represented;
  };

  /// Each octant of the leaves `asked`, at its centre c, but those their own corner clears (|f|
  /// there beyond the octant's diagonal: no surface in it): c on the side of the nearest plane
  /// that f says, unless near both; and, where |f| is a distance, the surface no nearer c than
  /// every plane. Clears `fits` where an octant disagrees.
  void octants_agree(const std::vector<Job>& jobs, const std::vector<size_t>& cand, const std::vector<size_t>& asked,
                     const std::vector<std::array<uint32_t, 12>>& cell_edges, const std::vector<Edge>& edges,
                     const std::vector<uint32_t>& site, std::vector<char>& fits) {
    const double tolerance = sheet_tolerance();
    std::vector<size_t> leaf;  // per centre
    std::vector<Vec3> centres;
    std::vector<PlaneDistances> planes;  // per centre
    std::vector<Crease> creases;         // per centre
    for (size_t k : asked) {
      const Job& j = jobs[cand[k]];
      const Vec3 m = j.cell.min_unit();
      const double q = j.cell.size() / 4, diagonal = j.cell.size() * std::sqrt(3.0) / 2;
      const Crease crease = crease_of(j, cell_edges[k], edges);
      for (int o = 0; o < 8; ++o) {
        if (reach(j.v[o]) > diagonal) continue;
        const Vec3 c{m[0] + (o & 1 ? 3 : 1) * q, m[1] + (o & 2 ? 3 : 1) * q, m[2] + (o & 4 ? 3 : 1) * q};
        // Within the tolerance of a plane both tests below pass, whatever f says there.
        const PlaneDistances plane = plane_distances(c, crease, cell_edges[k], edges);
        if (plane.nearest <= tolerance) continue;
        const Outcome known = octant_by_corners(j, o, c, site[k], plane, tolerance);
        if (known == Outcome::Agrees) continue;
        if (known == Outcome::Disagrees) {
          fits[k] = 0;
          continue;
        }
        leaf.push_back(k);
        centres.push_back(c);
        planes.push_back(plane);
        creases.push_back(crease);
      }
    }
    const std::vector<double> f = values(centres);
    std::vector<size_t> unrepresented;
    for (size_t i = 0; i < centres.size(); ++i) {
      const size_t k = leaf[i];
      const double size = jobs[cand[k]].cell.size(), r = reach(f[i]), half_diagonal = size * std::sqrt(3.0) / 4;
      const auto [nearest, side, represented] = planes[i];
      if (r > tolerance && nearest > tolerance && (f[i] < 0) != (side < 0)) fits[k] = 0;
      if (!f_.distance) continue;
      // Here |f| is taken at slope 1, as the distance along f's gradient to where f is 0: at
      // most the distance to the surface, for a bound steeper than 1 only near it.
      const double along = std::abs(f[i]) / cube_.size;
      if (along < half_diagonal && nearest > along + tolerance) fits[k] = 0;
      else if (fits[k] && !represented_reaches(along, represented, size, tolerance)) unrepresented.push_back(i);
    }
    if (!memo_) return;  // a batched f: no hidden-part check
    for (size_t i : unrepresented) {
      const size_t k = leaf[i];
      if (!fits[k]) continue;
      if (const auto p = unrepresented_surface_point(jobs[cand[k]], centres[i], creases[i], cell_edges[k], edges,
                                                     tolerance))
        memo_->unrepresented.local().push_back(*p);
    }
  }

  /// Whether the surface a leaf's planes stand for reaches the ball of radius `along` about an
  /// octant centre (within the tolerance), or that ball leaves the cell. Where |f| is the
  /// distance to the surface and the ball lies in the cell, the surface point nearest the
  /// centre is in the cell and must be represented there.
  static bool represented_reaches(double along, double represented, double size, double tolerance) {
    return along > size / 4 || represented <= along + tolerance;
  }

  /// The surface point f's gradient leads to from octant centre c (Newton steps: the first
  /// lands on the surface point nearest c where |f| is the distance; where |f| falls short of
  /// the distance, beside an offset's medial axis, a few more), when f confirms it on the
  /// surface, inside the cell and beyond the tolerance from the surface the leaf's planes
  /// stand for.
  /// Such a point may be a part of the solid lying in the cell apart from the leaf's surface,
  /// farther from c than a plane's extension but nearer than the surface the planes bound (a
  /// box 4 units wide hidden in a leaf 16 units wide, 0.6 from an octant centre whose leaf's
  /// planes meet 3.7 away), or surface the neighbours' vertices draw; the polygons' check
  /// tells the two apart once the tree is whole. One more value of f per step; none without
  /// f's gradient.
  std::optional<Vec3> unrepresented_surface_point(const Job& j, const Vec3& c, Crease crease,
                                                  const std::array<uint32_t, 12>& ids, const std::vector<Edge>& edges,
                                                  double tolerance) {
    if (!f_.value_gradient && !f_.gradient) return std::nullopt;
    const auto value_gradient = [&](const Vec3& x, Vec3& g) {
      ++evaluations;
      if (f_.value_gradient) return f_.value_gradient(world(x), g);
      g = f_.gradient(world(x));
      return f_.value(world(x));
    };
    const Vec3 lo = j.cell.min_unit();
    Vec3 p = c, g;
    double fp = value_gradient(p, g);
    for (int step = 0; step < kSurfaceSteps && reach(fp) > tolerance; ++step) {
      const double g2 = dot3(g, g);
      if (!(g2 > 0)) return std::nullopt;
      p = sub3(p, scale3(g, fp / (g2 * cube_.size)));  // unit space
      for (int k = 0; k < 3; ++k)
        if (!(p[k] >= lo[k] && p[k] <= lo[k] + j.cell.size())) return std::nullopt;
      fp = value_gradient(p, g);
    }
    if (reach(fp) > tolerance) return std::nullopt;
    if (plane_distances(p, crease, ids, edges).represented <= tolerance) return std::nullopt;
    return p;
  }

  static Crease crease_of(const Job& j, const std::array<uint32_t, 12>& ids, const std::vector<Edge>& edges) {
    bool convex = true, concave = true;
    for (int k = 0; k < 8 && (convex || concave); ++k) {
      const Vec3 x = lattice_unit(j.cell.corner(k));
      bool all = true, any = false, some = false;
      for (uint32_t id : ids) {
        if (id == kNone || !(norm3(edges[id].g) > 0)) continue;
        const bool in = dot3(edges[id].g, sub3(x, edges[id].x)) < 0;
        all = all && in, any = any || in, some = true;
      }
      if (!some) return Crease::Other;
      const bool inside = j.v[k] < 0;
      convex = convex && inside == all;
      concave = concave && inside == any;
    }
    return convex ? Crease::Convex : concave ? Crease::Concave : Crease::Other;
  }

  /// Where c lies among a leaf's planes: the distance to the nearest, c's signed distance to it,
  /// and a lower bound on the distance to the surface the planes stand for — outside the
  /// intersection of their inner sides (or inside their union), the farthest plane c lies
  /// beyond (on the wrong side of); else the nearest plane.
  static PlaneDistances plane_distances(const Vec3& c, Crease crease, const std::array<uint32_t, 12>& ids,
                                        const std::vector<Edge>& edges) {
    double nearest = detail::kHuge, side = 0, beyond = 0;
    bool all_in = true, any_in = false;
    for (uint32_t id : ids) {
      if (id == kNone) continue;
      const double len = norm3(edges[id].g);
      if (!(len > 0)) continue;
      const double d = dot3(edges[id].g, sub3(c, edges[id].x)) / len;
      if (std::abs(d) < nearest) nearest = std::abs(d), side = d;
      all_in = all_in && d < 0, any_in = any_in || d < 0;
      if (crease == Crease::Convex && d > 0) beyond = std::max(beyond, d);
      if (crease == Crease::Concave && d < 0) beyond = std::max(beyond, -d);
    }
    const bool outside = (crease == Crease::Convex && !all_in) || (crease == Crease::Concave && any_in);
    return {nearest, side, outside ? beyond : nearest};
  }

  enum class Outcome { Agrees, Disagrees, Unknown };
  /// What octants_agree would find at octant o's centre c, where the leaf's corner values
  /// already decide it: f's bound from each corner x_k keeps |f(c)| at least |f(x_k)| - L|c - x_k|,
  /// and where that is positive f(c) has x_k's sign. For an offset, also the corners' distance
  /// bound (offset_bound) and, from the site of the leaf's vertex, an upper bound on c's distance
  /// to s's surface.
  Outcome octant_by_corners(const Job& j, int o, const Vec3& c, uint32_t site, const PlaneDistances& plane,
                            double tolerance) const {
    const double q = j.cell.size() / 4;
    double low = 0;  // a lower bound on reach(f(c))
    bool negative = false;
    for (int k = 0; k < 8; ++k) {
      const int far = std::popcount(unsigned(k ^ o));
      const double bound = reach(j.v[k]) - q * std::sqrt(double(3 - far) + 9.0 * far);
      if (bound > low) low = bound, negative = j.v[k] < 0;
    }
    low -= kCornerBoundSlack * j.cell.size();
    if (f_.offset) {
      bool offset_negative = false;
      const double b = reach(offset_bound(j, o, offset_negative)) - kCornerBoundSlack * j.cell.size();
      if (b > low) low = b, negative = offset_negative;
      // Nearer s's surface than |offset| (the distance to the vertex's site bounds |s(c)|), c is
      // on its side of f's zero: f = s - offset has the sign of -offset there.
      if (site != kNone && f_.site_distance) {
        const double inside = std::abs(*f_.offset) - f_.site_distance(world(c), site);
        const double near = inside > 0 ? reach(inside) - kCornerBoundSlack * j.cell.size() : 0;
        if (near > low) low = near, negative = *f_.offset > 0;
      }
    }
    if (!(low > 0)) return Outcome::Unknown;
    const auto [nearest, side, represented] = plane;
    const bool sign_differs = negative != (side < 0);
    if (sign_differs && low > tolerance) return Outcome::Disagrees;
    if (sign_differs) return Outcome::Unknown;
    if (!f_.distance) return Outcome::Agrees;
    // Passes for every |f(c)| at least `along` (surface_as_represented).
    const double along = low * f_.lipschitz, half_diagonal = j.cell.size() * std::sqrt(3.0) / 4;
    const bool planes_pass = along >= half_diagonal || nearest <= along + tolerance;
    const bool represented_pass = along > j.cell.size() / 4 || represented <= along + tolerance;
    if (planes_pass && represented_pass) return Outcome::Agrees;
    return Outcome::Unknown;
  }

  /// For f = s - offset (ImplicitSolid::offset): a lower bound on |f| at octant o's centre c
  /// and f's sign there (`negative`), from s at the leaf's corners x_k, or 0. Where every corner
  /// lies on one side of s's surface, farther than the spread below, the segment from the
  /// nearest corner to c does not meet that surface (c is on that side too), and |s(c)|^2 is at
  /// least sum w_k s(x_k)^2 - 9/16 h^2 (w_k: c's trilinear weights, 27/64 at the nearest corner
  /// down to 1/64 at the farthest; 9/16 h^2 = sum w_k |x_k - c|^2 for a cell of side h).
  double offset_bound(const Job& j, int o, bool& negative) const {
    const double offset = *f_.offset, h = j.cell.size() * cube_.size, spread = 9.0 / 16 * h * h;
    double sum = 0, least = detail::kHuge;
    int side = 0;
    for (int k = 0; k < 8; ++k) {
      // A corner resampled against f's sign holds a hair (the tree's sign), not f's value.
      if (std::abs(j.v[k]) <= std::numeric_limits<double>::min()) return 0;
      const double s = j.v[k] + offset;
      const int sk = s > 0 ? 1 : s < 0 ? -1 : 0;
      if (sk == 0 || (side != 0 && sk != side)) return 0;
      side = sk;
      static constexpr double kWeight[4] = {27.0 / 64, 9.0 / 64, 3.0 / 64, 1.0 / 64};
      sum += kWeight[std::popcount(unsigned(k ^ o))] * s * s;
      least = std::min(least, s * s);
    }
    if (!(least > spread)) return 0;
    const double d = parallelogram_bound(sum, spread);
    // f(c) = s(c) - offset, with s(c) beyond side * d.
    const double beyond = side > 0 ? d - offset : -d - offset;
    if ((side > 0) != (beyond > 0)) return 0;
    negative = beyond < 0;
    return std::abs(beyond);
  }

  /// The surface point on every edge and f's gradient there, for a batched f: the edges'
  /// false-position finders run in step, then the gradients in one more batch (f's own, or
  /// central differences).
  void crossings(std::vector<Edge>& edges) {
    if (edges.empty()) return;
    auto point = [&](const Edge& e, double t) { return add3(e.a, scale3(sub3(e.b, e.a), t)); };
    std::vector<size_t> active(edges.size());
    for (size_t i = 0; i < edges.size(); ++i) active[i] = i;
    std::vector<IllinoisRoot> r;
    for (const Edge& e : edges) r.emplace_back(e.fa, e.fb, kEdgeRoot, kEdgeRootSteps);
    std::erase_if(active, [&](size_t i) { return r[i].done(); });
    while (!active.empty()) {
      std::vector<Vec3> at(active.size());
      for (size_t k = 0; k < active.size(); ++k) at[k] = point(edges[active[k]], r[active[k]].next());
      const std::vector<double> fx = values(at);
      for (size_t k = 0; k < active.size(); ++k) r[active[k]].take(fx[k]);
      std::erase_if(active, [&](size_t i) { return r[i].done(); });
    }
    for (size_t i = 0; i < edges.size(); ++i) edges[i].x = point(edges[i], r[i].root());
    gradients(edges);
  }

  /// One edge's crossing and gradient, f asked point by point: Newton steps where f gives its
  /// gradient with its value, else false position and then the gradient.
  void cross_one(Edge& e) {
    auto point = [&](double t) { return add3(e.a, scale3(sub3(e.b, e.a), t)); };
    if (f_.value_gradient) {
      NewtonRoot r(e.fa, e.fb, kEdgeRoot, kEdgeRootSteps);
      while (!r.done()) {
        ++evaluations;
        const double fx = f_.value_gradient(world(point(r.next())), e.g);
        r.take(fx, dot3(e.g, sub3(e.b, e.a)) * cube_.size);
      }
      e.x = point(r.root());
      return;
    }
    IllinoisRoot r(e.fa, e.fb, kEdgeRoot, kEdgeRootSteps);
    while (!r.done()) {
      ++evaluations;
      r.take(f_.value(world(point(r.next()))));
    }
    e.x = point(r.root());
    if (f_.gradient) {
      ++evaluations;
      e.g = f_.gradient(world(e.x));
      return;
    }
    const double h = e.size * kGradientStep;
    for (int k = 0; k < 3; ++k) {
      Vec3 lo = e.x, hi = e.x;
      lo[k] -= h, hi[k] += h;
      evaluations += 2;
      e.g[k] = (f_.value(world(hi)) - f_.value(world(lo))) / (2 * h * cube_.size);
    }
  }

  /// f's gradient at every edge's crossing (its direction is the same in unit space).
  void gradients(std::vector<Edge>& edges) {
    if (f_.gradients || f_.gradient) {
      std::vector<Vec3> w(edges.size()), g(edges.size());
      for (size_t i = 0; i < edges.size(); ++i) w[i] = world(edges[i].x);
      evaluations += edges.size();
      if (f_.gradients) f_.gradients(w, g);
      else for_each(edges.size(), [&](size_t i) { g[i] = f_.gradient(w[i]); });
      for (size_t i = 0; i < edges.size(); ++i) edges[i].g = g[i];
      return;
    }
    std::vector<Vec3> at;
    at.reserve(6 * edges.size());
    for (const Edge& e : edges) {
      const double h = e.size * kGradientStep;
      for (int k = 0; k < 3; ++k)
        for (const double sign : {-1.0, 1.0}) {
          Vec3 p = e.x;
          p[k] += sign * h;
          at.push_back(p);
        }
    }
    const std::vector<double> fx = values(at);
    for (size_t i = 0; i < edges.size(); ++i) {
      const double h = edges[i].size * kGradientStep;
      for (int k = 0; k < 3; ++k) edges[i].g[k] = (fx[6 * i + 2 * k + 1] - fx[6 * i + 2 * k]) / (2 * h * cube_.size);
    }
  }

  /// Splits every cell in `split` into its children, their new corners -- the parents'
  /// 27-point grids, shared between neighbours -- asked in one batch of distinct points (a
  /// function asked one point at a time: in cell order, through the memo). No child is settled
  /// from its parent's corner alone: a distance to a surface that nearly touches itself can
  /// break the Lipschitz bound by a sign, and a child's corner must have the sign its
  /// neighbours see. Returns the children to look at on the next level.
  std::vector<Job> subdivide(const std::vector<Job>& split, Builder& out) {
    std::vector<Job> next;
    std::vector<std::pair<uint64_t, uint32_t>> refs;  // (lattice point, 8 * child + corner)
    for (const Job& j : split) {
      const uint32_t first = out.alloc_children();
      out.nodes[j.slot] = Node{first, CellKind::Internal, 0, 0, 0};
      for (int c = 0; c < 8; ++c) {
        const Cell child = j.cell.child(c);
        Job n{child, first + c, {}};
        for (int k = 0; k < 8; ++k) {
          const int a = (c & 1) + (k & 1), b = ((c >> 1) & 1) + ((k >> 1) & 1), d = ((c >> 2) & 1) + ((k >> 2) & 1);
          if (a != 1 && b != 1 && d != 1) n.v[k] = j.v[(a / 2) | ((b / 2) << 1) | ((d / 2) << 2)];
          else if (memo_) n.v[k] = value_at(child.corner(k));
          else refs.push_back({pack(child.corner(k)), uint32_t(8 * next.size() + k)});
        }
        next.push_back(n);
      }
    }
    if (memo_) return next;
    std::vector<uint32_t> id(8 * next.size());
    std::vector<Vec3> points(number_keys(refs, id, parallel_));
    for (const auto& [key, at] : refs) points[id[at]] = lattice_unit(unpack(key));
    const std::vector<double> fx = values(points);
    for (size_t at = 0; at < id.size(); ++at)
      if (id[at] != kNone) next[at / 8].v[at % 8] = fx[id[at]];
    return next;
  }
};

/// A leaf sampled again from f around p and the points of `also` it holds (down to the cap, or
/// with `to_corner` until each is a corner), with the leaf's own corner signs (a settled sign
/// may differ from f's: its value then only keeps that sign). Safe to call from several
/// threads.
struct FunctionResample {
  const ImplicitSolid& solid;
  const SampleOptions& options;
  const Octree& tree;
  Memos* memo;
  std::vector<Lat> also;  ///< sorted
  bool to_corner = false;  ///< split only until the points are corners, not down to the cap
  std::atomic<size_t> evaluations{0}, capped{0};

  Builder operator()(const LeafRef& l, const Lat& p) {
    LevelSampler one(solid, *options.cube, options.depth, options.error, false, memo);
    std::vector<Lat> focus{p};
    const Lat lo = l.cell.lat, hi = l.cell.corner(7);
    for (auto it = std::lower_bound(also.begin(), also.end(), lo); it != also.end() && (*it)[0] <= hi[0]; ++it)
      if (l.cell.holds(*it)) focus.push_back(*it);
    one.focus_on(std::move(focus), to_corner);
    std::vector<Vec3> at(8);
    for (int k = 0; k < 8; ++k) at[k] = lattice_unit(l.cell.corner(k));
    const std::vector<double> fv = one.values(at);
    const uint8_t signs = signs_of(tree.nodes[l.node]);
    constexpr double kHair = std::numeric_limits<double>::min();
    std::array<double, 8> corner{};
    for (int k = 0; k < 8; ++k) {
      const bool inside = (signs >> k) & 1;
      corner[k] = (fv[k] < 0) == inside ? fv[k] : inside ? -kHair : kHair;
    }
    size_t more = 0;
    Builder sub = one.run(l.cell, corner, more);
    evaluations += one.evaluations;
    capped += more;
    return sub;
  }
};

/// Where f crosses a coarse leaf's edge or face twice between its corners, its finer
/// neighbours sampled the points between with f's sign, against the side's; the settling would
/// flip them, a coarse cell off the surface. Such leaves are sampled again until those points
/// are corners of theirs (f's sign there then agrees on both sides), all at once; each further
/// round looks only around what the last one split.
void refine_coarse_sides(Octree& tree, FunctionResample& resample, const ResampleLeaf& from_function) {
  // A batched function (one call per batch, such as a Python one) sees one batch at a time.
  const bool parallel = resample.options.parallel && !resample.solid.values;
  std::vector<std::pair<Lat, Lat>> near;
  for (int round = 0; round < 8; ++round) {
    const std::vector<Lat> against = points_against_coarse_sides(tree, near, parallel);
    if (against.empty()) break;
    near.clear();
    for (const Lat& p : against) {
      int64_t span = 0;
      for (int o = 0; o < 8; ++o)
        if (Lat q; octant_cell(p, o, q)) span = std::max(span, leaf_at(tree, q).cell.span());
      near.push_back({{p[0] - span, p[1] - span, p[2] - span}, {p[0] + span, p[1] + span, p[2] + span}});
    }
    resample.also = against;
    resample.to_corner = true;
    refine_all_around(tree, against, from_function, parallel);
  }
  resample.also.clear();
  resample.to_corner = false;
}

/// Each gray leaf by its vertex number: the leaf, and its vertex in unit coordinates.
struct GrayLeaves {
  std::vector<LeafRef> leaf;
  std::vector<Vec3> pos;
};
GrayLeaves gray_leaves(const Octree& tree) {
  GrayLeaves g;
  g.leaf.resize(tree.vertices.size());
  g.pos.resize(tree.vertices.size());
  const auto place = [&](uint32_t node, const Cell& cell) {
    const Node& n = tree.nodes[node];
    if (n.kind != CellKind::Gray) return;
    g.leaf[n.index] = {node, cell};
    g.pos[n.index] = vertex_unit(cell, tree.vertices[n.index]);
  };
  if (tree.nodes[0].kind == CellKind::Internal)
    tbb::parallel_for(0, 8, [&](int c) { visit_leaves(tree, tree.nodes[0].index + c, Cell{}.child(c), place); });
  else
    visit_leaves(tree, 0, Cell{}, place);
  return g;
}

/// Which of `points` (unit space) the bounds of f = s - offset (ImplicitSolid::offset, with
/// sites) leave to be asked, each point the mean of the polygon vertices `from` (kNone past the
/// last); `off` gets, per point, whether |f| there is proven beyond `tolerance` (f's units).
/// f is asked at those vertices (once each, with their sites; counted in `asked`) but where
/// the vertex checks found it (`known`, sorted by position). Where they all lie on one side of
/// s's surface, farther than half their spread's diameter, no point of their hull meets that
/// surface, and |s| at their mean m is at least sqrt(mean s_k^2 - mean |x_k - m|^2) (the
/// parallelogram law) and at most m's distance to each vertex's site: f(m) lies between. A
/// point whose interval lies inside or outside the tolerance, with a hair to spare for
/// rounding, is decided as asking f would decide it.
std::vector<size_t> undecided_by_bounds(const ImplicitSolid& f, const Cube& cube, const GrayLeaves& g,
                                        const std::vector<Vec3>& points, const std::vector<std::array<uint32_t, 4>>& from,
                                        double tolerance, bool parallel, const std::vector<VertexValue>& known,
                                        std::vector<char>& off, size_t& asked) {
  off.assign(points.size(), 0);
  std::vector<size_t> undecided(points.size());
  std::iota(undecided.begin(), undecided.end(), size_t{0});
  if (!f.offset || !f.value_site || !f.site_distance || points.empty()) return undecided;
  const double offset = *f.offset;
  // The vertices worth asking: those of points whose spread could let the lower bound come
  // within the tolerance of |offset| (s at the vertices is about the offset).
  const auto spread_allows = [&](size_t i) {
    const Vec3 m = unit_to_world(cube, points[i]);
    double spread = 0, diameter2 = 0;
    int n = 0;
    for (uint32_t v : from[i]) {
      if (v == kNone) break;
      const Vec3 x = unit_to_world(cube, g.pos[v]);
      spread += dot3(sub3(x, m), sub3(x, m));
      for (int a = 0; a < n; ++a) {
        const Vec3 y = unit_to_world(cube, g.pos[from[i][a]]);
        diameter2 = std::max(diameter2, dot3(sub3(x, y), sub3(x, y)));
      }
      ++n;
    }
    const double reach = std::abs(offset) - tolerance;
    return n > 0 && spread / n <= 2 * std::abs(offset) * tolerance && reach > 0 && diameter2 / 2 < reach * reach;
  };
  const auto each = [&](size_t n, auto&& fn) {
    if (parallel) tbb::parallel_for(size_t{0}, n, fn);
    else for (size_t i = 0; i < n; ++i) fn(i);
  };
  std::vector<char> allowed(points.size());
  each(points.size(), [&](size_t i) { allowed[i] = spread_allows(i); });
  std::vector<uint32_t> index(g.pos.size(), kNone), used;
  for (size_t i = 0; i < points.size(); ++i)
    if (allowed[i])
      for (uint32_t v : from[i])
        if (v != kNone && index[v] == kNone) index[v] = uint32_t(used.size()), used.push_back(v);
  std::vector<double> s(used.size()), slack(used.size(), 0);
  std::vector<uint32_t> site(used.size());
  std::vector<char> ask(used.size(), 1);
  each(used.size(), [&](size_t k) {
    const Vec3& at = g.pos[used[k]];
    const auto it = std::lower_bound(known.begin(), known.end(), at, [](const VertexValue& v, const Vec3& p) { return v.at < p; });
    if (it == known.end() || it->at != at) return;
    s[k] = it->f + offset, slack[k] = it->slack, site[k] = it->site, ask[k] = 0;
  });
  each(used.size(), [&](size_t k) {
    if (ask[k]) s[k] = f.value_site(unit_to_world(cube, g.pos[used[k]]), site[k]) + offset;
  });
  asked += size_t(std::count(ask.begin(), ask.end(), 1));
  std::vector<char> decided(points.size(), 0);
  const double inner = tolerance * (1 - kBoundMargin), outer = tolerance * (1 + kBoundMargin);
  each(points.size(), [&](size_t i) {
    const Vec3 m = unit_to_world(cube, points[i]);
    int n = 0, side = 0;
    double mean_s2 = 0, spread = 0, least = detail::kHuge, diameter2 = 0, high = detail::kHuge;
    std::array<Vec3, 4> x;
    for (uint32_t v : from[i]) {
      if (v == kNone) break;
      const uint32_t k = index[v];
      if (k == kNone) return;
      // |s| at the vertex, to within the slack of where it was asked.
      const double near = std::abs(s[k]) - slack[k];
      const int sk = !(near > 0) ? 0 : s[k] > 0 ? 1 : -1;
      if (sk == 0 || (side != 0 && sk != side)) return;
      side = sk;
      x[n] = unit_to_world(cube, g.pos[v]);
      for (int a = 0; a < n; ++a) diameter2 = std::max(diameter2, dot3(sub3(x[a], x[n]), sub3(x[a], x[n])));
      mean_s2 += near * near, spread += dot3(sub3(x[n], m), sub3(x[n], m)), least = std::min(least, near * near);
      high = std::min(high, f.site_distance(m, site[k]));
      ++n;
    }
    if (n == 0 || !(least > diameter2 / 2)) return;
    const double low = parallelogram_bound(mean_s2 / n, spread / n);
    if (!(low > 0)) return;
    const double f_lo = side > 0 ? low - offset : -high - offset, f_hi = side > 0 ? high - offset : -low - offset;
    if (f_lo >= -inner && f_hi <= inner) decided[i] = 1;
    else if (f_lo > outer || f_hi < -outer) decided[i] = 1, off[i] = 1;
  });
  std::erase_if(undecided, [&](size_t i) { return decided[i] != 0; });
  return undecided;
}

/// The vertex checks' values so far, by position: those found since the last call merged in.
const std::vector<VertexValue>& sorted_vertex_values(Memos& memo) {
  const auto by_position = [](const VertexValue& a, const VertexValue& b) { return a.at < b.at; };
  std::vector<VertexValue>& all = memo.vertices_sorted;
  const size_t before = all.size();
  for (std::vector<VertexValue>& part : memo.vertices) {
    all.insert(all.end(), part.begin(), part.end());
    part.clear();
  }
  tbb::parallel_sort(all.begin() + std::ptrdiff_t(before), all.end(), by_position);
  std::inplace_merge(all.begin(), all.begin() + std::ptrdiff_t(before), all.end(), by_position);
  return all;
}

/// The distance from p to polygon `poly` (vertex positions `pos`), over both ways of cutting a
/// quadrilateral into triangles.
double polygon_distance(const Vec3& p, const MeshPolygon& poly, const std::vector<Vec3>& pos) {
  const auto at = [&](int i) -> const Vec3& { return pos[poly.v[i]]; };
  if (poly.count == 3) return std::sqrt(point_triangle_distance2(p, at(0), at(1), at(2)));
  const double d2 = std::min({point_triangle_distance2(p, at(0), at(1), at(2)), point_triangle_distance2(p, at(0), at(2), at(3)),
                              point_triangle_distance2(p, at(0), at(1), at(3)), point_triangle_distance2(p, at(1), at(2), at(3))});
  return std::sqrt(d2);
}

/// The surface points the octant checks found in a leaf away from its planes
/// (Memos::unrepresented) that still lie in a leaf wider than 2^kUncheckedLevels finest cells
/// must lie within `tolerance` (unit space) of a polygon of that leaf's vertex, or of a vertex
/// beside it (the surface near a cell's side is drawn by its neighbours' polygons too); where
/// one does not, a part of the solid lies in the leaf apart from its surface, and the leaf is
/// marked in `off`.
void mark_unrepresented(const Octree& tree, const GrayLeaves& g, const std::vector<MeshPolygon>& polys, Memos& memo,
                        double tolerance, std::vector<char>& off) {
  std::vector<Vec3> points;
  for (std::vector<Vec3>& part : memo.unrepresented) {
    points.insert(points.end(), part.begin(), part.end());
    part.clear();
  }
  if (points.empty()) return;
  // Only the points not drawn yet are asked again next round (leaves only grow finer).
  std::vector<Vec3>& left = memo.unrepresented.local();
  // The polygons of each vertex.
  std::vector<uint32_t> start(g.pos.size() + 1, 0), of;
  for (const MeshPolygon& poly : polys)
    for (int i = 0; i < poly.count; ++i) ++start[poly.v[i] + 1];
  for (size_t v = 0; v < g.pos.size(); ++v) start[v + 1] += start[v];
  of.resize(start.back());
  std::vector<uint32_t> next(start.begin(), start.end() - 1);
  for (uint32_t i = 0; i < polys.size(); ++i)
    for (int k = 0; k < polys[i].count; ++k) of[next[polys[i].v[k]]++] = i;
  const int64_t span = int64_t{1} << kMaxLevel;
  for (const Vec3& p : points) {
    Lat q;
    for (int k = 0; k < 3; ++k) q[k] = std::clamp(int64_t(std::floor(p[k] * double(span))), int64_t{0}, span - 1);
    const LeafRef l = leaf_at(tree, q);
    const Node& n = tree.nodes[l.node];
    if (l.cell.level + kUncheckedLevels >= tree.max_depth) continue;
    if (n.kind != CellKind::Gray) {
      left.push_back(p);
      continue;
    }
    double best = detail::kHuge;
    const auto near_polygons_of = [&](uint32_t u) {
      for (uint32_t i = start[u]; i < start[u + 1] && best > tolerance; ++i)
        best = std::min(best, polygon_distance(p, polys[of[i]], g.pos));
    };
    near_polygons_of(n.index);
    for (uint32_t i = start[n.index]; i < start[n.index + 1] && best > tolerance; ++i)
      for (int k = 0; k < polys[of[i]].count; ++k)
        if (polys[of[i]].v[k] != n.index) near_polygons_of(polys[of[i]].v[k]);
    if (best > tolerance) off[n.index] = 1, left.push_back(p);
  }
}

/// The points of f.features moved onto f's zero (Newton steps along the gradient, within a
/// tenth of `tolerance`, f's units) that lie in a leaf above the cap, into memo.unrepresented:
/// mark_unrepresented then asks for each to be drawn. A point already in a leaf near the cap
/// before its steps is not asked (its surface is sampled finely there). Returns f's values asked.
size_t add_feature_points(const ImplicitSolid& f, const Octree& tree, Memos& memo, double tolerance, bool parallel) {
  std::vector<Vec3> seeds;
  f.features(seeds);
  // In Morton order: each thread's nearest-triangle hint then serves the next point.
  const auto spread = [](uint64_t x) {
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffULL;
    x = (x | x << 16) & 0x1f0000ff0000ffULL;
    x = (x | x << 8) & 0x100f00f00f00f00fULL;
    x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
    return (x | x << 2) & 0x1249249249249249ULL;
  };
  std::vector<std::pair<uint64_t, Vec3>> keyed(seeds.size());
  for (size_t i = 0; i < seeds.size(); ++i) {
    const Vec3 u = world_to_unit(tree.cube, seeds[i]);
    uint64_t key = 0;
    for (int k = 0; k < 3; ++k) key |= spread(uint64_t(std::clamp(u[k], 0.0, 1.0) * double(0x1fffff))) << k;
    keyed[i] = {key, seeds[i]};
  }
  std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (size_t i = 0; i < seeds.size(); ++i) seeds[i] = keyed[i].second;
  const int64_t span = int64_t{1} << kMaxLevel;
  const auto lattice_of = [&](const Vec3& u, Lat& q) {
    for (int k = 0; k < 3; ++k) {
      if (!(u[k] >= 0 && u[k] < 1)) return false;
      q[k] = int64_t(std::floor(u[k] * double(span)));
    }
    return true;
  };
  std::atomic<size_t> asked{0};
  const auto one = [&](size_t i) {
    Lat q;
    Vec3 x = seeds[i];
    if (!lattice_of(world_to_unit(tree.cube, x), q) || leaf_at(tree, q).cell.level + kUncheckedLevels >= tree.max_depth)
      return;
    size_t n = 0;
    Vec3 g;
    double fx = f.value_gradient(x, g);
    ++n;
    for (int step = 0; step < kSurfaceSteps && std::abs(fx) > tolerance / 10; ++step) {
      const double g2 = dot3(g, g);
      if (!(g2 > 0)) break;
      x = sub3(x, scale3(g, fx / g2));
      fx = f.value_gradient(x, g);
      ++n;
    }
    asked += n;
    if (std::abs(fx) <= tolerance / 10 && lattice_of(world_to_unit(tree.cube, x), q))
      memo.unrepresented.local().push_back(world_to_unit(tree.cube, x));
  };
  if (parallel) tbb::parallel_for(size_t{0}, seeds.size(), one);
  else for (size_t i = 0; i < seeds.size(); ++i) one(i);
  return asked;
}

/// A coarse leaf's polygons join its vertex to its neighbours' by straight sides, but its
/// planes come from its own edges' crossings only: a crease inside the cell that no edge
/// crosses, or one in a neighbour, can lie between two vertices, and the polygon then cuts
/// across it (a faceted sphere shrunk by a third of a unit: the polygons from a leaf holding
/// the top cap's corner cut its equator half a unit deep, at every depth). f at the middle of
/// every polygon side that leaves a leaf wider than 2^kUncheckedLevels finest cells, and at
/// the centre of every polygon that has one, must put the surface within the planes' own fit
/// (2δ, as the octant questions), at most half a finest cell (by f's Lipschitz bound); where it
/// does not, those leaves are sampled again, split at least once, until every polygon keeps to
/// the surface or the rounds run out. The mesh sampler needs no such pass: its planes are
/// every input triangle that meets the cell.
/// `checked`: nodes below this number were asked already, as they are (a polygon all of whose
/// leaves are among them is not asked again). Returns the tree's node count when done.
size_t refine_polygons_off_surface(Octree& tree, LevelSampler& sampler, FunctionResample& resample,
                                   const ResampleLeaf& from_function, const ImplicitSolid& f, size_t checked) {
  const bool parallel = resample.options.parallel && !f.values;
  // In f's units.
  const double tolerance = bend_tolerance(tree.cube, tree.max_depth, resample.options.error) * f.lipschitz;
  const auto coarse = [&](const LeafRef& l) { return l.cell.level + kUncheckedLevels < tree.max_depth; };
  for (int round = 0; round < 8 && checked < tree.nodes.size(); ++round) {
    const GrayLeaves g = gray_leaves(tree);
    const std::vector<MeshPolygon> polys = dual_polygons(tree);
    const size_t before = checked;
    checked = tree.nodes.size();
    // Each point asked, the vertices of the coarse leaves it answers for (kNone: none), and
    // the polygon's vertices it is the mean of.
    std::vector<Vec3> points;
    std::vector<std::array<uint32_t, 4>> blamed, from;
    for (const MeshPolygon& poly : polys) {
      std::array<uint32_t, 4> mine{kNone, kNone, kNone, kNone};
      bool any = false, changed = false;  // a polygon whose leaves all passed the last round is the same
      for (int i = 0; i < poly.count; ++i) {
        const LeafRef& l = g.leaf[poly.v[i]];
        if (coarse(l)) mine[i] = poly.v[i], any = true;
        changed = changed || l.node >= before;
      }
      if (!any || !changed) continue;
      Vec3 centre{0, 0, 0};
      for (int i = 0; i < poly.count; ++i) {
        const int j = (i + 1) % poly.count;
        centre = add3(centre, scale3(g.pos[poly.v[i]], 1.0 / poly.count));
        // Each side once: from the polygon that runs it from the lower vertex number.
        if ((mine[i] == kNone && mine[j] == kNone) || poly.v[i] > poly.v[j]) continue;
        points.push_back(scale3(add3(g.pos[poly.v[i]], g.pos[poly.v[j]]), 0.5));
        blamed.push_back({mine[i], mine[j], kNone, kNone});
        from.push_back({poly.v[i], poly.v[j], kNone, kNone});
      }
      points.push_back(centre);
      blamed.push_back(mine);
      from.push_back({kNone, kNone, kNone, kNone});
      std::copy_n(poly.v.begin(), poly.count, from.back().begin());
    }
    std::vector<char> proven_off;
    static const std::vector<VertexValue> kNoValues;
    const std::vector<VertexValue>& known = resample.memo ? sorted_vertex_values(*resample.memo) : kNoValues;
    const std::vector<size_t> asked = undecided_by_bounds(f, tree.cube, g, points, from, tolerance, parallel, known,
                                                          proven_off, sampler.evaluations);
    std::vector<Vec3> at(asked.size());
    for (size_t k = 0; k < asked.size(); ++k) at[k] = points[asked[k]];
    const std::vector<double> fv = sampler.values(at);
    for (size_t k = 0; k < asked.size(); ++k) proven_off[asked[k]] = std::abs(fv[k]) > tolerance;
    std::vector<char> off(tree.vertices.size(), 0);
    for (size_t i = 0; i < points.size(); ++i)
      if (proven_off[i])
        for (uint32_t v : blamed[i])
          if (v != kNone) off[v] = 1;
    if (resample.memo) mark_unrepresented(tree, g, polys, *resample.memo, tolerance / (f.lipschitz * tree.cube.size), off);
    std::vector<Lat> centres;
    for (size_t v = 0; v < off.size(); ++v)
      if (off[v]) {
        const Cell& c = g.leaf[v].cell;
        const int64_t h = c.span() / 2;
        centres.push_back({c.lat[0] + h, c.lat[1] + h, c.lat[2] + h});
      }
    if (centres.empty()) return checked;
    std::sort(centres.begin(), centres.end());
    resample.also = centres;
    resample.to_corner = true;
    refine_all_around(tree, centres, from_function, parallel);
    resample.also.clear();
    resample.to_corner = false;
  }
  return checked;
}

/// x moved towards f's zero by Newton steps along f's gradient, each clamped into `cell` and
/// kept only where |f| falls (halved up to three times), until |f| is within `tolerance`.
/// `asked` counts f's values.
Vec3 towards_zero_in_cell(const ImplicitSolid& f, const Cube& cube, const Cell& cell, Vec3 x, double tolerance,
                          size_t& asked) {
  Vec3 g;
  double fx = f.value_gradient(unit_to_world(cube, x), g);
  ++asked;
  const Vec3 lo = cell.min_unit();
  for (int step = 0; step < 8 && std::abs(fx) > tolerance; ++step) {
    const double g2 = dot3(g, g);
    if (!(g2 > 0)) break;
    const Vec3 full = scale3(g, fx / (g2 * cube.size));
    bool moved = false;
    for (double t = 1; t > 0.1 && !moved; t /= 2) {
      Vec3 y = sub3(x, scale3(full, t));
      for (int k = 0; k < 3; ++k) y[k] = std::clamp(y[k], lo[k], lo[k] + cell.size());
      Vec3 gy;
      const double fy = f.value_gradient(unit_to_world(cube, y), gy);
      ++asked;
      if (std::abs(fy) < std::abs(fx)) x = y, fx = fy, g = gy, moved = true;
    }
    if (!moved) break;
  }
  return x;
}

/// A gray leaf at the cap keeps whatever vertex its planes gave, fitting or not (capped), and
/// the settling changes the signs of leaves there without moving their vertices: such a vertex
/// can lie up to half a finest cell off the surface. Each of those (a capped leaf, or one whose
/// node differs from `sampled`, the tree before the settling) farther than the fit test allows
/// (sqrt(error)) is moved towards f's zero within its cell, so it stays in its cell (the
/// contour's guarantee) and only nears the surface. A leaf whose signs make two surface
/// components is left alone: its one vertex stands for both, and moving it onto one pulls the
/// polygons off the other. Needs f's gradient with its value, one point at a time. Returns
/// the values asked.
size_t move_cap_vertices_onto_surface(Octree& tree, const std::vector<Node>& sampled, const ImplicitSolid& f,
                                      double error, bool parallel) {
  if (!f.value_gradient) return 0;
  std::vector<std::pair<uint32_t, Cell>> leaves;
  visit_leaves(tree, 0, Cell{}, [&](uint32_t node, const Cell& cell) {
    const Node& n = tree.nodes[node];
    if (n.kind != CellKind::Gray || cell.level != tree.max_depth || !one_component(n.signs)) return;
    const bool settled = node >= sampled.size() || sampled[node].kind != n.kind || sampled[node].signs != n.signs;
    if (settled || (n.flags & kFlagCapped)) leaves.push_back({node, cell});
  });
  const double tolerance = std::sqrt(error) * f.lipschitz * tree.cube.size;
  std::vector<size_t> asked(leaves.size(), 0);
  auto move = [&](size_t i) {
    const auto& [node, cell] = leaves[i];
    std::array<float, 3>& local = tree.vertices[tree.nodes[node].index];
    const Vec3 x = vertex_unit(cell, local), moved = towards_zero_in_cell(f, tree.cube, cell, x, tolerance, asked[i]);
    if (moved != x) local = to_local(cell, moved);
  };
  if (parallel) tbb::parallel_for(size_t{0}, leaves.size(), move);
  else for (size_t i = 0; i < leaves.size(); ++i) move(i);
  return std::accumulate(asked.begin(), asked.end(), size_t{0});
}

}  // namespace

Octree sample(const ImplicitSolid& solid, const SampleOptions& options, SampleStats* stats) {
  const auto t0 = Clock::now();
  if (!solid.value && !solid.values) throw InvalidInput("an implicit solid needs a function");
  if (!options.cube) throw InvalidInput("sampling a function needs a root cube (--cube)");
  if (options.depth < 1 || options.depth > kMaxLevel)
    throw InvalidInput("depth must be between 1 and " + std::to_string(kMaxLevel));
  if (!(solid.lipschitz > 0) || !std::isfinite(solid.lipschitz)) throw InvalidInput("lipschitz must be positive");
  Memos memo;
  LevelSampler sampler(solid, *options.cube, options.depth, options.error, options.parallel,
                       solid.values ? nullptr : &memo);
  std::vector<Vec3> corners(8);
  for (int k = 0; k < 8; ++k) corners[k] = lattice_unit(Cell{}.corner(k));
  const std::vector<double> v = sampler.values(corners);
  std::array<double, 8> root{};
  for (int k = 0; k < 8; ++k) root[k] = v[k];
  for (double x : root)
    if (!std::isfinite(x)) throw InvalidInput("the function is not finite at a corner of the cube");
  size_t capped = 0;
  Builder b = sampler.run(Cell{}, root, capped);
  Octree tree;
  tree.cube = *options.cube;
  tree.max_depth = options.depth;
  tree.nodes = std::move(b.nodes);
  tree.vertices = std::move(b.vertices);
  FunctionResample resample{solid, options, tree, solid.values ? nullptr : &memo, {}};
  const ResampleLeaf from_function = [&](const LeafRef& l, const Lat& p) { return resample(l, p); };
  if (solid.features && solid.value_gradient && !solid.values)
    sampler.evaluations += add_feature_points(
        solid, tree, memo, detail::bend_tolerance(tree.cube, tree.max_depth, options.error) * solid.lipschitz,
        options.parallel);
  // The coarse sides' resampling makes new coarse leaves: their polygons are asked in turn.
  const size_t checked = refine_polygons_off_surface(tree, sampler, resample, from_function, solid, 0);
  refine_coarse_sides(tree, resample, from_function);
  refine_polygons_off_surface(tree, sampler, resample, from_function, solid, checked);
  // Leaves the cap stopped with two surface components get one, as after any sampling; a
  // point the settling flips at a coarser leaf is refined around first.
  const std::vector<Node> sampled = tree.nodes;
  const double finest = tree.cube.size / double(int64_t{1} << options.depth) * solid.lipschitz;
  const std::function<double(const Lat&)> margin = [&](const Lat& p) {
    return std::abs(sampler.values({lattice_unit(p)})[0]) / finest;
  };
  settle_sampled(tree, SettleRegion{}, &from_function, &margin);
  sampler.evaluations += resample.evaluations;
  capped += resample.capped;
  sampler.evaluations += move_cap_vertices_onto_surface(tree, sampled, solid, options.error, options.parallel);
  PIC_CHECK_OCTREE(tree, "sampling a function");
  if (tree.vertices.empty()) throw EmptySolid("the function's solid does not meet the cube's inside and outside");
  if (stats) {
    *stats = SampleStats{};
    stats->max_depth = stats->depth = options.depth;
    stats->error = options.error;
    stats->pics = tree.vertices.size();
    stats->capped = capped;
    stats->classifier = "implicit";
    stats->evaluations = sampler.evaluations;
    stats->seconds = since(t0);
  }
  return tree;
}

}  // namespace pic
