// The bookkeeping an edge collapse shares between the flat merge and the simplification: the
// triangles of a star handed from one vertex to another (live_mesh.h turns the live ones back
// into a mesh).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "geometry/live_mesh.h"
#include "pic/types.h"

namespace pic::detail {

/// u merged into v: u's triangles on the edge uv die (and leave their corners' lists), the
/// others take v for u and join v's list; u's list empties.
inline void hand_star_over(uint32_t u, uint32_t v, std::vector<std::array<uint32_t, 3>>& tris,
                           std::vector<std::vector<uint32_t>>& faces, std::vector<uint8_t>& alive) {
  for (uint32_t f : faces[u]) {
    auto& t = tris[f];
    if (t[0] == v || t[1] == v || t[2] == v) {
      alive[f] = 0;
      for (uint32_t w : t)
        if (w != u) std::erase(faces[w], f);
      continue;
    }
    for (uint32_t& w : t)
      if (w == u) w = v;
    faces[v].push_back(f);
  }
  faces[u].clear();
}

}  // namespace pic::detail
