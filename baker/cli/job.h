// One bake of the nmbake command: load the meshes, bake, write the outputs and the report, as
// `nmbake LOW HIGH -o MAP` does. A batch (batch.h) runs one per job, sharing what it loaded.
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/args.h"
#include "cli/progress.h"
#include "core/mesh.h"
#include "pipeline/bake.h"

namespace nmbake {

// High-poly meshes loaded by earlier jobs of a batch, by their files and origin: a sculpt several
// jobs bake from is read once.
struct LoadedHigh {
  Mesh mesh;                           // the files merged (merge_meshes)
  std::vector<MeshLoadInfo> infos;     // each file's
  std::vector<std::size_t> triangles;  // each file's
  mutable BvhCache bvh;                // its BVH, built by the first job and reused by the next (bake.h)
};
struct MeshCache {
  std::map<std::string, std::shared_ptr<const LoadedHigh>> highs;
  std::size_t hits = 0;  // loads saved
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
};

// Checks the options and outputs, then bakes; the outputs are in place when it returns. Throws
// the errors of the stages (Error and its kinds, std::bad_alloc, Cancelled).
void bake_job(const Args& a, const JobEnv& env);

}  // namespace nmbake
