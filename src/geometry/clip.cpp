// Triangles against axis-aligned boxes on the grid: which lines they may cross, which boxes
// they meet, and the QEF of their parts inside a box.
#include "geometry/clip.h"

#include <tbb/parallel_for.h>

#include <optional>

namespace pic::detail {

LineMask line_mask(const ITri& t, const I3& base, i64 step, int count) {
  LineMask m;
  for (int d = 0; d < 3; ++d) {
    for (int b = 0; b < count; ++b) {
      const i64 x = base[d] + b * step;
      m.on[d] |= unsigned(x >= t.lo[d] && x < t.hi[d]) << b;
    }
    m.spans[d] = base[d] + step >= t.lo[d] && base[d] <= t.hi[d];
  }
  return m;
}

void box_qef(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const IBox& box,
             double face, Qef& q) {
  // Weight of a plane that only touches the cell: well above the pseudo-inverse cutoff, so a
  // sharp edge lying on the cell boundary still pins the vertex (box edges on octree planes).
  constexpr double kFloor = 0.1;
  bool area_or_edge = false;
  auto add = [&](const ITri& t, double w) { q.add_plane(t.unit_normal, t.plane, w); };
  for (uint32_t k : idx) {
    const ITri& t = tris[k];
    if (is_degenerate(t) || !(t.use & kUseQef)) continue;
    const double area = clipped_area(t, box);
    if (area < 0) {
      // No area in the box under the perturbation, yet it may cross one of the box's edges
      // (a slanted face through an edge that is high on one axis and low on another): that
      // crossing is a sign change of this cell, so its plane is part of the cell's surface.
      // Only a triangle that touches the closed box (in a low face) can.
      if (area != kTouchesLowFace || !crosses_box_edge(t, box)) continue;
      area_or_edge = true;
      add(t, kFloor);
      continue;
    }
    area_or_edge = true;
    add(t, area / face + kFloor);
  }
  if (!area_or_edge) {
    // The surface only grazes the cell (e.g. a mesh vertex exactly on a cell corner): the
    // perturbation still puts a sliver inside, so use the planes that touch the closed cell.
    for (uint32_t k : idx)
      if (!is_degenerate(tris[k]) && (tris[k].use & kUseQef)) add(tris[k], kFloor);
  }
}

bool meets_box(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const IBox& box) {
  // An exact clip: the conservative list also holds triangles that pass beside the box.
  for (uint32_t k : idx)
    if ((tris[k].use & kUseMeets) && !is_degenerate(tris[k]) && clipped_area(tris[k], box) >= 0) return true;
  return false;
}

void filter_box(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const IBox& b,
                std::vector<uint32_t>& out) {
  out.clear();
  for (uint32_t k : idx)
    if (overlaps_box(tris[k], b.lo, b.hi)) out.push_back(k);
}

namespace {

/// split_box over idx[begin, end), appending to `out`.
void split_range(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, size_t begin, size_t end,
                 const IBox& b, std::array<std::vector<uint32_t>, 8>& out) {
  I3 mid;
  for (int a = 0; a < 3; ++a) mid[a] = b.lo[a] + (b.hi[a] - b.lo[a]) / 2;
  std::array<IBox, 8> boxes;
  for (int c = 0; c < 8; ++c)
    for (int a = 0; a < 3; ++a) {
      const bool high = (c >> a) & 1;
      boxes[c].lo[a] = high ? mid[a] : b.lo[a];
      boxes[c].hi[a] = high ? b.hi[a] : mid[a];
    }
  for (size_t i = begin; i < end; ++i) {
    const uint32_t k = idx[i];
    const ITri& t = tris[k];
    // Per axis, which halves (closed) the box reaches: bit 0 low, bit 1 high.
    std::array<unsigned, 3> halves{};
    for (int a = 0; a < 3; ++a)
      halves[a] = unsigned(t.lo[a] <= mid[a] && t.hi[a] >= b.lo[a]) | unsigned(t.hi[a] >= mid[a] && t.lo[a] <= b.hi[a]) << 1;
    std::optional<ChildEdgeTest> edges;  // built for the first child that needs it
    for (int c = 0; c < 8; ++c) {
      if (!((halves[0] >> (c & 1)) & 1) || !((halves[1] >> ((c >> 1) & 1)) & 1) || !((halves[2] >> ((c >> 2) & 1)) & 1))
        continue;
      const IBox& cb = boxes[c];
      // A triangle inside the child's box meets it; otherwise the exact plane test decides.
      const bool inside = t.lo[0] >= cb.lo[0] && t.lo[1] >= cb.lo[1] && t.lo[2] >= cb.lo[2] && t.hi[0] <= cb.hi[0] &&
                          t.hi[1] <= cb.hi[1] && t.hi[2] <= cb.hi[2];
      if (!inside) {
        if (!overlaps_box(t, cb.lo, cb.hi)) continue;
        if (!edges) edges.emplace(t, b);
        if (!edges->may_touch(c)) continue;
      }
      out[c].push_back(k);
    }
  }
}

}  // namespace

void split_box(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const IBox& box,
                std::array<std::vector<uint32_t>, 8>& out) {
  for (auto& o : out) o.clear();
  if (idx.size() < kParallelTris) {
    split_range(tris, idx, 0, idx.size(), box, out);
    return;
  }
  // Blocks in parallel, joined in order: the same lists as one pass.
  const size_t block = kParallelTris / 4, blocks = (idx.size() + block - 1) / block;
  std::vector<std::array<std::vector<uint32_t>, 8>> parts(blocks);
  tbb::parallel_for(size_t{0}, blocks, [&](size_t b) {
    split_range(tris, idx, b * block, std::min(idx.size(), (b + 1) * block), box, parts[b]);
  });
  for (const auto& part : parts)
    for (int c = 0; c < 8; ++c) out[c].insert(out[c].end(), part[c].begin(), part[c].end());
}

}  // namespace pic::detail
