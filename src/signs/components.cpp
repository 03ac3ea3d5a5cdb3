// The one-component pass: a leaf whose corner signs make two surface components gets one
// corner flipped. See consistency.h (enforce_one_component).
#include "signs/consistency.h"
#include "signs/leaf_walks.h"

#include <algorithm>
#include <array>
#include <vector>

namespace pic::detail {

using Lat = std::array<int64_t, 3>;

bool multi_component(uint8_t s) { return s != 0 && s != 0xff && !one_component(s); }

namespace {

/// Whether a flip leaves a coarser gray leaf without a sign change: its surface is gone and
/// only a crack repair's vertex is left, whose faces the island pass then clears of the finer
/// side's sign changes too. At the thin end of a wedge that erodes the wedge by a cell or two
/// (1.5 to 2 finest cells gone where the exact solid is a cell thick).
bool emptied_coarse_leaf(const Octree& t, const Around& a, uint8_t flipped) {
  return a.cell.level < t.max_depth && t.nodes[a.node].kind == CellKind::Gray && (flipped == 0 || flipped == 0xff);
}

}  // namespace

TopologyFix enforce_one_component(Octree& t, const std::function<bool(uint32_t)>* active, const ComponentFlips& how) {
  TopologyFix fix;
  for (int pass = 0; pass < 6; ++pass) {
    // Only subtrees with active nodes are visited: a sculpting stroke stays local.
    std::vector<LeafRef> bad;
    for_each_gray_leaf(t, active, [&](uint32_t node, const Cell& cell) {
      if (multi_component(t.nodes[node].signs)) bad.push_back({node, cell});
    });
    fix.remaining = bad.size();
    if (bad.empty()) break;
    for (const LeafRef& l : bad) {
      const uint8_t s = t.nodes[l.node].signs;
      if (!multi_component(s)) continue;  // fixed by an earlier flip
      // Try each corner; keep the flip that leaves the fewest multi-component leaves around it,
      // preferring the point nearest the surface (or of the minority sign: the thinner feature).
      int best = -1;
      double best_cost = 1e30;
      bool best_breaks_coarse = false;  // the best flip leaves a coarser leaf two components
      const bool minority_inside = __builtin_popcount(s) <= 4;
      for (int k = 0; k < 8; ++k) {
        if (multi_component(uint8_t(s ^ (1 << k)))) continue;
        const auto around = leaves_around(t, l.cell.corner(k));
        const bool inside = !((s >> k) & 1);
        double cost = 0;
        bool breaks_coarse = false;
        for (const auto& a : around) {
          const uint8_t flipped = with_corner(signs_of(t.nodes[a.node]), a.corner, inside);
          cost += 2 * multi_component(flipped);
          cost += how.spare_coarse && emptied_coarse_leaf(t, a, flipped);
          breaks_coarse = breaks_coarse || (a.cell.level < t.max_depth && multi_component(flipped));
        }
        // A point a cell or more from the surface moves it as much as any other: among
        // those the minority sign still decides (a hair of cost).
        const bool majority = (((s >> k) & 1) != 0) != minority_inside;
        if (how.margin) {
          const double m = (*how.margin)(l.cell.corner(k));
          cost += (m < 1 ? m : 1) + 1e-3 * majority;  // NaN counts as far
        } else {
          cost += majority;
        }
        // Undoing what remove_islands just set would bring its defect back.
        if (how.pinned && how.pinned->count(lattice_key(l.cell.corner(k)))) cost += 16;
        if (cost < best_cost) {
          best_cost = cost;
          best = k;
          best_breaks_coarse = breaks_coarse;
        }
      }
      if (best < 0) continue;
      if (best_breaks_coarse && l.cell.level == t.max_depth) {
        // Two components in a finest leaf are the depth cap's to keep (the contour's sheets
        // are split apart); in a coarser leaf no PIC can hold them. Trading the one for the
        // other made the two leaves flip the same points back and forth.
        t.nodes[l.node].flags |= kFlagCapped;
        continue;
      }
      const Lat p = l.cell.corner(best);
      if (how.refine) (*how.refine)(p);
      set_point_sign(t, p, !((s >> best) & 1), how.touched);
      ++fix.flipped;
    }
  }
  return fix;
}

size_t erode_to_one_component(Octree& t, const std::function<bool(uint32_t)>* active,
                              const std::function<void(uint32_t)>* touched,
                              const std::function<void(const Lat&)>* flipped) {
  size_t count = 0;
  for (;;) {
    std::vector<LeafRef> bad;
    for_each_gray_leaf(t, active, [&](uint32_t node, const Cell& cell) {
      if (multi_component(t.nodes[node].signs)) bad.push_back({node, cell});
    });
    if (bad.empty()) return count;
    for (const LeafRef& l : bad) {
      const uint8_t s = t.nodes[l.node].signs;
      if (!multi_component(s)) continue;
      // Of the inside corners, the one whose removal leaves the fewest two-component leaves.
      int best = -1, best_cost = 1 << 30;
      for (int k = 0; k < 8; ++k) {
        if (!((s >> k) & 1)) continue;
        int cost = 0;
        for (const auto& a : leaves_around(t, l.cell.corner(k)))
          cost += multi_component(with_corner(signs_of(t.nodes[a.node]), a.corner, false));
        if (cost < best_cost) best_cost = cost, best = k;
      }
      set_point_sign(t, l.cell.corner(best), false, touched);
      if (flipped) (*flipped)(l.cell.corner(best));
      ++count;
    }
  }
}

}  // namespace pic::detail
