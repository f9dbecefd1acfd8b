// Assimp's reader timed on the bench's files (issue 20): what reading OBJ and PLY through Assimp,
// as nmbake reads glTF, FBX and DAE, would cost against nmbake's own parsers.
#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "bench_support.h"

namespace nmbake::bench {

OpenMeshRead assimp_read(const std::string& path) {
  OpenMeshRead r;
  const auto t0 = Clock::now();
  Assimp::Importer importer;
  // As io/mesh_io_assimp.cpp reads: points and lines dropped, the scene validated.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(path, aiProcess_ValidateDataStructure | aiProcess_SortByPType);
  if (!scene) return r;
  r.seconds = since(t0);
  for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
    r.vertices += scene->mMeshes[i]->mNumVertices;
    r.faces += scene->mMeshes[i]->mNumFaces;
  }
  return r;
}

}  // namespace nmbake::bench
