// nmdiff: compares two tangent-space normal maps by the angle between their normals, and the
// texture set's other maps in their own units. Parses arguments, reads files and wires them to the
// pure comparisons in nmdiff.h and map_diff.h (command.h).
#include "command.h"

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli/numbers.h"
#include "cli/shell.h"
#include "core/errors.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "io/output_files.h"
#include "io/text_file.h"
#include "conventions.h"
#include "map_diff.h"
#include "nmdiff.h"

namespace {

namespace diff = nmbake::diff;
using diff::DiffStats;

// Exit status, as documented in --help.
constexpr int kWithin = 0, kOutside = 1, kError = 2, kOutput = 3, kMemory = 4;

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

void print_summary(const std::string& a, const std::string& b, const DiffStats& s, const nmbake::diff::DiffOptions& o,
                   bool resampled, const std::string& resample) {
  std::cout << "nmdiff: " << a << " vs " << b << " (" << s.width << "x" << s.height
            << (resampled ? ", B resampled " + resample : std::string()) << ")\n";
  std::cout << "compared " << s.texels_compared << " texels";
  if (s.padding_compared) std::cout << " (" << s.padding_compared << " of them padding)";
  std::cout << "; skipped " << s.skipped_mask << " outside the mask, " << s.skipped_alpha << " by alpha, " << s.invalid_a
            << " invalid in A, " << s.invalid_b << " invalid in B\n";
  std::cout << "angle (deg): mean " << fmt("%.4f", s.mean_deg) << "  rms " << fmt("%.4f", s.rms_deg) << "  p95 "
            << fmt("%.4f", s.p95_deg) << "  p99 " << fmt("%.4f", s.p99_deg) << "  max " << fmt("%.4f", s.max_deg);
  if (s.worst_x >= 0) std::cout << " at texel (" << s.worst_x << ", " << s.worst_y << ")";
  std::cout << "\nover 1 deg: " << fmt("%.3f", 100 * s.over_1deg) << "%  over 5 deg: " << fmt("%.3f", 100 * s.over_5deg) << "%\n";
  const auto& t = o.tolerances;
  std::cout << "tolerances: mean <= " << t.max_mean_deg << ", p99 <= " << t.max_p99_deg << ", max <= " << t.max_deg << ": "
            << (s.within ? "within" : "OUTSIDE") << "\n";
}

// What the maps' metadata says of their conventions, and nmdiff's verdict on them (conventions.h).
struct Conventions {
  diff::MapConventions a, b;
  diff::ConventionVerdict verdict;
  bool same_convention = false;  // --same-convention
};

// nmdiff's verdict: the angles within tolerance and the conventions the same (exit 0).
bool verdict_within(const DiffStats& s, const Conventions& seen) { return s.within && seen.verdict.differences.empty(); }

nlohmann::json or_null(const std::string& s) { return s.empty() ? nlohmann::json(nullptr) : nlohmann::json(s); }

nlohmann::json to_json(const std::string& a, const std::string& b, const DiffStats& s, const nmbake::diff::DiffOptions& o,
                       const std::string& mask, const std::string& resample, const Conventions& seen) {
  nlohmann::json j;
  j["a"] = a;
  j["b"] = b;
  j["width"] = s.width;
  j["height"] = s.height;
  j["mean_deg"] = s.mean_deg;
  j["rms_deg"] = s.rms_deg;
  j["p95_deg"] = s.p95_deg;
  j["p99_deg"] = s.p99_deg;
  j["max_deg"] = s.max_deg;
  j["over_1deg"] = s.over_1deg;
  j["over_5deg"] = s.over_5deg;
  j["texels_compared"] = s.texels_compared;
  j["worst"] = s.worst_x >= 0 ? nlohmann::json{{"x", s.worst_x}, {"y", s.worst_y}, {"deg", s.max_deg}} : nlohmann::json(nullptr);
  j["within"] = verdict_within(s, seen);  // the verdict: the exit status is 0
  j["within_tolerance"] = s.within;       // the angles alone
  j["tolerances"] = {
      {"max_mean_deg", o.tolerances.max_mean_deg}, {"max_p99_deg", o.tolerances.max_p99_deg}, {"max_deg", o.tolerances.max_deg}};
  j["skipped"] = {{"mask", s.skipped_mask}, {"alpha", s.skipped_alpha}, {"invalid_a", s.invalid_a}, {"invalid_b", s.invalid_b}};
  j["padding_compared"] = s.padding_compared;
  j["nonfinite_texels"] = s.nonfinite_texels;
  j["green_a"] = o.green_a == nmbake::diff::GreenAxis::up ? "up" : "down";
  j["green_b"] = o.green_b == nmbake::diff::GreenAxis::up ? "up" : "down";
  j["green"] = {j["green_a"], j["green_b"]};
  j["green_flipped"] = o.green_a != o.green_b;  // B's green negated to compare in A's convention
  j["green_from"] = seen.verdict.green_from_metadata ? "metadata" : "options";
  j["metadata"] = {{"green", {or_null(seen.a.green), or_null(seen.b.green)}},
                   {"space", {or_null(seen.a.space), or_null(seen.b.space)}}};
  j["convention_differs"] = !seen.verdict.differences.empty();  // then "within" is false
  j["conventions"] = {{"differences", seen.verdict.differences},
                      {"bitangent", {or_null(seen.a.bitangent), or_null(seen.b.bitangent)}},
                      {"same_convention", seen.same_convention}};
  j["resample"] = resample;
  j["mask"] = mask.empty() ? nlohmann::json(nullptr) : nlohmann::json(mask);
  j["warnings"] = s.warnings;
  return j;
}

// The other maps' summary: the same lines as print_summary's, in the map's units.
void print_map_summary(const std::string& a, const std::string& b, const diff::MapDiffStats& s, const diff::MapDiffOptions& o,
                       bool resampled, const std::string& resample) {
  const bool id = diff::map_family(s.kind) == diff::MapFamily::id;
  std::cout << "nmdiff: " << a << " vs " << b << " (" << nmbake::map_name(s.kind) << " maps, " << s.width << "x" << s.height
            << (resampled ? ", B resampled " + (id ? std::string("nearest") : resample) : std::string()) << ")\n";
  std::cout << "compared " << s.texels_compared << " texels";
  if (s.padding_compared) std::cout << " (" << s.padding_compared << " of them padding)";
  std::cout << "; skipped " << s.skipped_mask << " outside the mask, " << s.skipped_alpha << " by alpha\n";
  const auto& t = o.tolerances;
  if (id) {
    std::cout << "colour differs: " << s.texels_differing << " texels (" << fmt("%.4f", 100 * s.share_differing) << "%)";
    if (s.texels_differing) std::cout << ", first at texel (" << s.worst_x << ", " << s.worst_y << ")";
    std::cout << "\ntolerance: share <= " << t.max_share << ": " << (s.within ? "within" : "OUTSIDE") << "\n";
    return;
  }
  std::cout << "absolute difference (" << s.units << "): mean " << fmt("%.6g", s.mean) << "  rms " << fmt("%.6g", s.rms)
            << "  p95 " << fmt("%.6g", s.p95) << "  p99 " << fmt("%.6g", s.p99) << "  max " << fmt("%.6g", s.max);
  if (s.worst_x >= 0) std::cout << " at texel (" << s.worst_x << ", " << s.worst_y << ")";
  std::cout << "\ntolerances: mean <= " << t.max_mean << ", p99 <= " << t.max_p99 << ", max <= " << t.max_abs << ": "
            << (s.within ? "within" : "OUTSIDE") << "\n";
}

nlohmann::json decoding_json(const diff::MapDecoding& d) {
  if (!d.from_metadata) return nullptr;
  nlohmann::json j{{"metadata", d.range_text}};
  if (d.kind == nmbake::MapKind::position) {
    j["offset"] = {d.offset[0], d.offset[1], d.offset[2]};
    j["scale"] = {d.scale[0], d.scale[1], d.scale[2]};
  } else {
    j["offset"] = d.offset[0];
    j["scale"] = d.scale[0];
  }
  return j;
}

// The other maps' statistics; the keys of to_json where they mean the same.
nlohmann::json map_to_json(const std::string& a, const std::string& b, const diff::MapDiffStats& s, const diff::MapDiffOptions& o,
                           const std::string& mask, const std::string& resample) {
  nlohmann::json j;
  j["a"] = a;
  j["b"] = b;
  j["map"] = nmbake::map_name(s.kind);
  j["units"] = s.units;
  j["width"] = s.width;
  j["height"] = s.height;
  j["texels_compared"] = s.texels_compared;
  if (diff::map_family(s.kind) == diff::MapFamily::id) {
    j["texels_differing"] = s.texels_differing;
    j["share_differing"] = s.share_differing;
    j["first_differing"] = s.texels_differing ? nlohmann::json{{"x", s.worst_x}, {"y", s.worst_y}} : nlohmann::json(nullptr);
    j["tolerances"] = {{"max_share", o.tolerances.max_share}};
  } else {
    j["mean"] = s.mean;
    j["rms"] = s.rms;
    j["p95"] = s.p95;
    j["p99"] = s.p99;
    j["max"] = s.max;
    j["worst"] = s.worst_x >= 0 ? nlohmann::json{{"x", s.worst_x}, {"y", s.worst_y}, {"value", s.max}} : nlohmann::json(nullptr);
    j["tolerances"] = {{"max_mean", o.tolerances.max_mean}, {"max_p99", o.tolerances.max_p99}, {"max_abs", o.tolerances.max_abs}};
    j["decoding"] = {{"a", decoding_json(o.decoding_a)}, {"b", decoding_json(o.decoding_b)}};
  }
  j["within"] = s.within;
  j["skipped"] = {{"mask", s.skipped_mask}, {"alpha", s.skipped_alpha}};
  j["padding_compared"] = s.padding_compared;
  j["nonfinite_texels"] = s.nonfinite_texels;
  j["resample"] = resample;
  j["mask"] = mask.empty() ? nlohmann::json(nullptr) : nlohmann::json(mask);
  j["warnings"] = s.warnings;
  return j;
}

// The command line as given, and the comparison options it sets.
struct CommandLine {
  diff::DiffOptions options;
  std::string path_a, path_b, heatmap_path, json_path, mask_path;
  std::string green_a = "up", green_b = "up", resample = "none";
  bool green_given = false;  // --green-a or --green-b was given: the maps' nmbake:green is not used
  bool same_convention = false;
  double heatmap_scale = 0.0;  // 0 = automatic
  bool ignore_alpha = false;
  std::string map_kind;  // --map: "" = from the maps' nmbake:map metadata
  double max_abs = 0.0, max_share = 0.0;
  // Which tolerances the command line gives (the others take their defaults for the map's kind).
  bool mean_given = false, p99_given = false, deg_given = false, abs_given = false, share_given = false;
};

// A tolerance is a finite number of degrees, at least 0 (NaN would make every comparison pass or
// fail by accident).
const CLI::Validator finite_tolerance(
    [](std::string& text) {
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0' || !std::isfinite(v) || v < 0.0)
        return std::string("a tolerance must be a finite number of degrees >= 0, got '") + text + "'";
      return std::string();
    },
    "DEG>=0");

// --max-abs is in the map's units, --max-share a share of texels in [0,1].
CLI::Validator finite_at_least_zero(double most) {
  return CLI::Validator(
      [most](std::string& text) {
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0' || !std::isfinite(v) || v < 0.0 || v > most)
          return std::string("a tolerance must be a finite number from 0") + (std::isinf(most) ? "" : " to 1") + ", got '" +
                 text + "'";
        return std::string();
      },
      std::isinf(most) ? "NUMBER>=0" : "SHARE 0-1");
}

// nmdiff's arguments, bound to the fields of `cl`, and the text of --help.
void add_arguments(CLI::App& app, CommandLine& cl) {
  diff::DiffOptions& options = cl.options;
  app.add_option("A", cl.path_a, "Map to check (e.g. a fresh bake); any format OpenImageIO reads")->required();
  app.add_option("B", cl.path_b, "Reference map (e.g. the golden map)")->required();
  app.add_option("--max-mean", options.tolerances.max_mean_deg,
                 "Tolerance on the mean difference, degrees (other maps: in the map's units, default 0.005 x its range)")
      ->capture_default_str()
      ->check(finite_tolerance);
  app.add_option("--max-p99", options.tolerances.max_p99_deg,
                 "Tolerance on the 99th percentile, degrees (other maps: in the map's units, default 0.01 x its range)")
      ->capture_default_str()
      ->check(finite_tolerance);
  app.add_option("--max-deg", options.tolerances.max_deg, "Tolerance on the largest difference, degrees (normal maps)")
      ->capture_default_str()
      ->check(finite_tolerance);
  app.add_option("--max-abs", cl.max_abs,
                 "Grey maps (ao, thickness, height, curvature, position, vertex-color): tolerance on the largest "
                 "absolute difference, in the map's units (default 0.02 x its range)")
      ->check(finite_at_least_zero(std::numeric_limits<double>::infinity()));
  app.add_option("--max-share", cl.max_share,
                 "ID maps (object-id, material-id): tolerance on the share of texels whose colour differs (default 0)")
      ->check(finite_at_least_zero(1.0));
  app.add_option("--map", cl.map_kind,
                 "Compare as this kind of map, whatever the files' nmbake:map metadata says (needed for maps "
                 "without it; without either, a normal map)")
      ->check(CLI::IsMember({"normal", "object-normal", "ao", "bent-normal", "height", "thickness", "curvature", "position",
                             "object-id", "material-id", "vertex-color"}));
  app.add_option("--mask", cl.mask_path,
                 "Low-poly mesh with UVs (OBJ, PLY, OFF, STL, glTF .gltf/.glb, FBX, DAE: what nmbake reads; its UV set 0): "
                 "compare only texels inside its UV layout, "
                 "rasterized as the baker does, so padding is ignored");
  app.add_flag("--include-padding", options.include_padding,
               "Also compare texels outside the --mask layout and outside alpha coverage");
  app.add_flag("--ignore-alpha", cl.ignore_alpha, "Do not treat a 4th channel as coverage");
  app.add_option("--green-a", cl.green_a,
                 "Green convention of A: up (OpenGL Y+) or down (DirectX Y-). Without --green-a and --green-b, "
                 "when both maps carry nmbake:green metadata and it differs, that is a difference (exit 1)")
      ->capture_default_str()
      ->check(CLI::IsMember({"up", "down"}));
  app.add_option("--green-b", cl.green_b, "Green convention of B: up or down")
      ->capture_default_str()
      ->check(CLI::IsMember({"up", "down"}));
  app.add_flag("--same-convention", cl.same_convention,
               "Maps whose nmbake:green metadata differ are compared in one convention (B's green flipped) "
               "and their nmbake:bitangent is not compared, instead of being a difference");
  app.add_option("--resample", cl.resample,
                 "When sizes differ, bring B onto A's grid: nearest, bilinear or box (mean of the texels "
                 "inside); none = sizes must match")
      ->capture_default_str()
      ->check(CLI::IsMember({"none", "nearest", "bilinear", "box"}));
  app.add_option("--heatmap", cl.heatmap_path,
                 "Write a colour picture of the difference (.png, .tif, .exr): dark violet 0 deg to yellow at "
                 "the scale; dark grey = not compared; legend bar below, its range also in metadata");
  app.add_option("--heatmap-scale", cl.heatmap_scale,
                 "Difference shown as full yellow, degrees; 0 = max(--max-deg, observed p99)")
      ->capture_default_str()
      ->check(finite_tolerance);
  app.add_option("--json", cl.json_path, "Write the statistics as JSON");
  app.footer(
      "Defaults accept 8-bit rounding: a float map against its own 8-bit quantisation differs by at most\n"
      "0.39 deg (mean 0.17 deg on random normals, 0.32 deg everywhere on a flat map); two 8-bit roundings\n"
      "of nearly equal float maps by at most 0.78 deg (p99 0.45 deg).\n"
      "A warning is printed when the maps look like they differ by a green flip or a red/green swap.\n"
      "The last line of output is: mean=<deg> p99=<deg> max=<deg> texels=<n> within=<0|1>\n"
      "Other maps (kind from nmbake:map or --map) compare in their units, decoded with each file's own\n"
      "range (height and position: scene units, curvature: 1/scene units, ao and thickness: a share,\n"
      "vertex-color: RGB 0-1); ID maps by exact colour. Their last line: map=<kind> units=<units>\n"
      "mean=<v> p99=<v> max=<v> texels=<n> within=<0|1> (ID maps: differing=<n> share=<v>).\n"
      "Maps whose nmbake:green, nmbake:space or nmbake:bitangent metadata disagree are a difference:\n"
      "exit 1, said on stderr (with --same-convention green is normalised, different spaces refused).\n"
      "Outputs are checked first (an input or another output: exit 2; a folder, device, FIFO or\n"
      "dangling link: exit 3) and written to temporaries renamed into place only when all are complete.\n"
      "Exit status: 0 within tolerance, 1 outside tolerance, nothing compared, or conventions differ,\n"
      "             2 unreadable or invalid input, or a bad command line, 3 output not written,\n"
      "             4 out of memory, or a map whose header states more pixels than its file or memory can hold.");
}

// Sets cl.options from the words given for the green conventions, the resampling and alpha.
void apply_choices(CommandLine& cl) {
  diff::DiffOptions& options = cl.options;
  const std::string &green_a = cl.green_a, &green_b = cl.green_b, &resample = cl.resample;
  options.green_a = green_a == "down" ? diff::GreenAxis::down : diff::GreenAxis::up;
  options.green_b = green_b == "down" ? diff::GreenAxis::down : diff::GreenAxis::up;
  options.resample = resample == "nearest"    ? diff::Resample::nearest
                     : resample == "bilinear" ? diff::Resample::bilinear
                     : resample == "box"      ? diff::Resample::box
                                              : diff::Resample::none;
  options.use_alpha = !cl.ignore_alpha;
}

// Parses the command line into `cl`. Returns the exit status when nmdiff is to stop there (after
// --help, or with the error printed), nothing when it is to go on.
std::optional<int> parse_command_line(int argc, char** argv, CommandLine& cl) {
  CLI::App app{
      "nmdiff: compare two tangent-space normal maps by the angle between their normals.\n"
      "Texels decode as n = normalize(rgb * 2 - 1); the angle is reported in degrees."};
  add_arguments(app, cl);
  nmbake::require_numbers(app);

  if (const std::optional<int> status = nmbake::parse_command_line(app, argc, argv, "nmdiff")) return status;
  cl.green_given = app.count("--green-a") + app.count("--green-b") > 0;
  cl.mean_given = app.count("--max-mean") > 0;
  cl.p99_given = app.count("--max-p99") > 0;
  cl.deg_given = app.count("--max-deg") > 0;
  cl.abs_given = app.count("--max-abs") > 0;
  cl.share_given = app.count("--max-share") > 0;
  apply_choices(cl);
  return std::nullopt;
}

// Map A and map B compared.
struct Comparison {
  nmbake::MapKind kind = nmbake::MapKind::normal;
  DiffStats stats;         // normal-like maps
  diff::AngleField field;  // filled only when a heatmap is asked for
  bool resized = false;    // B was resampled onto A's grid
  Conventions seen;        // what the maps' metadata said
  // The other maps (diff::map_family not normal): what was compared with what, and how.
  diff::MapDiffOptions map_options;
  diff::MapDiffStats map_stats;
};

bool is_normal_like(const Comparison& c) { return diff::map_family(c.kind) == diff::MapFamily::normal; }

std::string metadata_value(const std::map<std::string, std::string>& metadata, const char* key) {
  const auto it = metadata.find(key);
  return it == metadata.end() ? std::string() : it->second;
}

diff::MapConventions conventions_of(const std::string& path) {
  const auto metadata = nmbake::read_image_metadata(path);
  return {metadata_value(metadata, "nmbake:green"), metadata_value(metadata, "nmbake:space"),
          metadata_value(metadata, "nmbake:bitangent")};
}

// The maps' conventions from their metadata (diff::compare_conventions), the greens to decode
// with set in cl.options, each difference or flip said in one line on stderr.
Conventions read_conventions(CommandLine& cl) {
  Conventions seen{conventions_of(cl.path_a), conventions_of(cl.path_b), {}, cl.same_convention};
  seen.verdict = diff::compare_conventions(seen.a, seen.b, cl.green_given, cl.same_convention);
  const diff::ConventionVerdict& v = seen.verdict;
  if (v.spaces_clash)
    throw nmbake::InputError(cl.path_a + " is a map in " + seen.a.space + " space, " + cl.path_b + " in " + seen.b.space +
                             " space (nmbake:space metadata): normals in different frames cannot be compared");
  if (v.green_from_metadata) {
    cl.options.green_a = v.green_a;
    cl.options.green_b = v.green_b;
    if (v.green_a != v.green_b)
      std::cerr << "nmdiff: " << cl.path_a << " is green " << seen.a.green << ", " << cl.path_b << " green " << seen.b.green
                << " (nmbake:green metadata): compared in one convention, B's green flipped\n";
  }
  if (!v.differences.empty()) {
    if (v.differences.front() == "green") cl.options.detect_convention_mistakes = false;  // the line below says it
    std::cerr << "nmdiff: " << cl.path_a << " and " << cl.path_b << " differ in convention (nmbake metadata): " << v.described
              << "; a difference, compared as they are (--same-convention to compare them in one)\n";
  }
  return seen;
}

// Refuses a tolerance option of another family of maps than `kind`'s (a bad command line, exit 2).
void check_tolerance_options(const CommandLine& cl, nmbake::MapKind kind) {
  const std::string what = cl.path_a + " is " + (cl.map_kind.empty() ? "" : "compared as ") +
                           (nmbake::map_name(kind)[0] == 'a' || nmbake::map_name(kind)[0] == 'o' ? "an " : "a ") +
                           nmbake::map_name(kind) + " map";
  switch (diff::map_family(kind)) {
    case diff::MapFamily::normal:
      if (cl.abs_given || cl.share_given)
        throw nmbake::UsageError(std::string(cl.abs_given ? "--max-abs" : "--max-share") + " is for the other maps: " + what +
                                 " (its tolerances are --max-mean, --max-p99 and --max-deg, degrees)");
      break;
    case diff::MapFamily::grey:
      if (cl.deg_given || cl.share_given)
        throw nmbake::UsageError(std::string(cl.deg_given ? "--max-deg" : "--max-share") + " is not for this map: " + what +
                                 " (its tolerances are --max-mean, --max-p99 and --max-abs, in its units)");
      break;
    case diff::MapFamily::id:
      if (cl.mean_given || cl.p99_given || cl.deg_given || cl.abs_given)
        throw nmbake::UsageError(std::string(cl.mean_given  ? "--max-mean"
                                             : cl.p99_given ? "--max-p99"
                                             : cl.deg_given ? "--max-deg"
                                                            : "--max-abs") +
                                 " is not for this map: " + what + " (compared by exact colour; its tolerance is --max-share)");
      break;
  }
}

// The other maps: decoded with each file's ranges and compared in their units (map_diff.h).
void compare_other_maps(const CommandLine& cl, const nmbake::Image& a, const nmbake::Image& b,
                        const std::map<std::string, std::string>& metadata_a,
                        const std::map<std::string, std::string>& metadata_b, Comparison& c) {
  diff::MapDiffOptions& mo = c.map_options;
  mo.decoding_a = diff::map_decoding(c.kind, metadata_a, cl.path_a);
  mo.decoding_b = diff::map_decoding(c.kind, metadata_b, cl.path_b);
  mo.mask = cl.options.mask;
  mo.use_alpha = cl.options.use_alpha;
  mo.include_padding = cl.options.include_padding;
  mo.resample = cl.options.resample;
  // Defaults from A's range (B's where A has none: the comparison decodes A with it then).
  const bool a_ranged = mo.decoding_a.from_metadata || !mo.decoding_b.from_metadata;
  mo.tolerances = diff::default_map_tolerances(a_ranged ? mo.decoding_a : mo.decoding_b);
  if (cl.mean_given) mo.tolerances.max_mean = cl.options.tolerances.max_mean_deg;
  if (cl.p99_given) mo.tolerances.max_p99 = cl.options.tolerances.max_p99_deg;
  if (cl.abs_given) mo.tolerances.max_abs = cl.max_abs;
  if (cl.share_given) mo.tolerances.max_share = cl.max_share;
  c.map_stats = diff::compare_maps(a, b, mo, cl.heatmap_path.empty() ? nullptr : &c.field);
}

// Reads both maps and the --mask mesh (setting cl.options.mask) and compares the maps.
Comparison compare_files(CommandLine& cl) {
  const std::string &path_a = cl.path_a, &path_b = cl.path_b;
  diff::DiffOptions& options = cl.options;
  Comparison c;
  const nmbake::Image a = nmbake::read_image(path_a);
  const nmbake::Image b = nmbake::read_image(path_b);
  const auto metadata_a = nmbake::read_image_metadata(path_a);
  const auto metadata_b = nmbake::read_image_metadata(path_b);
  c.kind = diff::resolve_map_kind(cl.map_kind, metadata_value(metadata_a, "nmbake:map"), metadata_value(metadata_b, "nmbake:map"),
                                  path_a, path_b);
  check_tolerance_options(cl, c.kind);
  // Both kinds of map: sizes that differ need --resample; --mask's layout at A's size.
  const auto sizes_and_mask = [&] {
    c.resized = a.width != b.width || a.height != b.height;
    if (c.resized && options.resample == diff::Resample::none)
      throw nmbake::InputError("sizes differ: " + path_a + " is " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                               ", " + path_b + " is " + std::to_string(b.width) + "x" + std::to_string(b.height) +
                               " (use --resample nearest|bilinear|box)");
    if (!cl.mask_path.empty()) {
      nmbake::LoadOptions load;
      load.require_uvs = true;
      options.mask = diff::uv_layout_mask(nmbake::load_mesh(cl.mask_path, load), a.width, a.height);
    }
  };
  if (!is_normal_like(c)) {
    sizes_and_mask();
    compare_other_maps(cl, a, b, metadata_a, metadata_b, c);
    return c;
  }
  diff::check_normal_map(a, path_a);
  diff::check_normal_map(b, path_b);
  c.seen = read_conventions(cl);
  sizes_and_mask();

  c.stats = diff::compare_normal_maps(a, b, options, cl.heatmap_path.empty() ? nullptr : &c.field);
  return c;
}

// The heatmap of the angles, with its scale in the metadata, to its temporary in `outputs`.
// Returns the scale.
double write_heatmap(const CommandLine& cl, const Comparison& c, nmbake::OutputFiles& outputs) {
  const double scale = cl.heatmap_scale > 0 ? cl.heatmap_scale : diff::auto_heatmap_scale(c.stats, cl.options.tolerances);
  nmbake::WriteOptions out;
  out.metadata = {{"nmdiff:scale_min_deg", "0"},
                  {"nmdiff:scale_max_deg", fmt("%.6g", scale)},
                  {"nmdiff:legend",
                   "bar under the map: 0 deg at the left, scale_max_deg at the right; "
                   "dark grey texels were not compared"},
                  {"nmdiff:a", cl.path_a},
                  {"nmdiff:b", cl.path_b}};
  out.temp_path = outputs.add(cl.heatmap_path);
  nmbake::write_image(cl.heatmap_path, diff::render_heatmap(c.field, scale), out);
  return scale;
}

// The other maps' heatmap: the absolute differences in the map's units (ID maps: 1 where the colour
// differs), with the scale and units in the metadata, to its temporary in `outputs`. Returns the scale.
double write_map_heatmap(const CommandLine& cl, const Comparison& c, nmbake::OutputFiles& outputs) {
  const diff::MapDiffStats& s = c.map_stats;
  const bool id = diff::map_family(s.kind) == diff::MapFamily::id;
  const double automatic = id ? 1.0 : std::max(c.map_options.tolerances.max_abs, s.p99);
  const double scale = cl.heatmap_scale > 0 ? cl.heatmap_scale : automatic > 0 ? automatic : 1.0;
  nmbake::WriteOptions out;
  out.metadata = {{"nmdiff:map", nmbake::map_name(s.kind)},
                  {"nmdiff:units", s.units},
                  {"nmdiff:scale_min", "0"},
                  {"nmdiff:scale_max", fmt("%.6g", scale)},
                  {"nmdiff:legend",
                   "bar under the map: 0 at the left, scale_max (in units) at the right; "
                   "dark grey texels were not compared"},
                  {"nmdiff:a", cl.path_a},
                  {"nmdiff:b", cl.path_b}};
  out.temp_path = outputs.add(cl.heatmap_path);
  nmbake::write_image(cl.heatmap_path, diff::render_heatmap(c.field, scale, ""), out);
  return scale;
}

// report() for the other maps.
void report_map(const CommandLine& cl, const Comparison& c) {
  const diff::MapDiffStats& s = c.map_stats;
  print_map_summary(cl.path_a, cl.path_b, s, c.map_options, c.resized, cl.resample);
  for (const std::string& w : s.warnings) std::cerr << "warning: " << w << "\n";
  nmbake::OutputFiles outputs;
  const double scale = cl.heatmap_path.empty() ? 0.0 : write_map_heatmap(cl, c, outputs);
  if (!cl.json_path.empty())
    nmbake::write_text_file(cl.json_path, outputs.add(cl.json_path),
                            map_to_json(cl.path_a, cl.path_b, s, c.map_options, cl.mask_path, cl.resample).dump(2) + "\n");
  outputs.commit();
  if (!cl.heatmap_path.empty())
    std::cout << "heatmap: " << cl.heatmap_path << " (0 to " << fmt("%.3g", scale) << " " << s.units << ")\n";
  std::cout << diff::map_summary_line(s) << std::endl;
}

// Everything nmdiff prints and writes after the comparison, in order: the summary, warnings, the
// heatmap and the JSON (renamed into place together), and the last line.
void report(const CommandLine& cl, const Comparison& c) {
  if (!is_normal_like(c)) return report_map(cl, c);
  print_summary(cl.path_a, cl.path_b, c.stats, cl.options, c.resized, cl.resample);
  for (const std::string& w : c.stats.warnings) std::cerr << "warning: " << w << "\n";
  nmbake::OutputFiles outputs;
  const double scale = cl.heatmap_path.empty() ? 0.0 : write_heatmap(cl, c, outputs);
  if (!cl.json_path.empty())
    nmbake::write_text_file(cl.json_path, outputs.add(cl.json_path),
                            to_json(cl.path_a, cl.path_b, c.stats, cl.options, cl.mask_path, cl.resample, c.seen).dump(2) + "\n");
  outputs.commit();
  if (!cl.heatmap_path.empty()) std::cout << "heatmap: " << cl.heatmap_path << " (0 to " << fmt("%.3g", scale) << " deg)\n";
  DiffStats verdict = c.stats;
  verdict.within = verdict_within(c.stats, c.seen);
  std::cout << diff::summary_line(verdict) << std::endl;
}

// Refuses outputs that are inputs or each other (exit 2) or cannot be written (exit 3) before
// anything is read (io/output_files.h).
void check_outputs(const CommandLine& cl) {
  nmbake::check_output_files({{"", cl.path_a, "map A"}, {"", cl.path_b, "map B"}, {"--mask", cl.mask_path, "the mask mesh"}},
                             {{"--heatmap", cl.heatmap_path, "the heatmap"}, {"--json", cl.json_path, "the statistics"}});
  if (!cl.heatmap_path.empty()) nmbake::check_output_format(cl.heatmap_path, 0);
}

// The comparison's exit status. Messages that cannot be written (a closed or full stdout) change
// neither the status nor the files (protect_standard_streams).
int run(int argc, char** argv) {
  CommandLine cl;
  if (const std::optional<int> status = parse_command_line(argc, argv, cl)) return *status;
  check_outputs(cl);
  const Comparison c = compare_files(cl);
  report(cl, c);
  if (!is_normal_like(c)) return c.map_stats.within ? kWithin : kOutside;
  return verdict_within(c.stats, c.seen) ? kWithin : kOutside;
}

}  // namespace

