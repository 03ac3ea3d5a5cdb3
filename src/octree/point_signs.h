// A lattice point's sign as the leaves around it hold it. One point has one sign whichever
// leaf asks: the leaves that have it as a corner store it, and every edit sets it in all of
// them. The queries find the leaf over a finest lattice cell and the leaves around a point.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "octree/cell.h"

namespace pic::detail {

/// A leaf (or node) and its cell.
struct LeafRef {
  uint32_t node;
  Cell cell;
};

/// The node covering cell `target`, or the leaf above it; `path` gets the nodes from the root
/// down to it.
LeafRef node_at(const Octree& t, const Cell& target, std::vector<uint32_t>* path = nullptr);
/// The leaf containing the finest lattice cell whose min corner is `q`; `path` gets the nodes
/// from the root down to it.
LeafRef leaf_at(const Octree& t, const std::array<int64_t, 3>& q, std::vector<uint32_t>* path = nullptr);

/// The finest lattice cell touching p in octant o (bit k set: on p's high side along k);
/// false when it falls outside the root.
bool octant_cell(const std::array<int64_t, 3>& p, int o, std::array<int64_t, 3>& q);

/// A leaf having a given lattice point as a corner, with the corner's index.
struct Around {
  uint32_t node;
  int corner;
  Cell cell;
};
/// The leaves having lattice point p as a corner; `path` gets every node on the way down to them.
std::vector<Around> leaves_around(const Octree& t, const std::array<int64_t, 3>& p,
                                  std::vector<uint32_t>* path = nullptr);

/// A leaf's corner signs as a mask (uniform leaves: all corners alike).
uint8_t signs_of(const Node& n);
/// `signs` with corner c set to `inside`.
uint8_t with_corner(uint8_t signs, int c, bool inside);
/// The sign of lattice point q where a leaf has it as a corner; nothing where none has (q lies
/// inside a coarser leaf's face, edge or body).
std::optional<bool> point_sign(const Octree& t, const std::array<int64_t, 3>& q);

/// Flips corner c of a leaf (its cell `cell`). A uniform leaf becomes gray with its vertex
/// right next to that corner (the only place its surface can be).
void flip_corner(Octree& t, uint32_t node, int c, const Cell& cell);
/// Gives lattice point p the sign `inside` in every leaf that has it as a corner (a uniform
/// leaf of the other sign turns gray); `touched` is told of the nodes on the way to them.
void set_point_sign(Octree& t, const std::array<int64_t, 3>& p, bool inside,
                    const std::function<void(uint32_t)>* touched);

}  // namespace pic::detail
