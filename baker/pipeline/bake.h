// bake_normal_map: the whole bake on in-memory meshes, from tangent frames to padded map.
//
// For every sample point of every texel covered by the low-poly's UV layout it finds the low-poly
// point P and ray normal N, casts a ray onto the high-poly (policy below), interpolates the
// high-poly normal at the hit with the hit's own barycentrics, and expresses it in the low-poly
// tangent frame at P (the exact inverse of the renderer's decoding, tangent_frames.h). A texel's
// value is the renormalized mean of its covered samples; uncovered texels are filled by padding.
// Conventions: ../shared/docs/baking.md. Meshes are never rotated or scaled; internally all
// coordinates are re-centred on the scene's bounding-box centre for precision.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/image.h"
#include "core/maps.h"
#include "core/mesh.h"
#include "core/mesh_topology.h"
#include "core/tangent_frames.h"

namespace nmbake {

enum class RayPolicy {
  cage_first,  // start at P + front*N (or on the cage), travel inward to rear, first hit wins
  closest,     // cast outward up to front and inward up to rear from P, nearest hit wins
};

enum class NormalSpace { tangent, object };

constexpr int kMaxMapSide = 65536;  // texels per side; larger maps are refused (ResourceError)
constexpr int kMaxSamples = 1024;   // sample points per texel
constexpr int kMaxThreads = 1024;
constexpr double kMaxDistance = 1e30;  // --front, --rear: scene units
// Largest |coordinate| of a mesh, and of a ray's start (coordinate + --front + --rear), a bake
// takes: Embree asserts (aborts) on ray origins beyond 1.8e18, and float geometry there has no
// digits left for a map anyway.
constexpr double kMaxCoordinate = 1e17;
constexpr double kCoordinateSpacingWarn = 1e-3;  // BakeStats::Prepare::coordinate_spacing above this: warn
// BakeStats::Distances::backface_probe_share above which the high-poly is taken as inverted, and above which
// (up to the first) as partly inverted, when back faces are kept.
constexpr double kInvertedShare = 0.5;
// Suspect texels (BakeStats::Pad::suspect_texels): the tilt from the low-poly normal above which, and
// the length of the mean of a texel's unit sample values below which, a texel is suspect; the
// share of covered texels above which nmbake warns.
constexpr double kSuspectTiltDeg = 85.0;
constexpr double kSuspectAgreement = 0.8;
constexpr double kSuspectShareWarn = 0.005;
constexpr double kMixedShare = 0.2;
// BakeOptions::low_object_group: a low-poly object matched to no high-poly object.
constexpr std::uint32_t kNoMatch = 0xffffffffu;

struct KeptBvh;  // pipeline/bvh.h

// A high-poly's BVH kept for the next bakes from the same high-poly (nmbake --batch). The first
// bake given an empty cache builds its BVH over every triangle (none culled: the map is the same)
// and keeps it; a later bake whose high-poly has the same content (positions and faces) and whose
// scene has the same centre and diagonal (its low-poly lies within the high-poly's bounds, or is
// the same) traces that BVH instead of building one. The maps are the same either way.
struct BvhCache {
  std::shared_ptr<const KeptBvh> kept;  // null until a bake keeps its BVH
  std::size_t reused = 0;               // bakes that took it
};

// --max-error's default (BakeOptions::max_error_deg) and the third level's factor, chosen on the
// accuracy bench's real scenes (docs/accuracy.md): the fixed 16-sample bake's mean error in well
// under half its time; lower thresholds cost more time, higher ones more error.
inline constexpr double kDefaultMaxErrorDeg = 4.0;
inline constexpr double kDefaultDeepFactor = 4.0;  // BakeOptions::deep_factor

struct BakeOptions {
  int width = 2048;   // map width in texels
  int height = 2048;  // map height in texels
  int samples = 1;    // sample points per texel; 1 = the texel centre only (no AA loop)
  // --samples auto: each texel first takes 4 samples at the 2x2 Gauss-Legendre points (exact for
  // a normal that varies smoothly, up to cubic terms, across the texel); a texel whose samples
  // disagree (one lies more than max_error_deg from their mean, or some miss and some hit), or
  // that an island's edge cuts, is baked again with `samples` stratified samples (a square number,
  // 16 by default), exactly as a fixed bake with that many gives it, and one whose `samples` still
  // disagree (deep_factor below) a third time with 4x as many. BakeStats::Trace::texels_refined and
  // texels_deep count them.
  bool adaptive = false;
  double max_error_deg = kDefaultMaxErrorDeg;  // with adaptive: the disagreement that refines a texel, degrees
  // With adaptive: a texel whose `samples` samples still lie farther than deep_factor * max_error_deg
  // from their mean (or some miss) is baked a third time with 4 * samples (when that is at most
  // kMaxSamples); <= 0: no third level.
  double deep_factor = kDefaultDeepFactor;
  float front = -1.0f;  // scene units the ray starts outside the low-poly; < 0 = auto (measured)
  float rear = -1.0f;   // scene units the ray reaches inside the low-poly; < 0 = auto (measured)
  RayPolicy policy = RayPolicy::cage_first;
  NormalSpace space = NormalSpace::tangent;
  bool green_down = false;  // DirectX "Y-" maps: negate the bitangent component
  BitangentMode bitangent = BitangentMode::per_pixel;
  int padding = 16;           // texels of edge padding around islands; 0 = none
  int threads = 0;            // worker threads; 0 = all cores
  bool miss_mask = false;     // fill BakeResult::miss_mask (share of missed samples per texel)
  bool suspect_mask = false;  // fill BakeResult::suspect_mask (1 for suspect texels, BakeStats::Pad::suspect_texels)
  // Leave high-poly triangles out of the BVH when they lie farther from the low-poly (and cage)
  // than any ray reaches (cull.h). The map is the same either way; off only for comparison.
  bool cull_far = true;
  // Take the first hit along the ray whatever it faces (earlier nmbake's rule). By default a hit on
  // a back face (the inside of some part of the high-poly, judged against the side the low-poly's
  // normal points to) is passed over for the next one, and a hit whose normal points away from the
  // low-poly's outside is taken only when the ray finds no other (raycast::HitRule).
  bool keep_backfaces = false;
  // Bytes the bake's buffers may take (estimate_bake_bytes); 0 = what the machine has
  // (memory_budget_bytes: MemAvailable, cgroup limit, ulimit -v). Larger bakes are refused.
  std::uint64_t memory_limit = 0;
  // Matching (--match names): per object of the low-poly and of the high-poly (Mesh::objects), its
  // group. A low-poly object's rays see only the high-poly objects of its group; one in kNoMatch
  // casts no ray and is written flat (counted in BakeStats::Trace::samples_unmatched). Empty: no matching,
  // every ray sees the whole high-poly. The probes that measure the distances see all of it.
  std::vector<std::uint32_t> low_object_group, high_object_group;
  // A BVH to reuse or to keep for later bakes from the same high-poly (BvhCache); null: none.
  BvhCache* bvh_cache = nullptr;
  // Keep what the trace read in BakeResult::trace_inputs (UdimBake's), for the error estimate.
  bool keep_trace = false;
  // The maps to bake and their definitions' options (core/maps.h). The normal map is always
  // traced (BakeResult::map); every other map asked for comes in BakeResult::maps.
  MapOptions maps;
  // Called from the calling thread with the fraction done in [0,1]; return false to cancel
  // (bake_normal_map then throws Cancelled).
  std::function<bool(double)> progress;
  // Called from the calling thread as each stage begins: "preparing", "building the BVH",
  // "measuring distances", "tracing", "padding" (a progress line names them).
  std::function<void(const char*)> on_stage;
};

// What a bake found and did, grouped by stage (docs/layout.md: prepare, select, BVH, distances,
// trace, pad).
struct BakeStats {
  enum class HighFacing { sound, inverted, mixed };
  // Where rays start: a cage from a file, the automatic cage (no --cage, --front or --rear), or
  // none (one fixed distance for the scene).
  enum class CageSource { none, automatic, file };
  struct Range {
    double min = 0.0, mean = 0.0, max = 0.0;
  };

