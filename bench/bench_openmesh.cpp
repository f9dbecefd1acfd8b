// OpenMesh's readers timed on the bench's files: whether OpenMesh would be the loading bottleneck.
// OpenMesh's property containers trip GCC 12's -Wmaybe-uninitialized inside its own headers.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include "bench_support.h"

namespace nmbake::bench {

OpenMeshRead openmesh_read(const std::string& path) {
  using TriMesh = OpenMesh::TriMesh_ArrayKernelT<>;
  OpenMeshRead r;
  const auto t0 = Clock::now();
  TriMesh mesh;
  mesh.request_vertex_normals();
  OpenMesh::IO::Options options = OpenMesh::IO::Options::VertexNormal;
  if (!OpenMesh::IO::read_mesh(mesh, path, options)) return r;
  r.seconds = since(t0);
  r.vertices = mesh.n_vertices();
  r.faces = mesh.n_faces();
  return r;
}

}  // namespace nmbake::bench
