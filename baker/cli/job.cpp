#include "cli/job.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <exception>
#include <future>
#include <optional>
#include <tuple>

#include "cli/map_outputs.h"
#include "cli/outputs.h"
#include "cli/pair_checks.h"
#include "cli/report.h"
#include "cli/udim_outputs.h"
#include "cli/warnings.h"
#include "core/stopwatch.h"
#include "core/errors.h"
#include "core/normals.h"
#include "core/parallel.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "io/text_file.h"
#include "pipeline/bake.h"
#include "pipeline/error_estimate.h"

namespace nmbake {

namespace {

using Clock = std::chrono::steady_clock;

// One line on how far rays reached, unless --quiet.
void print_distances(const BakeStats& s) {
  if (s.distances.cage == BakeStats::CageSource::automatic)
    std::fprintf(
        stderr,
        "nmbake: automatic cage: front %.3g-%.3g (mean %.3g), rear %.3g-%.3g (mean %.3g) per vertex; limited by a neighbouring "
        "part at %zu and %zu vertices\n",
        s.distances.vertex_front.min, s.distances.vertex_front.max, s.distances.vertex_front.mean, s.distances.vertex_rear.min,
        s.distances.vertex_rear.max, s.distances.vertex_rear.mean, s.distances.cage_front_limited, s.distances.cage_rear_limited);
  else if (s.distances.cage == BakeStats::CageSource::file && s.distances.auto_distances)
    std::fprintf(stderr, "nmbake: rear distances measured per vertex: %.3g-%.3g (mean %.3g)\n", s.distances.vertex_rear.min,
                 s.distances.vertex_rear.max, s.distances.vertex_rear.mean);
  else if (s.distances.auto_distances)
    std::fprintf(stderr, "nmbake: ray distances measured: --front %.6g --rear %.6g (%.2f%% of probes lie beyond)\n",
                 s.distances.front, s.distances.rear, 100.0 * s.distances.auto_probe_beyond);
}

// With <UDIM>, each tile's estimate goes into the report's udim tiles and the line gives them combined.
ErrorEstimate estimate_error(const Mesh& low, const BakeOptions& o, const BakeResult& r, const UdimBake* udim, RunInfo& run,
                             int bits, Progress& progress) {
  ErrorEstimateOptions eo;
  eo.bits = bits;
  ErrorEstimate estimate;
  if (udim) {
    const std::vector<ErrorEstimate> tiles = estimate_udim_errors(low, o, *udim, eo);
    for (std::size_t k = 0; k < tiles.size() && k < run.udim["tiles"].size(); ++k)
      run.udim["tiles"][k]["error_estimate"] = {{"mean_deg", tiles[k].mean_deg},
                                                {"p95_deg", tiles[k].p95_deg},
                                                {"max_deg", tiles[k].max_deg},
                                                {"texels", tiles[k].texels}};
    estimate = combine_estimates(tiles);
  } else {
    estimate = estimate_bake_error(low, o, r, eo);
  }
  // The estimate compares float values; say what the output's bit depth adds on top.
  char quant[128] = "float output adds no quantisation";
  if (bits != 32)
    std::snprintf(quant, sizeof quant, "%d-bit output adds quantisation of mean %.4f deg, max %.4f deg", bits,
                  estimate.quantization_mean_deg, estimate.quantization_max_deg);
  progress.above([&] {
    std::fprintf(stderr,
                 "nmbake: error estimate: mean %.4f deg, p95 %.4f deg, max %.4f deg against %d samples on %zu texels "
                 "(%.2f s); %s\n",
                 estimate.mean_deg, estimate.p95_deg, estimate.max_deg, estimate.samples, estimate.texels, estimate.seconds,
                 quant);
  });
  return estimate;
}

// A map set and its masks, and the files they go to (one set, or one per UDIM tile): the normal
// map's (empty when --maps leaves it out) and each other map's, as result->maps.
struct MapFiles {
  const BakeResult* result;
  std::string map, miss_mask, suspect_mask;
  std::vector<std::string> extra;
  int tile = 0;  // its UDIM tile, 0 without <UDIM>
};

std::vector<MapFiles> map_files(const Args& a, const BakeOptions& o, const BakeResult& r, const UdimBake* udim) {
  auto tile_path = [](const std::string& pattern, int n) { return pattern.empty() ? pattern : udim_path(pattern, n); };
  const auto set = [&](const BakeResult& result, int tile) {
    const auto path = [&](MapKind k) { return tile ? udim_path(map_path(a.output, k), tile) : map_path(a.output, k); };
    MapFiles f{&result,
               o.maps.wants(MapKind::normal) ? path(MapKind::normal) : "",
               tile_path(a.miss_mask, tile),
               tile_path(a.suspect_mask, tile),
               {},
               tile};
    if (!tile) f.miss_mask = a.miss_mask, f.suspect_mask = a.suspect_mask;
    for (const BakedMap& m : result.maps) f.extra.push_back(path(m.kind));
    return f;
  };
  if (!udim) return {set(r, 0)};
  std::vector<MapFiles> files;
  for (const TileBake& t : udim->tiles) files.push_back(set(t.result, t.tile.number));
  return files;
}

// The file metadata of a map other than the normal map.
std::vector<std::pair<std::string, std::string>> extra_metadata(const BakeOptions& o, const BakedMap& m) {
  std::vector<std::pair<std::string, std::string>> md = m.metadata;
  if (m.kind == MapKind::bent_normal || m.kind == MapKind::object_normal) {
    const NormalSpace space = m.kind == MapKind::object_normal ? NormalSpace::object : o.space;
    md.push_back({"nmbake:space", to_string(space)});
    if (space == NormalSpace::tangent) {
      md.push_back({"nmbake:green", o.green_down ? "down" : "up"});
      md.push_back({"nmbake:tangent_basis", "mikktspace"});
    }
  }
  md.push_back({"nmbake:version", NMBAKE_VERSION});
  md.push_back({"ImageDescription", std::string(map_name(m.kind)) + " map, baked by nmbake"});
  return md;
}

// The UDIM tiles' files may not be inputs or each other (checked with the pattern before the bake).
void check_tile_files(const Args& a, const std::vector<MapFiles>& files) {
  std::vector<NamedFile> inputs{{"", a.low, "the low-poly"}, {"--cage", a.cage, "the cage"}}, outputs;
  for (const std::string& h : a.highs) inputs.push_back({"", h, "the high-poly"});
  for (const MapFiles& f : files) {
    for (const auto& [option, path] :
         {std::pair{"--output", &f.map}, std::pair{"--miss-mask", &f.miss_mask}, std::pair{"--suspect-mask", &f.suspect_mask}})
      outputs.push_back({option, *path, "a UDIM tile"});
    for (const std::string& path : f.extra) outputs.push_back({"--output", path, "a UDIM tile"});
  }
  check_output_files(inputs, outputs);
}

// One image to its temporary file.
struct ImageWrite {
  std::string path;
  const Image* image;
  WriteOptions options;
};

// The images written, each to its temporary, largest first. One larger than all the rest together
// (a plain normal map, one with its masks) takes every thread its encoder uses, alone; the others
// go side by side, so that one file's serial parts (assembling, checksums, the write and its fsync)
// overlap another's encoding: as many at once as there are threads or files, each file with its
// share of the threads (a workstation's 16 threads write 4 UDIM tiles 4 at a time, 4 threads each,
// not 4 threads in all). The bytes do not depend on the threads (WriteOptions::threads). An error
// is the first file's in `writes` order that failed, whatever the threads did first.
void write_images(const JobEnv& env, std::vector<ImageWrite>& writes, int threads) {
  std::vector<std::size_t> order(writes.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  const auto size = [&](std::size_t i) { return writes[i].image->pixels.size(); };
  std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return size(x) > size(y); });
  std::size_t rest = 0, k = 0;
  for (std::size_t i : order) rest += size(i);
  for (; k < order.size() && 2 * size(order[k]) >= rest; ++k) {  // alone, on every thread
    if (env.interrupted()) throw Cancelled();
    rest -= size(order[k]);
    write_image(writes[order[k]].path, *writes[order[k]].image, writes[order[k]].options);
  }
  if (k == order.size()) return;
  std::vector<std::exception_ptr> failed(writes.size());
  std::atomic<std::size_t> next{k};
  std::atomic<bool> stop{false};
  const int all = worker_threads(threads), side_by_side = std::max(1, std::min(all, int(order.size() - k)));
  run_on_threads(side_by_side, [&](int) {
    for (std::size_t j; !stop && (j = next++) < order.size();) {
      ImageWrite& w = writes[order[j]];
      try {
        if (env.interrupted()) throw Cancelled();
        w.options.threads = std::max(1, all / side_by_side);
        write_image(w.path, *w.image, w.options);
      } catch (...) {
        failed[order[j]] = std::current_exception();
        stop = true;
      }
    }
  });
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
}

// The maps, the masks and the cage, each to its temporary file in `outputs`.
void write_outputs(const JobEnv& env, OutputSet& outputs, const Args& a, const BakeOptions& o, const BakeResult& r,
                   const UdimBake* udim, const Mesh& low, int bits) {
  auto check_signal = [&env] {
    if (env.interrupted()) throw Cancelled();
  };
  WriteOptions wo;
  wo.bits = bits;
  wo.metadata = {
      {"nmbake:map", "normal"},
      {"nmbake:space", to_string(o.space)},
      {"nmbake:green", o.green_down ? "down" : "up"},
      {"nmbake:tangent_basis", "mikktspace"},
      {"nmbake:bitangent", o.bitangent == BitangentMode::per_vertex ? "vertex" : "pixel"},
      {"nmbake:version", NMBAKE_VERSION},
      {"ImageDescription",
       std::string(o.space == NormalSpace::object ? "object-space normal map" : "tangent-space normal map, ") +
           (o.space == NormalSpace::object ? "" : (o.green_down ? "DirectX (Y-)" : "OpenGL (Y+)")) + ", baked by nmbake"}};
  wo.compression = a.compression;
  wo.dither = a.dither;
  wo.threads = o.threads;
  const std::vector<MapFiles> files = map_files(a, o, r, udim);
  if (udim) check_tile_files(a, files);
  std::vector<ImageWrite> writes;
  // Each image to env.on_image, then to its temporary (a map not when !env.write_maps).
  const auto add = [&](const char* name, int tile, const std::string& path, const Image& image, WriteOptions options, bool map) {
    if (env.on_image) env.on_image({name, tile, path, &image, &options});
    if (map && !env.write_maps) return;
    options.temp_path = outputs.add(path);
    writes.push_back({path, &image, std::move(options)});
  };
  for (const MapFiles& f : files) {
    if (!f.map.empty()) add(map_name(MapKind::normal), f.tile, f.map, f.result->map, wo, true);
    for (std::size_t i = 0; i < f.extra.size(); ++i) {
      const BakedMap& m = f.result->maps[i];
      if (m.image.pixels.empty()) continue;  // skipped (a warning says why)
      WriteOptions mo = wo;
      mo.metadata = extra_metadata(o, m);
      mo.dither = wo.dither && !map_is_flat(m.kind);        // an ID's colour is exact
      mo.indexed = map_is_flat(m.kind);                     // and few: a PNG palette
      if (map_is_flat(m.kind)) mo.palette = id_palette(m);  // the image holds their indices
      add(map_name(m.kind), f.tile, f.extra[i], m.image, std::move(mo), true);
    }
    for (const auto& [name, path, image] : {std::tuple{"miss-mask", &f.miss_mask, &f.result->miss_mask},
                                            std::tuple{"suspect-mask", &f.suspect_mask, &f.result->suspect_mask}}) {
      if (path->empty()) continue;
      WriteOptions mo;
      mo.bits = default_bits_for(*path);
      mo.threads = o.threads;
      add(name, f.tile, *path, *image, std::move(mo), false);
    }
  }
  if (!writes.empty()) write_images(env, writes, o.threads);
  if (!a.save_cage.empty()) {
    check_signal();
    Mesh cage_mesh;
    cage_mesh.origin = low.origin;
    cage_mesh.positions = r.cage_positions;
    cage_mesh.uvs = low.uvs;
    cage_mesh.position_index = low.position_index;
    cage_mesh.uv_index = low.uv_index;
    write_text_file(a.save_cage, outputs.add(a.save_cage),
                    obj_text(cage_mesh, "nmbake " NMBAKE_VERSION " automatic cage of " + a.low + " for " + a.high));
  }
}

// The report's "maps": per map of --maps, its file (the pattern with <UDIM>) and what it was
// encoded with; the ranges, distances and ID colours are the same in every UDIM tile, the standard
// errors are combined (mean over the covered texels, the largest tile's p95).
nlohmann::json maps_report(const Args& a, const BakeOptions& o, const BakeResult& r, const UdimBake* udim) {
  nlohmann::json maps = nlohmann::json::array();
  std::vector<const BakeResult*> parts;
  if (udim)
    for (const TileBake& t : udim->tiles) parts.push_back(&t.result);
  else parts.push_back(&r);
  std::size_t extra = 0;
  for (MapKind kind : o.maps.maps) {
    nlohmann::json j = {{"map", map_name(kind)}, {"file", map_path(a.output, kind)}};
    if (kind == MapKind::normal || parts.empty() || extra >= parts.front()->maps.size()) {
      maps.push_back(j);
      continue;
    }
    const BakedMap& m = parts.front()->maps[extra];
    if (!m.skipped.empty()) j["skipped"] = m.skipped;
    switch (kind) {
      case MapKind::ao:
      case MapKind::bent_normal:
        j["ao_distance"] = m.distance;
        j["rays_per_texel"] = o.maps.ao_rays_auto ? nlohmann::json("auto") : nlohmann::json(o.maps.ao_rays);
        break;
      case MapKind::thickness:
        j["thickness_distance"] = m.distance;
        j["rays_per_texel"] = o.maps.ao_rays_auto ? nlohmann::json("auto") : nlohmann::json(o.maps.ao_rays);
        break;
      case MapKind::height:
        j["height_range"] = {m.range_min, m.range_max};
        j["height_range_given"] = o.maps.height_range_given;
        break;
      case MapKind::curvature:
        j["curvature_scale"] = m.range_max;
        j["curvature_scale_given"] = o.maps.curvature_scale > 0.0;
        j["curvature_smoothing"] = o.maps.curvature_smoothing;
        break;
      case MapKind::position:
        j["box"] = {{"min", {m.box_min.x, m.box_min.y, m.box_min.z}}, {"max", {m.box_max.x, m.box_max.y, m.box_max.z}}};
        break;
      case MapKind::object_id:
      case MapKind::material_id: {
        nlohmann::json colors = nlohmann::json::object();
        for (const auto& [name, c] : m.colors)
          colors[name] = {int(std::lround(c.r * 255.0f)), int(std::lround(c.g * 255.0f)), int(std::lround(c.b * 255.0f))};
        j["colors"] = colors;
        break;
      }
      default: break;
    }
    if (m.rays_mean >= 0.0) {  // --ao-rays auto: its threshold and the rays it spent, over every tile
      double sum = 0.0, texels = 0.0, most = 0.0;
      for (const BakeResult* p : parts) {
        const double n = double(p->stats.trace.texels_covered);
        sum += p->maps[extra].rays_mean * n, texels += n;
        most = std::max(most, p->maps[extra].rays_max);
      }
      j["max_ao_error"] = o.maps.max_ao_error;
      j["rays"] = {{"mean", texels > 0.0 ? sum / texels : 0.0}, {"max", most}};
    }
    if (m.error_mean >= 0.0) {
      double sum = 0.0, texels = 0.0, p95 = 0.0;
      for (const BakeResult* p : parts) {
        const double n = double(p->stats.trace.texels_covered);
        sum += p->maps[extra].error_mean * n, texels += n;
        p95 = std::max(p95, p->maps[extra].error_p95);
      }
      j["standard_error"] = {{"mean", texels > 0.0 ? sum / texels : 0.0}, {"p95", p95}};
    }
    maps.push_back(j);
    ++extra;
  }
  return maps;
}

// The texture set's warnings: a map not written, a map in fewer bits than it needs.
std::vector<std::string> map_warnings(const BakeResult& r, int bits) {
  std::vector<std::string> out;
  for (const BakedMap& m : r.maps) {
    if (!m.skipped.empty()) out.push_back("warning: " + m.skipped + ": the " + map_name(m.kind) + " map is not written");
    if (bits == 8 && (m.kind == MapKind::height || m.kind == MapKind::position))
      out.push_back(std::string("warning: the ") + map_name(m.kind) +
                    " map in 8 bits steps visibly (256 levels); a .tif (16-bit) or .exr (float) output keeps it smooth");
  }
  return out;
}

// The job's report, written to --report and handed to the batch.
void report_job(const JobEnv& env, OutputSet& outputs, const Args& a, const BakeOptions& o, const RunInfo& run,
                const BakeResult& r, const UdimBake* udim, const ErrorEstimate* estimate) {
  if (a.report.empty() && !env.report) return;
  nlohmann::json report = make_report(o, r.stats, run);
  report["maps"] = maps_report(a, o, r, udim);
  if (estimate)
    report["error_estimate"] = {{"mean_deg", estimate->mean_deg},
                                {"p95_deg", estimate->p95_deg},
                                {"max_deg", estimate->max_deg},
                                {"texels", estimate->texels},
                                {"seconds", estimate->seconds}};
  if (!a.report.empty()) write_text_file(a.report, outputs.add(a.report), report.dump(2) + "\n");
  if (env.report) *env.report = std::move(report);
}

// "4", or with --samples auto "auto (16 at 3.2%, 64 at 0.4% of texels, 4 elsewhere)".
std::string samples_text(const BakeOptions& o, const BakeStats& s) {
  if (!o.adaptive) return std::to_string(o.samples);
  const double texels = double(s.trace.texels_base + s.trace.texels_refined + s.trace.texels_deep);
  auto share = [texels](std::uint64_t n) { return texels > 0 ? 100.0 * double(n) / texels : 0.0; };
  char text[120];
  std::snprintf(text, sizeof text, "auto (%d at %.1f%%, %d at %.1f%% of texels, 4 elsewhere)", o.samples,
                share(s.trace.texels_refined), 4 * o.samples, share(s.trace.texels_deep));
  return text;
}

void print_summary(const Args& a, const BakeOptions& o, const RunInfo& run, const BakeStats& s, int bits) {
  std::string tiles;
  if (run.udim.is_object()) {
    for (const nlohmann::json& t : run.udim["tiles"]) tiles += (tiles.empty() ? "" : ", ") + std::to_string(t["tile"].get<int>());
    tiles = std::to_string(run.udim["tiles"].size()) + (run.udim["tiles"].size() == 1 ? " UDIM tile: " : " UDIM tiles: ") +
            tiles + ", ";
  }
  std::printf(
      "nmbake: wrote %s (%s%dx%d, %d-bit, %s%s): samples %s, rays %s, misses %llu (%.2f%%), coverage %.1f%%, "
      "seconds: load %.2f prepare %.2f bvh %.2f distances %.2f trace %.2f padding %.2f write %.2f total %.2f\n",
      a.output.c_str(), tiles.c_str(), o.width, o.height, bits, to_string(o.space),
      o.space == NormalSpace::tangent ? (o.green_down ? ", green down" : ", green up") : "", samples_text(o, s).c_str(),
      human(double(s.trace.rays)).c_str(), (unsigned long long)s.trace.misses,
      s.trace.samples_covered ? 100.0 * double(s.trace.misses) / double(s.trace.samples_covered) : 0.0, 100.0 * s.trace.coverage,
      run.seconds_load, s.prepare.seconds, s.bvh.seconds, s.distances.seconds, s.trace.seconds, s.pad.seconds, run.seconds_write,
      run.seconds_total);
}

// What loading found in several high-poly files, summed (one file: its own).
MeshLoadInfo combined_info(const std::vector<MeshLoadInfo>& infos) {
  MeshLoadInfo all = infos.front();
  for (std::size_t i = 1; i < infos.size(); ++i) {
    const MeshLoadInfo& f = infos[i];
    if (all.format.find(f.format) == std::string::npos) all.format += "+" + f.format;
    all.file_faces += f.file_faces;
    all.polygons_triangulated += f.polygons_triangulated;
    all.normals_renormalized += f.normals_renormalized;
    all.zero_normals += f.zero_normals;
    all.normals_dropped = all.normals_dropped || f.normals_dropped;
    all.uvs_dropped = all.uvs_dropped || f.uvs_dropped;
    all.faces_without_normals += f.faces_without_normals;
    all.faces_without_uvs += f.faces_without_uvs;
    all.degenerate_faces_dropped += f.degenerate_faces_dropped;
    all.colors_dropped = all.colors_dropped || f.colors_dropped;
    all.vertices_without_colors += f.vertices_without_colors;
    all.largest_coordinate = std::max(all.largest_coordinate, f.largest_coordinate);
    if (f.unit_scale != all.unit_scale) all.unit_scale = 0.0;  // mixed: high_files gives each
  }
  return all;
}

// What the report says of the run besides the bake's counts (the timings come later).
RunInfo run_info(const Args& a, const std::vector<std::string>& command, int bits) {
  RunInfo run;
  run.low_path = a.low;
  run.high_path = a.highs.front();
  run.high_paths = a.highs;
  run.cage_path = a.cage;
  run.save_cage_path = a.save_cage;
  run.output_path = a.output;
  run.miss_mask_path = a.miss_mask;
  run.suspect_mask_path = a.suspect_mask;
  run.bits = bits;
  run.dither = a.dither;
  run.uv_set = a.uv_set;
  if (image_io_detail::lower_extension(a.output) == ".exr") run.compression = a.compression.empty() ? "zip" : a.compression;
  run.command = command;
  run.started = utc_time_text(report_time());
  return run;
}

// A mesh file loaded in its role (LOW, HIGH, --cage): an error loading it says which it was given as
// (a sculpt given as LOW fails for want of UVs; the line then says the order of the arguments).
Mesh load_as(const JobEnv& env, const char* role, const std::string& path, const LoadOptions& options, MeshLoadInfo* info) {
  try {
    return env.load_mesh ? env.load_mesh(path, options, info) : load_mesh(path, options, info);
  } catch (const Error& e) {
    const std::string what = e.what();
    const bool low = std::string(role) == "LOW";
    throw Error(e.code(), what + (low && what.find("no UVs") != std::string::npos
                                      ? " (given as LOW, the low-poly to bake into, which needs UVs; is it the high-poly? "
                                        "nmbake LOW HIGH -o MAP)"
                                      : " (given as " + std::string(role) + ")"));
  }
}

// The high-poly files merged, from the cache when an earlier job loaded them.
std::shared_ptr<const LoadedHigh> load_highs(const JobEnv& env, const std::vector<std::string>& paths, const LoadOptions& options,
                                             MeshCache* cache) {
  std::string key;
  for (const std::string& p : paths) key += p + '\n';
  const glm::dvec3 origin = options.origin ? *options.origin : glm::dvec3(0.0);
  char at[100];
  std::snprintf(at, sizeof at, "%.17g %.17g %.17g", origin.x, origin.y, origin.z);
  key += at;
  if (cache)
    if (const auto it = cache->highs.find(key); it != cache->highs.end()) {
      ++cache->hits;
      return it->second;
    }
  auto loaded = std::make_shared<LoadedHigh>();
  std::vector<Mesh> meshes;
  for (const std::string& path : paths) {
    meshes.push_back(load_as(env, "HIGH", path, options, &loaded->infos.emplace_back()));
    loaded->triangles.push_back(meshes.back().triangle_count());
  }
  loaded->mesh = merge_meshes(std::move(meshes));
  if (cache) cache->highs[key] = loaded;
  return loaded;
}

}  // namespace

