#include <algorithm>
#include <functional>

#include "octree/cell.h"

namespace pic::detail {

void Builder::set_gray(uint32_t slot, const Cell& cell, uint8_t signs, const Vec3& x, uint8_t flags) {
  nodes[slot] = add_gray(vertices, cell, signs, x, flags);
}

Node append_subtree(std::vector<Node>& nodes, std::vector<std::array<float, 3>>& vertices, const Builder& sub) {
  const auto offset = static_cast<uint32_t>(nodes.size()) - 1;  // sub's node k >= 1 lands at offset + k
  const auto vbase = static_cast<uint32_t>(vertices.size());
  // Room for the subtree, growing geometrically: a reserve of exactly what this call needs
  // would move the whole array at every call, and refining leaf by leaf calls it per leaf.
  const size_t need = nodes.size() + sub.nodes.size();
  if (nodes.capacity() < need) nodes.reserve(std::max(need, 2 * nodes.capacity()));
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

/// Drops unreachable nodes and vertices (left behind by in-place replacement).
void compact(Octree& t) {
  Octree c;
  c.cube = t.cube;
  c.max_depth = t.max_depth;
  c.nodes.clear();
  c.nodes.reserve(t.nodes.size());
  c.nodes.push_back(Node{});
  std::function<void(uint32_t, uint32_t)> copy = [&](uint32_t from, uint32_t to) {
    Node n = t.nodes[from];
    if (n.kind == CellKind::Gray) {
      c.vertices.push_back(t.vertices[n.index]);
      n.index = static_cast<uint32_t>(c.vertices.size() - 1);
    } else if (n.kind == CellKind::Internal) {
      const auto first = static_cast<uint32_t>(c.nodes.size());
      c.nodes.resize(first + 8);
      for (int k = 0; k < 8; ++k) copy(n.index + k, first + k);
      n.index = first;
    }
    c.nodes[to] = n;
  };
  copy(0, 0);
  t.nodes = std::move(c.nodes);
  t.vertices = std::move(c.vertices);
}

size_t reachable_nodes(const Octree& t) {
  size_t n = 0;
  std::function<void(uint32_t)> walk = [&](uint32_t i) {
    ++n;
    if (t.nodes[i].kind == CellKind::Internal)
      for (int c = 0; c < 8; ++c) walk(t.nodes[i].index + c);
  };
  walk(0);
  return n;
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
