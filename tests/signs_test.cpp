// The sign clean-up passes (src/signs): whatever they flip, every leaf that has a lattice point
// as a corner must still give it one sign, or the contour gets a hole there.
#include <gtest/gtest.h>

#include <set>

#include "octree/cell.h"
#include "pic/pic.h"
#include "signs/consistency.h"
#include "signs/invariants.h"

namespace pic {
namespace {

using Lat = std::array<int64_t, 3>;

/// The signs the leaves around lattice point p give it (one per leaf that has it as a corner).
std::set<bool> signs_around(const Octree& t, const Lat& p) {
  std::set<bool> out;
  for (int o = 0; o < 8; ++o) {
    const Lat q{p[0] - 1 + (o & 1), p[1] - 1 + ((o >> 1) & 1), p[2] - 1 + ((o >> 2) & 1)};
    const detail::LeafRef l = detail::leaf_at(t, q);
    if (const int c = l.cell.corner_index(p); c >= 0) out.insert(((detail::signs_of(t.nodes[l.node]) >> c) & 1) != 0);
  }
  return out;
}

/// A depth-2 tree: a coarse gray leaf G = [0, 1/2]^3 (only its corner at the origin inside),
/// and finer leaves across its faces y = 1/2 and z = 1/2 around P = (1/4, 1/2, 1/2), the
/// midpoint of G's edge between two outside corners. Four of the six fine leaves around P are
/// gray with P inside (an island on G's edge); the other two are white: a crack, as a Boolean
/// leaves where an operand's uniform leaf meets new surface.
Octree island_beside_a_crack(Lat& p) {
  constexpr int64_t kHalf = int64_t{1} << (kMaxLevel - 1), kQuarter = kHalf / 2;
  p = {kQuarter, kHalf, kHalf};
  Octree t;
  t.max_depth = 2;
  t.nodes.assign(33, Node{});
  t.nodes[0] = Node{1, CellKind::Internal};
  auto gray = [&](uint32_t node, uint8_t signs) {
    t.nodes[node] = Node{uint32_t(t.vertices.size()), CellKind::Gray, signs};
    t.vertices.push_back({0.5f, 0.5f, 0.5f});
  };
  gray(1, 0x01);                                   // G, level-1 child 0
  t.nodes[3] = Node{9, CellKind::Internal};        // child 2: y high
  t.nodes[5] = Node{17, CellKind::Internal};       // child 4: z high
  t.nodes[7] = Node{25, CellKind::Internal};       // child 6: y and z high
  gray(9 + 4, 1 << 5);                             // P is each leaf's corner 5, 4, 3, 2
  gray(9 + 5, 1 << 4);
  gray(17 + 2, 1 << 3);
  gray(17 + 3, 1 << 2);
  return t;                                        // nodes 25, 26 (P's corners 1, 0): white
}

TEST(Signs, IslandFlipBesideACrackKeepsOneSignPerPoint) {
  Lat p;
  Octree t = island_beside_a_crack(p);
  ASSERT_EQ(signs_around(t, p).size(), 2u);  // the crack: gray leaves say in, white ones out
  EXPECT_GT(detail::remove_islands(t, nullptr), 0u);
  // The island is gone (P takes G's edge sign, outside) in every leaf around it. Toggling each
  // leaf's corner instead turned the white leaves gray with P inside: still two signs.
  EXPECT_EQ(signs_around(t, p), std::set<bool>{false});
  EXPECT_NO_THROW(detail::check_octree(t, "remove_islands"));
}

TEST(Signs, SettingAPointSignIsIdempotent) {
  Lat p;
  Octree t = island_beside_a_crack(p);
  detail::set_point_sign(t, p, true, nullptr);
  EXPECT_EQ(signs_around(t, p), std::set<bool>{true});
  detail::set_point_sign(t, p, true, nullptr);
  EXPECT_EQ(signs_around(t, p), std::set<bool>{true});
  detail::set_point_sign(t, p, false, nullptr);
  EXPECT_EQ(signs_around(t, p), std::set<bool>{false});
}

}  // namespace
}  // namespace pic
