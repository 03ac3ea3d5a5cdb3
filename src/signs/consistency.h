// Topology clean-up after sampling and CSG: leaves at the depth cap may hold two surface
// components (the paper's rule 3 could not be met). Dual contouring then makes non-manifold
// edges. A corner sign is flipped — consistently in every leaf that has that lattice point as
// a corner — until every leaf holds one component. This removes or joins features thinner
// than the finest cell, which the octree cannot represent anyway.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <unordered_set>
#include <vector>

#include "octree/cell.h"
#include "octree/point_signs.h"

namespace pic::detail {


/// Lattice points (key: x | y << 21 | z << 42) that remove_islands set in this operation, which
/// enforce_one_component should not flip back when anything else will do.
using PinnedPoints = std::unordered_set<uint64_t>;
inline uint64_t lattice_key(const std::array<int64_t, 3>& p) {
  return uint64_t(p[0]) | uint64_t(p[1]) << 21 | uint64_t(p[2]) << 42;
}

/// Whether corner signs make more than one surface component in a cell.
bool multi_component(uint8_t signs);

struct TopologyFix {
  size_t flipped = 0;    // lattice points whose sign changed
  size_t remaining = 0;  // leaves still holding more than one component
};

/// How enforce_one_component chooses and makes its flips.
struct ComponentFlips {
  /// Called for every node on the way to a leaf whose signs changed (so a later partial pass
  /// sees it).
  const std::function<void(uint32_t)>* touched = nullptr;
  /// Points another pass set in this operation: flipped back only when nothing else will do.
  const PinnedPoints* pinned = nullptr;
  /// CSG: a flip that leaves a coarser gray leaf without a sign change costs more (another
  /// flip usually does, and the coarse leaf keeps its surface).
  bool spare_coarse = false;
  /// Called before each flip with the point: the leaves coarser than the finest level that
  /// hold it are split first (refine_around), so no flip moves the surface by more than a
  /// finest cell.
  const std::function<void(const std::array<int64_t, 3>&)>* refine = nullptr;
  /// How far a lattice point lies from the sampled surface, in finest cells (|f| there over
  /// f's slope), where the sampled function is known: among flips that leave as many leaves
  /// with two components, the point nearest the surface goes, whose new sign moves the
  /// surface least. Without it, the point of the cell's minority sign (the thinner feature).
  const std::function<double(const std::array<int64_t, 3>&)>* margin = nullptr;
};

/// Works on the leaves for which `active` is true (all leaves when null).
TopologyFix enforce_one_component(Octree& t, const std::function<bool(uint32_t)>* active,
                                  const ComponentFlips& how = {});

/// Flips inside corners of two-component leaves to outside until no leaf has two components.
/// Every flip takes a point out of the solid, so it ends (at worst with every point outside),
/// and it ends only when no leaf has two components: a guarantee where enforce_one_component's
/// cheaper flips can cycle. Returns how many points changed.
/// `flipped`, when given, is told each point that changed.
size_t erode_to_one_component(Octree& t, const std::function<bool(uint32_t)>* active,
                              const std::function<void(uint32_t)>* touched,
                              const std::function<void(const std::array<int64_t, 3>&)>* flipped = nullptr);

/// Flips inside points on the boundaries of leaves coarser than the finest level until, on each,
/// the signs of its corners and of the finer corners its neighbours put on its faces form one
/// inside and one outside region (over the minimal edges between them): the condition for the
/// leaf's one vertex to be a manifold point of the contour. Monotone like
/// erode_to_one_component, so it ends. Returns how many points changed.
size_t erode_to_simple_boundaries(Octree& t, const std::function<bool(uint32_t)>* active,
                                  const std::function<void(uint32_t)>* touched,
                                  const std::function<void(const std::array<int64_t, 3>&)>* flipped = nullptr);

/// What remove_islands carries from one round of a settling loop to the next. Every check reads
/// only the stored signs of the leaves around it, so a later round need look again only near
/// the leaves a flip touched since the last round began, and at leaves it has not seen: anywhere
/// else it would find what the last round left, nothing.
struct IslandRounds {
  std::vector<uint32_t> touched;  ///< nodes set_point_sign reported since the last round began
  std::vector<uint8_t> seen;      ///< per node: a leaf a round has looked at
  std::vector<std::pair<LeafRef, int>> faces;  ///< the coarse faces (leaf, face) checked so far
};

/// A lattice point inside an edge or face of a bigger gray leaf, whose sign differs from all of
/// that leaf's corners on that edge or face, is an island finer than the leaf: dual contouring
/// would hang a second sheet on the leaf's vertex (a non-manifold edge). Its sign is flipped
/// to match, in every leaf that has it as a corner. Returns how many points changed.
/// With `rounds` (kept by the caller across rounds, and told of every node a flip touches
/// between them), a round after the first looks only where something changed; same result.
size_t remove_islands(Octree& t, const std::function<bool(uint32_t)>* active,
                      const std::function<void(uint32_t)>* touched = nullptr, PinnedPoints* pinned = nullptr,
                      IslandRounds* rounds = nullptr);

/// A speck: a few finest-level lattice points of one sign (`inside`) whose every neighbour
/// (every other corner of the leaves around them) has the other sign, i.e. a closed shell or
/// void a cell or two across; `leaves` are the leaves around its points.
struct Speck {
  std::vector<std::array<int64_t, 3>> points, rim;
  std::vector<uint32_t> leaves;
  bool inside = false;
};
/// Where remove_specks looks. By default as the CSG clean-up needs: points that are corners
/// of finest gray leaves only, every leaf around them gray.
struct SpeckSearch {
  int min_level = -1;        ///< the coarsest gray leaves whose corners may be specks (-1: finest)
  bool uniform_rim = false;  ///< uniform leaves of the other sign may surround the speck too
  /// Gray leaves one level coarser than the finest may have a speck point on a face or edge
  /// instead of a corner (a leaf copied whole from one operand beside finest ones the
  /// Boolean made).
  bool coarse_rim = false;
};
/// Removes the specks with a leaf for which `active` is true (all when null) unless `keep`
/// says otherwise: the speck's points take their neighbours' sign (its leaves become uniform).
/// Specks are features about a cell across. Returns how many were removed.
size_t remove_specks(Octree& t, const std::function<bool(uint32_t)>* active,
                     const std::function<bool(const Speck&)>& keep, const SpeckSearch& search = {});

/// Turns uniform leaves that border a sign change into gray leaves (vertex at the crossing
/// edges' midpoint), so the contour stays closed. Returns how many leaves changed.
size_t repair_cracks(Octree& t, const std::function<bool(uint32_t)>* active);

}  // namespace pic::detail
