// nmbake_accuracy: angular error against run time for map sizes and samples per texel.
//
// For every scene and setting it bakes in-process (bake_normal_map), takes the stage times from
// BakeStats, measures the angular error of the float map at every texel centre (both the bake and
// the reference decoded with the low-poly's tangent frame there), and writes accuracy.csv,
// accuracy.md (with the machine, date and commit) and accuracy.png (error against seconds).
//  - Analytic scenes: the reference is the exact normal, averaged over the texel with a 4x4
//    Gauss-Legendre rule in the low-poly tangent frame (the value an infinitely sampled bake of the
//    analytic surface would hold), so both the sampling error and the high-poly's tessellation
//    show.
//  - Real scenes: the reference is a 64-sample bake at the same size.
//  - Appearance: nmview --compare RMSE of the written map, when nmview is given.
//  - Hard assets (accuracy_hard_assets.h): known-answer models where rays can land on the wrong
//    part, with four hit settings; hard_assets.csv and a section of accuracy.md (hard_assets.md
//    when they run alone).
// The scenes are made in accuracy_scenes.cpp, measured in accuracy_error.cpp and written out in
// accuracy_report.cpp; this file parses the arguments and runs them.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "accuracy_ao.h"
#include "accuracy_error.h"
#include "accuracy_hard_assets.h"
#include "accuracy_report.h"
#include "accuracy_scenes.h"
#include "core/errors.h"
#include "core/tangent_frames.h"
#include "io/image_io.h"
#include "pipeline/bake.h"
#include "tests/build_paths.h"

using namespace nmbake;
using namespace nmbake::bench;
namespace fs = std::filesystem;

namespace {

struct Args {
  bool quick = false;
  bool check = false;  // exit 1 unless every analytic scene's error falls from the first setting to the last
  std::vector<std::string> scenes;
  // --max-errors E[:F],...: the --samples auto rows' thresholds (and deep factors, BakeOptions::deep_factor)
  std::vector<std::pair<double, double>> max_errors{{kDefaultMaxErrorDeg, kDefaultDeepFactor}};
  // The AO rows (scene "ao"): their sculpts, map side, --ao-rays auto thresholds and threads.
  std::vector<std::string> ao_scenes{"suz_L4", "torus_s3"};
  int ao_size = 128, ao_threads = 2;
  std::vector<double> max_ao_errors{0.015, kDefaultMaxAoError, 0.025, 0.03};
  std::string out = "docs/accuracy", data = nmbake::build::shared_data_dir(), nmview = nmbake::build::nmview_exe();
  std::string font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
  std::string command = "nmbake_accuracy";  // the command line as given, for accuracy.md
};

const char* kUsage =
    "usage: nmbake_accuracy [--quick] [--scenes a,b] [--max-errors 1,2:4] [--out DIR] [--data DIR] [--nmview PATH|none] [--font "
    "TTF]\n"
    "       [--ao-scenes a,b] [--ao-size N] [--ao-threads N] [--max-ao-errors 0.01,0.02]\n"
    "Bakes every scene at sizes 512, 1024, 2048 (height_field also 4096) with 1, 4 and 16 samples, and with\n"
    "--samples auto at each --max-errors threshold (default: nmbake's), and writes\n"
    "DIR/accuracy.csv, DIR/accuracy.md and DIR/accuracy.png (default DIR: docs/accuracy).\n"
    "Scenes: height_field, displaced_sphere (analytic), suz_L4, torus_s3 (sculpts), bunny00 (scan; needs --data),\n"
    "hard_assets (the known-answer models of tests/procedural at 512 and 1024 with 1 sample and four hit settings;\n"
    "writes DIR/hard_assets.csv and a section of accuracy.md, or DIR/hard_assets.md when it runs alone),\n"
    "ao (the AO map's error against its rays on --ao-scenes, default suz_L4,torus_s3, at --ao-size, default 128, with\n"
    "--ao-threads, default 2: fixed 8 to 1024 rays and --ao-rays auto at each --max-ao-errors against a 4096-ray\n"
    "reference; writes DIR/ao.{csv,md,png}).\n"
    "--quick: sizes 64 and 128 (real scenes 128, hard assets 256), samples 1 and 4, a coarse sphere: a smoke check of seconds.\n"
    "--check: exit 1 unless on every analytic scene the float error of the largest size and samples is below a\n"
    "quarter of the smallest's (the smoke test in ctest).\n";

// The arguments, with `command` the command line as given; exits on --help and on a bad argument.
// Drops an nmview that is "none" or not executable, and fills in the default scenes.
Args parse_args(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    a.command += " " + s;
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "error: %s needs a value\n%s", s.c_str(), kUsage);
        std::exit(1);
      }
      a.command += std::string(" ") + argv[i + 1];
      return argv[++i];
    };
    if (s == "--quick") a.quick = true;
    else if (s == "--check") a.check = true;
    else if (s == "--scenes") {
      std::stringstream ss(value());
      for (std::string t; std::getline(ss, t, ',');)
        if (!t.empty()) a.scenes.push_back(t);
    } else if (s == "--max-errors") {
      a.max_errors.clear();
      std::stringstream ss(value());
      for (std::string t; std::getline(ss, t, ',');)
        if (!t.empty())
          a.max_errors.push_back({std::atof(t.c_str()), t.find(':') == std::string::npos
                                                            ? kDefaultDeepFactor
                                                            : std::atof(t.c_str() + t.find(':') + 1)});
    } else if (s == "--ao-scenes") {
      a.ao_scenes.clear();
      std::stringstream ss(value());
      for (std::string t; std::getline(ss, t, ',');)
        if (!t.empty()) a.ao_scenes.push_back(t);
    } else if (s == "--max-ao-errors") {
      a.max_ao_errors.clear();
      std::stringstream ss(value());
      for (std::string t; std::getline(ss, t, ',');)
        if (!t.empty()) a.max_ao_errors.push_back(std::atof(t.c_str()));
    } else if (s == "--ao-size") a.ao_size = std::atoi(value().c_str());
    else if (s == "--ao-threads") a.ao_threads = std::atoi(value().c_str());
    else if (s == "--out") a.out = value();
    else if (s == "--data") a.data = value();
    else if (s == "--nmview") a.nmview = value();
    else if (s == "--font") a.font = value();
    else if (s == "--help" || s == "-h") {
      std::printf("%s", kUsage);
      std::exit(0);
    } else {
      std::fprintf(stderr, "error: unknown argument %s\n%s", s.c_str(), kUsage);
      std::exit(1);
    }
  }
  if (a.nmview == "none") a.nmview.clear();
  if (!a.nmview.empty() && ::access(a.nmview.c_str(), X_OK) != 0) {
    std::fprintf(stderr, "nmbake_accuracy: %s not executable: no appearance figures\n", a.nmview.c_str());
    a.nmview.clear();
  }
  if (a.scenes.empty())
    a.scenes = a.quick ? std::vector<std::string>{"height_field", "displaced_sphere", "hard_assets"}
                       : std::vector<std::string>{"height_field", "displaced_sphere", "suz_L4", "torus_s3",
                                                  "bunny00",      "hard_assets",      "ao"};
  return a;
}

