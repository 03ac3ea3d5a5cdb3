// The adaptive top-down sampler (paper section 4), generic over where the surface comes from:
// an input mesh (exact signs by crossing parity) or an operand's partial contour during CSG
// (signs from that operand's single-valued sign function).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "geometry.h"
#include "octree_util.h"
#include "qef.h"

namespace pic::detail {

/// Where the sampler gets triangles and corner signs.
class SurfaceSource {
 public:
  virtual ~SurfaceSource() = default;
  const std::vector<ITri>& tris() const { return *tris_; }
  /// Signs of the 3x3x3 child grid of `cell` (index a + 3b + 9c); the 8 entries at the
  /// parent's corners are already filled in.
  virtual void child_grid_signs(const Cell& cell, const std::vector<uint32_t>& idx,
                                std::array<bool, 27>& grid) const = 0;

 protected:
  const std::vector<ITri>* tris_ = nullptr;
};

/// Signs by crossing parity propagated from the parent's corners. Exact and path independent
/// for a closed triangle set.
class MeshSource : public SurfaceSource {
 public:
  explicit MeshSource(const std::vector<ITri>& t) { tris_ = &t; }
  void child_grid_signs(const Cell& cell, const std::vector<uint32_t>& idx,
                        std::array<bool, 27>& grid) const override;
};

struct SampleParams {
  int max_depth = 12;
  double error = 1e-8;
  bool invert = false;     // write complemented signs/colours (for black - X in CSG)
  int parallel_levels = 0; // build children of cells above this level with TBB
};

/// QEF of the triangles meeting `cell` (weights: clipped area / cell face area + a floor, so
/// planes that touch the cell only along its boundary still count — box corners on octree
/// planes need them).
void cell_qef(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell,
              Qef& q);
/// The same over an arbitrary box; `face_area` normalizes the weights (unit-space area).
void box_qef(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const IBox& box,
             double face_area, Qef& q);

/// Whether any triangle of `idx` meets the cell under the perturbation convention (a triangle
/// lying in one of the cell's low faces belongs to the neighbour below).
bool meets_cell(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell);

/// Triangles of `idx` overlapping the closed boxes of the 8 children of `cell` (conservative;
/// the same lists as filter_tris per child, in one pass).
void split_tris(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell,
                std::array<std::vector<uint32_t>, 8>& out);
/// Triangles of `idx` overlapping the closed box of `cell` (conservative).
void filter_tris(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell,
                 std::vector<uint32_t>& out);

/// The vertex of a gray cell: QEF minimum seeded at the centre, then at the corner with the
/// smallest error when the first solution leaves the cell (paper Figure 2). With no planes at
/// all, the mass point of the sign-changing edges' midpoints.
Qef::Solution cell_vertex(const Qef& q, const Cell& cell, uint8_t signs);
bool inside_cell(const Vec3& x, const Cell& cell);

/// Samples `cell` (corner `signs`, candidate triangles `idx`) into `out` at `slot`.
void sample_cell(const SurfaceSource& src, const SampleParams& p, const Cell& cell, uint8_t signs,
                 const std::vector<uint32_t>& idx, Builder& out, uint32_t slot, size_t& capped);

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

}  // namespace pic::detail
