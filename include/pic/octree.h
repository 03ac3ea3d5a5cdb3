// PIC — the PIC object: an octree whose gray leaves hold a vertex and 8 corner signs.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "pic/types.h"

namespace pic {

/// Deepest level any octree may reach (lattice of 2^kMaxLevel points per axis).
inline constexpr int kMaxLevel = 20;

enum class CellKind : uint8_t { White = 0, Black = 1, Gray = 2, Internal = 3 };

/// One octree node: 8 bytes. Children of an internal node are stored contiguously.
struct Node {
  uint32_t index = 0;  ///< Internal: first child. Gray: index into Octree::vertices.
  CellKind kind = CellKind::White;
  uint8_t signs = 0;   ///< Gray: bit c set = corner c inside; corner c = (c&1, c>>1&1, c>>2&1).
  uint8_t flags = 0;   ///< bit 0: leaf accepted only because the depth cap was reached.
  uint8_t reserved = 0;
};
inline constexpr uint8_t kFlagCapped = 1;

/// A PIC object. Plain data: nodes[0] is the root; vertices are stored in cell-local
/// coordinates in [0,1]^3 (so float keeps ~1e-7 of the *cell* size at every level).
struct Octree {
  Cube cube;
  int max_depth = 12;
  std::vector<Node> nodes{Node{}};
  std::vector<std::array<float, 3>> vertices;
};

/// A leaf as seen by visitors: its cell in the input's coordinates.
struct LeafView {
  uint32_t node = 0;
  int level = 0;
  Vec3 cell_min{0, 0, 0};  ///< input coordinates
  double cell_size = 0;    ///< input units
  CellKind kind = CellKind::White;
  uint8_t signs = 0;
  Vec3 vertex{0, 0, 0};    ///< gray leaves: representative vertex, input coordinates
};
/// Calls `visit` for every leaf, depth-first in child order.
void for_each_leaf(const Octree& tree, const std::function<void(const LeafView&)>& visit);

/// Cell counts of an octree (`pic info`).
struct OctreeStats {
  struct Level {
    size_t white = 0, black = 0, gray = 0, internal = 0;
  };
  std::vector<Level> levels;  ///< index = level
  size_t pics = 0, nodes = 0, capped = 0;
  size_t memory_bytes = 0;    ///< nodes + vertices in memory
  Vec3 bbox_min{0, 0, 0}, bbox_max{0, 0, 0};  ///< of the gray leaves' vertices
};
OctreeStats analyze(const Octree& tree);

}  // namespace pic
