#include "cli/args.h"

#include <cctype>
#include <charconv>
#include <climits>
#include <cstdio>
#include <filesystem>
#include <tuple>
#include <CLI/CLI.hpp>

#include "cli/map_outputs.h"
#include "cli/outputs.h"
#include "cli/spellings.h"
#include "core/errors.h"
#include "core/object_match.h"
#include "io/image_io.h"
#include "io/mesh_io.h"

namespace nmbake {

namespace {
// N or WxH, each side a whole number of texels or a count of 1024s (4k: cli/spellings.h).
void parse_size(const std::string& text, int& w, int& h) {
  auto parse_side = [&](const std::string& s) -> long long {
    long long texels = 0;
    if (!parse_texel_count(s, texels)) throw UsageError("--size: expected N or WxH with whole numbers, got '" + text + "'");
    return texels;
  };
  const auto x = text.find_first_of("xX");
  const long long a = parse_side(x == std::string::npos ? text : text.substr(0, x));
  const long long b = x == std::string::npos ? a : parse_side(text.substr(x + 1));
  // Sides beyond an int are clamped: validate_options refuses them.
  w = int(std::min<long long>(a, INT_MAX));
  h = int(std::min<long long>(b, INT_MAX));
}

}  // namespace

const char* kBatchExample =
    "Many bakes in one process: nmbake --batch jobs.json (nmbake --batch --help), with jobs.json e.g.\n"
    "  {\"defaults\": {\"size\": 2048, \"samples\": 4},\n"
    "   \"jobs\": [{\"low\": \"crate_low.fbx\", \"highs\": [\"crate_high.obj\"], \"output\": \"crate_normal.png\"},\n"
    "            {\"low\": \"lid_low.fbx\", \"high\": \"lid_high.obj\", \"output\": \"lid_dx.tga\",\n"
    "             \"options\": {\"green\": \"down\", \"report\": \"lid.json\"}}]}\n"
    "Options are the long options without their dashes (a flag: true); a job's options override the\n"
    "defaults; relative paths are relative to the file's folder. The format: docs/usage.md, \"Batch\".\n"
    "On a farm, task I of N bakes its part, nmbake --batch jobs.json --shard I/N --report partI.json, and\n"
    "nmbake --merge-reports part*.json -o batch.json makes the whole report (\"Batches on a farm\").\n";

const char* kExitCodes =
    "Exit codes:\n"
    "  0  success\n"
    "  1  bad command line (also: an output is an input or another output)\n"
    "  2  unreadable or invalid input\n"
    "  3  output could not be written (also: an output is a folder or a special file: device, FIFO, socket)\n"
    "  4  out of memory or refused size\n"
    "  5  warnings with --strict (no output written)\n"
    "  129, 130, 143  interrupted by SIGHUP, SIGINT (Ctrl-C), SIGTERM (no output written)\n"
    "Every output is written to a temporary file (.NAME.nmbake-tmp.PID) beside it and all are renamed\n"
    "into place together at the end: on any error or signal every old file stays as it was. An output\n"
    "that is a symbolic link to a regular file is written through: the link stays, its target changes.\n";

std::string human(double v) {
  char buf[32];
  if (v >= 1e9) std::snprintf(buf, sizeof buf, "%.2fG", v / 1e9);
  else if (v >= 1e6) std::snprintf(buf, sizeof buf, "%.2fM", v / 1e6);
  else if (v >= 1e3) std::snprintf(buf, sizeof buf, "%.1fk", v / 1e3);
  else std::snprintf(buf, sizeof buf, "%.0f", v);
  return buf;
}

// The command line's options, with its help text.
void add_options(CLI::App& app, Args& a) {
  app.footer(std::string("\nInputs: OBJ, PLY (ascii/binary), OFF, STL; glTF (.gltf/.glb), FBX (to metres), DAE, 3DS and\n"
                         "what else Assimp reads. The low-poly must have UVs.\n"
                         "Maps use the OpenGL convention (green = +bitangent, \"Y+\") unless --green down;\n"
                         "tangent frames follow MikkTSpace (Blender, glTF, Substance, Unity, Unreal).\n"
                         "-o normal.<UDIM>.png bakes one map per UDIM tile; -o crate_<MAP>.png --maps normal,ao one\n"
                         "file per map. Spellings: --size 4k (= 4096; 1k, 2k, 8k), --green dx or gl.\n\n") +
             kBatchExample + "\n" + kExitCodes);
  app.get_formatter()->column_width(34);
  app.add_option("low", a.low, "Low-poly mesh with UVs")->required();
  app.add_option("high", a.highs, "High-poly mesh (UVs not needed); several: baked as one")->required();
  app.add_option("-o,--output", a.output,
                 "Output map: .png (8-bit), .tga (8-bit), .tif/.tiff (16-bit), .exr (float); <UDIM> and <MAP> in the name: a map "
                 "per UDIM tile and per --maps name")
      ->required();
  app.add_option("--size", a.size, "Map size N or WxH in texels, a side also as Nk = N x 1024 (1k, 2k, 4k, 8k; default 2048)");
  app.add_option("--samples", a.samples,
                 "Sample points per texel, 1-1024, or auto: 4 per texel, 16 where those disagree, 64 where the 16 do "
                 "(default 1)");
  app.add_option("--max-error", a.max_error,
                 "With --samples auto: refine a texel whose 4 samples lie more than DEG degrees from their mean, and "
                 "again one whose 16 lie more than 4 x DEG (default 4)");
  app.add_option("--front", a.front,
                 "One ray start distance outside the low-poly for the whole scene, scene units (default: the automatic cage, "
                 "measured per vertex)");
  app.add_option("--rear", a.rear,
                 "One ray reach inside the low-poly for the whole scene, scene units (default: measured per vertex)");
  app.add_option("--cage", a.cage,
                 "Cage mesh with the low-poly's topology: rays go from cage to low-poly and on by --rear (default: measured per "
                 "vertex)");
  app.add_option("--save-cage", a.save_cage,
                 "Write the automatic cage (made when --cage, --front and --rear are absent) as OBJ with the low-poly's "
                 "topology and UVs; baking with --cage that file gives the same map");
  app.add_option("--policy", a.policy,
                 "cage-first (default: the first hit from the cage) or closest (the hit nearest the low-poly either way); "
                 "back faces are skipped in both")
      ->check(CLI::IsMember({"cage-first", "closest"}));
  app.add_option("--space", a.space, "tangent (default) or object")->check(CLI::IsMember({"tangent", "object"}));
  app.add_option("--green", a.green,
                 "up = OpenGL/Blender/glTF (default), down = DirectX/Unreal; also gl/opengl and dx/directx, any case")
      ->transform([](const std::string& value) { return canonical_green(value); })
      ->check(CLI::IsMember({"up", "down"}));
  app.add_option("--bitangent", a.bitangent, "pixel = B from interpolated N,T (MikkTSpace, default); vertex = interpolated B")
      ->check(CLI::IsMember({"pixel", "vertex"}));
  app.add_option("--bits", a.bits, "8, 16 or 32 (float); default from the extension")->check(CLI::IsMember({8, 16, 32}));
  app.add_option("--uv-set", a.uv_set, "The low-poly's UV set to bake into, from 0 (glTF, FBX, DAE may have several)")
      ->check(CLI::Range(0u, kMaxUvSets - 1));
  app.add_option("--compression", a.compression, "EXR compression: zip (lossless, default), none, piz (lossless) or dwaa (lossy)")
      ->check(CLI::IsMember({"none", "zip", "piz", "dwaa"}));
  app.add_flag("--dither", a.dither,
               "8-bit output: add triangular noise of one step before rounding (no banding in fine gradients; the same "
               "map whatever the thread count)");
  app.add_option("--match", a.match,
                 "names: bake each low-poly object only from the high-poly objects of the same base name (arm_low from "
                 "arm_high; objects: OBJ o/g, glTF/FBX/DAE nodes); an object without a match is left flat. none (default): "
                 "every ray sees the whole high-poly")
      ->check(CLI::IsMember({"none", "names"}));
  app.add_option("--match-suffixes", a.match_suffixes,
                 "With --match names: LOW:HIGH name suffixes, comma-separated, stripped to find the base name (default "
                 "_low:_high,_lp:_hp; case-insensitive)");
  app.add_option("--padding", a.padding, "Edge padding around UV islands in texels (default 16)");
  app.add_option("--miss-mask", a.miss_mask, "Write an image of the share of missed rays per texel");
  app.add_option("--suspect-mask", a.suspect_mask,
                 "Write an image of the suspect texels (1: normal tilted over 85 degrees from the low-poly's, or samples "
                 "disagreeing; suspect_texels in the report)");
  app.add_option("--report", a.report, "Write a JSON report of options, timings and counts");
  app.add_option("--threads", a.threads, "Worker threads (default: all cores)");
  app.add_flag("--no-cull", a.no_cull,
               "Keep high-poly triangles out of every ray's reach in the BVH (default: left out; same map)");
  app.add_flag("--keep-backfaces", a.keep_backfaces,
               "Take the first hit whatever it faces (default: hits on back faces, the insides of other parts, are passed "
               "over and counted as backface_skips in the report)");
  app.add_flag("--allow-mismatch", a.allow_mismatch,
               "Bake even when LOW and HIGH do not lie in one place or one is 10 or more times the other's size (by "
               "their bounding boxes; default: refused, exit 2, naming both boxes)");
  app.add_flag("--allow-overlap", a.allow_overlap,
               "Bake even when over 10% of the covered texels lie under three or more UV triangles (tiled UVs; default: "
               "refused, exit 2); stacked mirrored halves (two layers) bake without it, the lower face number winning");
  app.add_flag("--progress", a.progress,
               "Show the progress line (each stage, the time since the start, the time left once tracing has run a "
               "second) even when stderr is not a terminal (default: on a terminal only; never with --quiet)");
  app.add_flag("--quiet", a.quiet,
               "No progress line, no summary line, no distances line; warnings still print, one line each (twice: "
               "--quiet --quiet, no warnings either)");
  app.add_flag("--no-warnings", a.no_warnings, "Do not print warnings (they are still in --report's \"warnings\")");
  app.add_flag("--strict", a.strict,
               "Any warning is an error: exit 5, no output written (for CI); warnings of the meshes stop before the bake");
  app.add_flag("--estimate-error", a.estimate_error,
               "Re-bake 4096 random covered texels (fixed seed) with 64 samples (4x --samples if more) and report the "
               "angular error of the float map against them (one stderr line, \"error_estimate\" in --report); costs "
               "about 10% of a 2048^2 1-sample bake");
  app.add_option("--maps", a.maps,
                 "Maps to bake from the same hits, comma-separated (default normal): " + map_name_list() +
                     ". Several need <MAP> in -o (crate_<MAP>.png); docs/usage.md, \"Texture sets\", defines each");
  app.add_option("--ao-rays", a.ao_rays,
                 "Rays per texel for ao, bent-normal and thickness, 1-65536 (default 64), or auto: 32 rays, then more in "
                 "rounds where the texel's standard error is above --max-ao-error (where occlusion is partial), at most 1024");
  app.add_option("--max-ao-error", a.max_ao_error,
                 "With --ao-rays auto: the standard error (0-1 share) at which a texel's rays stop, for ao and bent-normal "
                 "the AO's, for thickness its own (default 0.02: about a fixed 256-ray bake's error)");
  app.add_option("--ao-distance", a.ao_distance,
                 "ao, bent-normal: a ray meeting the high-poly within D scene units is occluded (default 0.1 x the scene's "
                 "diagonal: measured to reach a sculpt's cavities before the whole object darkens itself)");
  app.add_option("--ao-occluders", a.ao_occluders,
                 "With --match names: group (default: only the object's own high-poly objects occlude) or all")
      ->check(CLI::IsMember({"group", "all"}));
  app.add_option("--height-range", a.height_range,
                 "height: A:B, the distances (scene units, outwards positive) written as 0 and 1 (default: the bake's own "
                 "largest distance each way, so 0.5 is the low-poly surface; in the report)");
  app.add_option("--thickness-distance", a.thickness_distance,
                 "thickness: the distance that counts as fully thick, scene units (default 0.2 x the scene's diagonal: "
                 "measured to spread the map most between thin and thick parts)");
  app.add_option("--curvature-scale", a.curvature_scale,
                 "curvature: the mean curvature (1/scene units) written as 0 or 1 (default: the bake's mean + one standard "
                 "deviation of |curvature|, in the report)");
  app.add_option("--curvature-smoothing", a.curvature_smoothing,
                 "curvature: passes of smoothing over the high-poly, each reaching one ring of neighbours further, 0-" +
                     std::to_string(kMaxCurvatureSmoothing) + " (default " + std::to_string(kDefaultCurvatureSmoothing) +
                     ": measured to cut a sculpt's texel-scale noise 4 to 8 times while moving a torus's answer by 0.2 to 3%)");
  app.set_version_flag("--version", std::string("nmbake ") + NMBAKE_VERSION);
  require_numbers(app);
}

// The texture set's options from the flags, each refused where it is absurd or applies to no map
// asked for.
MapOptions map_options(const Args& a) {
  MapOptions m;
  m.maps = parse_maps(a.maps);
  const auto needs = [&](bool given, const char* option, std::initializer_list<MapKind> kinds) {
    if (!given) return;
    for (MapKind k : kinds)
      if (m.wants(k)) return;
    std::string names;
    for (MapKind k : kinds) names += (names.empty() ? "" : " or ") + std::string(map_name(k));
    throw UsageError(std::string(option) + " applies to --maps with " + names);
  };
  const auto distance = [](bool given, double d, const char* option, const char* what = "a distance above 0 in scene units") {
    if (given && !(d > 0.0 && d < kMaxDistance)) {
      char got[32];
      std::snprintf(got, sizeof got, "%g", d);
      throw UsageError(std::string(option) + " must be " + what + ", got " + got);
    }
  };
  needs(a.ao_distance_given, "--ao-distance", {MapKind::ao, MapKind::bent_normal});
  distance(a.ao_distance_given, a.ao_distance, "--ao-distance");
  if (a.ao_distance_given) m.ao_distance = a.ao_distance;
  needs(a.thickness_distance_given, "--thickness-distance", {MapKind::thickness});
  distance(a.thickness_distance_given, a.thickness_distance, "--thickness-distance");
  if (a.thickness_distance_given) m.thickness_distance = a.thickness_distance;
  needs(a.curvature_scale_given, "--curvature-scale", {MapKind::curvature});
  distance(a.curvature_scale_given, a.curvature_scale, "--curvature-scale", "a mean curvature above 0 in 1/scene units");
  if (a.curvature_scale_given) m.curvature_scale = a.curvature_scale;
  needs(a.curvature_smoothing_given, "--curvature-smoothing", {MapKind::curvature});
  if (a.curvature_smoothing_given) {
    if (a.curvature_smoothing < 0 || a.curvature_smoothing > kMaxCurvatureSmoothing)
      throw UsageError("--curvature-smoothing takes a number of rings from 0 to " + std::to_string(kMaxCurvatureSmoothing) +
                       ", got " + std::to_string(a.curvature_smoothing));
    m.curvature_smoothing = a.curvature_smoothing;
  }
  needs(a.ao_rays != "64", "--ao-rays", {MapKind::ao, MapKind::bent_normal, MapKind::thickness});
  if (a.ao_rays == "auto") {
    m.ao_rays_auto = true;
  } else {
    std::size_t used = 0;
    long long n = 0;
    try {
      if (is_number(a.ao_rays, true)) n = std::stoll(a.ao_rays, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != a.ao_rays.size() || n < 1 || n > kMaxAoRays)
      throw UsageError("--ao-rays takes a number of rays (1-" + std::to_string(kMaxAoRays) + ") or auto, got '" +
                       printable(a.ao_rays) + "'");
    m.ao_rays = int(n);
  }
  if (a.max_ao_error_given) {
    if (!m.ao_rays_auto) throw UsageError("--max-ao-error applies to --ao-rays auto");
    if (!(a.max_ao_error > 0.0 && a.max_ao_error < 0.5))
      throw UsageError("--max-ao-error must be a standard error above 0 and below 0.5");
    m.max_ao_error = a.max_ao_error;
  }
  m.ao_occluders_all = a.ao_occluders == "all";
  if (!a.height_range.empty()) {
    needs(true, "--height-range", {MapKind::height});
    const std::size_t colon = a.height_range.find(':');
    const std::string lo = a.height_range.substr(0, colon),
                      hi = colon == std::string::npos ? "" : a.height_range.substr(colon + 1);
    std::size_t u1 = 0, u2 = 0;
    double x = 0.0, y = 0.0;
    try {
      if (is_number(lo, false) && is_number(hi, false)) x = std::stod(lo, &u1), y = std::stod(hi, &u2);
    } catch (const std::exception&) {
      u1 = 0;
    }
    if (u1 == 0 || u1 != lo.size() || u2 != hi.size() || !std::isfinite(x) || !std::isfinite(y))
      throw UsageError("--height-range takes A:B, two distances in scene units, got '" + printable(a.height_range) + "'");
    if (!(x < y)) throw UsageError("--height-range " + a.height_range + ": A must be below B (A is written as 0, B as 1)");
    m.height_range_given = true;
    m.height_min = x, m.height_max = y;
  }
  return m;
}

// The library's options from the flags: translation only (validate_options checks them).
BakeOptions bake_options(const Args& a) {
  BakeOptions o;
  parse_size(a.size, o.width, o.height);
  // A distance given must be one, -1 included (the library reads a negative one as "measure it").
  for (const auto& [given, d, name] : {std::tuple{a.front_given, a.front, "--front"}, std::tuple{a.rear_given, a.rear, "--rear"}})
    if (given && !(d >= 0.0)) {
      char got[32];
      std::snprintf(got, sizeof got, "%g", d);
      throw UsageError(std::string(name) + " must be a distance >= 0 in scene units, got " + got);
    }
  if (a.samples == "auto") {
    o.adaptive = true;
    o.samples = 16;
    if (a.max_error_given) o.max_error_deg = a.max_error;  // validate_options refuses NaN, <= 0 and > 90
  } else {
    std::size_t used = 0;
    try {
      if (is_number(a.samples, true)) o.samples = std::stoi(a.samples, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != a.samples.size())
      throw UsageError("--samples takes a number of samples (1-1024) or auto, got '" + printable(a.samples) + "'");
    if (a.max_error_given) throw UsageError("--max-error applies to --samples auto");
  }
  o.front = a.front_given ? float(a.front) : -1.0f;
  o.rear = a.rear_given ? float(a.rear) : -1.0f;
  o.policy = a.policy == "closest" ? RayPolicy::closest : RayPolicy::cage_first;
  o.space = a.space == "object" ? NormalSpace::object : NormalSpace::tangent;
  o.green_down = a.green == "down";
  o.bitangent = a.bitangent == "vertex" ? BitangentMode::per_vertex : BitangentMode::per_pixel;
  o.padding = a.padding;
  o.threads = a.threads;
  o.miss_mask = !a.miss_mask.empty();
  o.suspect_mask = !a.suspect_mask.empty();
  o.cull_far = !a.no_cull;
  o.keep_backfaces = a.keep_backfaces;
  if (!a.match_suffixes.empty()) {
    if (a.match != "names") throw UsageError("--match-suffixes applies with --match names");
    parse_match_suffixes(a.match_suffixes);  // a malformed list fails before the meshes load
  }
  o.maps = map_options(a);
  return o;
}

// Fails early, before a long bake, on outputs that cannot be written.
void check_outputs(const Args& a, int bits) {
  if (!a.save_cage.empty()) {
    if (!a.cage.empty() || a.front_given || a.rear_given)
      throw UsageError("--save-cage writes the automatic cage, which is made only without --cage, --front and --rear");
    std::string ext = std::filesystem::path(a.save_cage).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".obj") throw UsageError("--save-cage " + a.save_cage + ": the cage is written as OBJ (.obj)");
  }
  std::vector<NamedFile> inputs{{"", a.low, "the low-poly"}, {"--cage", a.cage, "the cage"}};
  for (const std::string& h : a.highs) inputs.push_back({"", h, "the high-poly"});
  const std::vector<MapKind> maps = parse_maps(a.maps);
  check_map_outputs(
      a.output, maps,
      {{"--miss-mask", a.miss_mask}, {"--suspect-mask", a.suspect_mask}, {"--save-cage", a.save_cage}, {"--report", a.report}});
  std::vector<NamedFile> outputs;
  for (MapKind k : maps)  // "the map" when it is the one map
    outputs.push_back(
        {"--output", map_path(a.output, k), maps.size() == 1 ? "the map" : "the " + std::string(map_name(k)) + " map"});
  outputs.insert(outputs.end(), {{"--miss-mask", a.miss_mask, "the miss mask"},
                                 {"--suspect-mask", a.suspect_mask, "the suspect mask"},
                                 {"--save-cage", a.save_cage, "the cage"},
                                 {"--report", a.report, "the report"}});
  check_output_files(inputs, outputs);
  check_output_format(map_path(a.output, maps.front()), bits);
  if (!a.compression.empty() && image_io_detail::lower_extension(a.output) != ".exr")
    throw UsageError("--compression " + a.compression + " applies to EXR output, not " + a.output);
  if (a.dither && bits != 8)
    throw UsageError("--dither applies to 8-bit output; " + a.output + " is " + std::to_string(bits) + "-bit");
  if (!a.miss_mask.empty()) check_output_format(a.miss_mask, default_bits_for(a.miss_mask));
  if (!a.suspect_mask.empty()) check_output_format(a.suspect_mask, default_bits_for(a.suspect_mask));
}

void finish_args(Args& a, const CLI::App& app) {
  a.high = a.highs.front() + (a.highs.size() > 1 ? " and " + std::to_string(a.highs.size() - 1) + " more" : "");
  a.front_given = app.count("--front") > 0;
  a.rear_given = app.count("--rear") > 0;
  a.max_error_given = app.count("--max-error") > 0;
  a.ao_distance_given = app.count("--ao-distance") > 0;
  a.max_ao_error_given = app.count("--max-ao-error") > 0;
  a.thickness_distance_given = app.count("--thickness-distance") > 0;
  a.curvature_scale_given = app.count("--curvature-scale") > 0;
  a.curvature_smoothing_given = app.count("--curvature-smoothing") > 0;
}

}  // namespace nmbake
