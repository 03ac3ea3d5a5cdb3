#include "octree/subdivide.h"

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
  return meets_box(tris(), idx, cell.box());
}

namespace {


int edge_crossings(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const I3& a, int axis,
                   i64 len, EdgeCountMemo* memo) {
  // A short list is counted faster than the memo's slot is fetched from memory.
  constexpr size_t kMemoFrom = 8;
  if (!memo || idx.size() < kMemoFrom) return count_crossings(tris, idx, a, axis, len);
  EdgeCount& e = memo->slot(edge_memo_slot(a, axis, len, EdgeCountMemo::kBits));
  if (!e.filled || e.a != a || e.axis != axis || e.len != len)
    e = {a, len, axis, true, count_crossings(tris, idx, a, axis, len)};
  return e.count;
}

bool has_double_crossing(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx,
                         const Cell& cell, uint8_t signs, EdgeCountMemo* memo) {
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
    const I3 a = lattice_to_grid(cell.corner(c0));
    if (edge_crossings(tris, idx, a, edge_axis(e), s, memo) >= needed) return true;
  }
  return false;
}

constexpr uint8_t kAll = 0xff;

/// A capped cell can hold a feature of one sign passing between two corners of the other (its
/// edge crossing the surface twice). Where the feature is thin — the edge crosses it through faces
/// that turn by more than kThinFeatureTurn (a wall, a blade, a wedge under 18 degrees; a slot, a
/// crevice) — dropping it would cut it back by h / tan(angle), a whole wall's width: both ends
/// of each such edge are asked to take the feature's sign, a row of lattice points two deep
/// along it, which every cell across holds as one component. The feature stays, up to a cell
/// thicker. A wider wedge is cut back by at most about three cells (a box's edge by less than
/// one) and is left as is, unless it lies beside a thin feature (two thin walls at an angle).
void record_thin_feature(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell,
                         uint8_t written, EdgeCountMemo* memo, ThinFeaturePoints& thin) {
  const int64_t s = lattice_to_grid(cell.span());
  std::vector<std::pair<std::array<int64_t, 3>, bool>> found, beside;
  std::vector<Vec3> normals;
  for (int e = 0; e < 12; ++e) {
    const int c0 = kEdgeCorners[e][0], c1 = kEdgeCorners[e][1], axis = edge_axis(e);
    const bool end_sign = (written >> c0) & 1;
    if (end_sign != bool((written >> c1) & 1)) continue;
    const I3 a = lattice_to_grid(cell.corner(c0));
    if (edge_crossings(tris, idx, a, axis, s, memo) < 2) continue;
    normals.clear();
    for (uint32_t k : idx)
      if (crosses(tris[k], a, axis, s)) normals.push_back(tris[k].unit_normal);
    bool thin_here = false;
    for (size_t i = 0; i < normals.size() && !thin_here; ++i)
      for (size_t j = i + 1; j < normals.size() && !thin_here; ++j)
        thin_here = dot3(normals[i], normals[j]) < -kThinFeatureTurn;
    auto& to = thin_here ? found : beside;
    to.push_back({cell.corner(c0), !end_sign});
    to.push_back({cell.corner(c1), !end_sign});
  }
  if (found.empty() && beside.empty()) return;
  const std::lock_guard<std::mutex> hold(thin.lock);
  thin.points.insert(thin.points.end(), found.begin(), found.end());
  thin.beside.insert(thin.beside.end(), beside.begin(), beside.end());
}

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
                       (!at_cap && has_double_crossing(src.tris(), idx, cell, signs, p.edge_memo));
    if (!meets || at_cap) {
      if (meets) {
        ++capped;
        if (p.thin) record_thin_feature(src.tris(), idx, cell, written, p.edge_memo, *p.thin);
      }
      out.set_uniform(slot, (written & 1) != 0);
      return;
    }
  } else if (at_cap || one_component(signs)) {
    // (Two components by the signs always split, below the cap: no QEF needed to know.)
    Qef q;
    // A partial contour's cell with a sign change but no triangle of it: no plane, and no
    // split either -- its corners' signs are the parity walks', which no crossing inside
    // explains, so a child grid walked from them would give its faces' points signs its
    // neighbours do not share. It takes the vertex beside its minority corners.
    const bool planeless = p.partial_contour && !meets_box(src.tris(), idx, cell.box());
    if (!planeless) cell_qef(src.tris(), idx, cell, q);
    src.add_fill_planes(cell, signs, wind, idx, q);
    const Qef::Solution sol = cell_vertex_sharp(q, cell, signs, p.tips_at_corners, p.error);
    const bool ok = sol.error < p.error && inside_cell(sol.position, cell) && one_component(signs) &&
                    !has_double_crossing(src.tris(), idx, cell, signs, p.edge_memo);
    if (ok || at_cap) {
      if (!ok) ++capped;
      if (!ok && p.thin) record_thin_feature(src.tris(), idx, cell, written, p.edge_memo, *p.thin);
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
    split_box(src.tris(), idx, cell.box(), cidx);
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
  split_box(src.tris(), idx, cell.box(), cidx);
  for (int c = 0; c < 8; ++c)
    sample_cell(src, p, cell.child(c), child_signs(grid, c), cidx[c], out, first + c, capped,
                wind ? &cwind[c] : nullptr);
}

}  // namespace pic::detail

