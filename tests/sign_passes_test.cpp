// Contracts of the sign passes (src/signs), each on small hand-built octrees: what a pass
// changes, and what it must leave alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <map>

#include "octree/cell.h"
#include "pic/pic.h"
#include "signs/consistency.h"
#include "signs/refine.h"
#include "signs/settle.h"

#include <random>

namespace pic {
namespace {

using Lat = std::array<int64_t, 3>;
using detail::Cell;

/// Lattice coordinates (kMaxLevel units) of a point given in units of a level's cells.
Lat at(int level, int64_t x, int64_t y, int64_t z) {
  const int64_t s = int64_t{1} << (kMaxLevel - level);
  return {x * s, y * s, z * s};
}

/// A tree of depth `depth` whose cells split while `split(cell)` says so; each leaf's corner
/// signs come from `inside`, its vertex at its cell's centre (uniform leaves where the
/// corners agree).
Octree build(int depth, const std::function<bool(const Cell&)>& split, const std::function<bool(const Lat&)>& inside) {
  Octree t;
  t.max_depth = depth;
  t.nodes.assign(1, Node{});
  std::function<void(uint32_t, const Cell&)> make = [&](uint32_t slot, const Cell& cell) {
    if (cell.level < depth && split(cell)) {
      const auto first = static_cast<uint32_t>(t.nodes.size());
      t.nodes.resize(first + 8);
      t.nodes[slot] = Node{first, CellKind::Internal};
      for (int c = 0; c < 8; ++c) make(first + c, cell.child(c));
      return;
    }
    uint8_t s = 0;
    for (int c = 0; c < 8; ++c) s |= uint8_t(inside(cell.corner(c))) << c;
    if (s == 0 || s == 0xff) {
      t.nodes[slot] = Node{0, s ? CellKind::Black : CellKind::White};
      return;
    }
    const Vec3 lo = cell.min_unit();
    const double h = cell.size() / 2;
    t.nodes[slot] = detail::add_gray(t.vertices, cell, s, {lo[0] + h, lo[1] + h, lo[2] + h});
  };
  make(0, Cell{});
  return t;
}

const auto everywhere = [](const Cell&) { return true; };

/// Every edge of the mesh on exactly two triangles, once each way.
bool test_closed(const TriMesh& m) {
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  for (const auto& [e, n] : directed)
    if (n != 1 || directed.count({e.second, e.first}) == 0) return false;
  return !m.triangles.empty();
}

size_t multi_component_leaves(const Octree& t) {
  size_t n = 0;
  detail::visit_leaves(t, 0, Cell{}, [&](uint32_t node, const Cell&) {
    n += t.nodes[node].kind == CellKind::Gray && detail::multi_component(t.nodes[node].signs);
  });
  return n;
}

// ---- one component per leaf (components.cpp) ----

TEST(ComponentsPass, TwoDiagonalCornersBecomeOneComponent) {
  // The finest cell [1, 2]^3 (level 2) has its corners (1,1,1) and (2,2,2) inside, nothing else.
  const Lat a = at(2, 1, 1, 1), b = at(2, 2, 2, 2);
  Octree t = build(2, everywhere, [&](const Lat& p) { return p == a || p == b; });
  ASSERT_EQ(multi_component_leaves(t), 1u);
  const detail::TopologyFix fix = detail::enforce_one_component(t, nullptr);
  EXPECT_EQ(fix.flipped, 1u);
  EXPECT_EQ(fix.remaining, 0u);
  EXPECT_EQ(multi_component_leaves(t), 0u);
}

TEST(ComponentsPass, LeavesOneComponentTreesAlone) {
  const Lat a = at(2, 1, 1, 1);
  Octree t = build(2, everywhere, [&](const Lat& p) { return p == a; });
  const std::vector<Node> before = t.nodes;
  EXPECT_EQ(detail::enforce_one_component(t, nullptr).flipped, 0u);
  for (size_t k = 0; k < before.size(); ++k) EXPECT_EQ(t.nodes[k].signs, before[k].signs);
}

TEST(ComponentsPass, AsksToRefineEveryPointItFlipsFirst) {
  const Lat a = at(2, 1, 1, 1), b = at(2, 2, 2, 2);
  Octree t = build(2, everywhere, [&](const Lat& p) { return p == a || p == b; });
  std::vector<Lat> asked;
  const std::function<void(const Lat&)> refine = [&](const Lat& p) {
    asked.push_back(p);
    EXPECT_EQ(detail::point_sign(t, p), std::optional<bool>(true));  // asked before the flip
  };
  detail::enforce_one_component(t, nullptr, {.refine = &refine});
  ASSERT_EQ(asked.size(), 1u);
  EXPECT_TRUE(asked[0] == a || asked[0] == b);
  EXPECT_EQ(detail::point_sign(t, asked[0]), std::optional<bool>(false));
}

TEST(ComponentsPass, FlipsThePointNearestTheSurfaceWhenTheFunctionIsKnown) {
  // Cell [1, 2]^3 (level 2) has (1,1,1), (2,1,2) and (2,2,2) inside: (1,1,1) apart from the
  // other two across a face diagonal, which the cell below shares. Taking (1,1,1) out (the
  // minority sign) or putting (1,1,2) or (2,1,1) in each leaves one component in both cells;
  // the sampled function says (1,1,2) lies a hundredth of a cell from the surface and the
  // others far from it, so its sign is the one to give up.
  const Lat a = at(2, 1, 1, 1), b = at(2, 2, 1, 2), c = at(2, 2, 2, 2), near = at(2, 1, 1, 2), mid = at(2, 2, 1, 1);
  const auto inside = [&](const Lat& p) { return p == a || p == b || p == c; };
  Octree minority = build(2, everywhere, inside);
  ASSERT_EQ(multi_component_leaves(minority), 2u);
  detail::enforce_one_component(minority, nullptr);
  EXPECT_EQ(detail::point_sign(minority, a), std::optional<bool>(false));
  Octree nearest = build(2, everywhere, inside);
  const std::function<double(const Lat&)> margin = [&](const Lat& p) { return p == near ? 0.01 : p == mid ? 0.5 : 0.9; };
  const detail::TopologyFix fix = detail::enforce_one_component(nearest, nullptr, {.margin = &margin});
  EXPECT_EQ(fix.flipped, 1u);
  EXPECT_EQ(multi_component_leaves(nearest), 0u);
  EXPECT_EQ(detail::point_sign(nearest, near), std::optional<bool>(true));
  EXPECT_EQ(detail::point_sign(nearest, a), std::optional<bool>(true));
}

// ---- islands on coarse faces (islands.cpp) ----

/// Octant 0 a coarse gray leaf (level 1, its corner at the origin inside); the other octants
/// split to level 2. `island`: the middle of the coarse leaf's face x = 1/2 inside too.
Octree coarse_face(bool island) {
  const Lat origin{0, 0, 0}, mid = at(2, 2, 1, 1);
  return build(
      2, [](const Cell& c) { return c.level == 0 || c.lat != Lat{0, 0, 0}; },
      [&](const Lat& p) { return p == origin || (island && p == mid); });
}

TEST(IslandsPass, AnIslandOnACoarseFaceTakesTheFacesSign) {
  Octree t = coarse_face(true);
  const Lat mid = at(2, 2, 1, 1);
  ASSERT_EQ(detail::point_sign(t, mid), std::optional<bool>(true));
  detail::PinnedPoints pinned;
  EXPECT_EQ(detail::remove_islands(t, nullptr, nullptr, &pinned), 1u);
  EXPECT_EQ(detail::point_sign(t, mid), std::optional<bool>(false));
  EXPECT_EQ(pinned.count(detail::lattice_key(mid)), 1u);  // the one-component pass keeps it
}

TEST(IslandsPass, LeavesFacesThatLookLikeOneCellsFaceAlone) {
  Octree t = coarse_face(false);
  EXPECT_EQ(detail::remove_islands(t, nullptr), 0u);
}

TEST(IslandsPass, NeverChangesTheCoarseLeafsOwnCorners) {
  Octree t = coarse_face(true);
  const uint8_t before = t.nodes[1].signs;  // octant 0: the coarse gray leaf
  ASSERT_EQ(t.nodes[1].kind, CellKind::Gray);
  detail::remove_islands(t, nullptr);
  EXPECT_EQ(t.nodes[1].signs, before);
}

// ---- specks (specks.cpp) ----

const std::function<bool(const detail::Speck&)> keep_none = [](const detail::Speck&) { return false; };

TEST(SpecksPass, ASinglePointShellIsAbsorbed) {
  const Lat a = at(2, 1, 1, 1);
  Octree t = build(2, everywhere, [&](const Lat& p) { return p == a; });
  EXPECT_EQ(detail::remove_specks(t, nullptr, keep_none), 1u);
  size_t gray = 0;
  detail::visit_leaves(t, 0, Cell{}, [&](uint32_t n, const Cell&) { gray += t.nodes[n].kind == CellKind::Gray; });
  EXPECT_EQ(gray, 0u);
}

TEST(SpecksPass, KeepsWhatTheCallerKeeps) {
  const Lat a = at(2, 1, 1, 1);
  Octree t = build(2, everywhere, [&](const Lat& p) { return p == a; });
  EXPECT_EQ(detail::remove_specks(t, nullptr, [](const detail::Speck&) { return true; }), 0u);
  EXPECT_EQ(detail::point_sign(t, a), std::optional<bool>(true));
}

TEST(SpecksPass, APointAtTheCornerOfBigLeavesIsNoSpeck) {
  // The root's middle inside, its eight octants coarse gray leaves (two levels above the
  // finest): a part's corner meeting another's there, seen from the big leaves.
  const Lat mid = at(1, 1, 1, 1);
  Octree t = build(3, [](const Cell& c) { return c.level == 0; }, [&](const Lat& p) { return p == mid; });
  detail::SpeckSearch search;
  search.min_level = 1;
  search.uniform_rim = true;
  EXPECT_EQ(detail::remove_specks(t, nullptr, keep_none, search), 0u);
  EXPECT_EQ(detail::point_sign(t, mid), std::optional<bool>(true));
}

// ---- cracks (cracks.cpp) ----

/// Octant 0 a coarse white leaf (level 1); the other octants split to level 2, with the
/// middle of the coarse leaf's face x = 1/2 inside: the finer side shows a sign change on that
/// face, and the polygons around it need a vertex in the coarse leaf (a Boolean leaves this
/// where an operand's uniform leaf meets new surface).
Octree with_a_crack(uint32_t& cracked) {
  const Lat mid = at(2, 2, 1, 1);
  Octree t = build(
      2, [](const Cell& c) { return c.level == 0 || c.lat != Lat{0, 0, 0}; }, [&](const Lat& p) { return p == mid; });
  cracked = 1;  // the root's first child: octant 0
  return t;
}

TEST(CracksPass, AUniformLeafBesideASignChangeGetsAVertex) {
  uint32_t cracked = 0;
  Octree t = with_a_crack(cracked);
  ASSERT_EQ(t.nodes[cracked].kind, CellKind::White);
  ASSERT_FALSE(test_closed(unsplit_contour(t)));
  EXPECT_EQ(detail::repair_cracks(t, nullptr), 1u);
  EXPECT_EQ(t.nodes[cracked].kind, CellKind::Gray);
  EXPECT_EQ(t.nodes[cracked].signs, 0u);  // its own signs stay: only a vertex for the polygons
  EXPECT_TRUE(test_closed(unsplit_contour(t)));
}

TEST(CracksPass, LeavesClosedTreesAlone) {
  const Lat a = at(2, 1, 1, 1);
  Octree t = build(2, everywhere, [&](const Lat& p) { return p == a; });
  EXPECT_EQ(detail::repair_cracks(t, nullptr), 0u);
}

TEST(CracksPass, NeverChangesASign) {
  uint32_t cracked = 0;
  Octree t = with_a_crack(cracked);
  std::vector<uint8_t> before;
  detail::visit_leaves(t, 0, Cell{}, [&](uint32_t n, const Cell&) { before.push_back(detail::signs_of(t.nodes[n])); });
  detail::repair_cracks(t, nullptr);
  size_t k = 0;
  detail::visit_leaves(t, 0, Cell{}, [&](uint32_t n, const Cell&) { EXPECT_EQ(detail::signs_of(t.nodes[n]), before[k++]); });
}

// ---- refining around a point (refine.cpp) ----

TEST(RefinePass, SplitsTheCoarseLeavesAroundAPointDownToTheFinestLevel) {
  const Lat mid = at(1, 1, 1, 1);
  Octree t = build(3, [](const Cell& c) { return c.level == 0; }, [&](const Lat& p) { return p == mid; });
  size_t grown = 0;
  // Resampled as the tree was built: from the same sign function.
  const detail::ResampleLeaf resample = [&](const detail::LeafRef& l, const Lat& p) {
    const Octree sub = build(3 - l.cell.level, [&](const Cell& c) {
      Cell in_tree{c.level + l.cell.level, {}};
      for (int k = 0; k < 3; ++k) in_tree.lat[k] = l.cell.lat[k] + (c.lat[k] >> l.cell.level);
      return in_tree.holds(p);
    }, [&](const Lat& q) {
      Lat in_tree;
      for (int k = 0; k < 3; ++k) in_tree[k] = l.cell.lat[k] + (q[k] >> l.cell.level);
      return in_tree == mid;
    });
    detail::Builder b;
    b.nodes = sub.nodes;
    b.vertices = sub.vertices;
    return b;
  };
  EXPECT_EQ(detail::refine_around(t, mid, resample, [&](uint32_t) { ++grown; }), 8u);
  for (int o = 0; o < 8; ++o) {
    const Lat q{mid[0] - 1 + (o & 1), mid[1] - 1 + ((o >> 1) & 1), mid[2] - 1 + ((o >> 2) & 1)};
    EXPECT_EQ(detail::leaf_at(t, q).cell.level, 3);
  }
  EXPECT_GT(grown, 8u);
  EXPECT_EQ(detail::point_sign(t, mid), std::optional<bool>(true));
}

// ---- the settling loop: a guarantee where leaves cannot refine ----

/// A random tree: cells split with probability `split` per level, so capped leaves sit
/// beside leaves of every coarser level; every lattice point's sign is a coin toss (outside on the root cube's faces), and each
/// gray leaf's vertex a random point inside its cell; the finest gray leaves are capped.
Octree random_tree(uint64_t seed, int depth, double split) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::map<Lat, bool> coin;
  Octree t = build(depth, [&](const Cell& c) { return c.level == 0 || u(rng) < split; }, [&](const Lat& p) {
    const int64_t end = int64_t{1} << kMaxLevel;  // the root cube's faces are outside, as sampled
    if (std::any_of(p.begin(), p.end(), [&](int64_t x) { return x == 0 || x == end; })) return false;
    const auto [it, fresh] = coin.try_emplace(p, false);
    if (fresh) it->second = u(rng) < 0.5;
    return it->second;
  });
  detail::visit_leaves(t, 0, Cell{}, [&](uint32_t n, const Cell& c) {
    if (t.nodes[n].kind != CellKind::Gray) return;
    const Vec3 lo = c.min_unit();
    if (c.level == t.max_depth) t.nodes[n].flags |= kFlagCapped;  // at the cap: any pattern
    auto& v = t.vertices[t.nodes[n].index];
    for (int k = 0; k < 3; ++k) v[k] = float(lo[k] + c.size() * (0.1 + 0.8 * u(rng)));
  });
  return t;
}

TEST(Settle, RandomSignsAtEveryLevelContourValid) {
  // Depth 4 and 5, every corner-sign pattern and neighbour level in some tree.
  size_t invalid_unsettled = 0, trees = 0;
  for (uint64_t seed = 1; seed <= 60; ++seed) {
    Octree t = seed <= 40 ? random_tree(seed, 4, 0.6) : random_tree(seed, 5, 0.45);
    invalid_unsettled += !check_validity(contour(t)).valid();
    detail::settle_sampled(t, {});
    const TriMesh m = contour(t);
    if (m.triangles.empty()) continue;
    ++trees;
    const MeshValidity v = check_validity(m);
    EXPECT_TRUE(v.valid()) << "tree " << seed << ": " << v.boundary_edges << " boundary edges, " << v.nonmanifold_edges
                           << " non-manifold edges, " << v.nonmanifold_vertices << " non-manifold vertices, "
                           << v.self_intersections << " self-intersections";
    EXPECT_EQ(multi_component_leaves(t), 0u) << "tree " << seed;
  }
  EXPECT_GT(trees, 40u);
  EXPECT_GT(invalid_unsettled, 30u);  // without the settling these trees do not contour valid
}

}  // namespace
}  // namespace pic
