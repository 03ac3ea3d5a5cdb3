// The Thingi10K difference pair (1706459 and 1514499, already placed in one
// frame). Its meshes are not in this repository: tests find them where PIC_THINGI_DIR (or the
// workplace's shared data folder) points, and skip elsewhere.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <optional>

#include "pic/pic.h"

namespace pic::test {

struct ThingiPair {
  TriMesh a, b;
  Cube cube;  ///< bounding both: the common frame CSG needs
};

inline std::optional<ThingiPair> load_thingi_pair() {
  const char* env = std::getenv("PIC_THINGI_DIR");
  const std::filesystem::path dir = env ? env : "/work/shared/data";
  const auto pa = dir / "thingi10k-1706459.obj", pb = dir / "thingi10k-1514499.obj";
  if (!std::filesystem::exists(pa) || !std::filesystem::exists(pb)) return std::nullopt;
  ThingiPair p{read_mesh(pa), read_mesh(pb), {}};
  TriMesh both = p.a;
  both.positions.insert(both.positions.end(), p.b.positions.begin(), p.b.positions.end());
  p.cube = bounding_cube(both);
  return p;
}

}  // namespace pic::test
