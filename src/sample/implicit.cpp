// Sampling a solid given by a function of space (pic::ImplicitSolid): the paper's top-down
// rules with f in place of a mesh. Corner signs are f's sign at the lattice point, so one sign
// per point holds by construction; a cell whose corners agree is subdivided unless f's
// Lipschitz bound proves the surface out of reach, so no sign change hides in a coarse uniform
// leaf above the cap (no cracks for the settling to mend).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>

#include "geometry/lattice.h"
#include "geometry/memo.h"
#include "geometry/qef.h"
#include "geometry/root.h"
#include "geometry/stopwatch.h"
#include "geometry/vec3.h"
#include "octree/cell.h"
#include "octree/cell_vertex.h"
#include "pic/sample.h"
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

/// f at a lattice point: up to 8 cells of a level ask for each of their corners, and a
/// child grid's face and edge points are shared with the neighbours' grids.
struct PointValue {
  Lat p;
  bool filled = false;
  double f = 0;
};
/// The surface point on a cell edge and f's gradient there: up to 4 cells share the edge.
struct EdgeHermite {
  Lat a;
  int64_t span = 0;
  int axis = 0;
  bool filled = false;
  Vec3 x, g;
};

class ImplicitSampler {
 public:
  ImplicitSampler(const ImplicitSolid& f, const Cube& cube, const SampleOptions& o)
      : f_(f), cube_(cube), max_depth_(o.depth), error_(o.error), parallel_levels_(o.parallel ? 3 : 0) {}

  double value(const Vec3& unit) {
    ++evaluations;
    return f_.value(world(unit));
  }

  /// Samples `cell` (its corners' values `v`) into `out` at `slot`.
  void sample(const Cell& cell, const std::array<double, 8>& v, Builder& out, uint32_t slot, size_t& capped) {
    uint8_t signs = 0;
    for (int k = 0; k < 8; ++k) signs |= uint8_t(v[k] < 0) << k;
    const bool uniform = signs == 0 || signs == 0xff;
    const bool at_cap = cell.level >= max_depth_;
    if (uniform && (at_cap || out_of_reach(cell, v))) {
      out.set_uniform(slot, signs != 0);
      return;
    }
    if (!uniform && (at_cap || one_component(signs))) {
      Qef q;
      hermite_planes(cell, v, signs, q);
      const Qef::Solution sol = cell_vertex(q, cell, signs);
      // Edge crossings only see the surface where it meets the cell's edges: a rounded corner
      // between them looks like the sharp one. The vertex must lie on the surface, within the
      // error's distance (f is a distance bound in world units).
      const double off = std::abs(value(sol.position)) / (f_.lipschitz * cube_.size);
      const bool ok = sol.error < error_ && off * off < error_ && inside_cell(sol.position, cell) && one_component(signs);
      if (ok || at_cap) {
        if (!ok) ++capped;
        out.set_gray(slot, cell, signs, sol.position, ok ? 0 : kFlagCapped);
        return;
      }
    }
    subdivide(cell, v, out, slot, capped);
  }

  /// f at lattice point p (memoized).
  double value_at(const Lat& p) {
    PointValue& e = values_.slot(memo_slot(p, 0, decltype(values_)::kBits));
    if (!e.filled || e.p != p) e = {p, true, value(lattice_unit(p))};
    return e.f;
  }

  std::atomic<size_t> evaluations{0};

 private:
  ThreadMemo<PointValue, 16> values_;
  ThreadMemo<EdgeHermite, 14> edges_;
  const ImplicitSolid& f_;
  Cube cube_;
  int max_depth_;
  double error_;
  int parallel_levels_;

  Vec3 world(const Vec3& unit) const {
    return {cube_.origin[0] + unit[0] * cube_.size, cube_.origin[1] + unit[1] * cube_.size,
            cube_.origin[2] + unit[2] * cube_.size};
  }

