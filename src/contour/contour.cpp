// The contour stage: each gray leaf's vertex placed, the dual polygons collected
// (contour/dual_walk.cpp), triangulated (contour/triangulate.cpp) and the sheets split apart
// where the surface touches itself (contour/split_sheets.cpp).
#include <tbb/parallel_for.h>

#include <algorithm>

#include "octree/dual_walk.h"
#include "contour/triangulate.h"
#include "octree/cell.h"
#include "pic/contour.h"

namespace pic {

TriMesh contour(const Octree& tree, const ContourOptions& options, ContourStats* stats) {
  using namespace detail;
  const bool split = tree.nodes[0].kind == CellKind::Internal;
  const Triangulation how = options.fan_all             ? Triangulation::kFanAll
                            : options.intersection_free ? Triangulation::kConstruct
                                                        : Triangulation::kPlain;
  // Each gray leaf's vertex in input coordinates, once (the walk meets it up to 12 times).
  // The construction needs each vertex strictly inside its cell, and its edge and face points
  // strictly inside their edge or face: a vertex on its cell's border (a QEF minimum clamped to
  // the cell, a box corner on a lattice point) goes 2^-24 of the root cube inside (6e-8 of the
  // model's size, far below any cell), and so do edge and face points at a border.
  std::vector<Vec3> pos(tree.vertices.size());
  std::vector<VertexCell> cell_of(tree.vertices.size());
  const double inset = how == Triangulation::kPlain ? 0.0 : tree.cube.size * 0x1p-24;
  auto place = [&](uint32_t node, const Cell& cell) {
    const Node& n = tree.nodes[node];
    if (n.kind != CellKind::Gray) return;
    const VertexCell c{unit_to_world(tree.cube, vertex_unit(cell, {0.5f, 0.5f, 0.5f})), 0.5 * cell.size() * tree.cube.size};
    Vec3 p = unit_to_world(tree.cube, vertex_unit(cell, tree.vertices[n.index]));
    if (inset > 0)
      for (int a = 0; a < 3; ++a) p[a] = std::clamp(p[a], c.center[a] - c.half + inset, c.center[a] + c.half - inset);
    pos[n.index] = p;
    cell_of[n.index] = c;
  };
  if (split) {
    tbb::parallel_for(0, 8, [&](int c) { visit_leaves(tree, tree.nodes[0].index + c, Cell{}.child(c), place); });
  } else {
    visit_leaves(tree, 0, Cell{}, place);
  }
  std::vector<MeshPolygon> polys = dual_polygons(tree);
  // Vertices numbered in the tree's vertex order, keeping those the polygons use.
  std::vector<uint32_t> remap(tree.vertices.size(), 0);
  for (const auto& p : polys)
    for (int k = 0; k < p.count; ++k) remap[p.v[k]] = 1;
  TriMesh out;
  uint32_t used = 0;
  for (uint32_t& r : remap) used += r;
  out.positions.reserve(used);
  std::vector<VertexCell> cells;
  cells.reserve(used);
  for (size_t i = 0; i < remap.size(); ++i)
    if (remap[i]) {
      remap[i] = static_cast<uint32_t>(out.positions.size());
      out.positions.push_back(pos[i]);
      cells.push_back(cell_of[i]);
    }
  for (auto& p : polys)
    for (int k = 0; k < p.count; ++k) p.v[k] = remap[p.v[k]];
  TriangulationStats ts;
  out.triangles = triangulate(out.positions, cells, polys, how, inset, options.surface, &ts);
  if (stats) {
    stats->fans = ts.fans;
    stats->other_diagonal = ts.other_diagonal;
    stats->face_points = ts.face_points;
    stats->face_fans = ts.face_fans;
  }
  const size_t split_vertices = options.split_sheets ? split_nonmanifold(out) : 0;
  if (stats) stats->split_vertices = split_vertices;
  if (options.simplify > 0) {
    const size_t removed = simplify(out, options.simplify * tree.cube.size / double(int64_t{1} << tree.max_depth));
    if (stats) stats->simplified_away = removed;
  }
  return out;
}

}  // namespace pic
