#include "cli/udim_outputs.h"

#include "core/errors.h"

namespace nmbake {

bool has_udim(const std::string& path) { return path.find(kUdimToken) != std::string::npos; }

std::string udim_path(const std::string& pattern, int number) {
  std::string out = pattern;
  const std::string n = std::to_string(number), token = kUdimToken;
  for (std::size_t at; (at = out.find(token)) != std::string::npos;) out.replace(at, token.size(), n);
  return out;
}

void check_udim_outputs(const Args& a) {
  const bool udim = has_udim(a.output);
  for (const auto& [option, path] : {std::pair{"--report", &a.report}, std::pair{"--save-cage", &a.save_cage}})
    if (has_udim(*path))
      throw UsageError(std::string(option) + " " + *path + ": one file for the whole bake cannot hold UDIM tiles; remove <UDIM>");
  for (const auto& [option, path] :
       {std::pair{"--output", &a.output}, std::pair{"--miss-mask", &a.miss_mask}, std::pair{"--suspect-mask", &a.suspect_mask}}) {
    if (path->empty()) continue;
    const std::size_t slash = path->find_last_of('/');
    if (has_udim(*path) && slash != std::string::npos && path->find(kUdimToken) < slash)
      throw UsageError(std::string(option) + " " + *path + ": <UDIM> must be in the file's name, not a folder's");
    if (has_udim(*path) != udim)
      throw UsageError(std::string(option) + " " + *path +
                       (udim ? ": the map has <UDIM>, so its masks need it too (one per tile)"
                             : ": <UDIM> in a mask needs it in the map's name (-o) too"));
  }
}

UvTilesNote uv_tiles_note(const Mesh& low, const Args& a, int width, int height) {
  UvTilesNote note;
  note.udim = has_udim(a.output);
  if (note.udim || !low.has_uvs()) return note;
  const UdimLayout quick = find_udim_tiles(low);
  if (quick.triangles_beyond_first() == 0) return note;
  const UdimLayout layout = find_udim_tiles(low, width, height);
  note.beyond_triangles = layout.triangles_beyond_first();
  note.beyond_texels = layout.texels_beyond_first();
  std::size_t listed = 0;
  for (const UdimTile& t : layout.tiles) {
    if (t.number == kUdimFirst) continue;
    if (++listed > 8) {
      note.beyond_tiles += " and more";
      break;
    }
    note.beyond_tiles += (note.beyond_tiles.empty() ? "" : ", ") + std::to_string(t.number);
  }
  return note;
}

nlohmann::json udim_report(const UdimBake& bake, const std::string& pattern) {
  nlohmann::json tiles = nlohmann::json::array();
  for (const TileBake& t : bake.tiles) {
    const BakeStats& s = t.result.stats;
    tiles.push_back({{"tile", t.tile.number},
                     {"file", udim_path(pattern, t.tile.number)},
                     {"triangles", t.tile.triangles},
                     {"straddling_triangles", t.tile.straddling},
                     {"texels_covered", s.trace.texels_covered},
                     {"coverage", s.trace.coverage},
                     {"overlapping_samples", s.trace.overlapping_samples},
                     {"rays", s.trace.rays},
                     {"hits", s.trace.hits},
                     {"misses", s.trace.misses}});
  }
  return {{"tiles", tiles}, {"outside_triangles", bake.outside_triangles}, {"straddling_triangles", bake.straddling_triangles}};
}

}  // namespace nmbake
