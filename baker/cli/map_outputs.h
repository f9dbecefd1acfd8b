// The texture set on the command line: --maps LIST, and -o with <MAP> (replaced by each map's name,
// composing with <UDIM>): `-o crate_<MAP>.png --maps normal,ao` writes crate_normal.png and
// crate_ao.png.
#pragma once

#include <string>
#include <vector>

#include "core/maps.h"

namespace nmbake {

constexpr const char* kMapToken = "<MAP>";

// The maps of --maps (comma-separated names, core/maps.h). UsageError (exit 1) for an unknown name
// (with the list of names), an empty one, or a map given twice.
std::vector<MapKind> parse_maps(const std::string& list);

bool has_map_token(const std::string& path);
// `pattern` with every <MAP> replaced by the map's name; `pattern` itself when it has none.
std::string map_path(const std::string& pattern, MapKind kind);

// Refuses (UsageError) several maps on an -o without <MAP>, and <MAP> in a folder's name or in
// another output (--report, --miss-mask, --suspect-mask, --save-cage: one file for the set).
void check_map_outputs(const std::string& output, const std::vector<MapKind>& maps,
                       const std::vector<std::pair<const char*, std::string>>& others);

}  // namespace nmbake
