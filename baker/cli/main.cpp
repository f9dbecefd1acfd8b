// nmbake: the command line. Parses arguments and wires the stages together; nothing else.
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <future>
#include <iostream>
#include <new>
#include <sstream>
#include <string>
#include <system_error>
#include <thread>
#include <tuple>

#include <CLI/CLI.hpp>

#include "pipeline/bake.h"
#include "pipeline/error_estimate.h"
#include "core/errors.h"
#include "core/normals.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "io/text_file.h"
#include "cli/outputs.h"
#include "cli/progress.h"
#include "cli/report.h"
#include "core/parallel.h"
#include "cli/warnings.h"

namespace {

using namespace nmbake;
using Clock = std::chrono::steady_clock;

// The first of SIGINT, SIGTERM and SIGHUP received, or 0. The handler only records it: the bake
// stops at its next progress call, the writes between two files, and the temporaries are removed
// on the way out; once the renames of the finished outputs have begun, the run completes.
std::atomic<int> g_signal{0};
extern "C" void on_signal(int sig) {
  int none = 0;
  g_signal.compare_exchange_strong(none, sig);
}
bool interrupted() { return g_signal.load() != 0; }

void install_signal_handlers() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    // A SIGHUP ignored on entry (nohup) stays ignored.
    if (sig == SIGHUP && ::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    ::sigaction(sig, &action, nullptr);
  }
}

const char* signal_name(int sig) { return sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : "SIGINT"; }

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

struct Args {
  std::string low, high, output, cage, miss_mask, report, save_cage, suspect_mask;
  std::vector<std::string> highs;  // every HIGH given; `high` names them in messages
  std::string size = "2048";
  int samples = 1;
  double front = -1.0, rear = -1.0;
  bool front_given = false, rear_given = false;  // set after parsing: a distance given is never "auto"
  std::string policy = "cage-first", space = "tangent", green = "up", bitangent = "pixel";
  int bits = 0;
  std::string compression;  // --compression: EXR only
  unsigned uv_set = 0;
  bool dither = false;
  int padding = 16;
  int threads = 0;
  int quiet = 0;  // times --quiet was given
  bool no_warnings = false, strict = false, progress = false;
  bool no_cull = false;
  bool keep_backfaces = false;
  bool estimate_error = false;
  std::string match = "none", match_suffixes;  // --match, --match-suffixes
};

void parse_size(const std::string& text, int& w, int& h) {
  auto parse_side = [&](const std::string& s) -> long long {
    if (s.empty() || s.size() > 12 || s.find_first_not_of("0123456789") != std::string::npos)
      throw UsageError("--size: expected N or WxH with whole numbers, got '" + text + "'");
    return std::stoll(s);
  };
  const auto x = text.find_first_of("xX");
  const long long a = parse_side(x == std::string::npos ? text : text.substr(0, x));
  const long long b = x == std::string::npos ? a : parse_side(text.substr(x + 1));
  // Sides beyond an int are clamped: validate_options refuses them.
  w = int(std::min<long long>(a, INT_MAX));
  h = int(std::min<long long>(b, INT_MAX));
}

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
                         "tangent frames follow MikkTSpace (Blender, glTF, Substance, Unity, Unreal).\n\n") +
             kExitCodes);
  app.get_formatter()->column_width(34);
  app.add_option("low", a.low, "Low-poly mesh with UVs")->required();
  app.add_option("high", a.highs, "High-poly mesh (UVs not needed); several: baked as one")->required();
  app.add_option("-o,--output", a.output, "Output map: .png (8-bit), .tif (16-bit), .exr (float)")->required();
  app.add_option("--size", a.size, "Map size N or WxH in texels (default 2048)");
  app.add_option("--samples", a.samples, "Sample points per texel, 1-1024 (default 1)");
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
  app.add_option("--green", a.green, "up = OpenGL/Blender/glTF (default), down = DirectX/Unreal")
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
               "about 10% of a 2048^2 1-sample bake (measured on torus_s3 and suz_L4: 0.13-0.31 s, 6-12% of the command)");
  app.set_version_flag("--version", std::string("nmbake ") + NMBAKE_VERSION);
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
  o.samples = a.samples;
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
  check_output_files(inputs, {{"--output", a.output, "the map"},
                              {"--miss-mask", a.miss_mask, "the miss mask"},
                              {"--suspect-mask", a.suspect_mask, "the suspect mask"},
                              {"--save-cage", a.save_cage, "the cage"},
                              {"--report", a.report, "the report"}});
  check_output_format(a.output, bits);
  if (!a.compression.empty() && image_io_detail::lower_extension(a.output) != ".exr")
    throw UsageError("--compression " + a.compression + " applies to EXR output, not " + a.output);
  if (a.dither && bits != 8)
    throw UsageError("--dither applies to 8-bit output; " + a.output + " is " + std::to_string(bits) + "-bit");
  if (const std::string problem = image_io_problem(); !problem.empty()) {
    if (problem.rfind("out of memory", 0) == 0) throw ResourceError(a.output + ": " + problem);
    throw OutputError(a.output + ": " + problem);
  }
  if (!a.miss_mask.empty()) check_output_format(a.miss_mask, default_bits_for(a.miss_mask));
  if (!a.suspect_mask.empty()) check_output_format(a.suspect_mask, default_bits_for(a.suspect_mask));
}

