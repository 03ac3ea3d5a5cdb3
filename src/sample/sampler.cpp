#include "sample/sampler.h"

#include "sample/sources.h"
#include "mesh/clean.h"
#include "signs/passes.h"
#include "geometry/vec3.h"

#include <tbb/parallel_for.h>

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
  uint32_t parity = 0;
  for (uint32_t k : idx) {
    const ITri& t = (*tris_)[k];
    const LineMask mask = line_mask(t, base, h, 3);
    for (const GridSegment& s : kGridSegments) {
      if (!mask.may_cross(s.axis, s.i, s.ci, s.j, s.cj)) continue;
      I3 start = base;
      start[s.i] += s.ci * h;
      start[s.j] += s.cj * h;
      if (crosses(t, start, s.axis, h)) parity ^= 1u << s.to;
    }
  }
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
  bool any = false;
  auto add = [&](const ITri& t, double w) { q.add_plane(t.unit_normal, t.plane, w); };
  for (uint32_t k : idx) {
    const ITri& t = tris[k];
    if (is_degenerate(t) || !(t.use & kUseQef)) continue;
    const double area = clipped_area(t, box);
    if (area < 0) continue;
    any = true;
    add(t, area / face + kFloor);
  }
  if (!any) {
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

void split_tris(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell,
                std::array<std::vector<uint32_t>, 8>& out) {
  std::array<IBox, 8> boxes;
  for (int c = 0; c < 8; ++c) {
    out[c].clear();
    boxes[c] = cell.child(c).box();
  }
  const IBox b = cell.box();
  const I3 mid = boxes[7].lo;
  for (uint32_t k : idx) {
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

bool inside_cell(const Vec3& x, const Cell& cell) {
  const Vec3 m = cell.min_unit();
  const double s = cell.size();
  const double slack = 1e-9 * s;
  for (int k = 0; k < 3; ++k)
    if (x[k] < m[k] - slack || x[k] > m[k] + s + slack) return false;
  return true;
}

Qef::Solution cell_vertex(const Qef& q, const Cell& cell, uint8_t signs) {
  const Vec3 m = cell.min_unit();
  const double s = cell.size();
  if (q.empty()) {
    // No surface to fit: a sub-cell whose corner signs disagree with the contour by less than
    // the contour's own error. Put the vertex on the sign-changing edges right next to the
    // minority corners, so the patch this makes is tiny instead of spanning the cell.
    const bool minority_inside = __builtin_popcount(signs) <= 4;
    Vec3 acc{0, 0, 0};
    int n = 0;
    for (const auto& [c0, c1] : kEdgeCorners) {
      if (!(((signs >> c0) ^ (signs >> c1)) & 1)) continue;
      const bool c0_minority = (((signs >> c0) & 1) != 0) == minority_inside;
      const double t = c0_minority ? 0.02 : 0.98;
      for (int k = 0; k < 3; ++k) acc[k] += m[k] + s * ((1 - t) * ((c0 >> k) & 1) + t * ((c1 >> k) & 1));
      ++n;
    }
    if (n == 0) return {{m[0] + s / 2, m[1] + s / 2, m[2] + s / 2}, 0, 0};
    return {{acc[0] / n, acc[1] / n, acc[2] / n}, 0, 0};
  }
  const Vec3 hi{m[0] + s, m[1] + s, m[2] + s};
  Qef::Solution sol = q.solve_in_box({m[0] + s / 2, m[1] + s / 2, m[2] + s / 2}, m, hi);
  if (inside_cell(sol.position, cell)) return sol;
  // Reseed from the corner closest to the surface (smallest QEF value).
  int best = 0;
  double best_err = 1e300;
  for (int c = 0; c < 8; ++c) {
    const Vec3 p{m[0] + (c & 1) * s, m[1] + ((c >> 1) & 1) * s, m[2] + ((c >> 2) & 1) * s};
    const double e = q.error(p);
    if (e < best_err) {
      best_err = e;
      best = c;
    }
  }
  const Vec3 p{m[0] + (best & 1) * s, m[1] + ((best >> 1) & 1) * s, m[2] + ((best >> 2) & 1) * s};
  Qef::Solution again = q.solve_in_box(p, m, hi);
  return inside_cell(again.position, cell) ? again : sol;
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
  if (idx.empty() && uniform) {
    out.set_uniform(slot, (written & 1) != 0);
    return;
  }
  const bool at_cap = cell.level >= p.max_depth;
  if (uniform) {
    // No vertex here: only whether surface enters the cell matters, not its QEF.
    const bool meets = src.surface_matters(cell, signs, wind, idx);
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
    const Qef::Solution sol = cell_vertex(q, cell, signs);
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

namespace pic {

using namespace detail;

Cube bounding_cube(const TriMesh& mesh, double margin) {
  if (mesh.positions.empty()) throw InvalidInput("mesh has no vertices");
  Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const Vec3& p : mesh.positions)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  if (!(extent > 0) || !std::isfinite(extent)) throw InvalidInput("mesh has zero or non-finite extent");
  const double side = extent * (1 + 2 * margin);
  Cube c;
  for (int k = 0; k < 3; ++k) c.origin[k] = (lo[k] + hi[k]) / 2 - side / 2;
  c.size = side;
  return c;
}

namespace {

void check_options(const SampleOptions& options) {
  if (options.depth < 1 || options.depth > kMaxLevel)
    throw InvalidInput("depth must be between 1 and " + std::to_string(kMaxLevel));
  if (!(options.error >= 0) || !std::isfinite(options.error)) throw InvalidInput("error must be a finite number >= 0");
}

void check_finite(const std::vector<Vec3>& points, const char* what) {
  for (const Vec3& p : points)
    for (double x : p)
      if (!std::isfinite(x)) throw InvalidInput(std::string(what) + " has non-finite (NaN or inf) coordinates");
}

void check_mesh(const TriMesh& mesh) {
  if (mesh.triangles.empty()) throw InvalidInput("mesh has no triangles");
  check_finite(mesh.positions, "mesh");
  for (const auto& t : mesh.triangles)
    for (uint32_t v : t)
      if (v >= mesh.positions.size()) throw InvalidInput("mesh has a triangle with an invalid vertex index");
}

/// Crossing parity needs every edge on an even number of triangles.
void check_closed(const TriMesh& mesh) {
  std::unordered_map<uint64_t, uint32_t> edges;
  edges.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    for (int e = 0; e < 3; ++e) {
      const uint64_t a = t[e], b = t[(e + 1) % 3];
      ++edges[std::min(a, b) << 32 | std::max(a, b)];
    }
  }
  size_t odd = 0;
  for (const auto& [k, n] : edges) odd += n & 1;
  if (odd > 0)
    throw InvalidInput("mesh is not closed: " + std::to_string(odd) +
                       " boundary edges (crossing parity needs a closed mesh; use --inside winding or auto)");
}

Cube checked_cube(const SampleOptions& options, const std::vector<Vec3>& points) {
  const Cube cube = options.cube ? *options.cube : bounding_cube(TriMesh{points, {}}, options.margin);
  if (!(cube.size > 0) || !std::isfinite(cube.size) || !std::isfinite(cube.origin[0]) ||
      !std::isfinite(cube.origin[1]) || !std::isfinite(cube.origin[2]))
    throw InvalidInput("root cube must have a finite origin and a positive size");
  return cube;
}

std::vector<I3> to_grid_inside(const Cube& cube, const std::vector<Vec3>& points, const char* what) {
  std::vector<I3> grid(points.size());
  for (size_t i = 0; i < grid.size(); ++i) {
    grid[i] = to_grid(world_to_unit(cube, points[i]));
    for (int k = 0; k < 3; ++k)
      if (grid[i][k] <= 0 || grid[i][k] >= (int64_t{1} << kGridBits))
        throw InvalidInput(std::string(what) + " does not fit strictly inside the root cube");
  }
  return grid;
}

SampleParams params_of(const SampleOptions& options) {
  SampleParams p;
  p.memo_id = new_memo_id();
  p.max_depth = options.depth;
  p.error = options.error;
  p.parallel_levels = options.parallel ? 2 : 0;
  return p;
}

/// Where a tree's signs may disagree between levels (islands, cracks): everywhere, or only
/// within these unit-space boxes.
struct SettleRegion {
  bool everywhere = true;
  std::vector<Box> boxes;
};

/// Per node: whether its cell meets one of the region's boxes (an ancestor of such a node
/// does too, as the passes in topology.h need of an `active` filter). Each node tests only
/// the boxes its parent met.
std::vector<uint8_t> nodes_in(const Octree& t, const SettleRegion& region) {
  std::vector<uint8_t> in(t.nodes.size(), 0);
  std::vector<std::vector<uint32_t>> met(kMaxLevel + 2);  // per level: the boxes the cell meets
  met[0].resize(region.boxes.size());
  std::iota(met[0].begin(), met[0].end(), 0u);
  auto walk = [&](auto&& self, uint32_t node, const Cell& cell) -> void {
    const Box box{cell.min_unit(), cell.max_unit()};
    const std::vector<uint32_t>& from = met[cell.level];
    std::vector<uint32_t>& here = met[cell.level + 1];
    here.clear();
    for (uint32_t i : from)
      if (overlap(region.boxes[i], box)) here.push_back(i);
    if (here.empty()) return;
    in[node] = 1;
    const Node& n = t.nodes[node];
    if (n.kind != CellKind::Internal) return;
    for (int c = 0; c < 8; ++c) self(self, n.index + c, cell.child(c));  // children fill the next list
  };
  walk(walk, 0, Cell{});
  return in;
}

/// Settles the signs of a tree whose signs may change inside uniform leaves (a winding
/// number's level set can cross a cell without touching its corners): finer neighbours can
/// then show islands and cracks on their faces. The passes visit the region only, plus every
/// leaf a flip touched.
void settle_signs(Octree& tree, const SettleRegion& region) {
  std::vector<uint8_t> in;
  if (!region.everywhere) in = nodes_in(tree, region);
  const std::function<bool(uint32_t)> active = [&](uint32_t n) { return in[n] != 0; };
  const std::function<void(uint32_t)> touched = [&](uint32_t n) { in[n] = 1; };
  const auto* a = region.everywhere ? nullptr : &active;
  const auto* t = region.everywhere ? nullptr : &touched;
  PinnedPoints pinned;
  for (int round = 0; round < 4; ++round) {
    const size_t islands = remove_islands(tree, a, t, &pinned);
    // Leaves at the depth cap may hold two components anywhere: this pass is cheap, and global.
    if (enforce_one_component(tree, nullptr, t, &pinned).flipped == 0 && (islands == 0 || round > 0)) break;
  }
  // Where |w| hovers at 1/2 (an open part's end inside another part) the level set leaves
  // specks a cell across, closed shells or voids of a few triangles: resolution noise.
  remove_specks(tree, a, [](const Speck&) { return false; }, {tree.max_depth - 1, true});
  repair_cracks(tree, a);
}

/// Runs the sampler from the root and assembles the tree.
Octree sample_tree(const SurfaceSource& src, const SampleOptions& options, const Cube& cube, uint8_t root_signs,
                   const Wind8* root_wind, size_t& capped) {
  std::vector<uint32_t> idx(src.tris().size());
  for (uint32_t k = 0; k < idx.size(); ++k) idx[k] = k;
  Builder b;
  b.nodes.resize(1);
  sample_cell(src, params_of(options), Cell{}, root_signs, idx, b, 0, capped, root_wind);
  Octree tree;
  tree.cube = cube;
  tree.max_depth = options.depth;
  tree.nodes = std::move(b.nodes);
  tree.vertices = std::move(b.vertices);
  return tree;
}

/// Each boundary loop's box (unit space), grown by `margin` plus `spread` times its diagonal.
std::vector<Box> loop_boxes(const std::vector<std::vector<uint32_t>>& loops, const std::vector<I3>& grid,
                            double margin, double spread) {
  std::vector<Box> out;
  for (const auto& loop : loops) {
    Box b{{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}};
    for (uint32_t v : loop) {
      const Vec3 p = to_unit(grid[v]);
      for (int k = 0; k < 3; ++k) b.lo[k] = std::min(b.lo[k], p[k]), b.hi[k] = std::max(b.hi[k], p[k]);
    }
    const double grow = margin + spread * norm3(sub3(b.hi, b.lo));
    for (int k = 0; k < 3; ++k) b.lo[k] -= grow, b.hi[k] += grow;
    out.push_back(b);
  }
  return out;
}

Octree sample_winding(const CleanMesh& clean, const std::vector<I3>& grid, const SampleOptions& options,
                      const Cube& cube, SampleStats& st, size_t& capped) {
  // Close the input's boundary with caps: input + caps has an exact integer winding number.
  const auto chain = boundary_chain(clean.mesh);
  const auto cones = cap_loops(chain, &st.boundary_loops);
  const std::vector<I3>& g = grid;
  std::vector<ITri> tris;
  tris.reserve(clean.mesh.triangles.size() + cones.size());
  for (const auto& t : clean.mesh.triangles) tris.push_back(make_itri(g[t[0]], g[t[1]], g[t[2]]));
  for (const auto& t : cones) {
    tris.push_back(make_itri(g[t[0]], g[t[1]], g[t[2]]));
    tris.back().use = 0;  // a cap: counts in the winding number, is no part of the surface
  }
  std::vector<std::array<Vec3, 2>> boundary;
  boundary.reserve(chain.size());
  for (const auto& [a, b] : chain) boundary.push_back({to_unit(g[a]), to_unit(g[b])});
  // Caps decide signs only in their loops' boxes (two cells of slack): a box holds its loop's
  // convex hull, outside which the signs are parity's (see WindingSource::inside).
  const auto loops = boundary_loops(chain);
  const double cell = 1.0 / double(int64_t{1} << options.depth);
  WindingSource src(std::move(tris), clean.mesh.triangles.size(), std::move(boundary),
                    loop_boxes(loops, grid, 2 * cell, 0));
  // Interior walls exist only where parts meet or overlap.
  if (clean.defects.shells > 1 || clean.defects.nonmanifold_edges > 0)
    st.interior_triangles = src.drop_interior_triangles();
  // Nothing lies outside the cube: the root's corners have winding number 0.
  const Wind8 root_wind{};
  uint8_t signs = 0;
  for (int c = 0; c < 8; ++c)
    signs |= uint8_t(src.inside(lattice_to_grid(Cell{}.corner(c)), 0)) << c;
  Octree tree = sample_tree(src, options, cube, signs, &root_wind, capped);
  // Islands and cracks come from the caps' decisions and from uniform cells whose triangles
  // showed no sign change (the sampler's only departures from crossing parity): settle there,
  // with room for the leaves around them.
  SettleRegion region{false, loop_boxes(loops, grid, 16 * cell, 0.1)};
  for (const Cell& c : src.skipped_cells()) {
    const Vec3 lo = c.min_unit();
    const double s = c.size();
    region.boxes.push_back({{lo[0] - s, lo[1] - s, lo[2] - s}, {lo[0] + 2 * s, lo[1] + 2 * s, lo[2] + 2 * s}});
  }
  settle_signs(tree, region);
  if (tree.vertices.empty())
    throw InvalidInput("mesh encloses no solid: its winding number never reaches 1/2 (an open sheet or stray triangles?)");
  return tree;
}

}  // namespace

std::string to_string(InsideMode mode) {
  switch (mode) {
    case InsideMode::Auto: return "auto";
    case InsideMode::Parity: return "parity";
    case InsideMode::Winding: return "winding";
  }
  return "auto";
}

std::optional<InsideMode> parse_inside_mode(const std::string& s) {
  if (s == "auto") return InsideMode::Auto;
  if (s == "parity") return InsideMode::Parity;
  if (s == "winding") return InsideMode::Winding;
  return std::nullopt;
}

Octree sample(const TriMesh& mesh, const SampleOptions& options, SampleStats* stats) {
  const auto t0 = std::chrono::steady_clock::now();
  check_options(options);
  check_mesh(mesh);
  const Cube cube = checked_cube(options, mesh.positions);
  const CleanMesh clean = clean_mesh(mesh);
  if (clean.mesh.triangles.empty()) throw InvalidInput("mesh has no triangles (all degenerate or cancelling)");
  InsideMode mode = options.inside;
  if (mode == InsideMode::Auto) mode = clean.defects.clean() ? InsideMode::Parity : InsideMode::Winding;
  const std::vector<I3> grid = to_grid_inside(cube, clean.mesh.positions, "mesh");

  SampleStats st;
  st.defects = clean.defects;
  st.classifier = to_string(mode);
  size_t capped = 0;
  Octree tree;
  if (mode == InsideMode::Parity) {
    check_closed(clean.mesh);
    std::vector<ITri> tris;
    tris.reserve(clean.mesh.triangles.size());
    for (const auto& t : clean.mesh.triangles) tris.push_back(make_itri(grid[t[0]], grid[t[1]], grid[t[2]]));
    // Root corners are outside: the mesh lies strictly inside the cube.
    tree = sample_tree(MeshSource(tris), options, cube, 0, nullptr, capped);
    // Leaves at the depth cap may hold two components; make each hold one (see topology.h).
    if (capped > 0 && enforce_one_component(tree, nullptr).flipped > 0) repair_cracks(tree, nullptr);
  } else {
    tree = sample_winding(clean, grid, options, cube, st, capped);
  }
  if (stats) {
    st.triangles_in = mesh.triangles.size();
    st.pics = tree.vertices.size();
    st.capped = capped;
    st.depth = options.depth;
    st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    *stats = st;
  }
  return tree;
}

Octree sample(const PointCloud& cloud, const SampleOptions& options, SampleStats* stats) {
  const auto t0 = std::chrono::steady_clock::now();
  check_options(options);
  if (cloud.positions.empty()) throw InvalidInput("point cloud has no points");
  if (cloud.normals.size() != cloud.positions.size())
    throw InvalidInput("point cloud needs one normal per point: normals are needed to tell inside from outside");
  check_finite(cloud.positions, "point cloud");
  check_finite(cloud.normals, "point cloud normals");
  size_t zero = 0;
  for (const Vec3& n : cloud.normals) zero += n[0] == 0 && n[1] == 0 && n[2] == 0;
  if (zero > 0)
    throw InvalidInput("point cloud has " + std::to_string(zero) +
                       " points with a zero normal: normals are needed to tell inside from outside");
  const Cube cube = checked_cube(options, cloud.positions);
  to_grid_inside(cube, cloud.positions, "point cloud");
  std::vector<Vec3> unit(cloud.positions.size());
  for (size_t i = 0; i < unit.size(); ++i) unit[i] = world_to_unit(cube, cloud.positions[i]);
  const PointSource src(unit, cloud.normals);
  uint8_t signs = 0;
  for (int c = 0; c < 8; ++c) signs |= uint8_t(src.inside(lattice_to_grid(Cell{}.corner(c)))) << c;
  // Cells finer than the points' spacing would only resolve the noise between neighbouring
  // tangent planes: the depth stops where a cell is about half the spacing.
  SampleOptions opt = options;
  const double spacing = src.spacing();
  if (spacing > 0) opt.depth = std::clamp(int(std::ceil(std::log2(2 / spacing))), 1, options.depth);
  size_t capped = 0;
  Octree tree = sample_tree(src, opt, cube, signs, nullptr, capped);
  settle_signs(tree, SettleRegion{});
  if (tree.vertices.empty())
    throw InvalidInput("point cloud encloses no solid: its winding number never reaches 1/2 (normals pointing inward?)");
  if (stats) {
    *stats = SampleStats{};
    stats->triangles_in = 0;
    stats->pics = tree.vertices.size();
    stats->capped = capped;
    stats->classifier = "points";
    stats->depth = opt.depth;
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return tree;
}

}  // namespace pic
