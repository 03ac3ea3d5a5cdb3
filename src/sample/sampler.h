// The adaptive top-down sampler (paper section 4), generic over where the surface comes from:
// an input mesh (exact signs by crossing parity) or an operand's partial contour during CSG
// (signs from that operand's single-valued sign function).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "geometry/lattice.h"
#include "octree/cell.h"
#include "geometry/qef.h"
#include "geometry/tolerances.h"
#include "octree/cell_vertex.h"

namespace pic::detail {

/// Which axis-parallel grid lines a triangle's bounding box lets it cross: lines at
/// base + b step (b < count) on each axis, for segments from base to base + step along it.
struct LineMask {
  std::array<unsigned, 3> on{};  // bit b of on[d]: coordinate base[d] + b step within [lo, hi)
  std::array<bool, 3> spans{};   // segments along axis d overlap the box
  /// A segment along `axis` at grid steps ci (axis i) and cj (axis j), i < j the other two.
  bool may_cross(int axis, int i, int ci, int j, int cj) const {
    return spans[axis] && ((on[i] >> ci) & 1) && ((on[j] >> cj) & 1);
  }
};
/// The line mask of `t` for `count` grid lines per axis from `base`, `step` apart.
LineMask line_mask(const ITri& t, const I3& base, i64 step, int count);

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

struct SampleParams {
  int max_depth = 12;
  double error = kDefaultQefError;
  bool invert = false;     // write complemented signs/colours (for black - X in CSG)
  int parallel_levels = 0; // build children of cells above this level with TBB
  uint32_t memo_id = 0;    // nonzero: one triangle set, whose edge crossing counts may be memoized
  /// With `has_focus`: every cell whose closed box holds lattice point `focus` splits down to
  /// max_depth, so that the leaves around that point are finest cells.
  bool has_focus = false;
  std::array<int64_t, 3> focus{0, 0, 0};
  bool tips_at_corners = false;  ///< cell_vertex's tip_at_corner (Booleans' touching parts)
};

/// A slot index of `bits` bits for a grid point (and an extra word) in a direct-mapped,
/// per-thread memo.
size_t memo_slot(const I3& p, uint64_t extra, int bits);
/// The same for a cell edge: from `a`, `len` along `axis`.
inline size_t edge_memo_slot(const I3& a, int axis, i64 len, int bits) {
  return memo_slot(a, (uint64_t(len) * 0xD6E8FEB86659FD93ull) ^ uint64_t(axis), bits);
}
/// A fresh nonzero id for a memo (SampleParams::memo_id, a decision cache).
uint32_t new_memo_id();

/// QEF of the triangles meeting `cell` (weights: clipped area / cell face area + a floor, so
/// planes that touch the cell only along its boundary still count — box corners on octree
/// planes need them), and, at the floor weight, those that touch the cell only in a low face
/// but cross one of its edges (a slanted face or a crease through an octree line).
void cell_qef(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell,
              Qef& q);
/// The same over an arbitrary box; `face_area` normalizes the weights (unit-space area).
void box_qef(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const IBox& box,
             double face_area, Qef& q);

/// Whether any triangle of `idx` meets the cell under the perturbation convention (a triangle
/// lying in one of the cell's low faces belongs to the neighbour below).
bool meets_cell(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell);

/// How far the mesh's vertices spread across the plane of its largest triangle (-1 when every
/// triangle is degenerate). Below a finest cell the mesh is flat: no solid the octree holds.
double plane_spread(const TriMesh& mesh);

/// Triangles of `idx` overlapping the closed boxes of the 8 children of `cell` (conservative;
/// the same lists as filter_tris per child, in one pass).
void split_tris(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell,
                std::array<std::vector<uint32_t>, 8>& out);
/// Triangles of `idx` overlapping the closed box of `cell` (conservative).
void filter_tris(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell,
                 std::vector<uint32_t>& out);


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
