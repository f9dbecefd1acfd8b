// Sections 1 and 2 of the bake bench: the bake's trace stage against bare Embree loops on the rays
// the bake recorded, and the BVH build qualities on the same rays.
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_bake.h"
#include "bench_stages.h"
#include "bench_support.h"
#include "io/mesh_io.h"
#include "pipeline/bvh.h"

namespace nmbake::bench {

namespace {

// Positions re-centred like the bake does, so the bare loop traces the bake's own coordinates.
std::vector<glm::vec3> recentred(const Mesh& high, const glm::dvec3& centre) {
  std::vector<glm::vec3> pos(high.positions.size());
  for (std::size_t i = 0; i < pos.size(); ++i) pos[i] = glm::vec3(glm::dvec3(high.positions[i]) - centre);
  return pos;
}

// BVH build time and 8-packet trace time per build quality, on the same recorded rays.
std::vector<QualityRow> sweep_quality(const std::string& scene, const Recorded& rec, const Mesh& high, int threads, int rounds) {
  const raycast::BuildQuality qualities[] = {raycast::BuildQuality::low, raycast::BuildQuality::medium,
                                             raycast::BuildQuality::high};
  std::vector<QualityRow> rows;
  for (auto q : qualities)
    rows.push_back({scene, rec.options.samples, q, high.triangle_count() - rec.culled, 1e30, {}, rec.rays.size()});
  for (int round = 0; round < rounds; ++round)
    for (auto& row : rows) {
      const auto t0 = Clock::now();
      raycast::Scene bvh(&rec.positions[0].x, rec.positions.size(), high.position_index.data(), high.triangle_count(),
                         row.quality);
      row.build = std::min(row.build, since(t0));
      row.trace.keep_min(bare_loop(bvh, rec.rays, threads, Bare::arrays));
    }
  return rows;
}

// Section 1's rounds on one scene and sample count: the bake, the same bake without the hit rule,
// then the three bare loops.
struct TraceRounds {
  Timing trace, bare1, bare8, bare_arrays;  // the best of the rounds
  Timing no_rule;                           // the same bake with --keep-backfaces: no hit rule, no filter
  bool same_rays = true;                    // and it cast as many rays
  double bvh = 0, pad = 0;                  // stage seconds of the fastest trace's bake
  std::string hash;                         // the map's pixel_hash (or that it varies)
  std::vector<double> paired;               // per round: trace / that round's best bare loop (wall)
};

TraceRounds measure_trace_rounds(const Mesh& low, const Mesh& high, const Recorded& rec, const raycast::Scene& scene, int threads,
                                 int rounds) {
  TraceRounds t;
  for (int round = 0; round < rounds; ++round) {
    const BakeResult r = bake_normal_map(low, high, nullptr, rec.options);
    if (r.stats.trace.seconds < t.trace.wall) {
      t.bvh = r.stats.bvh.seconds, t.pad = r.stats.pad.seconds;
    }
    t.trace.keep_min(r.stats.trace.seconds, r.stats.trace.cpu_seconds);
    BakeOptions plain = rec.options;
    plain.keep_backfaces = true;
    const BakeStats nr = trace_by_texel(low, high, plain);  // the same packets as the bake under the rule
    t.no_rule.keep_min(nr.trace.seconds, nr.trace.cpu_seconds);
    t.same_rays = t.same_rays && nr.trace.rays == r.stats.trace.rays;
    const std::string h = hex(pixel_hash(r.map.pixels));
    t.hash = round == 0 ? h : (h == t.hash ? t.hash : t.hash + " VARIES between rounds");
    const Timing b1 = bare_loop(scene, rec.rays, threads, Bare::single);
    const Timing b8 = bare_loop(scene, rec.rays, threads, Bare::packets);
    const Timing ba = bare_loop(scene, rec.rays, threads, Bare::arrays);
    t.bare1.keep_min(b1);
    t.bare8.keep_min(b8);
    t.bare_arrays.keep_min(ba);
    t.paired.push_back(r.stats.trace.seconds / std::min({b1.wall, b8.wall, ba.wall}));
  }
  return t;
}

// One row of section 1 (and its targets); torus_s3's 1- and 16-sample rays also go to the BVH
// quality sweep of section 2.
void run_trace_row(BenchRun& run, const std::string& name, const Mesh& low, const Mesh& high, double load, int samples,
                   std::vector<QualityRow>& quality_rows) {
  const Args& args = run.args;
  const Recorded rec = record(low, high, 2048, samples);
  const raycast::BuildQuality quality = bvh_quality_for(rec.options, high.triangle_count() - rec.culled);
  raycast::Scene scene(&rec.positions[0].x, rec.positions.size(), high.position_index.data(), high.triangle_count(), quality);
  const TraceRounds t = measure_trace_rounds(low, high, rec, scene, run.threads, samples <= 4 ? args.trace_rounds : args.rounds);
  const double paired_median = median(t.paired);
  const auto [paired_min, paired_max] = std::minmax_element(t.paired.begin(), t.paired.end());
  const double best_wall = std::min({t.bare1.wall, t.bare8.wall, t.bare_arrays.wall});
  const double best_cpu = std::min({t.bare1.cpu, t.bare8.cpu, t.bare_arrays.cpu});
  const double ratio = t.trace.wall / best_wall, ratio_cpu = t.trace.cpu / best_cpu;
  const bool judged6 = samples == 1 || samples == 16, judged2 = samples == 1 || samples == 4;
  std::printf(
      "| %s | %d | %zu%s | %s | %.3f | %.3f | %.3f (%.3f) | %.3f | %.2fM | %.2f | %.3f (%.3f) | %.3f (%.3f) | %.3f (%.3f) | "
      "%.2fx (%.2fx) | %.2fx [%.2f .. %.2f] | %.3f | %.3f (%.3f)%s | %s | %s | %s |\n",
      name.c_str(), samples, high.triangle_count(),
      rec.culled ? (" (" + std::to_string(rec.culled) + " culled by the bake, traced by the bare loop)").c_str() : "",
      quality_name(quality), load, t.bvh, t.trace.wall, t.trace.cpu, t.pad, double(rec.rays.size()) / 1e6,
      double(rec.rays.size()) / t.trace.wall / 1e6, t.bare1.wall, t.bare1.cpu, t.bare8.wall, t.bare8.cpu, t.bare_arrays.wall,
      t.bare_arrays.cpu, ratio, ratio_cpu, paired_median, *paired_min, *paired_max, t.trace.wall - best_wall, t.no_rule.wall,
      t.no_rule.cpu, t.same_rays ? "" : " (other rays!)", judged2 ? verdict(ratio <= 1.3) : "-",
      judged6 ? verdict(ratio <= 1.15) : "-", t.hash.c_str());
  flush();
  const std::string what = "tracing " + name + " 2048^2 " + std::to_string(samples) + " sample" + (samples > 1 ? "s" : "");
  const std::string measured =
      fmt("%.2fx wall", ratio) + fmt(" (%.2fx CPU;", ratio_cpu) + fmt(" per round median %.2fx)", paired_median);
  if (judged2) run.add_target(what + " (issue 2)", "trace <= 1.3x bare loop", measured, ratio <= 1.3);
  if (judged6) run.add_target(what + " (issue 6)", "trace <= 1.15x bare loop", measured, ratio <= 1.15);
  if (name == "torus_s3" && (samples == 1 || samples == 16)) {
    auto rows = sweep_quality(name, rec, high, run.threads, args.rounds);
    quality_rows.insert(quality_rows.end(), rows.begin(), rows.end());
  }
}

// The fastest build + trace of the three qualities starting at rows[i].
std::size_t best_end_to_end(const std::vector<QualityRow>& rows, std::size_t i) {
  std::size_t best = i;
  for (std::size_t k = i; k < i + 3; ++k)
    if (rows[k].build + rows[k].trace.wall < rows[best].build + rows[best].trace.wall) best = k;
  return best;
}

}  // namespace

Recorded record(const Mesh& low, const Mesh& high, int size, int samples) {
  Recorded r;
  r.options.width = r.options.height = size;
  r.options.samples = samples;
  const BakeResult first = bake_normal_map(low, high, nullptr, r.options);
  r.options.front = first.stats.distances.front;
  r.options.rear = first.stats.distances.rear;
  BakeRays pinned = bake_rays(low, high, r.options);
  r.rays = std::move(pinned.rays);
  r.positions = recentred(high, pinned.stats.prepare.centre);
  r.culled = pinned.stats.select.high_triangles_culled;
  return r;
}

// 1. Tracing: the bake's trace stage against the bare loop on the same rays.
std::vector<QualityRow> run_tracing(BenchRun& run) {
  const Args& args = run.args;
  std::printf("## 1. Tracing stage vs bare Embree loop (2048^2)\n\n");
  std::printf("Load average %s.\n\n", load_average().c_str());
  std::printf(
      "Each round runs the bake, then the bare loops, back to back on the rays the bake recorded; CPU = process CPU\n"
      "seconds (all threads), less disturbed by other load than wall time. The bare loops trace a BVH of the build quality\n"
      "the bake picks (bvh_quality_for in pipeline/bvh.h: low below 16 rays per triangle, else high; column \"BVH\").\n"
      "Targets (wall, trace / best bare): issue 2 <= 1.3x for 1 and 4 samples, issue 6 <= 1.15x for 1 and 16 samples.\n"
      "Bare loops: one rtcIntersect1 per ray; packets filled from Ray structs; packets from arrays already in Embree's\n"
      "packet layout (filled before the clock starts; the bake writes its rays this way). Packets (the \"8-packet\"\n"
      "columns, and the bake's) are of raycast::Scene::packet_width rays: 16 where Embree traces them natively (an\n"
      "AVX-512 CPU), else 8; raycast.h has no rtcIntersect1M streams for primary rays, so those are not measured.\n"
      "The bake and both packet loops tell Embree the packets are coherent (RTC_INTERSECT_CONTEXT_FLAG_COHERENT: a\n"
      "texel's samples, or with one sample neighbouring texels of a row); the single-ray loop cannot.\n"
      "\"Own s\": the fastest bake's trace less the best bare loop on its rays: the bake's own rasterizing, ray making,\n"
      "shading and writing, as wall seconds. \"No rule\": the same bake with --keep-backfaces, the same rays cast\n"
      "in the same packets without the hit rule (no Embree filter; hits on back faces are taken): the rule's share of\n"
      "the trace.\n"
      "Rounds: %d at 1 and 4 samples, %d at 16; each timed column is the best of them. \"Per round\": each round's trace\n"
      "over that round's best bare loop, median [lowest .. highest]: how far the host's load moved the ratio in this run.\n\n",
      args.trace_rounds, args.rounds);
  {
    const float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const std::uint32_t tri[3] = {0, 1, 2};
    std::printf("Packets of %d rays on this CPU.\n\n", raycast::Scene(corners, 3, tri, 1).packet_width());
  }
  std::printf(
      "| scene | samples | high tris | BVH | load s | bvh s | trace s (CPU) | pad s | rays | Mrays/s | bare 1-ray s (CPU) | "
      "bare 8-packet s (CPU) | bare 8-packet from arrays s (CPU) | trace / best bare, wall (CPU) | per round, median [range] | "
      "own s | no rule: trace s (CPU) | "
      "issue 2 <= 1.3x | issue 6 <= 1.15x | map hash |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  flush();
  std::vector<QualityRow> quality_rows;
  const std::vector<int> ratio_samples = args.quick ? std::vector<int>{1} : std::vector<int>{1, 4, 16};
  for (const std::string name : {"torus_s3", "suz_L4"}) {
    const std::string dir = args.shared + "/sculpts/" + name;
    const auto t0 = Clock::now();
    LoadOptions low_options;
    low_options.require_uvs = true;
    const Mesh low = load_mesh(dir + "/low.obj", low_options);
    const Mesh high = load_mesh(dir + "/high.ply");
    const double load = since(t0);
    for (int samples : ratio_samples) run_trace_row(run, name, low, high, load, samples, quality_rows);
  }
  if (args.quick) run.skip_target("tracing, 4 and 16 samples", "trace <= 1.3x (4 samples), 1.15x (16) bare loop", "--quick");
  return quality_rows;
}

// 2. BVH build quality on the same rays.
void run_bvh_quality(const BenchRun& run, const Scenes& scenes, std::vector<QualityRow> quality_rows) {
  const Args& args = run.args;
  std::printf("\n## 2. BVH build quality (2048^2, bare 8-packet loop from arrays on the bake's recorded rays)\n\n");
  std::printf("Load average %s.\n\n", load_average().c_str());
  {
    LoadOptions low_options;
    low_options.require_uvs = true;
    const Mesh low = load_mesh(scenes.s4 + "/low.obj", low_options);
    const Mesh high = load_mesh(scenes.m1_ply);
    for (int samples : args.quick ? std::vector<int>{} : std::vector<int>{1, 16}) {
      const Recorded rec = record(low, high, 2048, samples);
      auto rows = sweep_quality("suz_L4_x4 (1M)", rec, high, run.threads, args.rounds);
      quality_rows.insert(quality_rows.end(), rows.begin(), rows.end());
    }
  }
  std::printf(
      "| scene | samples | rays | quality | build s | trace s (CPU) | build + trace s | best end to end "
      "|\n|---|---|---|---|---|---|---|---|\n");
  for (std::size_t i = 0; i < quality_rows.size(); i += 3) {
    const std::size_t best = best_end_to_end(quality_rows, i);
    for (std::size_t k = i; k < i + 3; ++k) {
      const QualityRow& q = quality_rows[k];
      std::printf("| %s | %d | %.2fM | %s | %.3f | %.3f (%.3f) | %.3f | %s |\n", q.scene.c_str(), q.samples, double(q.rays) / 1e6,
                  quality_name(q.quality), q.build, q.trace.wall, q.trace.cpu, q.build + q.trace.wall,
                  k == best ? "**best**" : "");
    }
  }
  std::printf("\nBest end to end (build + trace):");
  for (std::size_t i = 0; i < quality_rows.size(); i += 3) {
    const std::size_t best = best_end_to_end(quality_rows, i);
    std::printf("%s %s %d sample%s: %s", i ? ";" : "", quality_rows[i].scene.c_str(), quality_rows[i].samples,
                quality_rows[i].samples > 1 ? "s" : "", quality_name(quality_rows[best].quality));
    BakeOptions o;  // 2048^2, as the sweep
    o.samples = quality_rows[i].samples;
    std::printf(" (the bake picks %s)", quality_name(bvh_quality_for(o, quality_rows[i].triangles)));
  }
  std::printf(".\n\n");
  flush();
}

}  // namespace nmbake::bench