namespace nmbake {

int nmdiff_command(int argc, char** argv) {
  // Errors: 2, also for a bad command line (1 means "outside tolerance"), 3 output, 4 memory.
  return run_command([&] { return run(argc, argv); }, {kError, kError, kOutput, kMemory});
}

std::string nmdiff_json_text(const std::vector<std::string>& words) {
  std::vector<std::string> storage = words;
  std::vector<char*> argv;
  for (std::string& w : storage) argv.push_back(w.data());
  argv.push_back(nullptr);
  CommandLine cl;
  if (parse_command_line(int(storage.size()), argv.data(), cl)) throw UsageError("--help is not a comparison");
  check_outputs(cl);
  const Comparison c = compare_files(cl);
  // What report() writes, without its lines on stdout.
  const nlohmann::json json = is_normal_like(c)
                                  ? to_json(cl.path_a, cl.path_b, c.stats, cl.options, cl.mask_path, cl.resample, c.seen)
                                  : map_to_json(cl.path_a, cl.path_b, c.map_stats, c.map_options, cl.mask_path, cl.resample);
  OutputFiles outputs;
  if (!cl.heatmap_path.empty()) {
    if (is_normal_like(c)) write_heatmap(cl, c, outputs);
    else write_map_heatmap(cl, c, outputs);
  }
  const std::string text = json.dump(2) + "\n";
  if (!cl.json_path.empty()) write_text_file(cl.json_path, outputs.add(cl.json_path), text);
  outputs.commit();
  return text;
}

}  // namespace nmbake