  struct Prepare {
    std::size_t low_triangles = 0, high_triangles = 0;
    glm::dvec3 centre{0.0};  // subtracted from every coordinate before tracing (bounding-box centre)
    std::size_t degenerate_uv_triangles = 0, degenerate_3d_triangles = 0, corners_without_tangent = 0;
    std::size_t uv_outside_triangles = 0;           // low-poly triangles with a UV outside [0,1]
    std::size_t uv_outside_entirely_triangles = 0;  // of those, UV bounding box outside [0,1]^2: not baked
    // The high-poly's topology checks (inspect_topology), found on the way when its normals were
    // computed (it had none); empty when the file's normals were used.
    std::optional<MeshTopology> high_topology;
    bool high_normals_computed() const { return high_topology.has_value(); }
    // Computed high-poly normals: faces turned to their piece's winding.
    std::size_t high_faces_reoriented() const { return high_topology ? high_topology->inconsistent_winding_faces : 0; }
    // Float spacing at the largest (referenced) coordinate of the inputs, relative to the scene
    // diagonal: the precision the meshes themselves carry. Above kCoordinateSpacingWarn the map
    // degrades measurably (data/stability/README.md, case 5).
    double coordinate_spacing = 0.0;
    double largest_coordinate = 0.0;  // largest |x|, |y| or |z| of a position a face uses
    double seconds = 0;
  } prepare;

