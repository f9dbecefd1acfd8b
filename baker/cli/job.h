// One bake of the nmbake command: load the meshes, bake, write the outputs and the report, as
// `nmbake LOW HIGH -o MAP` does. A batch (batch.h) runs one per job, sharing what it loaded.
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <optional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/args.h"
#include "cli/progress.h"
#include "core/image.h"
#include "core/mesh.h"
#include "core/mesh_topology.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "pipeline/bake.h"

namespace nmbake {

// High-poly meshes loaded by earlier jobs of a batch, by their files and origin: a sculpt several
// jobs bake from is read once.
struct LoadedHigh {
  Mesh mesh;                           // the files merged (merge_meshes)
  std::vector<MeshLoadInfo> infos;     // each file's
  std::vector<std::size_t> triangles;  // each file's
  mutable BvhCache bvh;                // its BVH, built by the first job and reused by the next (bake.h)
  // Its topology check, made by the first job that reports it and read by the next (it depends on
  // the mesh alone).
  mutable std::optional<MeshTopology> topology;
};
struct MeshCache {
  std::map<std::string, std::shared_ptr<const LoadedHigh>> highs;
  std::size_t hits = 0;  // loads saved
};

// An image a job is about to encode (JobEnv::on_image): the map's name (map_name: "normal", "ao",
// ...) or "miss-mask" or "suspect-mask"; its UDIM tile (0 without <UDIM>); its file; the float
// image, valid during the call only; what it is written with (bits: 0 = default_bits_for(path)).
struct JobImage {
  std::string name;
  int tile = 0;
  std::string path;
  const Image* image = nullptr;
  const WriteOptions* options = nullptr;
};

// What a job shares with the command that runs it.
struct JobEnv {
  std::vector<std::string> command;  // for the report
  std::function<bool()> interrupted;
  const char** doing = nullptr;  // set to what runs, for an out-of-memory message
  Progress& progress;
  std::chrono::steady_clock::time_point start;  // of the job
  MeshCache* cache = nullptr;                   // null: load every mesh
  bool keep_progress = false;                   // the line goes on after the job (a batch)
  nlohmann::json* report = nullptr;             // when set, receives the job's report (as --report writes it)
  // The Python module's hooks (python/); the command and the batch leave them unset.
  // LOW, HIGH and --cage loaded by this instead of load_mesh (meshes given as arrays).
  std::function<Mesh(const std::string& path, const LoadOptions&, MeshLoadInfo*)> load_mesh = nullptr;
  // Each image as it is about to be encoded (the maps, the masks), on the calling thread.
  std::function<void(const JobImage&)> on_image = nullptr;
  // false: the maps go to on_image only, no file (the masks, the cage and the report are written
  // as asked).
  bool write_maps = true;
  // Each stage as it begins (share 0) and the share of it done (0-1), on the calling thread; it may
  // cancel through `interrupted`.
  std::function<void(const char* stage, double share)> on_progress = nullptr;
};

// Checks the options and outputs, then bakes; the outputs are in place when it returns. Throws
// the errors of the stages (Error and its kinds, std::bad_alloc, Cancelled).
void bake_job(const Args& a, const JobEnv& env);

}  // namespace nmbake
