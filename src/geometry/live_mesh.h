// A mesh kept as triangles with a live flag each (a hull being grown, a mesh being collapsed),
// turned back into a plain mesh.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "pic/types.h"

namespace pic::detail {

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
