// nmdiff: compares two tangent-space normal maps by the angle between their normals.
// Parses arguments, reads files and wires them to the pure comparison in nmdiff.h.
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
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

// The command line as given, and the comparison options it sets.
struct CommandLine {
  diff::DiffOptions options;
  std::string path_a, path_b, heatmap_path, json_path, mask_path;
  std::string green_a = "up", green_b = "up", resample = "none";
  bool green_given = false;  // --green-a or --green-b was given: the maps' nmbake:green is not used
  bool same_convention = false;
  double heatmap_scale = 0.0;  // 0 = automatic
  bool ignore_alpha = false;
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

// nmdiff's arguments, bound to the fields of `cl`, and the text of --help.
void add_arguments(CLI::App& app, CommandLine& cl) {
  diff::DiffOptions& options = cl.options;
  app.add_option("A", cl.path_a, "Map to check (e.g. a fresh bake); any format OpenImageIO reads")->required();
  app.add_option("B", cl.path_b, "Reference map (e.g. the golden map)")->required();
  app.add_option("--max-mean", options.tolerances.max_mean_deg, "Tolerance on the mean difference, degrees")
      ->capture_default_str()
      ->check(finite_tolerance);
  app.add_option("--max-p99", options.tolerances.max_p99_deg, "Tolerance on the 99th percentile, degrees")
      ->capture_default_str()
      ->check(finite_tolerance);
  app.add_option("--max-deg", options.tolerances.max_deg, "Tolerance on the largest difference, degrees")
      ->capture_default_str()
      ->check(finite_tolerance);
  app.add_option("--mask", cl.mask_path,
                 "Low-poly mesh (OBJ, PLY, OFF, STL with UVs): compare only texels inside its UV layout, "
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
  apply_choices(cl);
  return std::nullopt;
}

// Map A and map B compared.
struct Comparison {
  DiffStats stats;
  diff::AngleField field;  // filled only when a heatmap is asked for
  bool resized = false;    // B was resampled onto A's grid
  Conventions seen;        // what the maps' metadata said
};

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

// Reads both maps and the --mask mesh (setting cl.options.mask) and compares the maps.
Comparison compare_files(CommandLine& cl) {
  const std::string &path_a = cl.path_a, &path_b = cl.path_b;
  diff::DiffOptions& options = cl.options;
  Comparison c;
  const nmbake::Image a = nmbake::read_image(path_a);
  const nmbake::Image b = nmbake::read_image(path_b);
  diff::check_normal_map(a, path_a);
  diff::check_normal_map(b, path_b);
  c.seen = read_conventions(cl);
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

// Everything nmdiff prints and writes after the comparison, in order: the summary, warnings, the
// heatmap and the JSON (renamed into place together), and the last line.
void report(const CommandLine& cl, const Comparison& c) {
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

}  // namespace

// The comparison's exit status. Messages that cannot be written (a closed or full stdout) change
// neither the status nor the files (protect_standard_streams).
int run(int argc, char** argv) {
  CommandLine cl;
  if (const std::optional<int> status = parse_command_line(argc, argv, cl)) return *status;
  check_outputs(cl);
  const Comparison c = compare_files(cl);
  report(cl, c);
  return verdict_within(c.stats, c.seen) ? kWithin : kOutside;
}

int main(int argc, char** argv) {
  nmbake::protect_standard_streams();
  nmbake::remove_temporaries_on_signals();
  // Errors: 2, also for a bad command line (1 means "outside tolerance"), 3 output, 4 memory.
  return nmbake::run_command([&] { return run(argc, argv); }, {kError, kError, kOutput, kMemory});
}
