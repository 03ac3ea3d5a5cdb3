// Cell counts of an octree (`pic info`).
#include <algorithm>

#include "octree/cell.h"
#include "geometry/tolerances.h"

namespace pic {

OctreeStats analyze(const Octree& tree) {
  OctreeStats s;
  s.memory_bytes = tree.nodes.size() * sizeof(Node) + tree.vertices.size() * sizeof(tree.vertices[0]);
  s.levels.resize(tree.max_depth + 1);
  s.bbox_min = {detail::kHuge, detail::kHuge, detail::kHuge};
  s.bbox_max = {-detail::kHuge, -detail::kHuge, -detail::kHuge};
  std::function<void(uint32_t, const detail::Cell&)> walk = [&](uint32_t node, const detail::Cell& cell) {
    const Node& n = tree.nodes[node];
    ++s.nodes;  // reachable nodes: an octree edited in place may hold replaced ones
    if (cell.level >= static_cast<int>(s.levels.size())) s.levels.resize(cell.level + 1);
    auto& l = s.levels[cell.level];
    switch (n.kind) {
      case CellKind::White: ++l.white; break;
      case CellKind::Black: ++l.black; break;
      case CellKind::Gray: {
        ++l.gray;
        ++s.pics;
        if (n.flags & kFlagCapped) ++s.capped;
        const Vec3 p = detail::unit_to_world(tree.cube, detail::vertex_unit(cell, tree.vertices[n.index]));
        for (int k = 0; k < 3; ++k) {
          s.bbox_min[k] = std::min(s.bbox_min[k], p[k]);
          s.bbox_max[k] = std::max(s.bbox_max[k], p[k]);
        }
        break;
      }
      case CellKind::Internal:
        ++l.internal;
        for (int c = 0; c < 8; ++c) walk(n.index + c, cell.child(c));
        break;
    }
  };
  walk(0, detail::Cell{});
  if (s.pics == 0) s.bbox_min = s.bbox_max = {0, 0, 0};
  return s;
}

}  // namespace pic
