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
  const std::string map_path = maps.find(nmbake::MapKind::normal)->path;
  scene.map = nmbake::read_image(map_path);
  if (scene.map.channels < 3)
    throw nmbake::InputError(map_path + ": has " + std::to_string(scene.map.channels) + " channel(s); a normal map needs RGB");
  if (scene.map.width <= 0 || scene.map.height <= 0) throw nmbake::InputError(map_path + ": empty image");
  const std::map<std::string, std::string> metadata = nmbake::read_image_metadata(map_path);
  if (const auto it = metadata.find("nmbake:map"); it != metadata.end() && it->second != "normal")
    log << "nmview: warning: " << map_path << ": its nmbake:map metadata says '" << it->second << "', not normal"
        << (maps.has_token ? "; decoded as the normal map its name says"
                           : "; a set is shown from a path with <MAP> (crate_<MAP>.png)")
        << "\n";
  std::string note;
  scene.decoding = resolve_decoding(metadata, overrides, map_path, &note);
  log << "nmview: " << map_path << ": decoded as " << note << "\n";
  double blue = 0.0;
  for (int y = 0; y < scene.map.height; ++y)
    for (int x = 0; x < scene.map.width; ++x) blue += scene.map.at(x, y)[2];
  blue /= double(scene.map.width) * double(scene.map.height);
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
  scene.high_triangles = high.triangle_count();
  return scene;
}

void check_screenshot(const std::string& path, const std::string& low_path, const TextureSetFiles& maps,
                      const std::string& high_path) {
  // In command-line order, as before the texture set: the low-poly, the map(s), the high-poly.
  std::vector<nmbake::NamedFile> inputs = {{"", low_path, "the low-poly"}};
  for (const SetFile& f : maps.found)
    inputs.push_back({"", f.path, maps.has_token ? "the " + std::string(nmbake::map_name(f.kind)) + " map" : "the map"});
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
