#include "sample.h"

#include "topology.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <unordered_map>

namespace pic::detail {

namespace {

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

}  // namespace

void MeshSource::child_grid_signs(const Cell& cell, const std::vector<uint32_t>& idx,
                                  std::array<bool, 27>& g) const {
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
    if (is_degenerate(t)) continue;
    const double area = clipped_area(t, box);
    if (area < 0) continue;
    any = true;
    add(t, area / face + kFloor);
  }
  if (!any) {
    // The surface only grazes the cell (e.g. a mesh vertex exactly on a cell corner): the
    // perturbation still puts a sliver inside, so use the planes that touch the closed cell.
    for (uint32_t k : idx)
      if (!is_degenerate(tris[k])) add(tris[k], kFloor);
  }
}

bool meets_cell(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx, const Cell& cell) {
  // An exact clip: the conservative list also holds triangles that pass beside the cell.
  const IBox box = cell.box();
  for (uint32_t k : idx)
    if (!is_degenerate(tris[k]) && clipped_area(tris[k], box) >= 0) return true;
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
    for (int c = 0; c < 8; ++c) {
      if (!((halves[0] >> (c & 1)) & 1) || !((halves[1] >> ((c >> 1) & 1)) & 1) || !((halves[2] >> ((c >> 2) & 1)) & 1))
        continue;
      const IBox& cb = boxes[c];
      // A triangle inside the child's box meets it; otherwise the exact plane test decides.
      const bool inside = t.lo[0] >= cb.lo[0] && t.lo[1] >= cb.lo[1] && t.lo[2] >= cb.lo[2] && t.hi[0] <= cb.hi[0] &&
                          t.hi[1] <= cb.hi[1] && t.hi[2] <= cb.hi[2];
      if (inside || overlaps_box(t, cb.lo, cb.hi)) out[c].push_back(k);
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

bool has_double_crossing(const std::vector<ITri>& tris, const std::vector<uint32_t>& idx,
                         const Cell& cell, uint8_t signs) {
  const I3 lo = lattice_to_grid(cell.lat);
  const int64_t s = lattice_to_grid(cell.span());
  // Bounding boxes first: an edge needs 2 (3 with a sign change) triangles whose boxes reach
  // its line before the exact count can get there.
  std::array<int, 12> candidates{};
  for (uint32_t k : idx) {
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
    if (count_crossings(tris, idx, a, edge_axis(e), s) >= needed) return true;
  }
  return false;
}

constexpr uint8_t kAll = 0xff;

}  // namespace

void sample_cell(const SurfaceSource& src, const SampleParams& p, const Cell& cell, uint8_t signs,
                 const std::vector<uint32_t>& idx, Builder& out, uint32_t slot, size_t& capped) {
  const uint8_t written = p.invert ? uint8_t(~signs) : signs;
  const bool uniform = signs == 0 || signs == kAll;
  if (idx.empty() && uniform) {
    out.set_uniform(slot, (written & 1) != 0);
    return;
  }
  const bool at_cap = cell.level >= p.max_depth;
  if (uniform) {
    // No vertex here: only whether surface enters the cell matters, not its QEF.
    const bool meets = meets_cell(src.tris(), idx, cell);
    if (!meets || at_cap) {
      if (meets) ++capped;  // a feature thinner than the deepest cell is dropped
      out.set_uniform(slot, (written & 1) != 0);
      return;
    }
  } else if (at_cap || one_component(signs)) {
    // (Two components by the signs always split, below the cap: no QEF needed to know.)
    Qef q;
    cell_qef(src.tris(), idx, cell, q);
    const Qef::Solution sol = cell_vertex(q, cell, signs);
    const bool ok = sol.error < p.error && inside_cell(sol.position, cell) && one_component(signs) &&
                    !has_double_crossing(src.tris(), idx, cell, signs);
    if (ok || at_cap) {
      if (!ok) ++capped;
      out.set_gray(slot, cell, written, sol.position, ok ? 0 : kFlagCapped);
      return;
    }
  }
  // Subdivide: signs of the 27-point child grid, then each child with its own triangles.
  std::array<bool, 27> grid{};
  for (int k = 0; k < 8; ++k) grid[grid_index_of_corner(k)] = (signs >> k) & 1;
  src.child_grid_signs(cell, idx, grid);
  const uint32_t first = out.alloc_children();
  out.nodes[slot] = Node{first, CellKind::Internal, 0, 0, 0};
  if (cell.level < p.parallel_levels) {
    std::array<Builder, 8> subs;
    std::array<size_t, 8> caps{};
    std::array<std::vector<uint32_t>, 8> cidx;
    split_tris(src.tris(), idx, cell, cidx);
    tbb::parallel_for(0, 8, [&](int c) {
      subs[c].nodes.resize(1);
      sample_cell(src, p, cell.child(c), child_signs(grid, c), cidx[c], subs[c], 0, caps[c]);
    });
    for (int c = 0; c < 8; ++c) {
      out.splice(first + c, subs[c]);
      capped += caps[c];
    }
    return;
  }
  std::array<std::vector<uint32_t>, 8> cidx;
  split_tris(src.tris(), idx, cell, cidx);
  for (int c = 0; c < 8; ++c) sample_cell(src, p, cell.child(c), child_signs(grid, c), cidx[c], out, first + c, capped);
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

void validate_mesh(const TriMesh& mesh) {
  if (mesh.triangles.empty()) throw InvalidInput("mesh has no triangles");
  for (const Vec3& p : mesh.positions)
    for (double x : p)
      if (!std::isfinite(x)) throw InvalidInput("mesh has non-finite (NaN or inf) vertex coordinates");
  std::unordered_map<uint64_t, uint32_t> edges;
  edges.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) {
    for (uint32_t v : t)
      if (v >= mesh.positions.size()) throw InvalidInput("mesh has a triangle with an invalid vertex index");
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
                       " boundary edges (PIC sampling needs a closed, watertight mesh)");
}

}  // namespace

