#include "sample/sampler.h"

#include "geometry/vec3.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <numeric>
#include <optional>
#include <string>
#include <unordered_map>

namespace pic::detail {

// Cells with at least this many triangles share their per-triangle work between threads.
constexpr size_t kParallelTris = 4096;

size_t memo_slot(const I3& p, uint64_t extra, int bits) {
  const uint64_t h = (uint64_t(p[0]) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(p[1]) * 0xC2B2AE3D27D4EB4Full) ^
                     (uint64_t(p[2]) * 0x165667B19E3779F9ull) ^ extra;
  return (h ^ (h >> 29)) & ((size_t{1} << bits) - 1);
}

uint32_t new_memo_id() {
  static std::atomic<uint32_t> next{1};
  return next++;
}

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

void MeshSource::child_grid_signs(const Cell& cell, const std::vector<uint32_t>& idx,
                                  std::array<bool, 27>& g, Wind27*) const {
  const i64 h = lattice_to_grid(cell.span() / 2);
  const I3 base = lattice_to_grid(cell.lat);
  // One pass over the triangles (not one per segment): each triangle's box says which grid
  // lines it can cross, and only those get the exact test. Bit `to` = crossing parity of
  // segment `to`.
  auto parity_of = [&](size_t begin, size_t end) {
    uint32_t parity = 0;
    for (size_t i = begin; i < end; ++i) {
      const ITri& t = (*tris_)[idx[i]];
      const LineMask mask = line_mask(t, base, h, 3);
      for (const GridSegment& s : kGridSegments) {
        if (!mask.may_cross(s.axis, s.i, s.ci, s.j, s.cj)) continue;
        I3 start = base;
        start[s.i] += s.ci * h;
        start[s.j] += s.cj * h;
        if (crosses(t, start, s.axis, h)) parity ^= 1u << s.to;
      }
    }
    return parity;
  };
  // The top cells hold most of the triangles: there the work is shared out (parity is an
  // exclusive or, so the blocks' order does not matter).
  const uint32_t parity =
      idx.size() < kParallelTris
          ? parity_of(0, idx.size())
          : tbb::parallel_reduce(
                tbb::blocked_range<size_t>(0, idx.size(), kParallelTris / 4), uint32_t{0},
                [&](const tbb::blocked_range<size_t>& r, uint32_t p) { return p ^ parity_of(r.begin(), r.end()); },
                [](uint32_t a, uint32_t b) { return a ^ b; });
  for (const GridSegment& s : kGridSegments) g[s.to] = g[s.from] ^ ((parity >> s.to) & 1);
}

bool SurfaceSource::surface_matters(const Cell& cell, uint8_t, const Wind8*, const std::vector<uint32_t>& idx) const {
  return meets_cell(tris(), idx, cell);
}

void cell_qef(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell,
              Qef& q) {
  box_qef(tris, idx, cell.box(), cell.size() * cell.size(), q);
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

bool meets_cell(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell) {
  // An exact clip: the conservative list also holds triangles that pass beside the cell.
  const IBox box = cell.box();
  for (uint32_t k : idx)
    if ((tris[k].use & kUseMeets) && !is_degenerate(tris[k]) && clipped_area(tris[k], box) >= 0) return true;
  return false;
}

void filter_tris(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell,
                 std::vector<uint32_t>& out) {
  const IBox b = cell.box();
  out.clear();
  for (uint32_t k : idx)
    if (overlaps_box(tris[k], b.lo, b.hi)) out.push_back(k);
}

namespace {

/// split_tris over idx[begin, end), appending to `out`.
void split_range(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, size_t begin, size_t end,
                 const Cell& cell, std::array<std::vector<uint32_t>, 8>& out) {
  std::array<IBox, 8> boxes;
  for (int c = 0; c < 8; ++c) {
    boxes[c] = cell.child(c).box();
  }
  const IBox b = cell.box();
  const I3 mid = boxes[7].lo;
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

void split_tris(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell,
                std::array<std::vector<uint32_t>, 8>& out) {
  for (auto& o : out) o.clear();
  if (idx.size() < kParallelTris) {
    split_range(tris, idx, 0, idx.size(), cell, out);
    return;
  }
  // Blocks in parallel, joined in order: the same lists as one pass.
  const size_t block = kParallelTris / 4, blocks = (idx.size() + block - 1) / block;
  std::vector<std::array<std::vector<uint32_t>, 8>> parts(blocks);
  tbb::parallel_for(size_t{0}, blocks, [&](size_t b) {
    split_range(tris, idx, b * block, std::min(idx.size(), (b + 1) * block), cell, parts[b]);
  });
  for (const auto& part : parts)
    for (int c = 0; c < 8; ++c) out[c].insert(out[c].end(), part[c].begin(), part[c].end());
}

namespace {

/// Crossings of a cell edge, memoized per thread: up to 4 cells of a level share an edge, and
/// the count is the edge's own (every cell's list holds each triangle crossing its edges).
struct EdgeCount {
  I3 a;
  i64 len = 0;
  int axis = 0;
  uint32_t id = 0;  // 0: empty
  int count = 0;
};

int edge_crossings(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const I3& a, int axis,
                   i64 len, uint32_t memo_id) {
  // A short list is counted faster than the memo's slot is fetched from memory.
  constexpr size_t kMemoFrom = 8;
  if (memo_id == 0 || idx.size() < kMemoFrom) return count_crossings(tris, idx, a, axis, len);
  constexpr int kBits = 13;
  thread_local std::vector<EdgeCount> slots(size_t{1} << kBits);
  EdgeCount& e = slots[edge_memo_slot(a, axis, len, kBits)];
  if (e.id != memo_id || e.a != a || e.axis != axis || e.len != len)
    e = {a, len, axis, memo_id, count_crossings(tris, idx, a, axis, len)};
  return e.count;
}

bool has_double_crossing(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx,
                         const Cell& cell, uint8_t signs, uint32_t memo_id) {
  const I3 lo = lattice_to_grid(cell.lat);
  const int64_t s = lattice_to_grid(cell.span());
  // Bounding boxes first: an edge needs 2 (3 with a sign change) triangles whose boxes reach
  // its line before the exact count can get there.
  std::array<int, 12> candidates{};
  for (uint32_t k : idx) {
    if (!(tris[k].use & kUseCrossing)) continue;
    const LineMask mask = line_mask(tris[k], lo, s, 2);
    for (int e = 0; e < 12; ++e) {
      const int c0 = kEdgeCorners[e][0], axis = edge_axis(e);
      const int i = axis == 0 ? 1 : 0, j = axis == 2 ? 1 : 2;
      candidates[e] += mask.may_cross(axis, i, (c0 >> i) & 1, j, (c0 >> j) & 1);
    }
  }
  for (int e = 0; e < 12; ++e) {
    const int c0 = kEdgeCorners[e][0];
    const bool change = ((signs >> c0) ^ (signs >> kEdgeCorners[e][1])) & 1;
    const int needed = change ? 3 : 2;
    if (candidates[e] < needed) continue;
    const I3 a{lo[0] + (c0 & 1) * s, lo[1] + ((c0 >> 1) & 1) * s, lo[2] + ((c0 >> 2) & 1) * s};
    if (edge_crossings(tris, idx, a, edge_axis(e), s, memo_id) >= needed) return true;
  }
  return false;
}

constexpr uint8_t kAll = 0xff;

}  // namespace

void sample_cell(const SurfaceSource& src, const SampleParams& p, const Cell& cell, uint8_t signs,
                 const std::vector<uint32_t>& idx, Builder& out, uint32_t slot, size_t& capped,
                 const Wind8* wind) {
  const uint8_t written = p.invert ? uint8_t(~signs) : signs;
  const bool uniform = signs == 0 || signs == kAll;
  const bool at_cap = cell.level >= p.max_depth;
  const bool focused = !at_cap && p.has_focus && cell.holds(p.focus);
  if (focused) {
    // Split whatever the cell holds (below).
  } else if (idx.empty() && uniform) {
    out.set_uniform(slot, (written & 1) != 0);
    return;
  } else if (uniform) {
    // No vertex here: only whether surface enters the cell matters, not its QEF. A surface
    // that only touches one of the cell's edges (a prism's edge lying on an octree line,
    // the solid on the far side) has no area in the box, yet the edge's perturbed segment
    // runs through the solid: the finer lattice points on it are inside, so it must split.
    const bool meets = src.surface_matters(cell, signs, wind, idx) ||
                       (!at_cap && has_double_crossing(src.tris(), idx, cell, signs, p.memo_id));
    if (!meets || at_cap) {
      if (meets) ++capped;  // a feature thinner than the deepest cell is dropped
      out.set_uniform(slot, (written & 1) != 0);
      return;
    }
  } else if (at_cap || one_component(signs)) {
    // (Two components by the signs always split, below the cap: no QEF needed to know.)
    Qef q;
    cell_qef(src.tris(), idx, cell, q);
    src.add_fill_planes(cell, signs, wind, idx, q);
    const Qef::Solution sol = cell_vertex(q, cell, signs, p.tips_at_corners);
    const bool ok = sol.error < p.error && inside_cell(sol.position, cell) && one_component(signs) &&
                    !has_double_crossing(src.tris(), idx, cell, signs, p.memo_id);
    if (ok || at_cap) {
      if (!ok) ++capped;
      out.set_gray(slot, cell, written, sol.position, ok ? 0 : kFlagCapped);
      return;
    }
  }
  // Subdivide: signs of the 27-point child grid, then each child with its own triangles.
  std::array<bool, 27> grid{};
  for (int k = 0; k < 8; ++k) grid[grid_index_of_corner(k)] = (signs >> k) & 1;
  Wind27 wgrid{};
  if (wind)
    for (int k = 0; k < 8; ++k) wgrid[grid_index_of_corner(k)] = (*wind)[k];
  src.child_grid_signs(cell, idx, grid, wind ? &wgrid : nullptr);
  std::array<Wind8, 8> cwind{};
  if (wind)
    for (int c = 0; c < 8; ++c) cwind[c] = child_wind(wgrid, c);
  const uint32_t first = out.alloc_children();
  out.nodes[slot] = Node{first, CellKind::Internal, 0, 0, 0};
  if (cell.level < p.parallel_levels) {
    std::array<Builder, 8> subs;
    std::array<size_t, 8> caps{};
    std::array<std::vector<uint32_t>, 8> cidx;
    split_tris(src.tris(), idx, cell, cidx);
    tbb::parallel_for(0, 8, [&](int c) {
      subs[c].nodes.resize(1);
      sample_cell(src, p, cell.child(c), child_signs(grid, c), cidx[c], subs[c], 0, caps[c],
                  wind ? &cwind[c] : nullptr);
    });
    for (int c = 0; c < 8; ++c) {
      out.splice(first + c, subs[c]);
      capped += caps[c];
    }
    return;
  }
  std::array<std::vector<uint32_t>, 8> cidx;
  split_tris(src.tris(), idx, cell, cidx);
  for (int c = 0; c < 8; ++c)
    sample_cell(src, p, cell.child(c), child_signs(grid, c), cidx[c], out, first + c, capped,
                wind ? &cwind[c] : nullptr);
}

}  // namespace pic::detail

