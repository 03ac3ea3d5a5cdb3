// The adaptive top-down sampler (paper section 4), generic over where the surface comes from:
// an input mesh (exact signs by crossing parity) or an operand's partial contour during CSG
// (signs from that operand's single-valued sign function).
#pragma once

#include <array>
#include <cstdint>
#include <mutex>
#include <vector>

#include "geometry/clip.h"
#include "geometry/lattice.h"
#include "geometry/memo.h"
#include "octree/cell.h"
#include "geometry/qef.h"
#include "geometry/tolerances.h"
#include "octree/cell_vertex.h"

namespace pic::detail {


/// The 19 segments that carry signs from a cell's corners to the rest of its child grid: grid
/// point `to` is reached from `from` along `axis`; the segment's other two coordinates are
/// grid steps `ci` (axis i) and `cj` (axis j), i < j. Ordered so that `from` is always known.
struct GridSegment {
  int to, from, axis, i, j, ci, cj;
};
constexpr std::array<GridSegment, 19> make_grid_segments() {
  std::array<GridSegment, 19> out{};
  int n = 0;
  for (int ones = 1; ones <= 3; ++ones)
    for (int g = 0; g < 27; ++g) {
      const int a[3] = {g % 3, (g / 3) % 3, g / 9};
      if ((a[0] == 1) + (a[1] == 1) + (a[2] == 1) != ones) continue;
      const int axis = a[0] == 1 ? 0 : (a[1] == 1 ? 1 : 2);
      const int i = axis == 0 ? 1 : 0, j = axis == 2 ? 1 : 2;
      out[n++] = {g, g - (axis == 0 ? 1 : axis == 1 ? 3 : 9), axis, i, j, a[i], a[j]};
    }
  return out;
}
constexpr std::array<GridSegment, 19> kGridSegments = make_grid_segments();


/// Integer winding numbers of the closed triangle set at a cell's corners / child grid.
using Wind8 = std::array<int32_t, 8>;
using Wind27 = std::array<int32_t, 27>;

/// Where the sampler gets triangles and corner signs.
class SurfaceSource {
 public:
  virtual ~SurfaceSource() = default;
  const std::vector<ITri>& tris() const { return *tris_; }
  /// Signs of the 3x3x3 child grid of `cell` (index a + 3b + 9c); the 8 entries at the
  /// parent's corners are already filled in (in `wind` too, for a source that tracks_winding).
  virtual void child_grid_signs(const Cell& cell, const std::vector<uint32_t>& idx,
                                std::array<bool, 27>& grid, Wind27* wind) const = 0;
  /// Whether corner signs derive from integer winding numbers the sampler carries down.
  virtual bool tracks_winding() const { return false; }
  /// Whether the surface meeting uniform `cell` can change the sign inside it, so the cell
  /// must be subdivided. By default: any triangle meeting the cell (a feature may hide there).
  virtual bool surface_matters(const Cell& cell, uint8_t signs, const Wind8* wind,
                               const std::vector<uint32_t>& idx) const;
  /// Planes for a gray cell whose sign changes the triangles do not explain (where the solid's
  /// boundary crosses a hole of the input, or a gap of a point cloud).
  virtual void add_fill_planes(const Cell&, uint8_t /*signs*/, const Wind8* /*wind*/,
                               const std::vector<uint32_t>& /*idx*/, Qef& /*q*/) const {}

