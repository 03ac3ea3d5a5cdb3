// Mesh files. Reading goes through assimp (OBJ, STL ascii/binary, PLY, OFF, glTF/GLB, ...)
// followed by exact welding of duplicate positions, since many files repeat vertices per face.
// Writing OBJ/STL/PLY/OFF is done here (small, streaming, no side files such as .mtl);
// GLB goes through assimp's exporter (one file; .gltf would need a side .bin).
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <map>
#include <string>
#include <unordered_map>

#include "file_util.h"
#include "pic/pic.h"

namespace pic {
namespace {

std::string lower_ext(const std::filesystem::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

struct PosHash {
  size_t operator()(const Vec3& p) const {
    size_t h = 0;
    for (double x : p) {
      uint64_t b;
      x = x == 0 ? 0 : x;  // -0 and +0 weld
      std::memcpy(&b, &x, 8);
      h ^= std::hash<uint64_t>{}(b) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    }
    return h;
  }
};

void collect(const aiScene* scene, const aiNode* node, const aiMatrix4x4& parent, TriMesh& out,
             std::unordered_map<Vec3, uint32_t, PosHash>& weld) {
  const aiMatrix4x4 m = parent * node->mTransformation;
  for (unsigned k = 0; k < node->mNumMeshes; ++k) {
    const aiMesh* mesh = scene->mMeshes[node->mMeshes[k]];
    std::vector<uint32_t> ids(mesh->mNumVertices);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D p = m * mesh->mVertices[v];
      Vec3 q{p.x, p.y, p.z};
      for (double& x : q) x = x == 0 ? 0 : x;
      if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2]))
        throw InvalidInput("mesh has non-finite (NaN or inf) vertex coordinates");
      auto [it, fresh] = weld.try_emplace(q, static_cast<uint32_t>(out.positions.size()));
      if (fresh) out.positions.push_back(q);
      ids[v] = it->second;
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines carry no surface
      out.triangles.push_back({ids[face.mIndices[0]], ids[face.mIndices[1]], ids[face.mIndices[2]]});
    }
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) collect(scene, node->mChildren[c], m, out, weld);
}

// Assimp's OBJ/PLY readers accept "nan" silently or turn it into 0; check the raw text too.
void check_text_for_nan(const std::vector<uint8_t>& bytes) {
  const size_t n = std::min<size_t>(bytes.size(), size_t{1} << 30);
  for (size_t i = 0; i + 3 <= n; ++i) {
    const uint8_t first = bytes[i] | 0x20;  // ASCII lower case
    if (first != 'n' && first != 'i') continue;
    const char a = char(first), b = char(bytes[i + 1] | 0x20), c = char(bytes[i + 2] | 0x20);
    const bool word_start = i == 0 || std::isspace(bytes[i - 1]) || bytes[i - 1] == '-' || bytes[i - 1] == '+';
    if (word_start && ((a == 'n' && b == 'a' && c == 'n') || (a == 'i' && b == 'n' && c == 'f')))
      throw InvalidInput("mesh has non-finite (NaN or inf) vertex coordinates");
  }
}

}  // namespace

TriMesh read_mesh(const std::filesystem::path& path) {
  const auto bytes = detail::read_file(path);  // clear errors for missing/unreadable files
  if (bytes.empty()) throw InvalidInput(path.string() + ": file is empty");
  const std::string ext = lower_ext(path);
  const bool text = ext == ".obj" || ext == ".off" ||
                    (ext == ".ply" && bytes.size() > 20 && std::memcmp(bytes.data(), "ply", 3) == 0 &&
                     std::string(bytes.begin(), bytes.begin() + std::min<size_t>(bytes.size(), 200)).find("ascii") != std::string::npos) ||
                    (ext == ".stl" && bytes.size() > 5 && std::memcmp(bytes.data(), "solid", 5) == 0);
  if (text) check_text_for_nan(bytes);
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(),
                                                     aiProcess_Triangulate | aiProcess_SortByPType,
                                                     ext.empty() ? "" : ext.c_str() + 1);
  if (!scene || !scene->mRootNode) {
    std::string why = importer.GetErrorString();
    if (why.find("No suitable reader") != std::string::npos || why.find("unsupported") != std::string::npos)
      throw IoError(path.string() + ": unknown or unsupported mesh format '" + ext + "'");
    throw InvalidInput(path.string() + ": malformed mesh (" + why + ")");
  }
  TriMesh out;
  std::unordered_map<Vec3, uint32_t, PosHash> weld;
  collect(scene, scene->mRootNode, aiMatrix4x4(), out, weld);
  if (out.triangles.empty()) throw InvalidInput(path.string() + ": mesh has no triangles");
  return out;
}

namespace {

// Coordinates in the shortest text that reads back to the same double: a mesh checked in
// memory (self-intersections, pinched vertices) is exactly the mesh in the file; 9 digits
// moved vertices by up to 1e-8 and could fold a sliver triangle over its neighbour.
void write_point(std::FILE* f, const char* prefix, const Vec3& p) {
  char buf[96];
  char* e = buf;
  for (int k = 0; k < 3; ++k) {
    *e++ = ' ';
    e = std::to_chars(e, buf + sizeof buf, p[k]).ptr;
  }
  *e = 0;
  std::fprintf(f, "%s%s\n", prefix, buf + (prefix[0] ? 0 : 1));
}

void write_obj(const TriMesh& m, std::FILE* f) {
  std::fprintf(f, "# written by pic\n");
  for (const auto& p : m.positions) write_point(f, "v", p);
  for (const auto& t : m.triangles) std::fprintf(f, "f %u %u %u\n", t[0] + 1, t[1] + 1, t[2] + 1);
}

void write_off(const TriMesh& m, std::FILE* f) {
  std::fprintf(f, "OFF\n%zu %zu 0\n", m.positions.size(), m.triangles.size());
  for (const auto& p : m.positions) write_point(f, "", p);
  for (const auto& t : m.triangles) std::fprintf(f, "3 %u %u %u\n", t[0], t[1], t[2]);
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

void write_mesh(const TriMesh& mesh, const std::filesystem::path& path) {
  const std::string ext = lower_ext(path);
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
