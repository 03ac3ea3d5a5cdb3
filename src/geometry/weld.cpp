// Exact welding (weld.h).
#include "geometry/weld.h"

#include <cstdint>
#include <cstring>
#include <functional>
#include <unordered_map>
#include <vector>

namespace pic::detail {

namespace {

struct PosHash {
  size_t operator()(const Vec3& p) const {
    size_t h = 0;
    for (double x : p) {
      uint64_t b;
      std::memcpy(&b, &x, 8);
      h ^= std::hash<uint64_t>{}(b) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    }
    return h;
  }
};

}  // namespace

TriMesh weld(const TriMesh& mesh) {
  TriMesh out;
  std::unordered_map<Vec3, uint32_t, PosHash> ids;
  ids.reserve(mesh.positions.size());
  std::vector<uint32_t> map(mesh.positions.size());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    Vec3 p = mesh.positions[i];
    for (double& x : p) x = x == 0 ? 0 : x;
    auto [it, fresh] = ids.try_emplace(p, static_cast<uint32_t>(out.positions.size()));
    if (fresh) out.positions.push_back(p);
    map[i] = it->second;
  }
  out.triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) out.triangles.push_back({map[t[0]], map[t[1]], map[t[2]]});
  return out;
}

}  // namespace pic::detail