// RMSE from the last "psnr=... rmse=... within2=..." line, or < 0 when nmview failed.
double appearance_rmse(const std::string& nmview, const std::string& low, const std::string& map, const std::string& high) {
  // nmview --compare writes no image without --screenshot: the working folder does not matter.
  const std::string out = command_output(shell_quote(nmview) + " " + shell_quote(fs::absolute(low).string()) + " " +
                                         shell_quote(fs::absolute(map).string()) + " " +
                                         shell_quote(fs::absolute(high).string()) + " --compare --size 800x400 2>/dev/null");
  // The last line starting "psnr=": its first rmse= (the interior's; union_rmse= comes later).
  const std::size_t nl = out.rfind("\npsnr=");
  const std::size_t line = nl != std::string::npos ? nl + 1 : out.rfind("psnr=", 0) == 0 ? 0 : std::string::npos;
  if (line == std::string::npos) return -1.0;
  const std::size_t pos = out.find(" rmse=", line);
  if (pos == std::string::npos) return -1.0;
  return std::atof(out.c_str() + pos + 6);
}

// The scene called `name`, or nothing (with a line on stderr) when it is unknown or its data is missing.
std::optional<AccuracyScene> load_scene(const Args& a, const std::string& name) {
  if (name == "height_field") return height_field_scene(a.quick);
  if (name == "displaced_sphere") return displaced_sphere_scene(a.quick);
  if (name == "suz_L4" || name == "torus_s3" || name == "suz_L3" || name == "torus_demo") {
    if (!fs::exists(a.data + "/sculpts/" + name)) {
      std::fprintf(stderr, "nmbake_accuracy: skipping %s: %s/sculpts/%s not found\n", name.c_str(), a.data.c_str(), name.c_str());
      return std::nullopt;
    }
    return sculpt_scene(a.data, name, a.quick);
  }
  if (fs::exists(a.data + "/meshes/cgal/" + name + ".off")) return scan_scene(a.data, name + ".off", a.quick);
  std::fprintf(stderr, "nmbake_accuracy: skipping %s: unknown scene or data not found under %s\n", name.c_str(), a.data.c_str());
  return std::nullopt;
}

