// CSG on two PIC octrees (paper section 5), computed in place on A. The stages, each in its
// own file:
//   stamp.h      stamp the overlap cells with this operation's timestamp; partial contours
//   operand.h    an operand's signs, triangles and state over a cell
//   combine.h    the paired recursion: trivial cases, GraycellCSG (gray_cell.h), forced
//                subdivision (resampling a leaf's partial contour)
//   cleanup.h    sign hints, islands, one component per leaf, specks, crack repair on the
//                stamped part of the result
//   this file    the driver: a common frame for the operands, the stages in order, garbage
//                collection of replaced subtrees
//
// Topology comes from signs alone: each operand's sign is a single-valued function of the
// lattice point (stored corner signs first; inside a gray leaf, crossing parity along a fixed
// path from the leaf's most reliable corner through its partial contour), and the result's
// sign is op(sign_A, sign_B). Vertex positions only decide accuracy.
#include <algorithm>
#include <functional>
#include <optional>

#include "pic/contour.h"
#include "csg/combine.h"
#include "csg/operand.h"
#include "csg/stamp.h"
#include "signs/invariants.h"
#include "geometry/tolerances.h"

namespace pic {
namespace detail {
namespace {


/// One frame: B re-expressed in A's cube when they differ (its contour resampled). When B's
/// surface does not fit in A's cube, both are resampled into the cube around both cubes (A then
/// changes cube: its root grows). A op A works on a copy of B. Empty when B serves as it is.
std::optional<Octree> common_frame(Octree& a, const Octree& b_in, const CsgOptions& options, CsgStats& stats) {
  std::optional<Octree> resampled;
  if (!(a.cube == b_in.cube)) {
    SampleOptions so;
    so.cube = a.cube;
    so.depth = std::max(a.max_depth, b_in.max_depth);
    so.error = options.error;
    const TriMesh mb = unsplit_contour(b_in);
    try {
      resampled = sample(mb, so);
    } catch (const InvalidInput&) {
      Cube both;
      double hi = -kHuge;
      for (int k = 0; k < 3; ++k) {
        both.origin[k] = std::min(a.cube.origin[k], b_in.cube.origin[k]);
        hi = std::max({hi, a.cube.origin[k] + a.cube.size - both.origin[k],
                       b_in.cube.origin[k] + b_in.cube.size - both.origin[k]});
      }
      both.size = hi;
      so.cube = both;
      const TriMesh ma = unsplit_contour(a);
      if (!ma.triangles.empty()) a = sample(ma, so);
      else a = Octree{both, so.depth, {Node{}}, {}};
      resampled = sample(mb, so);
    }
    stats.resampled_b = true;
  } else if (&a == &b_in) {
    resampled = b_in;
  }
  return resampled;
}


}  // namespace

}  // namespace detail

std::string to_string(CsgOp op) {
  switch (op) {
    case CsgOp::Union: return "union";
    case CsgOp::Intersect: return "intersect";
    case CsgOp::Subtract: return "subtract";
  }
  return "?";
}

std::optional<CsgOp> parse_csg_op(const std::string& s) {
  if (s == "union" || s == "add") return CsgOp::Union;
  if (s == "intersect" || s == "intersection") return CsgOp::Intersect;
  if (s == "subtract" || s == "difference" || s == "minus") return CsgOp::Subtract;
  return std::nullopt;
}

void csg_inplace(Octree& a, const Octree& b_in, CsgOp op, const CsgOptions& options, CsgStats* stats_out) {
  using namespace detail;
  const auto t0 = Clock::now();
  CsgStats stats;
  const std::optional<Octree> resampled = common_frame(a, b_in, options, stats);
  const Octree& b = resampled ? *resampled : b_in;
  const int depth = std::max(a.max_depth, b.max_depth);

  // Stamps live in this operation's own per-node arrays (sa, sb): one value marks its cells.
  constexpr uint32_t stamp = 1;
  stats.stamp = stamp;
  // The cells this operation works on, per node of each operand: kept here, not in the
  // trees, so that csg(a, b) only reads b.
  Stamps sa, sb;
  PartialContour pa, pb;
  stamp_overlap(a, sa, b, sb, stamp, pa, pb, stats);

  const auto tc = Clock::now();
  const size_t before = a.nodes.size();
  // Around contacts, both operands' cells holding them take part, with their contours.
  const auto prepare_focus = [&](const std::vector<Lat>& points) {
    if (stamp_holding(a, sa, stamp, points) > 0) {
      pa = {};
      partial_contour(a, sa, stamp, pa);
    }
    if (stamp_holding(b, sb, stamp, points) > 0) {
      pb = {};
      partial_contour(b, sb, stamp, pb);
    }
  };
  const std::vector<SignHint> hints =
      combine_stamped(a, sa, b, sb, pa, pb, op, options, depth, stamp, stats, prepare_focus);
  a.max_depth = depth;
  const auto tclean = Clock::now();
  {
    Operand ob(b, sb, pb, stamp);
    clean_up(a, sa, stamp, op, hints, [&](const Lat& p) { return ob.sign(p); }, options.error, stats);
  }
  stats.cleanup_seconds = since(tclean);
  stats.csg_seconds = since(tc);
  // Amortized garbage collection of replaced subtrees.
  if (a.nodes.size() > 2 * std::max<size_t>(before, 4096) || a.nodes.size() > before + 65536) {
    if (a.nodes.size() > 2 * reachable_nodes(a)) compact(a);
  }
  stats.seconds = since(t0);
  PIC_CHECK_OCTREE(a, "a Boolean");
  if (stats_out) *stats_out = stats;
}

Octree csg(const Octree& a, const Octree& b, CsgOp op, const CsgOptions& options, CsgStats* stats) {
  Octree r = a;
  csg_inplace(r, b, op, options, stats);
  if (r.nodes.size() > a.nodes.size() + 1024 || r.nodes.size() > 2 * detail::reachable_nodes(r)) detail::compact(r);
  return r;
}

}  // namespace pic

