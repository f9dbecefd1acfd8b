#include "scene.h"

#include <algorithm>
#include <map>

#include "core/errors.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "io/output_files.h"
#include "core/normals.h"
#include "core/tangent_frames.h"

namespace nmview {
namespace {

void check_normal_image(const nmbake::Image& image, const std::string& path) {
  if (image.channels < 3)
    throw nmbake::InputError(path + ": has " + std::to_string(image.channels) + " channel(s); a normal map needs RGB");
  if (image.width <= 0 || image.height <= 0) throw nmbake::InputError(path + ": empty image");
}

// The tiles the faces use against the tiles found (udim_tiles.h): a note, and one warning for the
// faces drawn without a map. Without <UDIM>, a note when faces lie beyond the unit square.
void report_udim_use(Scene& scene, std::ostream& log) {
  std::vector<std::int32_t> cells = face_udim_cells(scene.low);
  const UdimUse use = count_udim_use(cells);
  const TextureSetFiles& maps = scene.map_files;
  if (!maps.udim) {
    const std::size_t beyond = scene.low_triangles - use.triangles[0];
    if (beyond == 0) return;
    std::vector<int> tiles;
    for (int cell = 1; cell < kUdimCells; ++cell)
      if (use.triangles[std::size_t(cell)] > 0) tiles.push_back(udim_tile_number(cell));
    const std::string& path = maps.found.front().path;
    const std::size_t at = path.rfind(std::to_string(kUdimFirstTile));
    const std::string example = at != std::string::npos && path.find('/', at) == std::string::npos
                                    ? std::string(path).replace(at, 4, kUdimPatternToken)
                                    : "name.<UDIM>.png";
    log << "nmview: " << beyond << " of the low-poly's triangles lie beyond the unit UV square ("
        << (tiles.empty() ? std::string("in no UDIM tile") : "UDIM tiles " + tile_number_list(tiles)) << "); " << path
        << " repeats over them; for a map per UDIM tile give the path with <UDIM> (" << example << ")\n";
    return;
  }
  // Per member: the tiles found, and the tiles faces use without a file.
  std::string found_text, missing_text;
  bool normal_missing = false;
  for (const SetFile& file : maps.found) {
    std::vector<int> numbers;
    for (const UdimTileFile& t : file.tiles) numbers.push_back(t.number);
    const std::string name = maps.has_token ? std::string(nmbake::map_name(file.kind)) + " " : "";
    found_text += (found_text.empty() ? "" : "; ") + name + tile_number_list(numbers);
    const std::vector<int> missing = missing_udim_tiles(use, numbers);
    if (missing.empty()) continue;
    normal_missing = normal_missing || file.kind == nmbake::MapKind::normal;
    missing_text += (missing_text.empty() ? "" : "; ") + name + describe_missing_tiles(use, missing);
  }
  log << "nmview: " << maps.pattern << ": UDIM tiles " << found_text << "\n";
  if (missing_text.empty() && use.outside == 0) {
    scene.face_cells = std::move(cells);
    return;
  }
  log << "nmview: warning: " << maps.pattern << ": ";
  if (!missing_text.empty()) log << "no file for the UDIM tile(s) " << missing_text;
  if (use.outside > 0)
    log << (missing_text.empty() ? "" : "; ") << use.outside
        << " triangle(s) in no UDIM tile (UVs with u below 0 or from 10 on, or v below 0)";
  log << (normal_missing || use.outside > 0 ? "; their faces are drawn magenta, unlit"
                                            : "; those maps are left out on their faces (magenta where shown)")
      << "\n";
  scene.face_cells = std::move(cells);
}

}  // namespace

Scene load_scene(const std::string& low_path, const TextureSetFiles& maps, const std::string& high_path, std::ostream& log,
                 const DecodingOverrides& overrides, unsigned uv_set) {
  Scene scene;
  scene.low_name = low_path;
  scene.map_name = maps.pattern;
  scene.high_name = high_path;
  scene.map_files = maps;

  // Inputs are read in command-line order so the first bad one is the one reported.
  nmbake::LoadOptions low_options;
  low_options.require_uvs = true;
  low_options.uv_set = uv_set;
  nmbake::Mesh low = nmbake::load_mesh(low_path, low_options);

  if (maps.has_token) log << "nmview: " << maps.pattern << ": " << describe_set(maps) << "\n";
  require_normal_map(maps);
  const SetFile& normal_file = *maps.find(nmbake::MapKind::normal);
  const std::string map_path = normal_file.tiles.empty() ? normal_file.path : normal_file.tiles.front().path;
  for (const UdimTileFile& tile : normal_file.tiles) {
    scene.map_tiles.push_back({tile.number, tile.path, nmbake::read_image(tile.path)});
    check_normal_image(scene.map_tiles.back().image, tile.path);
  }
  if (scene.map_tiles.empty()) scene.map = nmbake::read_image(map_path);
  else {
    check_tile_sizes(scene.map_tiles);
    scene.map = scene.map_tiles.front().image;
  }
  check_normal_image(scene.map, map_path);
  const std::map<std::string, std::string> metadata = nmbake::read_image_metadata(map_path);
  if (const auto it = metadata.find("nmbake:map"); it != metadata.end() && it->second != "normal")
    log << "nmview: warning: " << map_path << ": its nmbake:map metadata says '" << it->second << "', not normal"
        << (maps.has_token ? "; decoded as the normal map its name says"
                           : "; a set is shown from a path with <MAP> (crate_<MAP>.png)")
        << "\n";
  std::string note;
  scene.decoding = resolve_decoding(metadata, overrides, map_path, &note);
  log << "nmview: " << map_path << ": decoded as " << note << (scene.map_tiles.size() > 1 ? " (every tile alike)" : "") << "\n";
  double blue = 0.0;
  std::vector<const nmbake::Image*> normal_images = {&scene.map};
  if (!scene.map_tiles.empty()) {
    normal_images.clear();
    for (const UdimTileImage& t : scene.map_tiles) normal_images.push_back(&t.image);
  }
  for (const nmbake::Image* image : normal_images)
    for (int y = 0; y < image->height; ++y)
      for (int x = 0; x < image->width; ++x) blue += image->at(x, y)[2];
  blue /= double(scene.map.width) * double(scene.map.height) * double(normal_images.size());
  if (blue < 0.5 && !scene.decoding.object_space)
    log << "nmview: warning: " << map_path << ": mean blue " << blue
        << " < 0.5, so most normals point into the surface; is this a tangent-space normal map?\n";

  for (const SetFile& file : maps.found)
    if (file.kind != nmbake::MapKind::normal) scene.set_maps.push_back(load_set_map(file, log));

  nmbake::LoadOptions high_options;  // on the low-poly's origin (both re-centred when far), as nmbake does
  high_options.origin = low.origin;
  nmbake::Mesh high = nmbake::load_mesh(high_path, high_options);
  if (nmbake::ensure_normals(high))
    log << "nmview: " << high_path << " has no normals; using the bake's angle-weighted normals\n";

  scene.origin = low.origin;
  scene.bounds = mesh_bounds(low);
  scene.bounds.extend(mesh_bounds(high));
  const glm::vec3 centre = scene.bounds.centre();
  // The camera frames the sphere around the box centre through the farthest vertex: tighter than
  // the box's half diagonal for round or flat shapes.
  for (const nmbake::Mesh* mesh : {&low, &high})
    for (std::uint32_t i : mesh->position_index) scene.radius = std::max(scene.radius, glm::length(mesh->positions[i] - centre));

  const nmbake::TangentFrames frames = nmbake::compute_tangent_frames(low);
  scene.low = build_low_vertices(low, frames, centre);
  scene.high = build_high_vertices(high, centre);
  scene.low_triangles = low.triangle_count();
  report_udim_use(scene, log);
  scene.high_triangles = high.triangle_count();
  return scene;
}

void check_screenshot(const std::string& path, const std::string& low_path, const TextureSetFiles& maps,
                      const std::string& high_path) {
  // In command-line order, as before the texture set: the low-poly, the map(s), the high-poly.
  std::vector<nmbake::NamedFile> inputs = {{"", low_path, "the low-poly"}};
  for (const SetFile& f : maps.found) {
    const std::string what = maps.has_token ? "the " + std::string(nmbake::map_name(f.kind)) + " map" : "the map";
    if (f.tiles.empty()) inputs.push_back({"", f.path, what});
    for (const UdimTileFile& t : f.tiles) inputs.push_back({"", t.path, what + "'s tile " + std::to_string(t.number)});
  }
  inputs.push_back({"", high_path, "the high-poly"});
  nmbake::check_output_files(inputs, {{"--screenshot", path, "the screenshot"}});
}

void write_screenshot(const std::string& path, const Rgba8Image& image, const Scene& scene) {
  nmbake::Image rgb(image.width, image.height, 3);
  for (std::size_t i = 0; i < std::size_t(image.width) * std::size_t(image.height); ++i)
    for (int c = 0; c < 3; ++c) rgb.pixels[3 * i + std::size_t(c)] = float(image.pixels[4 * i + std::size_t(c)]) / 255.0f;
  // Checked again here: the interactive viewer's screenshots are checked nowhere else.
  check_screenshot(path, scene.low_name, scene.map_files, scene.high_name);
  nmbake::OutputFiles outputs;
  nmbake::WriteOptions options;
  options.temp_path = outputs.add(path);
  nmbake::write_image(path, rgb, options);
  outputs.commit();
}

}  // namespace nmview
