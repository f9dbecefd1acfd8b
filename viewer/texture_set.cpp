#include "texture_set.h"

#include <filesystem>
#include <map>
#include <system_error>

#include "cli/map_outputs.h"
#include "core/errors.h"
#include "io/image_io.h"

namespace nmview {

const SetFile* TextureSetFiles::find(nmbake::MapKind kind) const {
  for (const SetFile& f : found)
    if (f.kind == kind) return &f;
  return nullptr;
}

TextureSetFiles find_texture_set(const std::string& pattern) {
  TextureSetFiles files;
  files.pattern = pattern;
  files.has_token = nmbake::has_map_token(pattern);
  files.udim = has_udim_token(pattern);
  if (!files.has_token && !files.udim) {
    files.found.push_back({nmbake::MapKind::normal, pattern, {}});
    return files;
  }
  for (int k = 0; k < nmbake::kMapKinds; ++k) {
    const auto kind = nmbake::MapKind(k);
    if (!files.has_token && kind != nmbake::MapKind::normal) continue;
    const std::string path = files.has_token ? nmbake::map_path(pattern, kind) : pattern;
    if (files.udim) {
      std::vector<UdimTileFile> tiles = find_udim_files(path);
      if (tiles.empty()) files.missing.push_back(kind);
      else files.found.push_back({kind, path, std::move(tiles)});
      continue;
    }
    // status() follows links: a dangling link is "no such file"; any other failure (a folder we
    // may not search) counts as found, so that the loader names the real problem.
    std::error_code error;
    const std::filesystem::file_status status = std::filesystem::status(path, error);
    if (status.type() == std::filesystem::file_type::not_found) files.missing.push_back(kind);
    else files.found.push_back({kind, path, {}});
  }
  return files;
}

void require_normal_map(const TextureSetFiles& files) {
  if (files.found.empty() && !files.has_token)
    throw nmbake::InputError(files.pattern + ": no UDIM tile exists (<UDIM> replaced by " + std::to_string(kUdimFirstTile) +
                             " to " + std::to_string(kUdimFirstTile + kUdimCells - 1) + ": " +
                             udim_tile_path(files.pattern, kUdimFirstTile) + ", " +
                             udim_tile_path(files.pattern, kUdimFirstTile + 1) + ", ...)");
  if (files.found.empty()) {
    std::string examples;
    for (nmbake::MapKind k : {nmbake::MapKind::normal, nmbake::MapKind::ao})
      examples += (examples.empty() ? "" : ", ") + udim_tile_path(nmbake::map_path(files.pattern, k), kUdimFirstTile);
    throw nmbake::InputError(files.pattern + ": no file of the texture set exists (<MAP> replaced by each of " +
                             nmbake::map_name_list() + (files.udim ? ", <UDIM> by 1001 to 2000" : "") + ": " + examples +
                             ", ...)");
  }
  if (!files.find(nmbake::MapKind::normal)) {
    std::string names;
    for (const SetFile& f : files.found) names += (names.empty() ? "" : ", ") + std::string(nmbake::map_name(f.kind));
    throw nmbake::InputError(files.pattern + ": the set has " + names + " but no normal map (" +
                             nmbake::map_path(files.pattern, nmbake::MapKind::normal) + "); the lit render needs one");
  }
}

std::string describe_set(const TextureSetFiles& files) {
  std::string found, missing;
  for (const SetFile& f : files.found) found += (found.empty() ? "" : ", ") + std::string(nmbake::map_name(f.kind));
  for (nmbake::MapKind k : files.missing) missing += (missing.empty() ? "" : ", ") + std::string(nmbake::map_name(k));
  return "found " + (found.empty() ? std::string("none") : found) + (missing.empty() ? "" : "; not found: " + missing);
}

namespace {

// One file of a member (the member itself, or one of its UDIM tiles), read and checked.
nmbake::Image read_set_file(const std::string& path, nmbake::MapKind kind, std::ostream& log) {
  nmbake::Image image = nmbake::read_image(path);
  if (image.width <= 0 || image.height <= 0 || image.channels <= 0) throw nmbake::InputError(path + ": empty image");
  const std::map<std::string, std::string> metadata = nmbake::read_image_metadata(path);
  if (const auto it = metadata.find("nmbake:map"); it != metadata.end() && it->second != nmbake::map_name(kind))
    log << "nmview: warning: " << path << ": its nmbake:map metadata says '" << it->second << "'; shown as the name says, "
        << nmbake::map_name(kind) << "\n";
  return image;
}

}  // namespace

SetMap load_set_map(const SetFile& file, std::ostream& log) {
  SetMap map;
  map.kind = file.kind;
  map.path = file.path;
  if (file.tiles.empty()) {
    map.image = read_set_file(file.path, file.kind, log);
    return map;
  }
  for (const UdimTileFile& tile : file.tiles)
    map.tiles.push_back({tile.number, tile.path, read_set_file(tile.path, file.kind, log)});
  check_tile_sizes(map.tiles);
  map.image = map.tiles.front().image;
  return map;
}

std::vector<float> display_rgb(const nmbake::Image& image) {
  std::vector<float> rgb(std::size_t(image.width) * std::size_t(image.height) * 3);
  const bool grey = image.channels < 3;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const float* src = image.at(x, image.height - 1 - y);
      float* dst = &rgb[(std::size_t(y) * std::size_t(image.width) + std::size_t(x)) * 3];
      for (int c = 0; c < 3; ++c) dst[c] = src[grey ? 0 : c];
    }
  return rgb;
}

bool shown_texel_exact(nmbake::MapKind kind) { return nmbake::map_is_flat(kind); }

}  // namespace nmview
