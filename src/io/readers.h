// PIC's own readers for the simple mesh formats, and the guarded assimp path for the rest.
// Each reader takes the whole file as bytes and returns raw geometry (vertices not yet welded,
// not yet checked for NaN); mesh_io.cpp welds, checks and names the file in errors.
// Readers throw InvalidInput with a message that does not name the file.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "pic/io.h"
#include "pic/types.h"

namespace pic::detail {

struct RawGeometry {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;  ///< one per position, or empty when the file has none
  std::vector<std::array<uint32_t, 3>> triangles;  ///< indices into positions (checked)
  bool point_cloud = false;  ///< a vertex list with no face list at all (PLY, XYZ)
};

/// A view of the file's bytes.
struct Bytes {
  const uint8_t* data;
  size_t size;
  const char* chars() const { return reinterpret_cast<const char*>(data); }
};

RawGeometry read_ply(Bytes bytes);
RawGeometry read_off(Bytes bytes);
RawGeometry read_stl(Bytes bytes);
RawGeometry read_obj(Bytes bytes);
RawGeometry read_xyz(Bytes bytes);
/// glTF/GLB and every other format assimp knows; `ext` like ".glb". Assimp's internal asserts
/// become InvalidInput. \throws IoError for a format assimp does not know.
RawGeometry read_with_assimp(Bytes bytes, const std::string& ext);

/// Splits a polygon into a fan of triangles (a polygon with fewer than 3 corners adds none).
inline void add_fan(const uint32_t* corners, size_t n, std::vector<std::array<uint32_t, 3>>& out) {
  for (size_t k = 1; k + 1 < n; ++k) out.push_back({corners[0], corners[k], corners[k + 1]});
}

/// The message for a header that declares more records than the file can hold: `bytes` in
/// the file, `left` of them after the header.
std::string declares_too_many(uint64_t count, const std::string& what, size_t bytes, size_t left);

/// Entries by content (for the fuzz harnesses and tests): `ext` is the lower-case extension
/// with its dot; `name` prefixes error messages. \throws IoError, InvalidInput as read_mesh.
TriMesh read_mesh_bytes(const std::vector<uint8_t>& bytes, const std::string& ext, const std::string& name);
Geometry read_geometry_bytes(const std::vector<uint8_t>& bytes, const std::string& ext, const std::string& name);

}  // namespace pic::detail