  struct Select {
    std::size_t high_triangles_culled = 0;    // left out of the BVH: out of every ray's reach
    std::size_t high_duplicates_skipped = 0;  // of those, repeats in a stack of identical triangles (select.h)
  } select;

  struct Bvh {
    const char* quality = "medium";  // of the BVH traced: "low", "medium" or "high" (bvh_quality_for, bvh.h)
    bool reused = false;             // the BVH of an earlier bake from the same high-poly (BakeOptions::bvh_cache)
    double seconds = 0;              // select, BVH and narrow
  } bvh;

  struct Distances {
    float front = 0.0f, rear = 0.0f;  // distances used (scene units)
    bool auto_distances = false;      // front/rear were measured, not given
    double auto_probe_beyond = 0.0;   // share of probe points farther than the chosen distances
    // The distances measured for the whole scene (1.25 x the 99.9th percentile of the probes'
    // nearest facing hits, each side), which every vertex of the automatic cage gets at least; 0
    // when not measured.
    double scene_front = 0.0, scene_rear = 0.0;
    CageSource cage = CageSource::none;
    // Per low-poly vertex (file vertex) distances, scene units: front with the automatic cage, rear
    // with it and with a file's cage when --rear is not given (else all 0).
    Range vertex_front, vertex_rear;
    // Welded vertices whose measured front or rear need was cut by the limit (half the distance to
    // the next part of the low-poly along the normal).
    std::size_t cage_front_limited = 0, cage_rear_limited = 0;
    // Probes from the low-poly both ways along its normals: of those that hit, the share whose
    // nearest hit is a back face. Near 0 on a sound high-poly; near 1 when its winding and normals
    // are inverted (then the faces' fronts are taken the other way round, and computed normals are
    // turned outwards); in between, when only some parts are inverted, back faces are kept.
    double backface_probe_share = 0.0;
    HighFacing high_facing = HighFacing::sound;
    // The hit rule (BakeOptions::keep_backfaces): whether it was applied, and why not.
    bool backfaces_skipped = false;
    double seconds = 0;
  } distances;

  struct Trace {
    std::uint64_t rays = 0, hits = 0, misses = 0;  // misses/hits count samples, rays count casts
    std::uint64_t samples_covered = 0;
    // Covered samples of low-poly objects without a match (BakeOptions::low_object_group): written
    // flat, no ray cast; they count as neither hits nor misses.
    std::uint64_t samples_unmatched = 0;
    std::uint64_t overlapping_samples = 0;  // samples covered by more than one UV triangle
    // With BakeOptions::adaptive: covered texels baked with the first 4 samples only, those baked
    // again with BakeOptions::samples, and those baked a third time with 4x as many (the report's
    // sample count histogram).
    std::uint64_t texels_base = 0, texels_refined = 0, texels_deep = 0;
    std::size_t texels_total = 0, texels_covered = 0;
    double coverage = 0.0;  // texels_covered / texels_total
    // Signed distance from the low-poly surface to the hit along the ray (positive: in front of /
    // outside the low-poly), over all hits.
    double hit_distance_min = 0.0, hit_distance_mean = 0.0, hit_distance_max = 0.0;
    // Rays whose first hit was a back face, passed over for the next hit.
    std::uint64_t backface_skips = 0;
    // Samples whose hit has a normal pointing away from the low-poly's outside (no other hit was found).
    std::uint64_t hits_facing_away = 0;
    // Per object (Mesh::objects order): the covered samples of each low-poly object and how many of
    // them hit, and the hits on each high-poly object.
    std::vector<std::uint64_t> low_object_samples, low_object_hits, high_object_hits;
    double seconds = 0;
    double cpu_seconds = 0;  // process CPU time of the trace stage (all threads)
  } trace;