// What one size of a scene is measured against.
struct SizeReference {
  std::vector<TexelRef> refs;
  BakeResult bake;                 // the 64-sample bake (real scenes)
  double seconds = 0;              // building it
  double floor8 = 0, floor16 = 0;  // analytic scenes: quantisation floors, degrees
};

SizeReference make_reference(const AccuracyScene& sc, const TangentFrames& frames, const BakeOptions& o) {
  const auto t0 = Clock::now();
  SizeReference ref;
  if (sc.analytic) {
    ref.refs = texel_references(sc.low, frames, o.width, o.height, &sc.analytic);
    ref.floor8 = quantization_floor(ref.refs, frames, 8);
    ref.floor16 = quantization_floor(ref.refs, frames, 16);
  } else {
    BakeOptions ro = o;
    ro.samples = 64;
    ref.bake = bake_normal_map(sc.low, sc.high, nullptr, ro);
    ref.refs = texel_references(sc.low, frames, o.width, o.height, nullptr);
  }
  ref.seconds = since(t0);
  return ref;
}

// Bakes `sc` with `o`, measures the map (and, with nmview, its appearance) against `ref` at each
// bit depth, and adds a row per bit depth.
void bake_setting(const Args& a, const AccuracyScene& sc, const BakeOptions& o, const TangentFrames& frames,
                  const SizeReference& ref, const std::string& work, AccuracyResults& res) {
  auto t0 = Clock::now();
  BakeResult r = bake_normal_map(sc.low, sc.high, nullptr, o);
  const double wall = since(t0);
  AccuracyRow row;
  row.scene = sc.name;
  row.reference = sc.reference;
  row.size = o.width;
  row.samples = o.samples;
  row.adaptive = o.adaptive;
  row.max_error = o.max_error_deg;
  row.deep_factor = o.deep_factor;
  const double texels = double(r.stats.trace.texels_base + r.stats.trace.texels_refined + r.stats.trace.texels_deep);
  row.refined = texels > 0 ? double(r.stats.trace.texels_refined + r.stats.trace.texels_deep) / texels : 0.0;
  row.deep = texels > 0 ? double(r.stats.trace.texels_deep) / texels : 0.0;
  row.rays = r.stats.trace.rays;
  row.misses = r.stats.trace.misses;
  row.prepare = r.stats.prepare.seconds;
  row.bvh = r.stats.bvh.seconds;
  row.distances = r.stats.distances.seconds;
  row.trace = r.stats.trace.seconds;
  row.padding = r.stats.pad.seconds;
  row.total = wall;
  row.reference_seconds = ref.seconds;
  const Image* ref_map = sc.analytic ? nullptr : &ref.bake.map;
  if (!a.nmview.empty() && !sc.high_file.empty()) {
    const std::string map_path = work + "/map.png";
    WriteOptions wo;
    wo.bits = 16;
    write_image(map_path, r.map, wo);
    t0 = Clock::now();
    row.appearance = appearance_rmse(a.nmview, sc.low_file, map_path, sc.high_file);
    res.appearance_seconds += since(t0);
  }
  for (int bits : sc.quantization_runs ? std::vector<int>{32, 16, 8} : std::vector<int>{32}) {
    row.bits = bits;
    row.err = measure(r.map, r.coverage, ref.refs, ref_map, frames, bits);
    res.rows.push_back(row);
    std::fprintf(stderr,
                 "  %-16s %4d x %-2s %2d-bit  mean %.4f  rms %.4f  p95 %.4f  max %.3f deg  >1deg %.2f%%  misses %llu  "
                 "trace %.2f s  total %.2f s  %.2f Mrays/s%s\n",
                 sc.name.c_str(), row.size, row.sampling().c_str(), bits, row.err.mean, row.err.rms, row.err.p95, row.err.max,
                 100 * row.err.over1, (unsigned long long)row.misses, row.trace, row.total,
                 row.trace > 0 ? 1e-6 * double(row.rays) / row.trace : 0.0,
                 row.appearance >= 0 ? (" appearance rmse " + fmt("%.5f", row.appearance)).c_str() : "");
  }
}

