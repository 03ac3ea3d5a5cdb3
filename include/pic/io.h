// PIC — files: the .pic format, meshes and point clouds (atomic writes).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "pic/octree.h"

namespace pic {

/// @name The .pic file (docs/pic-format.md).
///@{
/// Writes atomically (temp file + rename). \throws IoError.
void save(const Octree& tree, const std::filesystem::path& path);
/// \throws IoError for a missing, truncated, corrupted or foreign file.
Octree load(const std::filesystem::path& path);
std::vector<uint8_t> serialize(const Octree& tree);
Octree deserialize(const std::vector<uint8_t>& bytes);
///@}

/// What a geometry file holds: a triangle mesh, or (PLY with vertices and no faces, or .xyz
/// text "x y z nx ny nz" per line) an oriented point cloud. Exactly one of the two is filled.
struct Geometry {
  TriMesh mesh;
  PointCloud points;
  bool is_point_cloud() const { return mesh.triangles.empty() && !points.positions.empty(); }
};
/// Reads a mesh file or a point cloud file. A point cloud without normals is InvalidInput
/// ("normals are needed"). \throws IoError, InvalidInput as read_mesh.
Geometry read_geometry(const std::filesystem::path& path);

/// @name Mesh files: OBJ, STL, PLY, OFF, glTF/GLB (assimp), duplicate vertices welded.
///@{
/// \throws IoError (missing/unreadable/unknown format) or InvalidInput (empty, non-finite).
TriMesh read_mesh(const std::filesystem::path& path);
/// Format from the extension; atomic write. STL and GLB store 32-bit floats: the positions are
/// rounded by round_to_float32 (which keeps a valid solid valid), not cast. \throws IoError.
void write_mesh(const TriMesh& mesh, const std::filesystem::path& path);
/// Whether the format of `path` (by its extension) stores 32-bit float coordinates (STL,
/// GLB): round with round_to_float32 first to check what the file will hold (write_mesh then
/// writes it unchanged).
bool stores_float32(const std::filesystem::path& path);
///@}

/// Writes a text file atomically (temp file + rename). \throws IoError.
void write_text(const std::filesystem::path& path, const std::string& text);

}  // namespace pic