  struct Pad {
    std::size_t texels_padded = 0;
    // Tangent space: covered texels whose normal points into the low-poly surface (z < 0), e.g.
    // from inverted high-poly normals or winding. 0 for object-space maps.
    std::size_t texels_facing_away = 0;
    // Suspect texels: covered texels whose tangent-space normal tilts more than 85 degrees from the
    // low-poly normal (z below cos 85 degrees: black patches where a ray took another part), or
    // whose samples disagree strongly (their mean is shorter than kSuspectAgreement: one texel, two
    // surfaces). suspect_share = suspect_texels / Trace::texels_covered. suspect_region: the cell of
    // an 8 x 8 grid over the UV square holding most of them (u0, v0, u1, v1), and the share of them
    // it holds.
    std::size_t suspect_texels = 0;
    double suspect_share = 0.0;
    double suspect_region[4] = {0, 0, 0, 0};
    double suspect_region_share = 0.0;
    double seconds = 0;
  } pad;
};

struct TraceInputs;  // bake_stages.h: the prepared scene, its BVH and the rays' set-up

// One map of the texture set other than the normal map (BakeOptions::maps), ready to write.
struct BakedMap {
  MapKind kind = MapKind::ao;
  // map_image_channels(kind) channels, values in [0, 1] as written, padded like the normal map;
  // the ID maps 1 channel of palette indices, their colours `colors` (expand_palette).
  Image image;
  // Written into the file: "nmbake:map" (the map's name) and its ranges ("nmbake:height_range",
  // "nmbake:position_box", "nmbake:curvature_scale", "nmbake:ao_distance", "nmbake:thickness_distance").
  std::vector<std::pair<std::string, std::string>> metadata;
  // height: the distances mapped to 0 and 1; curvature: -scale and +scale (1 / scene units);
  // position: unused (box_min, box_max). File coordinates for the box.
  double range_min = 0.0, range_max = 0.0;
  glm::dvec3 box_min{0.0}, box_max{0.0};
  double distance = 0.0;  // ao, bent-normal: the AO distance; thickness: its distance (scene units)
  // ID maps: per name its colour (0-1, 8-bit steps), in index order: image's palette (id_palette).
  std::vector<std::pair<std::string, glm::vec3>> colors;
  // ao, thickness: the standard error of the covered texels' values, mean and 95th percentile;
  // -1 for the other maps.
  double error_mean = -1.0, error_p95 = -1.0;
  Image error;  // ao, thickness: per texel the standard error of its value (1 channel, covered texels; else 0)
  // ao, bent-normal, thickness with --ao-rays auto: the rays per texel spent, mean and most over
  // the covered texels; -1 otherwise.
  double rays_mean = -1.0, rays_max = -1.0;
  // Not written, and why (vertex-color of a high-poly without colours): `image` is then empty.
  std::string skipped;
};

// An ID map's palette: its colours in index order, as expand_palette and WriteOptions::palette read
// it. Never empty (a map without names has only 0s: one black entry keeps it read as indices).
inline std::vector<glm::vec3> id_palette(const BakedMap& m) {
  std::vector<glm::vec3> out;
  for (const auto& named : m.colors) out.push_back(named.second);
  if (out.empty()) out.push_back(glm::vec3(0.0f));
  return out;
}

struct BakeResult {
  Image map;                           // RGB, encoded c = n * 0.5 + 0.5
  Image miss_mask;                     // 1 channel, share of missed samples (only with options.miss_mask)
  Image suspect_mask;                  // 1 channel, 1 for suspect texels, else 0 (only with options.suspect_mask)
  std::vector<std::uint8_t> coverage;  // per texel: 1 = covered by the UV layout
  BakeStats stats;
  // The automatic cage (BakeStats::CageSource::automatic): per low-poly position, object space as
  // the low-poly's (a cage file with the low-poly's topology holds these); else empty.
  std::vector<glm::vec3> cage_positions;
  // Per low-poly position, the rear distance measured (with the automatic cage or a file's cage
  // without --rear); else empty.
  std::vector<float> vertex_rear;
  // Per low-poly position, how far out rays search beyond a cage that a neighbouring part limits
  // (LocalDistances::search); empty where vertex_rear is.
  std::vector<float> vertex_search;
  // Every map of BakeOptions::maps but the normal map, in the order asked.
  std::vector<BakedMap> maps;
  // With BakeOptions::keep_trace, what the trace read (for estimate_bake_error, error_estimate.h);
  // it reads the low-poly and the high-poly given, which must outlive it unchanged. Else null.
  std::shared_ptr<const TraceInputs> trace_inputs;
};

struct Cancelled : Error {
  Cancelled() : Error(ExitCode::usage, "cancelled") {}
};

// Every check of the options alone, in one place (the command line calls it before loading the
// meshes, bake_normal_map again): UsageError for absurd values, ResourceError for a refused size.
void validate_options(const BakeOptions& options);

// Throws UsageError for absurd options (validate_options), InputError for meshes that cannot be baked (no UVs, cage
// topology mismatch), ResourceError when the buffers would not fit in memory, Cancelled.
BakeResult bake_normal_map(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& options);

// Bytes the bake will allocate for its images at this size (for the memory check and reports).
std::uint64_t estimate_bake_bytes(const BakeOptions& options);

// The direction rays follow at each low-poly position (unit, re-centring aside exactly the bake's):
// the mean of the normals of the corners at that position (positions compared by value), so split
// normals (hard edges) open no gaps between the rays of neighbouring faces.
std::vector<glm::vec3> low_ray_normals(const Mesh& low);

// The sample offsets inside a texel for `samples` samples, in [0,1)^2: the centre for 1, a
// regular grid for square counts, otherwise a stratified (Hammersley) set.
std::vector<glm::dvec2> sample_offsets(int samples);

}  // namespace nmbake
