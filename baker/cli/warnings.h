// The warnings nmbake prints after a bake: degenerate or suspicious input that still gave a
// defined map. One line each, naming the file; the same counts are in the --report JSON.
#pragma once

#include <string>
#include <vector>

#include "cli/pair_checks.h"
#include "cli/udim_outputs.h"
#include "pipeline/bake.h"
#include "core/errors.h"
#include "core/mesh.h"
#include "core/mesh_topology.h"

namespace nmbake {

// Share of missed samples, or of covered texels facing away, above which a warning is printed.
constexpr double kMissShareWarn = 0.01;
constexpr double kFacingAwayShareWarn = 0.2;

// What the checks before the bake found (pair_checks.h): the boxes did not match (baked with
// --allow-mismatch: misses and facing are then no fault of the distances or the winding), and the
// UVs' overlap (null: not measured; the bake's overlapping_samples then speak alone).
struct PairNote {
  bool boxes_mismatch = false;
  const UvOverlap* overlap = nullptr;
};

std::vector<std::string> bake_warnings(const BakeStats& stats, const MeshTopology& high_topology, const std::string& low_path,
                                       const std::string& high_path, const UvTilesNote& uv_tiles = {}, const PairNote& pair = {});

// What loading a mesh dropped: the file's normals (or UVs) when only some faces had them, or
// (normals) one had length 0. `path` names the file.
std::vector<std::string> load_warnings(const MeshLoadInfo& info, const std::string& path);

// --strict when there were warnings (exit 5): no output written.
struct StrictError : Error {
  explicit StrictError(const std::string& what) : Error(ExitCode::strict, what) {}
};

// Every warning of a run, in order: printed as it comes ("nmbake: warning: ..."; not with
// `print` false: --quiet --quiet or --no-warnings), kept for the report, and with `strict`
// (--strict) turned into a StrictError by check_strict().
class WarningLog {
 public:
  WarningLog(bool print, bool strict) : print_(print), strict_(strict) {}
  void add(const std::vector<std::string>& warnings);
  // Throws StrictError "--strict: N warnings, the first: ...; nothing written" under --strict.
  void check_strict() const;
  const std::vector<std::string>& all() const { return all_; }

 private:
  bool print_, strict_;
  std::vector<std::string> all_;
};

}  // namespace nmbake
