// The --report JSON of a bake, and atomic text output.
#pragma once

#include <array>
#include <cstdint>
#include <ctime>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/objects.h"
#include "pipeline/bake.h"
#include "core/mesh.h"
#include "core/mesh_topology.h"

namespace nmbake {

struct RunInfo {
  std::string low_path, high_path, cage_path, output_path, miss_mask_path, suspect_mask_path;
  std::string save_cage_path;  // --save-cage: where the cage the bake used was written
  int bits = 8;
  std::string compression;  // the EXR compression written ("zip", ...), "" for other formats
  bool dither = false;
  unsigned uv_set = 0;                          // --uv-set
  MeshLoadInfo low_info, high_info, cage_info;  // high_info: every high-poly file's, summed
  std::vector<std::string> high_paths;          // every HIGH, in order
  std::vector<MeshLoadInfo> high_infos;         // each file's
  std::vector<std::size_t> high_triangles;      // each file's triangles
  MeshTopology high_topology;                   // inspect_topology(high)
  double seconds_load = 0, seconds_write = 0, seconds_total = 0;
  // The high-poly's topology check after the bake: on one thread all its time, beside the write what
  // it adds after the write; 0 when the bake found it with the normals.
  double seconds_topology = 0;
  std::uint64_t peak_memory_bytes = 0;
  unsigned threads_used = 0;
  std::vector<std::string> command;      // argv, as given
  std::string started;                   // UTC, "2026-11-25T03:04:05Z" (utc_time_text(report_time()))
  std::vector<std::string> warnings;     // every warning line, "warning: ..." (printed or not)
  std::array<double, 3> origin{};        // the point the meshes were re-centred on (Mesh::origin), 0 when not
  ObjectList low_objects, high_objects;  // every object of the low-poly and of the high-poly files
  MatchInfo match;                       // --match
  nlohmann::json udim;                   // -o with <UDIM>: udim_report (udim_outputs.h); else null
  nlohmann::json pair;                   // pair_report (pair_checks.h): the meshes' boxes and how they compare
  nlohmann::json uv_overlap;             // overlap_report (pair_checks.h): the UVs' overlap on the check's grid
};

const char* to_string(RayPolicy p);
const char* to_string(NormalSpace s);
const char* to_string(BitangentMode m);

nlohmann::json make_report(const BakeOptions& options, const BakeStats& stats, const RunInfo& run);

// The time a run started: SOURCE_DATE_EPOCH (seconds since 1970, the reproducible-builds
// convention) when set to a whole number, else now.
std::time_t report_time();

// "2026-11-25T03:04:05Z" (ISO 8601, UTC).
std::string utc_time_text(std::time_t t);

// Peak resident memory of this process so far (bytes).
std::uint64_t peak_memory_bytes();

}  // namespace nmbake
