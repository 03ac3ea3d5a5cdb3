// glTF/GLB (and any other format assimp knows) through assimp, guarded:
// - assimp's internal asserts (ai_assert, compiled into Debian's build) call
//   Assimp::aiAssertViolation through the PLT; PIC defines that symbol, so the executable's
//   definition wins and turns an assert into an exception instead of abort(). The installed
//   headers have no setAiAssertHandler, which later assimp versions offer for the same purpose.
// - for .gltf/.glb only assimp's glTF importers stay registered: otherwise a broken glTF is
//   handed to every other importer whose signature test it passes (fuzzing found a 164-byte
//   "GLB" that the DXF importer then took, using 1.9 GB);
// - a GLB header's declared lengths are checked against the file size before assimp sees it
//   (assimp 5.2 allocates what the header declares);
// - the scene is validated (aiProcess_ValidateDataStructure) and every face index is checked
//   again while collecting;
// - the work of flattening the node tree (instances) is budgeted against the file size, and the
//   node tree's depth is bounded, so a small file cannot expand into gigabytes or recurse forever.
#include <assimp/BaseImporter.h>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cstring>
#include <stdexcept>
#include <string>

#include "io/readers.h"

namespace Assimp {
// Replaces assimp's own handler (which prints and aborts). Declared in <assimp/ai_assert.h>
// only for ASSIMP_BUILD_DEBUG builds, hence the local declaration.
void aiAssertViolation(const char* expression, const char* file, int line);
void aiAssertViolation(const char* expression, const char* file, int line) {
  throw pic::InvalidInput(std::string("malformed file (assimp internal check failed: ") + expression + " at " +
                          file + ":" + std::to_string(line) + ")");
}
}  // namespace Assimp

namespace pic::detail {
namespace {

constexpr int kMaxNodeDepth = 256;  // deeper scene graphs are refused (and cycles end here)

struct Collector {
  const aiScene* scene;
  RawGeometry& out;
  uint64_t budget;  // vertices + faces still allowed to be visited

  void node(const aiNode* node, const aiMatrix4x4& parent, int depth) {
    if (depth > kMaxNodeDepth) throw InvalidInput("the scene graph is deeper than " + std::to_string(kMaxNodeDepth));
    const aiMatrix4x4 m = parent * node->mTransformation;
    for (unsigned k = 0; k < node->mNumMeshes; ++k) {
      if (node->mMeshes[k] >= scene->mNumMeshes) throw InvalidInput("a node refers to a missing mesh");
      const aiMesh* mesh = scene->mMeshes[node->mMeshes[k]];
      const uint64_t cost = uint64_t(mesh->mNumVertices) + mesh->mNumFaces;
      if (cost > budget)
        throw InvalidInput("the scene expands to more geometry than its size allows (instancing budget)");
      budget -= cost;
      const auto base = uint32_t(out.positions.size());
      if (out.positions.size() + mesh->mNumVertices > UINT32_MAX) throw InvalidInput("more than 2^32 vertices");
      for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
        const aiVector3D p = m * mesh->mVertices[v];
        out.positions.push_back({p.x, p.y, p.z});
      }
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        const aiFace& face = mesh->mFaces[f];
        if (face.mNumIndices != 3) continue;  // points and lines carry no surface
        std::array<uint32_t, 3> t{};
        for (int c = 0; c < 3; ++c) {
          if (face.mIndices[c] >= mesh->mNumVertices) throw InvalidInput("a face index is out of range");
          t[c] = base + face.mIndices[c];
        }
        out.triangles.push_back(t);
      }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) this->node(node->mChildren[c], m, depth + 1);
  }
};

uint32_t u32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);  // GLB is little-endian, as is every machine PIC builds on
  return v;
}

// GLB: "glTF", version, total length, then (version 2) chunks of length + type + data, or
// (version 1) content length + format. Every length must fit in the file.
void check_glb_header(Bytes b) {
  if (b.size < 4 || std::memcmp(b.data, "glTF", 4) != 0) return;  // not binary glTF: assimp decides
  if (b.size < 20) throw InvalidInput("GLB: the header is cut short");
  const uint32_t version = u32(b.data + 4), length = u32(b.data + 8);
  if (version != 1 && version != 2) throw InvalidInput("GLB: unknown version " + std::to_string(version));
  if (length > b.size)
    throw InvalidInput("GLB: the header declares " + std::to_string(length) + " bytes but the file has only " +
                       std::to_string(b.size) + " bytes");
  if (version == 1) {
    if (u32(b.data + 12) > b.size - 20) throw InvalidInput("GLB: the content length exceeds the file");
    return;
  }
  for (size_t at = 12; at + 8 <= length;) {
    const uint64_t chunk = u32(b.data + at);
    if (chunk > length - at - 8) throw InvalidInput("GLB: a chunk length exceeds the file");
    at += 8 + size_t(chunk);
  }
}

bool is_gltf_importer(const aiImporterDesc* d) {
  const std::string exts = d && d->mFileExtensions ? d->mFileExtensions : "";
  return exts.find("gltf") != std::string::npos || exts.find("glb") != std::string::npos;
}

}  // namespace

RawGeometry read_with_assimp(Bytes bytes, const std::string& ext) {
  Assimp::Importer importer;
  const bool gltf = ext == ".gltf" || ext == ".glb";
  if (gltf) {
    check_glb_header(bytes);
    for (size_t i = importer.GetImporterCount(); i-- > 0;) {
      if (is_gltf_importer(importer.GetImporterInfo(i))) continue;
      Assimp::BaseImporter* other = importer.GetImporter(i);
      importer.UnregisterLoader(other);  // which does not delete it
      delete other;
    }
  }
  const aiScene* scene = importer.ReadFileFromMemory(
      bytes.data, bytes.size, aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_SortByPType,
      ext.empty() ? "" : ext.c_str() + 1);
  if (!scene || !scene->mRootNode) {
    const std::string why = importer.GetErrorString();
    if (!gltf && (why.find("No suitable reader") != std::string::npos || why.find("unsupported") != std::string::npos))
      throw IoError("unknown or unsupported mesh format '" + ext + "'");
    throw InvalidInput("malformed mesh (" + why + ")");
  }
  RawGeometry g;
  // Instancing may repeat a mesh; allow a generous multiple of what the file itself holds.
  Collector c{scene, g, 64 * uint64_t(bytes.size) + (uint64_t(1) << 20)};
  c.node(scene->mRootNode, aiMatrix4x4(), 0);
  return g;
}

}  // namespace pic::detail
