// Mesh files. Reading: PIC's own readers for PLY, OFF, STL, OBJ and XYZ point clouds (src/io/,
// small grammars whose every count is checked against the file size), assimp only for glTF/GLB
// and other formats (guarded, src/io/assimp.cpp); see docs/reliability.md for why. Then exact
// welding of duplicate positions, since many files repeat vertices per face.
// Writing OBJ/STL/PLY/OFF is done here (small, streaming, no side files such as .mtl);
// GLB goes through assimp's exporter (one file; .gltf would need a side .bin).
#include <assimp/Exporter.hpp>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <unordered_map>

#include "io/file_util.h"
#include "mesh/clean.h"
#include "io/readers.h"
#include "pic/io.h"
#include "pic/measure.h"
#include "pic/types.h"

namespace pic {
namespace {

bool finite(const Vec3& p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }

// Exact welding of equal positions (-0 == +0, mesh_repair's weld); refuses NaN and inf.
TriMesh weld(const detail::RawGeometry& g) {
  for (const Vec3& p : g.positions)
    if (!finite(p))
      throw InvalidInput("mesh has non-finite (NaN or inf) vertex coordinates");
  return detail::weld(TriMesh{g.positions, g.triangles});
}

detail::RawGeometry read_raw(const std::vector<uint8_t>& bytes, const std::string& ext, const std::string& name) {
  if (bytes.empty()) throw InvalidInput(name + ": file is empty");
  const detail::Bytes b{bytes.data(), bytes.size()};
  try {
    if (ext == ".ply") return detail::read_ply(b);
    if (ext == ".off") return detail::read_off(b);
    if (ext == ".stl") return detail::read_stl(b);
    if (ext == ".obj") return detail::read_obj(b);
    if (ext == ".xyz") return detail::read_xyz(b);
    return detail::read_with_assimp(b, ext);
  } catch (const InvalidInput& e) {
    throw InvalidInput(name + ": " + e.what());
  } catch (const IoError& e) {
    throw IoError(name + ": " + e.what());
  } catch (const std::bad_alloc&) {
    throw InvalidInput(name + ": out of memory while reading (file too large for this machine)");
  }
}

TriMesh to_mesh(const detail::RawGeometry& g, const std::string& name) {
  try {
    TriMesh m = weld(g);
    if (m.triangles.empty()) {
      if (g.point_cloud && !g.positions.empty())
        throw InvalidInput("has no triangles: it is a point cloud of " + std::to_string(g.positions.size()) +
                           " points, not a mesh");
      throw InvalidInput("mesh has no triangles");
    }
    return m;
  } catch (const InvalidInput& e) {
    throw InvalidInput(name + ": " + e.what());
  }
}

}  // namespace

namespace detail {

std::string declares_too_many(uint64_t count, const std::string& what, size_t bytes, size_t left) {
  return "declares " + std::to_string(count) + " " + what + " but the file has only " + std::to_string(bytes) +
         " bytes (" + std::to_string(left) + " after the header)";
}

TriMesh read_mesh_bytes(const std::vector<uint8_t>& bytes, const std::string& ext, const std::string& name) {
  if (ext == ".xyz")
    throw IoError(name + ": unknown or unsupported mesh format '.xyz' (a point cloud format: it has no triangles)");
  return to_mesh(read_raw(bytes, ext, name), name);
}

Geometry read_geometry_bytes(const std::vector<uint8_t>& bytes, const std::string& ext, const std::string& name) {
  const RawGeometry g = read_raw(bytes, ext, name);
  Geometry out;
  if (!g.point_cloud || g.positions.empty()) {
    out.mesh = to_mesh(g, name);
    return out;
  }
  if (g.normals.size() != g.positions.size())
    throw InvalidInput(name + ": point cloud has no normals (nx ny nz): normals are needed to tell inside from outside");
  for (size_t i = 0; i < g.positions.size(); ++i)
    if (!finite(g.positions[i]) || !finite(g.normals[i]))
      throw InvalidInput(name + ": point cloud has non-finite (NaN or inf) coordinates or normals");
  out.points.positions = g.positions;
  out.points.normals = g.normals;
  return out;
}

}  // namespace detail

TriMesh read_mesh(const std::filesystem::path& path) {
  return detail::read_mesh_bytes(detail::read_file(path), detail::lower_extension(path), path.string());
}

Geometry read_geometry(const std::filesystem::path& path) {
  return detail::read_geometry_bytes(detail::read_file(path), detail::lower_extension(path), path.string());
}

namespace {

// One line: `prefix` and three numbers, through to_chars and fwrite (printf cost as much as the
// contour on a mesh of a few hundred thousand triangles). Coordinates come out in the shortest
// text that reads back to the same double: a mesh checked in memory (self-intersections,
// pinched vertices) is exactly the mesh in the file; 9 digits moved vertices by up to 1e-8 and
// could fold a sliver triangle over its neighbour.
template <class T>
void write_line(std::FILE* f, const char* prefix, const std::array<T, 3>& values) {
  char buf[96];
  char* e = buf;
  for (const char* c = prefix; *c; ++c) *e++ = *c;
  for (int k = 0; k < 3; ++k) {
    if (k > 0 || prefix[0]) *e++ = ' ';
    e = std::to_chars(e, buf + sizeof buf - 1, values[k]).ptr;
  }
  *e++ = '\n';
  std::fwrite(buf, 1, size_t(e - buf), f);
}

void write_obj(const TriMesh& m, std::FILE* f) {
  std::fprintf(f, "# written by pic\n");
  for (const auto& p : m.positions) write_line(f, "v", p);
  for (const auto& t : m.triangles) write_line(f, "f", std::array{t[0] + 1, t[1] + 1, t[2] + 1});
}

void write_off(const TriMesh& m, std::FILE* f) {
  std::fprintf(f, "OFF\n%zu %zu 0\n", m.positions.size(), m.triangles.size());
  for (const auto& p : m.positions) write_line(f, "", p);
  for (const auto& t : m.triangles) write_line(f, "3", t);
}

void write_stl(const TriMesh& m, std::FILE* f) {
  char header[80] = "binary STL written by pic";
  std::fwrite(header, 1, 80, f);
  const auto n = static_cast<uint32_t>(m.triangles.size());
  std::fwrite(&n, 4, 1, f);
  for (const auto& t : m.triangles) {
    const Vec3 &a = m.positions[t[0]], &b = m.positions[t[1]], &c = m.positions[t[2]];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double nn[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    const double l = std::sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
    float rec[12];
    for (int k = 0; k < 3; ++k) rec[k] = l > 0 ? float(nn[k] / l) : 0.f;
    for (int k = 0; k < 3; ++k) {
      rec[3 + k] = float(a[k]);
      rec[6 + k] = float(b[k]);
      rec[9 + k] = float(c[k]);
    }
    std::fwrite(rec, 4, 12, f);
    const uint16_t attr = 0;
    std::fwrite(&attr, 2, 1, f);
  }
}

void write_ply(const TriMesh& m, std::FILE* f) {
  std::fprintf(f,
               "ply\nformat binary_little_endian 1.0\ncomment written by pic\nelement vertex %zu\n"
               "property double x\nproperty double y\nproperty double z\nelement face %zu\n"
               "property list uchar uint vertex_indices\nend_header\n",
               m.positions.size(), m.triangles.size());
  for (const auto& p : m.positions) std::fwrite(p.data(), 8, 3, f);
  for (const auto& t : m.triangles) {
    const uint8_t three = 3;
    std::fwrite(&three, 1, 1, f);
    std::fwrite(t.data(), 4, 3, f);
  }
}

void write_with_assimp(const TriMesh& m, const std::filesystem::path& tmp, const char* format_id) {
  aiScene scene;
  scene.mRootNode = new aiNode();
  scene.mMaterials = new aiMaterial*[1]{new aiMaterial()};
  scene.mNumMaterials = 1;
  scene.mMeshes = new aiMesh*[1]{new aiMesh()};
  scene.mNumMeshes = 1;
  scene.mRootNode->mMeshes = new unsigned[1]{0};
  scene.mRootNode->mNumMeshes = 1;
  aiMesh* mesh = scene.mMeshes[0];
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh->mNumVertices = static_cast<unsigned>(m.positions.size());
  mesh->mVertices = new aiVector3D[m.positions.size()];
  for (size_t i = 0; i < m.positions.size(); ++i)
    mesh->mVertices[i] = aiVector3D(float(m.positions[i][0]), float(m.positions[i][1]), float(m.positions[i][2]));
  mesh->mNumFaces = static_cast<unsigned>(m.triangles.size());
  mesh->mFaces = new aiFace[m.triangles.size()];
  for (size_t i = 0; i < m.triangles.size(); ++i) {
    aiFace& face = mesh->mFaces[i];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3]{m.triangles[i][0], m.triangles[i][1], m.triangles[i][2]};
  }
  Assimp::Exporter exporter;
  if (exporter.Export(&scene, format_id, tmp.string()) != AI_SUCCESS)
    throw IoError("cannot write " + tmp.string() + ": " + exporter.GetErrorString());
}

}  // namespace

bool stores_float32(const std::filesystem::path& path) {
  const std::string ext = detail::lower_extension(path);
  return ext == ".stl" || ext == ".glb";
}

void write_mesh(const TriMesh& input, const std::filesystem::path& path) {
  const std::string ext = detail::lower_extension(path);
  // STL and GLB hold floats: the rounding that keeps the solid free of crossings, not a cast
  // (a mesh rounded already is written as it is, without a copy).
  const bool round = stores_float32(path) && !holds_floats(input);
  const TriMesh rounded = round ? round_to_float32(input) : TriMesh{};
  const TriMesh& mesh = round ? rounded : input;
  using Writer = void (*)(const TriMesh&, std::FILE*);
  static const std::map<std::string, Writer> plain = {
      {".obj", write_obj}, {".off", write_off}, {".stl", write_stl}, {".ply", write_ply}};
  const auto it = plain.find(ext);
  if (it == plain.end() && ext != ".glb")
    throw IoError("cannot write " + path.string() + ": unknown mesh format '" + ext +
                  "' (use .obj, .stl, .ply, .off or .glb)");
  detail::write_atomically(path, [&](const std::filesystem::path& tmp) {
    if (it == plain.end()) {
      write_with_assimp(mesh, tmp, "glb2");
      return;
    }
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw IoError("cannot write " + path.string() + ": " + std::strerror(errno));
    it->second(mesh, f);
    const bool ok = std::ferror(f) == 0;
    if (std::fclose(f) != 0 || !ok) throw IoError("cannot write " + path.string() + ": write failed");
  });
}

}  // namespace pic
