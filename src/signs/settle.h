// The settling loop: after sampling and after a Boolean, corner signs are flipped until every
// leaf is a valid PIC (one surface component, no finer islands on a coarse leaf's faces, no
// specks a cell across, no cracks). Sampling and CSG run the same loop with their own scope.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "geometry/box_tree.h"
#include "signs/consistency.h"
#include "signs/refine.h"

namespace pic::detail {

/// What one settling run works on and how.
struct SettlePlan {
  const std::function<bool(uint32_t)>* active = nullptr;   ///< leaves to settle (null: all)
  const std::function<void(uint32_t)>* touched = nullptr;  ///< told of every node a flip changes
  /// The one-component pass looks at every leaf, not only the active ones (a sampled tree's
  /// depth-capped leaves may hold two components anywhere).
  bool one_component_everywhere = false;
  bool spare_coarse = false;  ///< see enforce_one_component
  std::function<bool(const Speck&)> keep_speck;  ///< specks to keep (null: remove them all)
  /// Splits the coarser leaves holding a point before the one-component pass flips it (null:
  /// flip in place); see enforce_one_component.
  std::function<void(const std::array<int64_t, 3>&)> refine;
  /// A lattice point's distance to the sampled surface in finest cells (null: unknown); see
  /// ComponentFlips::margin.
  std::function<double(const std::array<int64_t, 3>&)> margin;
  SpeckSearch specks;
  /// After a round that changed no sign, still run the erosions (erode_until_valid) around
  /// every capped leaf, which may hold any pattern. Sampling does; the CSG clean-up erodes
  /// around the capped leaves the passes left two components in, and over its whole scope
  /// only where its rounds ran out (checking every stamped coarse leaf's boundary on every
  /// Boolean costs it 1.5x).
  bool erode_after_quiet = false;
};

/// Islands and one component per leaf, alternated until both are quiet (at most 4 rounds);
/// then the erosions (see erode_after_quiet); then specks; then cracks. `pinned`: points set earlier in this operation (sign hints).
/// Returns how many leaves repair_cracks changed.
size_t settle(Octree& t, const SettlePlan& plan, PinnedPoints& pinned);

/// The settling's last step and its guarantee: erode_to_one_component and
/// erode_to_simple_boundaries in turn until neither flips a point (`components` and
/// `boundaries`: the leaves each looks at, all when null). Returns how many points changed.
size_t erode_until_valid(Octree& t, const std::function<bool(uint32_t)>* components,
                         const std::function<bool(uint32_t)>* boundaries, const std::function<void(uint32_t)>* touched);

/// erode_until_valid over the capped leaves and every leaf touching them (the leaves a flip
/// there reaches join as it goes). Returns how many points changed.
size_t erode_around_capped(Octree& t, const std::function<void(uint32_t)>* touched);

/// Where a tree's signs may disagree between levels (islands, cracks): everywhere, or only
/// within these unit-space boxes.
struct SettleRegion {
  bool everywhere = true;
  std::vector<Box> boxes;
};

/// Settles a sampled tree whose signs may change inside uniform leaves (a winding number's
/// level set can cross a cell without touching its corners): finer neighbours can then show
/// islands and cracks on their faces. Visits the region, plus every leaf a flip touched.
/// With `resample`, a flip at the corner of a coarser leaf splits it first (refine_around).
/// `margin`: see ComponentFlips::margin.
void settle_sampled(Octree& tree, const SettleRegion& region, const ResampleLeaf* resample = nullptr,
                    const std::function<double(const std::array<int64_t, 3>&)>* margin = nullptr);

}  // namespace pic::detail