Octree sample(const TriMesh& mesh, const SampleOptions& options, SampleStats* stats) {
  const auto t0 = std::chrono::steady_clock::now();
  if (options.depth < 1 || options.depth > kMaxLevel)
    throw InvalidInput("depth must be between 1 and " + std::to_string(kMaxLevel));
  if (!(options.error >= 0) || !std::isfinite(options.error)) throw InvalidInput("error must be a finite number >= 0");
  validate_mesh(mesh);
  const Cube cube = options.cube ? *options.cube : bounding_cube(mesh, options.margin);
  if (!(cube.size > 0) || !std::isfinite(cube.size) || !std::isfinite(cube.origin[0]) ||
      !std::isfinite(cube.origin[1]) || !std::isfinite(cube.origin[2]))
    throw InvalidInput("root cube must have a finite origin and a positive size");

  std::vector<I3> grid(mesh.positions.size());
  for (size_t i = 0; i < grid.size(); ++i) {
    grid[i] = to_grid(world_to_unit(cube, mesh.positions[i]));
    for (int k = 0; k < 3; ++k)
      if (grid[i][k] <= 0 || grid[i][k] >= (int64_t{1} << kGridBits))
        throw InvalidInput("mesh does not fit strictly inside the root cube");
  }
  std::vector<ITri> tris;
  tris.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) tris.push_back(make_itri(grid[t[0]], grid[t[1]], grid[t[2]]));
  std::vector<uint32_t> idx(tris.size());
  for (uint32_t k = 0; k < idx.size(); ++k) idx[k] = k;

  MeshSource src(tris);
  SampleParams p;
  p.max_depth = options.depth;
  p.error = options.error;
  p.parallel_levels = options.parallel ? 2 : 0;
  Builder b;
  b.nodes.resize(1);
  size_t capped = 0;
  // Root corners are outside: the mesh lies strictly inside the cube.
  sample_cell(src, p, Cell{}, 0, std::move(idx), b, 0, capped);

  Octree tree;
  tree.cube = cube;
  tree.max_depth = options.depth;
  tree.nodes = std::move(b.nodes);
  tree.vertices = std::move(b.vertices);
  // Leaves at the depth cap may hold two components; make each hold one (see topology.h).
  if (capped > 0 && enforce_one_component(tree, nullptr).flipped > 0) repair_cracks(tree, nullptr);
  if (stats) {
    stats->triangles_in = mesh.triangles.size();
    stats->pics = tree.vertices.size();
    stats->capped = capped;
    stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return tree;
}

}  // namespace pic
