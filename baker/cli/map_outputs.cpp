#include "cli/map_outputs.h"

#include <filesystem>

#include "cli/numbers.h"
#include "core/errors.h"

namespace nmbake {

std::vector<MapKind> parse_maps(const std::string& list) {
  std::vector<MapKind> out;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = list.find(',', start);
    const std::string name = list.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    MapKind kind;
    if (name.empty()) throw UsageError("--maps '" + printable(list) + "': an empty name (maps: " + map_name_list() + ")");
    if (!parse_map_name(name, kind))
      throw UsageError("--maps: unknown map '" + printable(name) + "' (maps: " + map_name_list() + ")");
    for (MapKind k : out)
      if (k == kind) throw UsageError("--maps: " + name + " is given twice: two maps would go to one file");
    out.push_back(kind);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

bool has_map_token(const std::string& path) { return path.find(kMapToken) != std::string::npos; }

std::string map_path(const std::string& pattern, MapKind kind) {
  std::string out = pattern;
  const std::string token = kMapToken, name = map_name(kind);
  for (std::size_t at = out.find(token); at != std::string::npos; at = out.find(token, at + name.size()))
    out.replace(at, token.size(), name);
  return out;
}

void check_map_outputs(const std::string& output, const std::vector<MapKind>& maps,
                       const std::vector<std::pair<const char*, std::string>>& others) {
  if (has_map_token(std::filesystem::path(output).parent_path().string()))
    throw UsageError("--output " + output + ": <MAP> must be in the file's name, not a folder's");
  if (maps.size() > 1 && !has_map_token(output)) {
    std::string list;
    for (MapKind k : maps) list += (list.empty() ? "" : ",") + std::string(map_name(k));
    const std::filesystem::path p(output);
    throw UsageError("--output " + output + ": --maps " + list + " writes " + std::to_string(maps.size()) +
                     " maps, so the name needs <MAP> (e.g. " + (p.parent_path() / (p.stem().string() + "_<MAP>")).string() +
                     p.extension().string() + ")");
  }
  for (const auto& [option, path] : others)
    if (has_map_token(path))
      throw UsageError(std::string(option) + " " + path + ": one file for the whole set; <MAP> goes in -o only");
}

}  // namespace nmbake
