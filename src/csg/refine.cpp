// A result leaf resampled from its contour: see refine.h.
#include "csg/refine.h"

#include "csg/operand.h"
#include "csg/stamp.h"
#include "signs/leaf_walks.h"

namespace pic::detail {

Builder resample_from_contour(const Octree& t, const LeafRef& leaf, const Lat& p, double error) {
  // The dual polygons of every leaf meeting the cell hold all of the surface inside it (a
  // polygon's vertices lie in their own cells).
  std::vector<uint32_t> near;  // a list: the box is small against the tree
  for_each_node_meeting(t, 0, Cell{}, leaf.cell.lat, leaf.cell.corner(7), [&](uint32_t n) { near.push_back(n); });
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
  params.tips_at_corners = true;
  params.partial_contour = true;
  Builder sub;
  sub.nodes.resize(1);
  size_t capped = 0;
  const std::vector<uint32_t> idx = x.triangles_in(leaf.node, leaf.cell);
  sample_cell(src, params, leaf.cell, signs_of(t.nodes[leaf.node]), idx, sub, 0, capped);
  return sub;
}

}  // namespace pic::detail
