// The triangles around each edge of a mesh, as runs of one sorted list.
#pragma once

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "pic/types.h"

namespace pic::detail {

/// Each edge of each triangle with three distinct vertices as (key, triangle), the key the
/// edge's vertex pair (smaller index high), sorted: the triangles around one edge are a run.
inline std::vector<std::pair<uint64_t, uint32_t>> edge_faces(const TriMesh& m) {
  std::vector<std::pair<uint64_t, uint32_t>> edges;
  edges.reserve(3 * m.triangles.size());
  for (uint32_t f = 0; f < m.triangles.size(); ++f) {
    const auto& t = m.triangles[f];
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    for (int k = 0; k < 3; ++k) {
      const uint64_t a = t[k], b = t[(k + 1) % 3];
      edges.push_back({std::min(a, b) << 32 | std::max(a, b), f});
    }
  }
  tbb::parallel_sort(edges.begin(), edges.end());
  return edges;
}

}  // namespace pic::detail
