// Refining around a lattice point: see refine.h.
#include "csg/refine.h"

#include "csg/operand.h"
#include "csg/stamp.h"

namespace pic::detail {
namespace {

/// Every node whose closed cell meets the closed lattice box [lo, hi] (a list: the box is
/// small against the tree).
void nodes_meeting(const Octree& t, uint32_t node, const Cell& cell, const Lat& lo, const Lat& hi,
                   std::vector<uint32_t>& out) {
  const int64_t s = cell.span();
  for (int k = 0; k < 3; ++k)
    if (cell.lat[k] > hi[k] || cell.lat[k] + s < lo[k]) return;
  out.push_back(node);
  const Node& n = t.nodes[node];
  if (n.kind == CellKind::Internal)
    for (int c = 0; c < 8; ++c) nodes_meeting(t, n.index + c, cell.child(c), lo, hi, out);
}

/// The gray leaf's cell resampled from the contour around it, split down to the finest level
/// around p.
Builder resample_leaf(const Octree& t, const LeafRef& leaf, const Lat& p, double error) {
  // The dual polygons of every leaf meeting the cell hold all of the surface inside it (a
  // polygon's vertices lie in their own cells).
  std::vector<uint32_t> near;
  nodes_meeting(t, 0, Cell{}, leaf.cell.lat, leaf.cell.corner(7), near);
  std::sort(near.begin(), near.end());
  PartialContour contour;
  contour_of(t, [&](uint32_t n) { return std::binary_search(near.begin(), near.end(), n); }, contour);
  const Stamps none(t.nodes.size(), 0);
  Operand x(t, none, contour, 1);
  FanSource src(x);
  SampleParams params;
  params.max_depth = t.max_depth;
  params.error = error;
  params.has_focus = true;
  params.focus = p;
  Builder sub;
  sub.nodes.resize(1);
  size_t capped = 0;
  const std::vector<uint32_t> idx = x.triangles_in(leaf.node, leaf.cell);
  sample_cell(src, params, leaf.cell, t.nodes[leaf.node].signs, idx, sub, 0, capped);
  return sub;
}

}  // namespace

size_t refine_around(Octree& t, const Lat& p, double error, const std::function<void(uint32_t)>& grown) {
  constexpr int64_t kLimit = int64_t{1} << kMaxLevel;
  size_t split = 0;
  for (int o = 0; o < 8; ++o) {
    Lat q;
    bool in_root = true;
    for (int k = 0; k < 3; ++k) {
      q[k] = p[k] - (((o >> k) & 1) ? 0 : 1);
      in_root = in_root && q[k] >= 0 && q[k] < kLimit;
    }
    if (!in_root) continue;
    for (LeafRef l = leaf_at(t, q); l.cell.level < t.max_depth; l = leaf_at(t, q)) {
      const Node n = t.nodes[l.node];
      const uint32_t first = static_cast<uint32_t>(t.nodes.size());
      if (n.kind == CellKind::Gray) {
        Builder sub = resample_leaf(t, l, p, error);
        t.nodes[l.node] = append_subtree(t.nodes, t.vertices, sub);
      } else {
        // A uniform leaf: uniform children, the one toward q split again next time round.
        t.nodes.resize(first + 8, Node{0, n.kind, 0, 0, 0});
        t.nodes[l.node] = Node{first, CellKind::Internal, 0, 0, 0};
      }
      ++split;
      grown(l.node);
      for (auto k = first; k < t.nodes.size(); ++k) grown(k);
    }
  }
  return split;
}

}  // namespace pic::detail
