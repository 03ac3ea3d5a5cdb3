// Sampling (paper section 4): the public entry points. A clean closed mesh runs the sampler
// kernel (octree/subdivide.h) over crossing parity; any other mesh over its winding number, a point
// cloud over the points' winding number (sources.h); both then settle their signs (signs/).
#include "octree/point_signs.h"
#include "octree/subdivide.h"

#include "sample/sources.h"
#include "mesh/clean.h"
#include "signs/invariants.h"
#include "signs/settle.h"
#include "signs/thin_features.h"
#include "geometry/bvh.h"
#include "geometry/stopwatch.h"
#include "geometry/tolerances.h"
#include "geometry/vec3.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <mutex>
#include <unordered_map>
#include <unordered_set>

namespace pic {

using namespace detail;
using Lat = std::array<int64_t, 3>;

Cube bounding_cube(const TriMesh& mesh, double margin) {
  if (mesh.positions.empty()) throw InvalidInput("mesh has no vertices");
  Vec3 lo{kHuge, kHuge, kHuge}, hi{-kHuge, -kHuge, -kHuge};
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

/// A mesh whose vertices all lie within a finest cell of one plane (a 2D drawing exported as a
/// mesh, a single sheet) has no solid the octree can hold: its thickness is below the
/// resolution everywhere.
void check_not_flat(const TriMesh& mesh, const Cube& cube, int depth) {
  const double spread = plane_spread(mesh);
  if (spread < 0) throw InvalidInput("mesh has no triangles (all degenerate or cancelling)");
  const double cell = cube.size / double(int64_t{1} << depth);
  if (spread < cell)
    throw InvalidInput("mesh encloses no solid: it is flat (all its vertices lie within " + std::to_string(spread) +
                       " of one plane, less than a finest cell; a 2D drawing?)");
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

SampleParams params_of(const SampleOptions& options, EdgeCountMemo& memo) {
  SampleParams p;
  p.edge_memo = &memo;
  p.max_depth = options.depth;
  p.error = options.error;
  p.parallel_levels = options.parallel ? 2 : 0;
  return p;
}

/// The input's triangles in a box tree, built when a leaf is first resampled (most samplings
/// resample none); safe to ask from several threads.
class LazyTriangleTree {
 public:
  explicit LazyTriangleTree(const std::vector<ITri>& tris) : tris_(tris) {}
  /// The triangles meeting `box`, in input order.
  void meeting(const IBox& box, std::vector<uint32_t>& idx) const {
    std::call_once(built_, [&] { tree_.build(tris_); });
    std::vector<uint32_t> near;
    tree_.query(tris_, box.lo, box.hi, near);
    std::sort(near.begin(), near.end());
    filter_box(tris_, near, box, idx);
  }

 private:
  const std::vector<ITri>& tris_;
  mutable std::once_flag built_;
  mutable TriangleBvh tree_;
};

/// A leaf of a sampled tree sampled again from the input, split down to the finest level
/// around lattice point p (refine_around); `winding`: the source when it carries winding numbers;
/// `near`: its triangles in a box tree (null: every triangle is tested against the leaf).
Builder resample_from_input(const SurfaceSource& src, const WindingSource* winding, const Octree& t,
                            const LeafRef& leaf, const Lat& p, double error, const LazyTriangleTree* near = nullptr) {
  std::vector<uint32_t> idx;
  if (near) {
    near->meeting(leaf.cell.box(), idx);
  } else {
    std::vector<uint32_t> all(src.tris().size());
    for (uint32_t k = 0; k < all.size(); ++k) all[k] = k;
    filter_box(src.tris(), all, leaf.cell.box(), idx);
  }
  SampleParams params;
  params.max_depth = t.max_depth;
  params.error = error;
  params.has_focus = true;
  params.focus = p;
  Wind8 wind{};
  if (winding)
    for (int c = 0; c < 8; ++c) wind[c] = winding->ray_winding(lattice_to_grid(leaf.cell.corner(c)));
  Builder sub;
  sub.nodes.resize(1);
  size_t capped = 0;
  sample_cell(src, params, leaf.cell, signs_of(t.nodes[leaf.node]), idx, sub, 0, capped, winding ? &wind : nullptr);
  return sub;
}

/// Runs the sampler from the root and assembles the tree.
Octree sample_tree(const SurfaceSource& src, const SampleOptions& options, const Cube& cube, uint8_t root_signs,
                   const Wind8* root_wind, size_t& capped, ThinFeaturePoints* thin = nullptr) {
  std::vector<uint32_t> idx(src.tris().size());
  for (uint32_t k = 0; k < idx.size(); ++k) idx[k] = k;
  Builder b;
  b.nodes.resize(1);
  EdgeCountMemo memo;
  SampleParams params = params_of(options, memo);
  params.thin = thin;
  sample_cell(src, params, Cell{}, root_signs, idx, b, 0, capped, root_wind);
  Octree tree;
  tree.cube = cube;
  tree.max_depth = options.depth;
  tree.nodes = std::move(b.nodes);
  tree.vertices = std::move(b.vertices);
  return tree;
}

/// Gives the lattice points that capped cells asked for (ThinFeaturePoints) their sign, the
/// coarser leaves around them split first. A point asked both ways (a thin wall beside a thin
/// slot) keeps its own.
void keep_thin_features(Octree& tree, ThinFeaturePoints& thin, const ResampleLeaf& resample, bool parallel) {
  if (thin.points.empty()) return;
  const std::vector<AskedSign> set =
      thin_feature_signs(thin.points, thin.beside, int64_t{1} << (kMaxLevel - tree.max_depth));
  std::vector<Lat> points(set.size());
  for (size_t i = 0; i < set.size(); ++i) points[i] = set[i].first;
  refine_all_around(tree, points, resample, parallel);
  for (const auto& [p, inside] : set) set_point_sign(tree, p, inside, nullptr);
}

Octree sample_winding(const CleanMesh& clean, const std::vector<I3>& grid, const SampleOptions& options,
                      const Cube& cube, SampleStats& st, size_t& capped) {
  const double cell = 1.0 / double(int64_t{1} << options.depth);
  WindingInput in = winding_input(clean.mesh, grid, cell, &st.boundary_loops);
  WindingSource& src = *in.source;
  // Interior walls exist only where parts meet or overlap.
  if (clean.defects.shells > 1 || clean.defects.nonmanifold_edges > 0)
    st.interior_triangles = src.drop_interior_triangles();
  // Nothing lies outside the cube: the root's corners have winding number 0.
  const Wind8 root_wind{};
  uint8_t signs = 0;
  for (int c = 0; c < 8; ++c)
    signs |= uint8_t(src.inside(lattice_to_grid(Cell{}.corner(c)), 0)) << c;
  ThinFeaturePoints thin;
  Octree tree = sample_tree(src, options, cube, signs, &root_wind, capped, &thin);
  // Islands and cracks come from the caps' decisions and from uniform cells whose triangles
  // showed no sign change (the sampler's only departures from crossing parity): settle there,
  // with room for the leaves around them.
  SettleRegion region{false, loop_boxes(in.loops, grid, 16 * cell, 0.1)};
  for (const Cell& c : src.skipped_cells()) {
    const Vec3 lo = c.min_unit();
    const double s = c.size();
    region.boxes.push_back({{lo[0] - s, lo[1] - s, lo[2] - s}, {lo[0] + 2 * s, lo[1] + 2 * s, lo[2] + 2 * s}});
  }
  const LazyTriangleTree near(src.tris());
  const ResampleLeaf from_input = [&](const LeafRef& l, const Lat& p) {
    return resample_from_input(src, &src, tree, l, p, options.error, &near);
  };
  keep_thin_features(tree, thin, from_input, options.parallel);
  // Their flips make islands and components like the caps': settle around them too.
  constexpr double kUnit = 1.0 / double(int64_t{1} << kMaxLevel);
  for (const auto& [p, inside] : thin.points) {
    const Vec3 u{double(p[0]) * kUnit, double(p[1]) * kUnit, double(p[2]) * kUnit};
    region.boxes.push_back({{u[0] - 2 * cell, u[1] - 2 * cell, u[2] - 2 * cell}, {u[0] + 2 * cell, u[1] + 2 * cell, u[2] + 2 * cell}});
  }
  settle_sampled(tree, region, &from_input);
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
  const auto t0 = Clock::now();
  check_options(options);
  check_mesh(mesh);
  const Cube cube = checked_cube(options, mesh.positions);
  check_not_flat(mesh, cube, options.depth);
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
    // Every edge on exactly two triangles is closed already (parity chosen by Auto).
    if (clean.defects.boundary_edges > 0 || clean.defects.nonmanifold_edges > 0) check_closed(clean.mesh);
    const std::vector<ITri> tris = grid_triangles(clean.mesh.triangles, grid);
    // Root corners are outside: the mesh lies strictly inside the cube.
    const MeshSource src(tris);
    ThinFeaturePoints thin;
    tree = sample_tree(src, options, cube, 0, nullptr, capped, &thin);
    // Leaves at the depth cap may hold two components; make each hold one, splitting coarser
    // leaves at the corners that change sign first.
    const LazyTriangleTree near(tris);
    const ResampleLeaf from_input = [&](const LeafRef& l, const Lat& p) {
      return resample_from_input(src, nullptr, tree, l, p, options.error, &near);
    };
    keep_thin_features(tree, thin, from_input, options.parallel);
    const std::function<void(const Lat&)> refine = [&](const Lat& p) {
      refine_around(tree, p, from_input, [](uint32_t) {});
    };
    if (capped > 0) {
      const size_t flipped = enforce_one_component(tree, nullptr, {.refine = &refine}).flipped;
      if (flipped + erode_around_capped(tree, nullptr) > 0) repair_cracks(tree, nullptr);
    }
  } else {
    tree = sample_winding(clean, grid, options, cube, st, capped);
  }
  if (stats) {
    st.triangles_in = mesh.triangles.size();
    st.pics = tree.vertices.size();
    st.capped = capped;
    st.depth = options.depth;
    st.max_depth = options.depth;
    st.error = options.error;
    st.seconds = since(t0);
    *stats = st;
  }
  PIC_CHECK_OCTREE(tree, "sampling a mesh");
  return tree;
}

Octree sample(const PointCloud& cloud, const SampleOptions& options, SampleStats* stats) {
  const auto t0 = Clock::now();
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
  const ResampleLeaf from_input = [&](const LeafRef& l, const Lat& p) {
    return resample_from_input(src, nullptr, tree, l, p, opt.error);
  };
  settle_sampled(tree, SettleRegion{}, &from_input);
  if (tree.vertices.empty())
    throw InvalidInput("point cloud encloses no solid: its winding number never reaches 1/2 (normals pointing inward?)");
  if (stats) {
    *stats = SampleStats{};
    stats->triangles_in = 0;
    stats->points_in = cloud.positions.size();
    stats->max_depth = options.depth;
    stats->error = options.error;
    stats->pics = tree.vertices.size();
    stats->capped = capped;
    stats->classifier = "points";
    stats->depth = opt.depth;
    stats->seconds = since(t0);
  }
  PIC_CHECK_OCTREE(tree, "sampling a point cloud");
  return tree;
}

}  // namespace pic