  /// Whether f's bound keeps the surface out of the whole cell: |f| at the centre beyond the
  /// half diagonal, or at a corner beyond the diagonal (world units).
  bool out_of_reach(const Cell& cell, const std::array<double, 8>& v) {
    const double diagonal = f_.lipschitz * cell.size() * cube_.size * std::sqrt(3.0);
    for (double x : v)
      if (std::abs(x) > diagonal) return true;
    const Vec3 m = cell.min_unit();
    const double h = cell.size() / 2;
    return std::abs(value({m[0] + h, m[1] + h, m[2] + h})) > diagonal / 2;
  }

  /// f's gradient at a unit-space point (its direction is the same in unit space).
  Vec3 gradient(const Vec3& unit, double cell_size) {
    if (f_.gradient) {
      ++evaluations;
      return f_.gradient(world(unit));
    }
    const double h = cell_size * 1e-3;
    Vec3 g;
    for (int k = 0; k < 3; ++k) {
      Vec3 a = unit, b = unit;
      a[k] -= h;
      b[k] += h;
      g[k] = (value(b) - value(a)) / (2 * h * cube_.size);
    }
    return g;
  }

  /// The point where f changes sign between a (value fa) and b (value fb), to a millionth of
  /// the edge.
  Vec3 crossing(const Vec3& a, double fa, const Vec3& b, double fb) {
    auto at = [&](double t) {
      return Vec3{a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t};
    };
    return at(illinois_root([&](double t) { return value(at(t)); }, fa, fb, 1e-6, 40));
  }

  /// The crossing between a (value fa) and b as crossing() finds it, with f's gradient there,
  /// by Newton steps on f and its gradient from one evaluation, kept inside the bracket that
  /// the values shrink (bisection where a step would leave it).
  std::pair<Vec3, Vec3> newton_crossing(const Vec3& a, double fa, const Vec3& b, double fb) {
    const Vec3 ab = sub3(b, a);
    auto at = [&](double t) { return add3(a, scale3(ab, t)); };
    double lo = 0, hi = 1, t = std::clamp(fa / (fa - fb), 0.0, 1.0);
    Vec3 g{0, 0, 0};
    for (int it = 0; it < 40; ++it) {
      ++evaluations;
      const double fx = f_.value_gradient(world(at(t)), g);
      if (fx == 0) break;
      ((fx < 0) == (fa < 0) ? lo : hi) = t;
      const double slope = dot3(g, ab) * cube_.size;
      double next = t - fx / slope;
      if (!(next > lo && next < hi)) next = (lo + hi) / 2;
      const bool done = std::abs(next - t) < 1e-6;
      t = next;
      if (done || hi - lo < 1e-6) break;
    }
    return {at(t), g};
  }

  /// A plane per sign-changing edge: through f's zero on it, normal to f's gradient there.
  void hermite_planes(const Cell& cell, const std::array<double, 8>& v, uint8_t signs, Qef& q) {
    const Vec3 m = cell.min_unit();
    const double s = cell.size();
    auto corner = [&](int k) { return Vec3{m[0] + (k & 1) * s, m[1] + ((k >> 1) & 1) * s, m[2] + ((k >> 2) & 1) * s}; };
    for (int e = 0; e < 12; ++e) {
      const int c0 = kEdgeCorners[e][0], c1 = kEdgeCorners[e][1];
      if (((signs >> c0) & 1) == ((signs >> c1) & 1)) continue;
      const Lat a = cell.corner(c0);
      EdgeHermite& h = edges_.slot(edge_memo_slot(a, edge_axis(e), cell.span(), decltype(edges_)::kBits));
      if (!h.filled || h.a != a || h.axis != edge_axis(e) || h.span != cell.span()) {
        if (f_.value_gradient) {
          const auto [x, g] = newton_crossing(corner(c0), v[c0], corner(c1), v[c1]);
          h = {a, cell.span(), edge_axis(e), true, x, g};
        } else {
          const Vec3 x = crossing(corner(c0), v[c0], corner(c1), v[c1]);
          h = {a, cell.span(), edge_axis(e), true, x, gradient(x, s)};
        }
      }
      const Vec3 &x = h.x, &g = h.g;
      const double len = norm3(g);
      if (!(len > 0)) continue;
      const Vec3 n = scale3(g, 1 / len);
      q.add_plane(n, dot3(n, x), 1);
    }
  }

