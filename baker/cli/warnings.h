// The warnings nmbake prints after a bake: degenerate or suspicious input that still gave a
// defined map. One line each, naming the file; the same counts are in the --report JSON.
#pragma once

#include <string>
#include <vector>

#include "pipeline/bake.h"
#include "core/mesh_topology.h"

namespace nmbake {

// Share of missed samples, or of covered texels facing away, above which a warning is printed.
constexpr double kMissShareWarn = 0.01;
constexpr double kFacingAwayShareWarn = 0.2;

std::vector<std::string> bake_warnings(const BakeStats& stats, const MeshTopology& high_topology, const std::string& low_path,
                                       const std::string& high_path);

}  // namespace nmbake
