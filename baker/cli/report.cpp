#include "cli/report.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "core/errors.h"

namespace nmbake {

const char* to_string(RayPolicy p) { return p == RayPolicy::closest ? "closest" : "cage-first"; }
const char* to_string(NormalSpace s) { return s == NormalSpace::object ? "object" : "tangent"; }
const char* to_string(BitangentMode m) { return m == BitangentMode::per_vertex ? "vertex" : "pixel"; }

std::time_t report_time() {
  const char* epoch = std::getenv("SOURCE_DATE_EPOCH");
  if (epoch && *epoch) {
    char* end = nullptr;
    errno = 0;
    const long long seconds = std::strtoll(epoch, &end, 10);
    if (*end == '\0' && errno == 0 && seconds >= 0) return std::time_t(seconds);
  }
  return std::time(nullptr);
}

std::string utc_time_text(std::time_t t) {
  std::tm utc{};
  char text[32] = "";
  if (gmtime_r(&t, &utc)) std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

std::uint64_t peak_memory_bytes() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return std::uint64_t(ru.ru_maxrss) * 1024;  // Linux reports KiB
}

namespace {

// The high-poly's topology, what the bake left out of it, and each of its files.
void add_high_details(nlohmann::json& report, const BakeStats& s, const RunInfo& r) {
  using json = nlohmann::json;
  const MeshTopology& t = r.high_topology;
  json& high = report["high_mesh"];
  high["welded_vertices"] = t.welded_vertices;
  high["isolated_vertices"] = t.isolated_vertices;
  high["duplicate_faces"] = t.duplicate_faces;
  high["boundary_edges"] = t.boundary_edges;
  high["non_manifold_edges"] = t.non_manifold_edges;
  high["inconsistent_winding_faces"] = t.inconsistent_winding_faces;
  high["triangles_culled"] = s.select.high_triangles_culled;
  high["duplicates_skipped"] = s.select.high_duplicates_skipped;
  report["origin"] = r.origin;
  report["highs"] = r.high_paths;
  json files = json::array();
  for (std::size_t i = 0; i < r.high_paths.size() && i < r.high_infos.size() && i < r.high_triangles.size(); ++i)
    files.push_back({{"file", r.high_paths[i]},
                     {"format", r.high_infos[i].format},
                     {"triangles", r.high_triangles[i]},
                     {"unit_scale", r.high_infos[i].unit_scale}});
  report["high_files"] = files;
}

// Covered texels by how many samples made them: one row for a fixed count; with --samples auto, 4,
// BakeOptions::samples and (when the bake has that level) 4x as many.
// --samples auto judged by the map's size (docs/accuracy.md, "Adaptive sampling"): from 2048^2 it
// bakes the fixed 16-sample bake's error in 31-45% of its time on the accuracy bench's sculpts;
// below, every texel's first 4 samples and the stages every bake has weigh too much.
constexpr int kAdaptivePaysFrom = 2048;

nlohmann::json samples_auto(const BakeOptions& o) {
  if (std::max(o.width, o.height) >= kAdaptivePaysFrom)
    return {{"pays_at_this_size", true},
            {"why",
             "from 2048^2 the refined texels are few among many: the accuracy bench's sculpts reach the "
             "--samples 16 bake's error in 31-45% of its time"}};
  return {{"pays_at_this_size", false},
          {"why",
           "below 2048^2 every texel's first 4 samples and the stages every bake has (load, BVH, padding, "
           "write) take most of the time: 68% (1024^2) to 103% (512^2) of a --samples 16 bake on the accuracy "
           "bench's sculpts; a fixed --samples 4 or 16 costs as little or gives the lower error"}};
}

nlohmann::json samples_histogram(const BakeOptions& o, const BakeStats& s) {
  using nlohmann::json;
  if (!o.adaptive) return json::array({{{"samples", o.samples}, {"texels", s.trace.texels_covered}}});
  json rows = json::array(
      {{{"samples", 4}, {"texels", s.trace.texels_base}}, {{"samples", o.samples}, {"texels", s.trace.texels_refined}}});
  if (4 * o.samples <= kMaxSamples) rows.push_back({{"samples", 4 * o.samples}, {"texels", s.trace.texels_deep}});
  return rows;
}

}  // namespace

nlohmann::json make_report(const BakeOptions& o, const BakeStats& s, const RunInfo& r) {
  using nlohmann::json;
  json options = {
      {"low", r.low_path},
      {"high", r.high_path},
      {"cage", r.cage_path.empty() ? json(nullptr) : json(r.cage_path)},
      {"save_cage", r.save_cage_path.empty() ? json(nullptr) : json(r.save_cage_path)},
      {"output", r.output_path},
      {"miss_mask", r.miss_mask_path.empty() ? json(nullptr) : json(r.miss_mask_path)},
      {"suspect_mask", r.suspect_mask_path.empty() ? json(nullptr) : json(r.suspect_mask_path)},
      {"size", {o.width, o.height}},
      {"samples", o.adaptive ? json("auto") : json(o.samples)},
      {"max_error_deg", o.adaptive ? json(o.max_error_deg) : json(nullptr)},
      {"front", s.distances.front},
      {"rear", s.distances.rear},
      {"front_rear_auto", s.distances.auto_distances},
      {"policy", to_string(o.policy)},
      {"space", to_string(o.space)},
      {"green", o.green_down ? "down" : "up"},
      {"bitangent", to_string(o.bitangent)},
      {"bits", r.bits},
      {"compression", r.compression},
      {"dither", r.dither},
      {"uv_set", r.uv_set},
      {"padding", o.padding},
      {"threads", r.threads_used},
      {"cull", o.cull_far},
      {"keep_backfaces", o.keep_backfaces},
      {"match", r.match.on ? "names" : "none"},
  };
  auto mesh_json = [](const MeshLoadInfo& info, std::size_t triangles) {
    return json{{"format", info.format},
                {"faces", info.file_faces},
                {"triangles", triangles},
                {"polygons_triangulated", info.polygons_triangulated},
                {"normals_renormalized", info.normals_renormalized},
                {"zero_normals", info.zero_normals},
                {"normals_dropped", info.normals_dropped},
                {"faces_without_normals", info.faces_without_normals},
                {"uvs_dropped", info.uvs_dropped},
                {"faces_without_uvs", info.faces_without_uvs},
                {"unit_scale", info.unit_scale}};
  };
  json report = {
      {"nmbake_version", NMBAKE_VERSION},
      {"options", options},
      {"seconds",
       {{"load", r.seconds_load},
        {"prepare", s.prepare.seconds},
        {"bvh", s.bvh.seconds},
        {"distances", s.distances.seconds},
        {"trace", s.trace.seconds},
        {"padding", s.pad.seconds},
        {"topology", r.seconds_topology},
        {"write", r.seconds_write},
        {"total", r.seconds_total}}},
      {"rays", s.trace.rays},
      {"rays_per_second", s.trace.seconds > 0 ? double(s.trace.rays) / s.trace.seconds : 0.0},
      {"samples_covered", s.trace.samples_covered},
      {"samples_histogram", samples_histogram(o, s)},
      {"hits", s.trace.hits},
      {"misses", s.trace.misses},
      {"texels", {{"total", s.trace.texels_total}, {"covered", s.trace.texels_covered}, {"padded", s.pad.texels_padded}}},
      {"coverage", s.trace.coverage},
      {"hit_distance",
       {{"min", s.trace.hit_distance_min}, {"mean", s.trace.hit_distance_mean}, {"max", s.trace.hit_distance_max}}},
      {"auto_distance_probes_beyond", s.distances.auto_probe_beyond},
      {"degenerate",
       {{"uv_triangles", s.prepare.degenerate_uv_triangles},
        {"triangles_3d", s.prepare.degenerate_3d_triangles},
        {"corners_without_tangent", s.prepare.corners_without_tangent}}},
      {"uv_outside_triangles", s.prepare.uv_outside_triangles},
      {"overlapping_samples", s.trace.overlapping_samples},
      {"low_mesh", mesh_json(r.low_info, s.prepare.low_triangles)},
      {"high_mesh", mesh_json(r.high_info, s.prepare.high_triangles)},
      {"high_normals_computed", s.prepare.high_normals_computed()},
      {"peak_memory_bytes", r.peak_memory_bytes},
      {"uv_outside_entirely_triangles", s.prepare.uv_outside_entirely_triangles},
      {"high_faces_reoriented", s.prepare.high_faces_reoriented()},
      {"texels_facing_away", s.pad.texels_facing_away},
      {"backfaces_skipped", s.distances.backfaces_skipped},
      {"backface_skips", s.trace.backface_skips},
      {"backface_probe_share", s.distances.backface_probe_share},
      {"high_facing", s.distances.high_facing == BakeStats::HighFacing::inverted ? "inverted"
                      : s.distances.high_facing == BakeStats::HighFacing::mixed  ? "mixed"
                                                                                 : "sound"},
      {"hits_facing_away", s.trace.hits_facing_away},
      {"suspect_texels", s.pad.suspect_texels},
      {"suspect_share", s.pad.suspect_share},
      {"suspect_region",
       {{"u", {s.pad.suspect_region[0], s.pad.suspect_region[2]}},
        {"v", {s.pad.suspect_region[1], s.pad.suspect_region[3]}},
        {"share", s.pad.suspect_region_share}}},
      {"cage",
       {{"source", s.distances.cage == BakeStats::CageSource::automatic ? "automatic"
                   : s.distances.cage == BakeStats::CageSource::file    ? "file"
                                                                        : "none"},
        {"front",
         {{"min", s.distances.vertex_front.min}, {"mean", s.distances.vertex_front.mean}, {"max", s.distances.vertex_front.max}}},
        {"rear",
         {{"min", s.distances.vertex_rear.min}, {"mean", s.distances.vertex_rear.mean}, {"max", s.distances.vertex_rear.max}}},
        {"scene_front", s.distances.scene_front},
        {"scene_rear", s.distances.scene_rear},
        {"front_limited_vertices", s.distances.cage_front_limited},
        {"rear_limited_vertices", s.distances.cage_rear_limited}}},
      {"coordinate_spacing", s.prepare.coordinate_spacing},
      {"largest_coordinate", s.prepare.largest_coordinate},
  };
  add_high_details(report, s, r);
  add_objects_report(report, r.low_objects, r.high_objects, r.match, s);
  report["udim"] = r.udim;
  report["pair"] = r.pair;
  report["uv_overlap"] = r.uv_overlap;
  report["version"] = NMBAKE_VERSION;
  report["command"] = r.command;
  report["started"] = r.started;
  report["warnings"] = r.warnings;
  report["bvh_reused"] = s.bvh.reused;
  if (o.adaptive) report["samples_auto"] = samples_auto(o);
  report["bvh_quality"] = s.bvh.quality;
  return report;
}

}  // namespace nmbake
