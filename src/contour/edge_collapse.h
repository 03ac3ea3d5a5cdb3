// The bookkeeping an edge collapse shares between the flat merge and the simplification: the
// triangles of a star handed from one vertex to another, and the live triangles as a mesh.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

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

/// The live triangles and the vertices they use, renumbered in the order first met;
/// `kept` (optional): the input vertex each output vertex is.
inline TriMesh live_mesh(const std::vector<Vec3>& pos, const std::vector<std::array<uint32_t, 3>>& tris,
                         const std::vector<uint8_t>& alive, std::vector<uint32_t>* kept = nullptr) {
  TriMesh out;
  if (kept) kept->clear();
  std::vector<uint32_t> remap(pos.size(), UINT32_MAX);
  for (uint32_t f = 0; f < tris.size(); ++f) {
    if (!alive[f]) continue;
    std::array<uint32_t, 3> t;
    for (int k = 0; k < 3; ++k) {
      uint32_t& r = remap[tris[f][k]];
      if (r == UINT32_MAX) {
        r = uint32_t(out.positions.size());
        out.positions.push_back(pos[tris[f][k]]);
        if (kept) kept->push_back(tris[f][k]);
      }
      t[k] = r;
    }
    out.triangles.push_back(t);
  }
  return out;
}

}  // namespace pic::detail
