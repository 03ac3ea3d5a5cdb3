// Shared body of the libFuzzer harnesses: read the bytes as one file type and, when the reader
// accepts them, run the next stages (sample at a small depth, contour). Refusals are the
// library's documented errors, pic::InvalidInput and pic::IoError; anything else escaping
// (another exception, an abort, a sanitizer report, a timeout) is a finding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <zlib.h>

#include "io/readers.h"
#include "pic/pic.h"

namespace pic::fuzz {

// Depth 5 with a loose error keeps one input well under a millisecond for small meshes while
// still running every stage (refinement, collapse, contouring).
inline void sample_and_contour(const TriMesh& mesh) {
  SampleOptions o;
  o.depth = 5;
  o.error = 1e-4;
  o.parallel = false;  // deterministic and cheaper under the sanitizers
  try {
    const Octree tree = sample(mesh, o);
    const TriMesh surface = unsplit_contour(tree);
    (void)surface;
  } catch (const InvalidInput&) {  // e.g. an open mesh: a legitimate refusal
  }
}

inline int run_reader(const uint8_t* data, size_t size, const std::string& ext) {
  const std::vector<uint8_t> bytes(data, data + size);
  Geometry g;
  try {
    g = detail::read_geometry_bytes(bytes, ext, "fuzz" + ext);
  } catch (const InvalidInput&) {
    return 0;
  } catch (const IoError&) {
    return 0;
  }
  if (!g.is_point_cloud()) sample_and_contour(g.mesh);
  return 0;
}

// The trailing CRC-32 is recomputed first, so mutations reach the parser instead of stopping
// at the checksum (whose check the unit tests cover).
inline int run_pic(const uint8_t* data, size_t size) {
  std::vector<uint8_t> bytes(data, data + size);
  if (bytes.size() >= 4) {
    const auto crc = uint32_t(crc32(0L, bytes.data(), uInt(bytes.size() - 4)));
    for (int k = 0; k < 4; ++k) bytes[bytes.size() - 4 + k] = uint8_t(crc >> (8 * k));
  }
  try {
    const Octree tree = deserialize(bytes);
    (void)analyze(tree);
    (void)unsplit_contour(tree);
  } catch (const IoError&) {
  } catch (const InvalidInput&) {
  }
  return 0;
}

/// One harness by name: obj, stl, ply, off, gltf (first byte picks .gltf/.glb), pic.
inline int run_harness(const std::string& kind, const uint8_t* data, size_t size) {
  if (kind == "pic") return run_pic(data, size);
  if (kind == "gltf") return size == 0 ? 0 : run_reader(data + 1, size - 1, (data[0] & 1) ? ".glb" : ".gltf");
  return run_reader(data, size, "." + kind);
}

}  // namespace pic::fuzz
