// Inside/outside for inputs that are not clean closed meshes (docs/algorithms.md, "Any input").
//
// Triangle soups: the generalized winding number w of the input M is split as
//   w_M(p) = w_{M+C}(p) - w_C(p),
// where C is a set of cones closing M's boundary chain. M + C has no boundary, so w_{M+C} is an
// integer that the sampler carries from corner to corner by signed crossing counts — exact, with
// the same predicates and tie-break as crossing parity. Only w_C, the few cone triangles, is a
// real number; a dipole tree evaluates it, exactly where the decision |w| >= 1/2 is close.
// Every sign is a function of the lattice point alone.
//
// Point clouds: w is the points' winding number (each point a disc of its neighbours' spacing),
// evaluated per lattice point with the same tree.
#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include "geometry/box_tree.h"
#include "geometry/bvh.h"
#include "geometry/memo.h"
#include "octree/subdivide.h"
#include "geometry/vec3.h"
#include "geometry/winding.h"

namespace pic::detail {

/// Remembers recent inside/outside decisions of one source per thread: a lattice point is
/// asked for by up to 4 cells of a level (shared faces and edges) and by their children, and
/// a decision near a hole costs hundreds of solid angles. Direct mapped, no locks.
class DecisionCache {
 public:
  /// The cached decision at p (-1: none).
  int find(const I3& p) const;
  void store(const I3& p, bool inside) const;

 private:
  struct Entry {
    I3 p;
    bool filled = false;
    bool inside = false;
  };
  using Memo = ThreadMemo<Entry, 15>;
  mutable Memo memo_;  // a memo of the source's pure decisions: asking fills it, answers never depend on it
};

/// A crossing found on a cell edge across a hole, with the level set's normal there: up to 4
/// cells of a level share each edge, and each would search it again.
struct HoleCrossing {
  I3 a;
  i64 len = 0;
  int axis = 0;
  bool filled = false;
  Vec3 x, n;
};
using HoleCrossingMemo = ThreadMemo<HoleCrossing, 13>;
/// The caps' winding number at a cell corner: the ends of the edges searched across a hole,
/// shared by the corner's edges in each cell around it.
struct CapValue {
  I3 p;
  bool filled = false;
  double w = 0;
};
using CapValueMemo = ThreadMemo<CapValue, 12>;

/// A connected cap's extent: an oriented box around its vertices (so around its convex hull),
/// axes along their principal directions (a flat cap gets a thin box).
struct CapExtent {
  Vec3 centre;
  std::array<Vec3, 3> axes;  ///< orthonormal
  Vec3 half;                 ///< half-extents along the axes
  double radius() const { return norm3(half); }
  /// An upper bound on |w| of anything inside the box seen from u: the solid angle of the faces
  /// u sees, over 4 pi (1/2 when u is in the box).
  double cover(const Vec3& u) const;
  /// Whether `b` certainly does not meet the box.
  bool apart(const Box& b) const;
};

class WindingSource : public SurfaceSource {
 public:
  /// `tris`: the input's triangles followed by the cone triangles (use = 0) closing it;
  /// `boundary`: the input's boundary edges; `caps`: each connected cap's extent (unit
  /// space), grown by `margin`.
  WindingSource(std::vector<ITri> tris, size_t mesh_count, std::vector<std::array<Vec3, 2>> boundary,
                std::vector<CapExtent> caps, double margin);
  void child_grid_signs(const Cell& cell, const std::vector<uint32_t>& idx, std::array<bool, 27>& grid,
                        Wind27* wind) const override;
  bool tracks_winding() const override { return true; }
  bool surface_matters(const Cell& cell, uint8_t signs, const Wind8* wind,
                       const std::vector<uint32_t>& idx) const override;
  void add_fill_planes(const Cell& cell, uint8_t signs, const Wind8* wind, const std::vector<uint32_t>& idx,
                       Qef& q) const override;

