// The topology count with the spots it found, for the passes that mend them.
#pragma once

#include <cstdint>
#include <vector>

#include "pic/measure.h"
#include "pic/types.h"

namespace pic::detail {

/// analyze_topology, also flagging in `off_fan` (one byte per vertex, when given) every vertex
/// whose triangles do not make one closed fan with each edge used once each way: the vertices
/// of non-manifold, boundary or inconsistent edges, pinched vertices, degenerate triangles'
/// vertices (and, to stay cheap, vertices with more than 32 triangles are checked the long way
/// and flagged whatever it finds). Every other vertex is 2-manifold as it stands.
MeshTopology analyze_topology(const TriMesh& mesh, std::vector<uint8_t>* off_fan);

}  // namespace pic::detail