// Every size and sample count of one scene; the analytic scenes' quantisation floors.
void bake_scene(const Args& a, AccuracyScene& sc, const std::string& work, AccuracyResults& res) {
  const std::vector<int> sample_counts = a.quick ? std::vector<int>{1, 4} : std::vector<int>{1, 4, 16};
  if (!a.nmview.empty()) {
    if (sc.low_file.empty()) write_scene_obj(sc.low_file = work + "/" + sc.name + "_low.obj", sc.low);
    if (sc.high_file.empty()) write_scene_ply(sc.high_file = work + "/" + sc.name + "_high.ply", sc.high);
  }
  const TangentFrames frames = compute_tangent_frames(sc.low);
  double f8 = 0, f16 = 0;
  for (int size : sc.sizes) {
    BakeOptions o;
    o.width = o.height = size;
    o.front = sc.front;
    o.rear = sc.rear;
    const SizeReference ref = make_reference(sc, frames, o);
    f8 += ref.floor8 / double(sc.sizes.size());
    f16 += ref.floor16 / double(sc.sizes.size());
    for (int samples : sample_counts) {
      if (size >= 4096 && samples > 4) continue;  // 268M rays: minutes on 2 cores for a point that says nothing new
      o.samples = samples;
      bake_setting(a, sc, o, frames, ref, work, res);
    }
    if (size >= 4096) continue;
    for (const auto& [e, deep] : a.max_errors) {
      BakeOptions ao = o;
      ao.adaptive = true;
      ao.samples = 16;
      ao.max_error_deg = e;
      ao.deep_factor = deep;
      bake_setting(a, sc, ao, frames, ref, work, res);
    }
  }
  if (sc.analytic) res.floor8[sc.name] = f8, res.floor16[sc.name] = f16;
}

AccuracyResults run_scenes(const Args& a, const std::string& work, Clock::time_point start, AoResults& ao) {
  AccuracyResults res;
  for (const std::string& name : a.scenes) {
    const auto t0 = Clock::now();
    if (name == "ao") {
      for (const std::string& scene : a.ao_scenes) {
        std::optional<AccuracyScene> sc = load_scene(a, scene);
        if (!sc) continue;
        std::fprintf(stderr, "nmbake_accuracy: ao on %s: %s\n", sc->name.c_str(), sc->description.c_str());
        run_ao_rows(*sc, a.ao_size, a.max_ao_errors, a.ao_threads, ao);
      }
      std::fprintf(stderr, "nmbake_accuracy: ao done in %.0f s, %.0f s since the start\n", since(t0), since(start));
      continue;
    }
    if (name == "hard_assets") {
      res.hard_rows = run_hard_assets(a.quick ? std::vector<int>{256} : std::vector<int>{512, 1024}, res.hard_notes);
      res.hard_seconds = since(t0);
      std::fprintf(stderr, "nmbake_accuracy: hard_assets done in %.0f s, %.0f s since the start\n", res.hard_seconds,
                   since(start));
      continue;
    }
    std::optional<AccuracyScene> sc = load_scene(a, name);
    if (!sc) continue;
    std::fprintf(stderr, "nmbake_accuracy: %s: %s (set up in %.1f s)\n", sc->name.c_str(), sc->description.c_str(), since(t0));
    res.notes.push_back("`" + sc->name + "`: " + sc->description + "; reference: " + sc->reference + ".");
    bake_scene(a, *sc, work, res);
    std::fprintf(stderr, "nmbake_accuracy: %s done, %.0f s since the start\n", sc->name.c_str(), since(start));
  }
  return res;
}

}  // namespace

int main(int argc, char** argv) {
  RunInfo info;
  info.load_at_start = load_average();
  const Args a = parse_args(argc, argv);
  info.command = a.command;
  info.nmview = !a.nmview.empty();
  const auto start = Clock::now();
  info.commit = git_commit();
  info.date = utc_now();
  try {
    fs::create_directories(a.out);
    const std::string work = (fs::path(a.out) / ".work").string();
    if (!a.nmview.empty()) fs::create_directories(work);
    AoResults ao;
    const AccuracyResults res = run_scenes(a, work, start, ao);
    if (!a.nmview.empty()) fs::remove_all(work);
    info.seconds = since(start);
    if (!ao.rows.empty()) {
      write_ao_files(a.out, ao, info, a.font);
      std::fprintf(stderr, "nmbake_accuracy: wrote %s/ao.{csv,md,png}; %zu rows\n", a.out.c_str(), ao.rows.size());
      if (res.rows.empty() && res.hard_rows.empty()) return 0;
    }
    const std::string md_name = write_accuracy_files(a.out, res, info, a.font);
    std::fprintf(stderr, "nmbake_accuracy: wrote %s/%s; %zu rows%s in %.0f s\n", a.out.c_str(),
                 res.rows.empty() ? md_name.c_str() : "accuracy.{csv,md,png}", res.rows.size(),
                 res.hard_rows.empty() ? "" : (", hard_assets.csv (" + std::to_string(res.hard_rows.size()) + " rows)").c_str(),
                 info.seconds);
    if (a.check && !check_error_falls(res.rows)) return 1;
  } catch (const Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return int(e.code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 0;
}
