#include <algorithm>

#include "octree/cell.h"

namespace pic::detail {

void Builder::set_gray(uint32_t slot, const Cell& cell, uint8_t signs, const Vec3& x, uint8_t flags) {
  nodes[slot] = add_gray(vertices, cell, signs, x, flags);
}

Node append_subtree(std::vector<Node>& nodes, std::vector<std::array<float, 3>>& vertices, const Builder& sub) {
  const auto offset = static_cast<uint32_t>(nodes.size()) - 1;  // sub's node k >= 1 lands at offset + k
  const auto vbase = static_cast<uint32_t>(vertices.size());
  nodes.reserve(nodes.size() + sub.nodes.size());
  Node root{};
  for (size_t k = 0; k < sub.nodes.size(); ++k) {
    Node n = sub.nodes[k];
    if (n.kind == CellKind::Internal) n.index += offset;
    if (n.kind == CellKind::Gray) n.index += vbase;
    if (k == 0) root = n;
    else nodes.push_back(n);
  }
  vertices.insert(vertices.end(), sub.vertices.begin(), sub.vertices.end());
  return root;
}

void Builder::splice(uint32_t slot, const Builder& sub) {
  const Node root = append_subtree(nodes, vertices, sub);
  nodes[slot] = root;
}

}  // namespace pic::detail

namespace pic {

void for_each_leaf(const Octree& tree, const std::function<void(const LeafView&)>& visit) {
  detail::visit_leaves(tree, 0, detail::Cell{}, [&](uint32_t node, const detail::Cell& cell) {
    const Node& n = tree.nodes[node];
    LeafView v;
    v.node = node;
    v.level = cell.level;
    v.cell_min = detail::unit_to_world(tree.cube, cell.min_unit());
    v.cell_size = cell.size() * tree.cube.size;
    v.kind = n.kind;
    v.signs = n.signs;
    if (n.kind == CellKind::Gray)
      v.vertex = detail::unit_to_world(tree.cube, detail::vertex_unit(cell, tree.vertices[n.index]));
    visit(v);
  });
}

}  // namespace pic
