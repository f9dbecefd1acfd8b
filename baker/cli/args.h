// The nmbake command's arguments: the options, their help text, and their translation into the
// library's BakeOptions. A batch file's jobs (batch.h) go through the same parser.
#pragma once

#include <string>
#include <vector>

// CLI11's App, declared: CLI/CLI.hpp costs seconds of compile time in every translation unit that
// includes it, so only the .cpp files that parse do.
namespace CLI {
class App;
}  // namespace CLI

#include "cli/numbers.h"
#include "pipeline/bake.h"

namespace nmbake {

// The exit codes, as --help lists them.
extern const char* kExitCodes;

// A jobs file for --batch with what its fields mean, as nmbake --help and nmbake --batch --help
// show it.
extern const char* kBatchExample;

struct Args {
  std::string low, high, output, cage, miss_mask, report, save_cage, suspect_mask;
  std::vector<std::string> highs;  // every HIGH given; `high` names them in messages
  std::string size = "2048";
  std::string samples = "1";     // a count, or "auto" (adaptive)
  double max_error = 0.0;        // --max-error (with --samples auto), when max_error_given
  bool max_error_given = false;  // set after parsing
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
  bool allow_mismatch = false;                 // --allow-mismatch: bake LOW and HIGH whose boxes do not match (pair_checks.h)
  bool allow_overlap = false;                  // --allow-overlap: bake UVs stacked three or more deep
  std::string match = "none", match_suffixes;  // --match, --match-suffixes
  // The texture set (core/maps.h): --maps, and the options of the maps' definitions; *_given set
  // after parsing.
  std::string maps = "normal";
  std::string ao_rays = "64";  // a count, or "auto"
  double ao_distance = 0.0, max_ao_error = 0.0, thickness_distance = 0.0, curvature_scale = 0.0;
  bool ao_distance_given = false, max_ao_error_given = false, thickness_distance_given = false, curvature_scale_given = false;
  int curvature_smoothing = kDefaultCurvatureSmoothing;
  bool curvature_smoothing_given = false;
  std::string ao_occluders = "group", height_range;
};

// The command line's options on `app`, with their help text.
void add_options(CLI::App& app, Args& a);

// What parsing leaves to be set from `app`: `high` (for messages) and whether --front and --rear
// were given.
void finish_args(Args& a, const CLI::App& app);

// The library's options from the flags: translation only (validate_options checks them).
BakeOptions bake_options(const Args& a);

// Fails early, before a long bake, on outputs that cannot be written.
void check_outputs(const Args& a, int bits);

// 1234567 as "1.23M".
std::string human(double v);

}  // namespace nmbake
