// TEMPORARY until the readers branch lands (it replaces this file): read_geometry over assimp.
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <fstream>
#include <sstream>

#include "pic/pic.h"

namespace pic {

Geometry read_geometry(const std::filesystem::path& path) {
  Geometry g;
  if (path.extension() == ".xyz") {
    std::ifstream in(path);
    if (!in) throw IoError(path.string() + ": cannot open");
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream ls(line);
      Vec3 p, n;
      if (!(ls >> p[0] >> p[1] >> p[2])) throw InvalidInput(path.string() + ": malformed line");
      if (!(ls >> n[0] >> n[1] >> n[2])) throw InvalidInput(path.string() + ": point cloud has no normals: normals are needed");
      g.points.positions.push_back(p);
      g.points.normals.push_back(n);
    }
    return g;
  }
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path.string(), 0);
  if (scene && scene->mNumMeshes == 1 && scene->mMeshes[0]->mNumFaces == 0) {
    const aiMesh* m = scene->mMeshes[0];
    if (!m->mNormals) throw InvalidInput(path.string() + ": point cloud has no normals: normals are needed");
    for (unsigned i = 0; i < m->mNumVertices; ++i) {
      g.points.positions.push_back({m->mVertices[i].x, m->mVertices[i].y, m->mVertices[i].z});
      g.points.normals.push_back({m->mNormals[i].x, m->mNormals[i].y, m->mNormals[i].z});
    }
    return g;
  }
  g.mesh = read_mesh(path);
  return g;
}

}  // namespace pic