// One line on how far rays reached, unless --quiet.
void print_distances(const BakeStats& s) {
  if (s.cage == BakeStats::CageSource::automatic)
    std::fprintf(
        stderr,
        "nmbake: automatic cage: front %.3g-%.3g (mean %.3g), rear %.3g-%.3g (mean %.3g) per vertex; limited by a neighbouring "
        "part at %zu and %zu vertices\n",
        s.vertex_front.min, s.vertex_front.max, s.vertex_front.mean, s.vertex_rear.min, s.vertex_rear.max, s.vertex_rear.mean,
        s.cage_front_limited, s.cage_rear_limited);
  else if (s.cage == BakeStats::CageSource::file && s.auto_distances)
    std::fprintf(stderr, "nmbake: rear distances measured per vertex: %.3g-%.3g (mean %.3g)\n", s.vertex_rear.min,
                 s.vertex_rear.max, s.vertex_rear.mean);
  else if (s.auto_distances)
    std::fprintf(stderr, "nmbake: ray distances measured: --front %.6g --rear %.6g (%.2f%% of probes lie beyond)\n", s.front,
                 s.rear, 100.0 * s.auto_probe_beyond);
}

ErrorEstimate estimate_error(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& o, const BakeResult& r,
                             int bits, Progress& progress) {
  ErrorEstimateOptions eo;
  eo.bits = bits;
  const ErrorEstimate estimate = estimate_bake_error(low, high, cage, o, r, eo);
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

// The map, the masks and the cage, each to its temporary file in `outputs`.
void write_outputs(OutputSet& outputs, const Args& a, const BakeOptions& o, const BakeResult& r, const Mesh& low, int bits) {
  auto check_signal = [] {
    if (interrupted()) throw Cancelled();
  };
  WriteOptions wo;
  wo.bits = bits;
  wo.metadata = {
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
  wo.temp_path = outputs.add(a.output);
  write_image(a.output, r.map, wo);
  for (const auto& [path, image] : {std::pair{&a.miss_mask, &r.miss_mask}, std::pair{&a.suspect_mask, &r.suspect_mask}}) {
    if (path->empty()) continue;
    check_signal();
    WriteOptions mo;
    mo.bits = default_bits_for(*path);
    mo.temp_path = outputs.add(*path);
    write_image(*path, *image, mo);
  }
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

void write_report(OutputSet& outputs, const Args& a, const BakeOptions& o, const RunInfo& run, const BakeStats& s,
                  const ErrorEstimate* estimate) {
  nlohmann::json report = make_report(o, s, run);
  if (estimate)
    report["error_estimate"] = {{"mean_deg", estimate->mean_deg},
                                {"p95_deg", estimate->p95_deg},
                                {"max_deg", estimate->max_deg},
                                {"texels", estimate->texels},
                                {"seconds", estimate->seconds}};
  write_text_file(a.report, outputs.add(a.report), report.dump(2) + "\n");
}

void print_summary(const Args& a, const BakeOptions& o, const RunInfo& run, const BakeStats& s, int bits) {
  std::printf(
      "nmbake: wrote %s (%dx%d, %d-bit, %s%s): samples %d, rays %s, misses %llu (%.2f%%), coverage %.1f%%, "
      "seconds: load %.2f prepare %.2f bvh %.2f distances %.2f trace %.2f padding %.2f write %.2f total %.2f\n",
      a.output.c_str(), o.width, o.height, bits, to_string(o.space),
      o.space == NormalSpace::tangent ? (o.green_down ? ", green down" : ", green up") : "", o.samples,
      human(double(s.rays)).c_str(), (unsigned long long)s.misses,
      s.samples_covered ? 100.0 * double(s.misses) / double(s.samples_covered) : 0.0, 100.0 * s.coverage, run.seconds_load,
      s.seconds_prepare, s.seconds_bvh, s.seconds_distances, s.seconds_trace, s.seconds_padding, run.seconds_write,
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
    all.largest_coordinate = std::max(all.largest_coordinate, f.largest_coordinate);
    if (f.unit_scale != all.unit_scale) all.unit_scale = 0.0;  // mixed: high_files gives each
  }
  return all;
}

// What the report says of the run besides the bake's counts (the timings come later).
RunInfo run_info(const Args& a, int argc, char** argv, int bits) {
  RunInfo run;
  run.low_path = a.low;
  run.high_path = a.highs.front();
  run.high_paths = a.highs;
  run.cage_path = a.cage;
  run.output_path = a.output;
  run.miss_mask_path = a.miss_mask;
  run.suspect_mask_path = a.suspect_mask;
  run.bits = bits;
  run.dither = a.dither;
  run.uv_set = a.uv_set;
  if (image_io_detail::lower_extension(a.output) == ".exr") run.compression = a.compression.empty() ? "zip" : a.compression;
  run.command.assign(argv, argv + argc);
  run.started = utc_time_text(report_time());
  return run;
}

// What the command does, for an out-of-memory message ("error: out of memory while writing the
// outputs"); the bake names its own stages.
const char* g_doing = nullptr;

int run(int argc, char** argv) {
  Args a;
  CLI::App app{"nmbake: bake a tangent-space normal map from a high-poly mesh onto a low-poly mesh with UVs.", "nmbake"};
  add_options(app, a);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    throw UsageError(e.what());
  }
  // OpenImageIO loads on its own thread while the meshes are read; not for --help, --version or a
  // command line in error (loading it took 0.37 s of `nmbake --version`).
  preload_image_io();

  a.high = a.highs.front() + (a.highs.size() > 1 ? " and " + std::to_string(a.highs.size() - 1) + " more" : "");
  a.front_given = app.count("--front") > 0;
  a.rear_given = app.count("--rear") > 0;
  const auto start = Clock::now();
  install_signal_handlers();
  BakeOptions o = bake_options(a);
  validate_options(o);  // the library's checks, before a long load
  const int bits = a.bits ? a.bits : default_bits_for(a.output);
  check_outputs(a, bits);
  WarningLog warnings(a.quiet < 2 && !a.no_warnings, a.strict);
  // One line for the whole command, on a terminal or with --progress; never with --quiet.
  Progress progress(!a.quiet && (a.progress || ::isatty(STDERR_FILENO)), start, interrupted);

  // Load.
  RunInfo run = run_info(a, argc, argv, bits);
  g_doing = "loading the meshes";
  progress.stage("loading");
  auto t0 = Clock::now();
  LoadOptions low_opts;
  low_opts.require_uvs = true;
  low_opts.uv_set = a.uv_set;
  Mesh low = load_mesh(a.low, low_opts, &run.low_info);
  run.origin = {low.origin.x, low.origin.y, low.origin.z};
  LoadOptions shared;  // the high-poly and the cage share the low-poly's origin (re-centred when far)
  shared.origin = low.origin;
  std::vector<Mesh> highs;
  for (const std::string& path : a.highs) {
    highs.push_back(load_mesh(path, shared, &run.high_infos.emplace_back()));
    run.high_triangles.push_back(highs.back().triangle_count());
  }
  run.high_info = combined_info(run.high_infos);
  Mesh high = merge_meshes(std::move(highs));
  Mesh cage;
  if (!a.cage.empty()) cage = load_mesh(a.cage, shared, &run.cage_info);
  const Mesh* cage_mesh = a.cage.empty() ? nullptr : &cage;
  run.seconds_load = std::chrono::duration<double>(Clock::now() - t0).count();
  run.low_objects = object_list(low);
  run.high_objects = object_list(high);
  if (a.match == "names") run.match = match_by_names(run.low_objects, run.high_objects, a.match_suffixes, o);
  progress.above([&] {
    warnings.add(load_warnings(run.low_info, a.low));
    for (std::size_t i = 0; i < a.highs.size(); ++i) warnings.add(load_warnings(run.high_infos[i], a.highs[i]));
    if (cage_mesh) warnings.add(load_warnings(run.cage_info, a.cage));
    warnings.add(match_warnings(run.match, run.low_objects, run.high_objects, a.low, a.high));
  });
  warnings.check_strict();  // before a long bake
  if (interrupted()) throw Cancelled();

  o.progress = [&](double f) { return progress.fraction(f); };
  o.on_stage = [&](const char* stage) { progress.stage(stage); };
  g_doing = "baking";
  const BakeResult r = bake_normal_map(low, high, cage_mesh, o);
  const BakeStats& s = r.stats;
  // Topology checks are only reported: they run beside the image write, which uses one core
  // (about 0.3-0.6 s CPU per 400k triangles; beside the bake they took time from its threads).
  auto topology = std::async(std::launch::async, [&high] { return inspect_topology(high); });
  if (!a.quiet) progress.above([&] { print_distances(s); });
  o.on_stage = nullptr;  // the estimate's re-bake is one stage
  if (interrupted()) throw Cancelled();
  ErrorEstimate estimate;
  g_doing = "estimating the error";
  if (a.estimate_error) {
    progress.stage("estimating the error");
    estimate = estimate_error(low, high, cage_mesh, o, r, bits, progress);
  }

  // Every output to its temporary file, then all renamed into place together.
  OutputSet outputs;
  g_doing = "writing the outputs";
  progress.stage("writing", false);  // not redrawn while the encoders' stderr is redirected
  t0 = Clock::now();
  write_outputs(outputs, a, o, r, low, bits);
  run.seconds_write = std::chrono::duration<double>(Clock::now() - t0).count();
  g_doing = "checking the high-poly's topology";
  run.high_topology = topology.get();
  progress.finish();
  warnings.add(bake_warnings(s, run.high_topology, a.low, a.high));
  warnings.check_strict();
  run.warnings = warnings.all();
  run.seconds_total = std::chrono::duration<double>(Clock::now() - start).count();
  run.peak_memory_bytes = peak_memory_bytes();
  run.threads_used = unsigned(worker_threads(a.threads));
  g_doing = "writing the report";
  if (!a.report.empty()) write_report(outputs, a, o, run, s, a.estimate_error ? &estimate : nullptr);
  outputs.commit(interrupted);
  if (!a.quiet) print_summary(a, o, run, s, bits);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // A closed stdout (nmbake ... | head -0) is an error like any other write, not a SIGPIPE death.
  std::signal(SIGPIPE, SIG_IGN);
  int code = 0;
  try {
    code = run(argc, argv);
  } catch (const nmbake::Cancelled&) {
    const int sig = g_signal.load() ? g_signal.load() : SIGINT;
    std::fprintf(stderr, "error: interrupted by %s; no output written\n", signal_name(sig));
    code = 128 + sig;
  } catch (const nmbake::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    code = int(e.code());
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "error: out of memory%s%s\n", g_doing ? " while " : "", g_doing ? g_doing : "");
    code = int(nmbake::ExitCode::memory);
  } catch (const std::system_error& e) {
    // A thread or resource the system would not give (EAGAIN under ulimit -v): out of memory.
    const bool memory = e.code() == std::errc::resource_unavailable_try_again || e.code() == std::errc::not_enough_memory;
    std::fprintf(stderr, "error: %s%s\n", memory ? "out of memory: " : "", e.what());
    code = memory ? int(nmbake::ExitCode::memory) : 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    code = 2;
  }
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    std::fprintf(stderr, "error: stdout: cannot write: %s\n", std::strerror(errno));
    if (code == 0) code = int(nmbake::ExitCode::output);
  }
  wait_for_image_io();  // never exit while the image library's constructors run
  return code;
}