  /// Integer winding number of input + cones at a grid point (a ray to the cube's boundary).
  int32_t ray_winding(const I3& p) const;
  /// Integer winding number at grid point b, given w at a nearby point a (after ray_winding).
  int32_t winding_from(const I3& a, int32_t w, const I3& b) const;
  /// The sign at grid point p whose integer winding number is w.
  bool inside(const I3& p, int32_t w) const;
  /// The sign at any grid point (its integer winding number by a ray): a query on its own.
  bool inside(const I3& p) const { return inside(p, ray_winding(p)); }
  /// Integer winding number at grid point p of `cell` (corner windings `wind`), by a path
  /// along the cell's edges directions from its first corner.
  int32_t winding_in_cell(const Cell& cell, const Wind8& wind, const std::vector<uint32_t>& idx, const I3& p) const;
  /// Uniform cells that input triangles meet without showing a sign change on them (interior
  /// walls, flaps): a sign change elsewhere in such a cell goes unseen, so finer neighbours
  /// can show islands and cracks there. Thread-safe; in no particular order.
  std::vector<Cell> skipped_cells() const;
  /// Marks input triangles with the solid on both sides or on neither (interior walls of
  /// overlapping shells, stray sheets) as playing no part in the surface. Returns how many.
  size_t drop_interior_triangles();

 private:
  /// Whether the caps' winding number is certainly below 1/2 in magnitude all over `box` (unit
  /// space): there the caps cannot move a decision.
  bool caps_below_half(const Box& box) const;
  /// The caps' winding number at p (their tree's evaluate()); `memoize` for cell corners.
  double cap_winding(const I3& p, bool memoize) const;
  /// Closed input with dropped walls: the planes of dropped triangles where they change a
  /// cell edge's sign (add_fill_planes).
  void add_dropped_wall_planes(const Cell& cell, uint8_t signs, const Wind8& wind, const std::vector<uint32_t>& idx,
                               Qef& q) const;

  std::vector<ITri> all_;
  size_t mesh_count_;
  bool dropped_any_ = false;  // drop_interior_triangles took some out of the surface
  // Built once, on the first ray (only rays read it; most inputs never need one), behind the
  // once-flag: concurrent first rays wait for the one build.
  mutable TriangleBvh bvh_;
  mutable std::once_flag bvh_built_;
  DipoleTree caps_;
  std::vector<CapExtent> cap_extents_;
  double far_share_ = 0;  // the most a cap out of reach adds to |w_C|
  BoxTree cap_boxes_;     // the caps' reach, one box per cap
  std::vector<std::array<Vec3, 2>> boundary_;  // unit space
  DecisionCache cache_;
  // Memos of pure functions of a grid point or edge (asking fills them; answers never depend on them).
  mutable HoleCrossingMemo crossings_;
  mutable CapValueMemo cap_values_;
  // Cells the sampling passed over, collected for the caller (skipped_cells).
  mutable std::mutex skipped_mutex_;
  mutable std::vector<Cell> skipped_;
};

/// The triangles (vertex indices into `grid`) as exact lattice triangles, made in parallel;
/// `room` more reserved.
std::vector<ITri> grid_triangles(const std::vector<std::array<uint32_t, 3>>& tris, const std::vector<I3>& grid,
                                size_t room = 0);

/// Each boundary loop's box (unit space), grown by `margin` plus `spread` times its diagonal.
std::vector<Box> loop_boxes(const std::vector<std::vector<uint32_t>>& loops, const std::vector<I3>& grid,
                            double margin, double spread);

/// A cleaned mesh (vertices at `grid`) made ready for winding-number decisions: the input
/// closed by caps over its boundary loops, which decide signs only near their loops.
struct WindingInput {
  std::unique_ptr<WindingSource> source;
  std::vector<std::vector<uint32_t>> loops;  ///< the input's boundary loops (vertex indices)
};
/// `cell`: a finest cell (unit space), the caps' slack; `loop_count`: how many loops were capped.
WindingInput winding_input(const TriMesh& mesh, const std::vector<I3>& grid, double cell, size_t* loop_count);

class PointSource : public SurfaceSource {
 public:
  /// Points and normals in unit space (root cube [0,1]^3).
  PointSource(const std::vector<Vec3>& pos, const std::vector<Vec3>& normals);
  void child_grid_signs(const Cell& cell, const std::vector<uint32_t>& idx, std::array<bool, 27>& grid,
                        Wind27* wind) const override;
  void add_fill_planes(const Cell& cell, uint8_t signs, const Wind8* wind, const std::vector<uint32_t>& idx,
                       Qef& q) const override;
  bool inside(const I3& p) const;
  /// Median distance from a point to its 8th nearest neighbour (unit space): the scale below
  /// which the cloud says nothing about the surface.
  double spacing() const { return spacing_; }

 private:
  double spacing_ = 0;
  std::vector<ITri> prims_;  // per point: a splat (QEF) and a tiny marker (meets)
  DipoleTree tree_;
  DecisionCache cache_;
};

}  // namespace pic::detail