  void subdivide(const Cell& cell, const std::array<double, 8>& v, Builder& out, uint32_t slot, size_t& capped) {
    // The 27-point child grid: the parent's corners known, the other 19 evaluated when a child
    // needs them (a child that a parent corner's value proves away from the surface does not).
    std::array<double, 27> g{};
    std::array<bool, 27> known{};
    const int64_t h = cell.span() / 2;
    for (int i = 0; i < 27; ++i) {
      const int a = i % 3, b = (i / 3) % 3, c = i / 9;
      if (a != 1 && b != 1 && c != 1) g[i] = v[(a / 2) | ((b / 2) << 1) | ((c / 2) << 2)], known[i] = true;
    }
    auto grid = [&](int i) {
      if (!known[i]) {
        const int a = i % 3, b = (i / 3) % 3, c = i / 9;
        g[i] = value_at({cell.lat[0] + a * h, cell.lat[1] + b * h, cell.lat[2] + c * h});
        known[i] = true;
      }
      return g[i];
    };
    auto child_values = [&](int c) {
      std::array<double, 8> cv;
      for (int k = 0; k < 8; ++k) {
        const int a = (c & 1) + (k & 1), b = ((c >> 1) & 1) + ((k >> 1) & 1), d = ((c >> 2) & 1) + ((k >> 2) & 1);
        cv[k] = grid(a + 3 * b + 9 * d);
      }
      return cv;
    };
    // The child at corner c is out of reach when |f| there exceeds its diagonal: sample() would
    // find it so from that one value.
    const double child_diagonal = f_.lipschitz * cell.size() / 2 * cube_.size * std::sqrt(3.0);
    auto away = [&](int c) { return std::abs(v[c]) > child_diagonal; };
    const uint32_t first = out.alloc_children();
    out.nodes[slot] = Node{first, CellKind::Internal, 0, 0, 0};
    if (cell.level < parallel_levels_) {
      for (int i = 0; i < 27; ++i) grid(i);
      std::array<Builder, 8> subs;
      std::array<size_t, 8> caps{};
      tbb::parallel_for(0, 8, [&](int c) {
        subs[c].nodes.resize(1);
        sample(cell.child(c), child_values(c), subs[c], 0, caps[c]);
      });
      for (int c = 0; c < 8; ++c) {
        out.splice(first + c, subs[c]);
        capped += caps[c];
      }
      return;
    }
    for (int c = 0; c < 8; ++c) {
      if (away(c)) out.set_uniform(first + c, v[c] < 0);
      else sample(cell.child(c), child_values(c), out, first + c, capped);
    }
  }
};

}  // namespace

Octree sample(const ImplicitSolid& solid, const SampleOptions& options, SampleStats* stats) {
  const auto t0 = Clock::now();
  if (!solid.value) throw InvalidInput("an implicit solid needs a function");
  if (!options.cube) throw InvalidInput("sampling a function needs a root cube (--cube)");
  if (options.depth < 1 || options.depth > kMaxLevel)
    throw InvalidInput("depth must be between 1 and " + std::to_string(kMaxLevel));
  if (!(solid.lipschitz > 0) || !std::isfinite(solid.lipschitz)) throw InvalidInput("lipschitz must be positive");
  ImplicitSampler sampler(solid, *options.cube, options);
  std::array<double, 8> root{};
  for (int k = 0; k < 8; ++k) root[k] = sampler.value_at(Cell{}.corner(k));
  for (double x : root)
    if (!std::isfinite(x)) throw InvalidInput("the function is not finite at a corner of the cube");
  Builder b;
  b.nodes.resize(1);
  size_t capped = 0;
  sampler.sample(Cell{}, root, b, 0, capped);
  Octree tree;
  tree.cube = *options.cube;
  tree.max_depth = options.depth;
  tree.nodes = std::move(b.nodes);
  tree.vertices = std::move(b.vertices);
  // Leaves the cap stopped with two surface components get one, as after any sampling.
  settle_sampled(tree, SettleRegion{});
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