 protected:
  const std::vector<ITri>* tris_ = nullptr;
};

/// Signs by crossing parity propagated from the parent's corners. Exact and path independent
/// for a closed triangle set.
class MeshSource : public SurfaceSource {
 public:
  explicit MeshSource(const std::vector<ITri>& t) { tris_ = &t; }
  void child_grid_signs(const Cell& cell, const std::vector<uint32_t>& idx,
                        std::array<bool, 27>& grid, Wind27* wind) const override;
};

/// A cell edge's crossing count (up to 4 cells of a level share an edge, and the count is the
/// edge's own: every cell's list holds each triangle crossing its edges).
struct EdgeCount {
  I3 a;
  i64 len = 0;
  int axis = 0;
  bool filled = false;
  int count = 0;
};
using EdgeCountMemo = ThreadMemo<EdgeCount, 13>;

/// Lattice points that capped cells ask to take the other sign (see sample_cell): both ends
/// of every edge of theirs that a feature thinner than the cell crosses twice.
struct ThinFeaturePoints {
  std::mutex lock;
  std::vector<std::pair<std::array<int64_t, 3>, bool>> points;  // point, inside
  /// Ends of edges whose faces turn by less (a wedge's edge, or where two thin walls meet):
  /// kept only next to a thin feature's point of the same sign.
  std::vector<std::pair<std::array<int64_t, 3>, bool>> beside;
};

struct SampleParams {
  int max_depth = 12;
  double error = kDefaultQefError;
  bool invert = false;     // write complemented signs/colours (for black - X in CSG)
  int parallel_levels = 0; // build children of cells above this level with TBB
  /// Set: one triangle set through the whole call, whose edge crossing counts may be memoized.
  EdgeCountMemo* edge_memo = nullptr;
  /// With `has_focus`: every cell whose closed box holds lattice point `focus` splits down to
  /// max_depth, so that the leaves around that point are finest cells.
  bool has_focus = false;
  std::array<int64_t, 3> focus{0, 0, 0};
  bool tips_at_corners = false;  ///< cell_vertex's tip_at_corner (Booleans' touching parts)
  /// The source is an operand's partial contour, its signs found by parity walks that may
  /// disagree with the triangles near a cell by the contour's own error: a gray cell none of
  /// whose triangles meets it has no plane to fit (the planes of triangles beside it, extended
  /// into it, can put its vertex most of a cell off the surface) and takes cell_vertex's
  /// vertex beside its minority corners (split, its child grid would disagree with its
  /// neighbours: no crossing inside explains its corners' signs).
  bool partial_contour = false;
  /// Set: capped cells whose corners miss a feature thinner than a cell record it here.
  ThinFeaturePoints* thin = nullptr;
};


/// QEF of the triangles meeting `cell` (weights: clipped area / cell face area + a floor, so
/// planes that touch the cell only along its boundary still count — box corners on octree
/// planes need them), and, at the floor weight, those that touch the cell only in a low face
/// but cross one of its edges (a slanted face or a crease through an octree line).
inline void cell_qef(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell,
                     Qef& q) {
  box_qef(tris, idx, cell.box(), cell.size() * cell.size(), q);
}





/// Samples `cell` (corner `signs`, candidate triangles `idx`) into `out` at `slot`. `wind`:
/// the corners' winding numbers, for a source that tracks_winding.
void sample_cell(const SurfaceSource& src, const SampleParams& p, const Cell& cell, uint8_t signs,
                 const std::vector<uint32_t>& idx, Builder& out, uint32_t slot, size_t& capped,
                 const Wind8* wind = nullptr);

/// The grid of `cell`'s lattice point with child-grid index g (a + 3b + 9c).
inline I3 child_grid_point(const Cell& cell, int g) {
  const int64_t h = cell.span() / 2;
  return lattice_to_grid({cell.lat[0] + (g % 3) * h, cell.lat[1] + ((g / 3) % 3) * h, cell.lat[2] + (g / 9) * h});
}

/// Corner signs of the 8 children of a cell from its child grid.
inline uint8_t child_signs(const std::array<bool, 27>& g, int c) {
  uint8_t s = 0;
  const int ox = c & 1, oy = (c >> 1) & 1, oz = (c >> 2) & 1;
  for (int k = 0; k < 8; ++k) {
    const int a = ox + (k & 1), b = oy + ((k >> 1) & 1), d = oz + ((k >> 2) & 1);
    s |= uint8_t(g[a + 3 * b + 9 * d]) << k;
  }
  return s;
}
inline int grid_index_of_corner(int k) { return (k & 1) * 2 + ((k >> 1) & 1) * 6 + ((k >> 2) & 1) * 18; }
/// Child c's corner windings from the child grid.
inline Wind8 child_wind(const Wind27& w, int c) {
  Wind8 out;
  for (int k = 0; k < 8; ++k) out[k] = w[grid_index_of_corner(k) / 2 + grid_index_of_corner(c) / 2];
  return out;
}

}  // namespace pic::detail
