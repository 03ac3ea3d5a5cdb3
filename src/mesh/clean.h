// Making a triangle soup fit for the winding-number classifier: exact welding, removal of
// degenerate and duplicated triangles, consistent orientation of each edge-connected part,
// and the input's boundary as a closed chain of directed edges.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "geometry/weld.h"
#include "pic/sample.h"
#include "pic/types.h"

namespace pic::detail {

struct CleanMesh {
  TriMesh mesh;         ///< welded; no degenerate or duplicated triangles; parts oriented
  MeshDefects defects;  ///< of the welded input
  size_t flipped = 0;   ///< triangles turned round to agree with their part's majority
};
/// Welds, drops degenerate triangles and repeats of a triangle (two opposite copies of one
/// triangle bound nothing: both go), and orients each part connected through two-triangle
/// edges the way most of its area already faces. A clean mesh comes back unchanged (same
/// triangles in the same order).
CleanMesh clean_mesh(const TriMesh& mesh);

/// The boundary of the mesh as a 1-chain: each edge whose triangles do not cancel (net count
/// of a->b minus b->a), repeated by its multiplicity, directed as the triangles traverse it.
/// It is a cycle; the components of its support are closed curves.
std::vector<std::array<uint32_t, 2>> boundary_chain(const TriMesh& mesh);

/// The chain split into closed loops (vertex sequences).
std::vector<std::vector<uint32_t>> boundary_loops(const std::vector<std::array<uint32_t, 2>>& chain);

/// Triangles on the chain's own vertices that close it into a cycle (input + caps has no
/// boundary), built as fans over runs of the loops, level by level. `count`: number of loops.
std::vector<std::array<uint32_t, 3>> cap_loops(const std::vector<std::array<uint32_t, 2>>& chain,
                                               size_t* count = nullptr);

/// How far the mesh's vertices spread across the plane of its largest triangle (-1 when every
/// triangle is degenerate). Below a finest cell the mesh is flat: no solid the octree holds.
double plane_spread(const TriMesh& mesh);

}  // namespace pic::detail