void bake_job(const Args& a, const JobEnv& env) {
  const AllCores cores(a.threads);  // --threads bounds every stage, the loading included
  BakeOptions o = bake_options(a);
  validate_options(o);  // the library's checks, before a long load
  const int bits = a.bits ? a.bits : default_bits_for(a.output);
  check_udim_outputs(a);
  check_outputs(a, bits);
  for (MapKind k : parse_maps(a.maps)) prepare_write(map_path(a.output, k));
  for (const std::string& mask : {a.miss_mask, a.suspect_mask})
    if (!mask.empty()) prepare_write(mask);
  WarningLog warnings(a.quiet < 2 && !a.no_warnings, a.strict);

  // Load.
  RunInfo run = run_info(a, env.command, bits);
  // Each stage to the progress line and to env.on_progress, which gets the stage's fractions too.
  const char* stage_now = "loading";
  const auto stage = [&](const char* name, bool tick = true) {
    stage_now = name;
    env.progress.stage(name, tick);
    if (env.on_progress) env.on_progress(name, 0.0);
  };
  *env.doing = "loading the meshes";
  stage("loading");
  auto t0 = Clock::now();
  LoadOptions low_opts;
  low_opts.require_uvs = true;
  low_opts.uv_set = a.uv_set;
  Mesh low = load_as(env, "LOW", a.low, low_opts, &run.low_info);
  run.origin = {low.origin.x, low.origin.y, low.origin.z};
  LoadOptions shared;  // the high-poly and the cage share the low-poly's origin (re-centred when far)
  shared.origin = low.origin;
  const std::shared_ptr<const LoadedHigh> loaded = load_highs(env, a.highs, shared, env.cache);
  run.high_infos = loaded->infos;
  run.high_triangles = loaded->triangles;
  run.high_info = combined_info(run.high_infos);
  const Mesh& high = loaded->mesh;
  Mesh cage;
  if (!a.cage.empty()) cage = load_as(env, "--cage", a.cage, shared, &run.cage_info);
  const Mesh* cage_mesh = a.cage.empty() ? nullptr : &cage;
  run.seconds_load = seconds_since(t0);
  run.low_objects = object_list(low);
  run.high_objects = object_list(high);
  if (a.match == "names") run.match = match_by_names(run.low_objects, run.high_objects, a.match_suffixes, o);
  // The pair as given, before a bake that could not be right: boxes apart or of other sizes, LOW and
  // HIGH the wrong way round, UVs stacked deep.
  const PairBoxes boxes = compare_boxes(low, high, o.threads);
  run.pair = pair_report(boxes);
  if (boxes.mismatched() && !a.allow_mismatch) throw InputError(mismatch_text(boxes, a.low, a.high, false));
  const UvOverlap overlap = measure_map_overlap(low, o.width, o.height, has_udim(a.output), o.threads);
  run.uv_overlap = overlap_report(overlap);
  if (overlap_refused(overlap) && !a.allow_overlap) throw InputError(overlap_text(overlap, 0, a.low, false));
  env.progress.above([&] {
    if (boxes.mismatched()) warnings.add({"warning: " + mismatch_text(boxes, a.low, a.high, true)});
    if (const auto swapped = swap_warning(low.triangle_count(), high.triangle_count(), high.has_uvs(), a.low, a.high))
      warnings.add({*swapped});
    warnings.add(load_warnings(run.low_info, a.low));
    for (std::size_t i = 0; i < a.highs.size(); ++i) {
      warnings.add(load_warnings(run.high_infos[i], a.highs[i]));
      if (o.maps.wants(MapKind::vertex_color) && run.high_infos[i].colors_dropped)
        warnings.add({"warning: " + a.highs[i] + ": " + std::to_string(run.high_infos[i].vertices_without_colors) +
                      " vertices have no colour: all the file's vertex colours were dropped"});
    }
    if (cage_mesh) warnings.add(load_warnings(run.cage_info, a.cage));
    warnings.add(match_warnings(run.match, run.low_objects, run.high_objects, a.low, a.high));
  });
  warnings.check_strict();  // before a long bake
  if (env.interrupted()) throw Cancelled();

  if (env.cache) o.bvh_cache = &loaded->bvh;  // a batch: the next job from this high-poly may trace its BVH
  o.progress = [&](double f) {
    if (env.on_progress) env.on_progress(stage_now, f);
    return env.progress.fraction(f);
  };
  o.on_stage = [&](const char* name) { stage(name); };
  o.keep_trace = a.estimate_error;  // the estimate traces the bake's scene again
  *env.doing = "baking";
  BakeResult r;
  std::optional<UdimBake> udim;
  if (has_udim(a.output)) {
    udim = bake_udim_tiles(low, high, cage_mesh, o);
    r.stats = udim->stats;
    r.cage_positions = udim->cage_positions;  // --save-cage
    run.udim = udim_report(*udim, a.output);
  } else {
    r = bake_normal_map(low, high, cage_mesh, o);
  }
  const BakeStats& s = r.stats;
  if (!a.quiet) env.progress.above([&] { print_distances(s); });
  o.on_stage = nullptr;  // the estimate's re-bake is one stage
  if (env.interrupted()) throw Cancelled();
  ErrorEstimate estimate;
  *env.doing = "estimating the error";
  if (a.estimate_error) {
    stage("estimating the error");
    estimate = estimate_error(low, o, r, udim ? &*udim : nullptr, run, bits, env.progress);
    r.trace_inputs.reset();
    if (udim) udim->trace_inputs.reset();
  }
  // Topology checks are only reported. A bake that computed the high-poly's normals found them on
  // the way; otherwise they run after the bake (and the estimate) have freed the BVH, so that they
  // add nothing to its peak memory: beside the image write, on threads of their own, where the
  // write leaves cores idle (its file and sync); on one thread (--threads 1), before it, so that
  // the command never takes a core --threads did not give it.
  std::future<MeshTopology> topology;
  const std::optional<MeshTopology> checked = loaded->topology;  // an earlier job of the batch's, for this high-poly
  if (!s.prepare.high_topology && !checked) {
    *env.doing = "checking the high-poly's topology";
    if (worker_threads(o.threads) > 1) {
      topology = std::async(std::launch::async, [&high, threads = o.threads] { return inspect_topology(high, threads); });
    } else {
      t0 = Clock::now();
      run.high_topology = inspect_topology(high, o.threads);
      run.seconds_topology = seconds_since(t0);
    }
  }
  // Every output to its temporary file, then all renamed into place together.
  OutputSet outputs;
  *env.doing = "writing the outputs";
  stage("writing", false);  // not redrawn while the encoders' stderr is redirected
  t0 = Clock::now();
  write_outputs(env, outputs, a, o, r, udim ? &*udim : nullptr, low, bits);
  run.seconds_write = seconds_since(t0);
  if (s.prepare.high_topology) {
    run.high_topology = *s.prepare.high_topology;
  } else if (checked) {
    run.high_topology = *checked;
  } else if (topology.valid()) {
    *env.doing = "checking the high-poly's topology";
    t0 = Clock::now();
    run.high_topology = topology.get();
    run.seconds_topology = seconds_since(t0);  // what the check adds after the write
  }
  if (env.cache) loaded->topology = run.high_topology;  // the batch's next job from this high-poly reads it
  if (env.keep_progress) env.progress.hold();
  else env.progress.finish();
  warnings.add(bake_warnings(s, run.high_topology, a.low, a.high, uv_tiles_note(low, a, o.width, o.height),
                             {boxes.mismatched(), &overlap}));
  warnings.add(map_warnings(udim ? (udim->tiles.empty() ? r : udim->tiles.front().result) : r, bits));
  warnings.check_strict();
  run.warnings = warnings.all();
  run.seconds_total = seconds_since(env.start);
  run.peak_memory_bytes = peak_memory_bytes();
  run.threads_used = unsigned(worker_threads(a.threads));
  *env.doing = "writing the report";
  report_job(env, outputs, a, o, run, r, udim ? &*udim : nullptr, a.estimate_error ? &estimate : nullptr);
  outputs.commit(env.interrupted);
  if (!a.quiet) print_summary(a, o, run, s, bits);
}

}  // namespace nmbake
