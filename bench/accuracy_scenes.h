// The accuracy bench's scenes: two analytic surfaces (a height field over one quad, a displaced
// sphere over a lat-long sphere) whose exact normal is known where each bake ray meets them, the
// shared sculpts, and scans over a cube-sphere low-poly made here. Also the mesh writers that put
// the generated scenes on disk for nmview.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/mesh.h"

namespace nmbake::bench {

// World normal of the analytic surface where the bake's ray from low-poly point `p` (object
// space) meets it.
using AnalyticNormal = std::function<glm::dvec3(const glm::dvec3& p)>;

struct AccuracyScene {
  std::string name, description, reference;  // reference: "analytic" or "64-sample bake"
  Mesh low, high;
  float front = -1, rear = -1;      // ray distances, scene units; < 0: measured by the bake
  AnalyticNormal analytic;          // empty for real scenes
  std::vector<int> sizes;           // map sides in texels
  bool quantization_runs = false;   // also measure 8- and 16-bit output
  std::string low_file, high_file;  // on disk, for nmview (written for generated meshes); empty: not on disk
};

// z = 0.05 sin(2 pi x) sin(3 pi y) on [-1,1]^2 over one quad (quick: sizes 64 and 128).
AccuracyScene height_field_scene(bool quick);
// r = 1 + 0.03 sin(41 theta) sin(41 phi) over a 48x24 lat-long sphere (quick: a coarser high-poly).
AccuracyScene displaced_sphere_scene(bool quick);
// `data`/sculpts/`name`/{low.obj,high.ply}, referenced by a 64-sample bake.
AccuracyScene sculpt_scene(const std::string& data, const std::string& name, bool quick);
// `data`/meshes/cgal/`file` over a cube-sphere projected onto it, referenced by a 64-sample bake.
AccuracyScene scan_scene(const std::string& data, const std::string& file, bool quick);

// OBJ with positions, UVs and (when present) normals. Throws OutputError when it cannot be written.
void write_scene_obj(const std::string& path, const Mesh& m);
// Binary PLY with per-vertex normals (normals must be indexed like positions). Throws OutputError.
void write_scene_ply(const std::string& path, const Mesh& m);

}  // namespace nmbake::bench
