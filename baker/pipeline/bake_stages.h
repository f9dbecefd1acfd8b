// The stages of bake_normal_map (bake.cpp) that another entry point over the same scene reuses:
// the input checks, the stages before the trace (prepare, select, BVH, distances) and the output
// buffers. Internal to the pipeline; bake.h is the public interface. udim.cpp bakes several maps
// with one run of the stages before the trace.
#pragma once

#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/bake.h"
#include "pipeline/bvh.h"
#include "pipeline/distances.h"
#include "pipeline/prepare.h"
#include "pipeline/rays.h"
#include "pipeline/select.h"

namespace nmbake {

// Process CPU time in seconds (all threads), for BakeStats::Trace::cpu_seconds.
double process_cpu_seconds();

// Calls options.on_stage when set.
void announce_stage(const BakeOptions& opt, const char* stage);

// Options and inputs a bake refuses (bake.h): UsageError, InputError, and ResourceError when
// `maps` maps of estimate_bake_bytes(opt) each would not fit in memory (BakeOptions::memory_limit).
// `what` names the maps in that message ("" for one map: "--size WxH needs ...").
void check_bake_inputs(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& opt, std::uint64_t maps = 1,
                       const std::string& what = "");

// What the trace reads but the bins: the stages up to the trace's, run once per scene.
struct TraceInputs {
  Prepared s;
  HighSelection selection;  // the high-poly triangles in the BVH
  HighScene scene;
  RaySetup rays;
};

// The stages before the trace, in order: prepare (prepare.h), select and BVH (select_and_build),
// distances (measure_reach, distances.h), narrow (narrow_and_rebuild). Fills `in`, result.stats
// (the stages' stats) and result's cage_positions, vertex_rear, vertex_search. `stage` says what
// runs, for an out-of-memory message.
void prepare_trace(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& opt, int threads, TraceInputs& in,
                   BakeResult& result, std::string& stage);

// `inputs` made to hold `high` too: a high-poly moved to the low-poly's origin for the bake, which
// they read (BakeResult::trace_inputs). Null stays null.
std::shared_ptr<const TraceInputs> holding(std::shared_ptr<const TraceInputs> inputs, std::shared_ptr<const Mesh> high);

// For meshes loaded each on its own (!share_origin; nmbake loads them on one origin): `bake`
// (bake_normal_map, bake_udim_tiles) of the high-poly and cage moved to the low-poly's origin, the
// moved high-poly held by the result's trace_inputs (holding).
template <typename Result>
Result bake_on_low_origin(Result (*bake)(const Mesh&, const Mesh&, const Mesh*, const BakeOptions&), const Mesh& low,
                          const Mesh& high, const Mesh* cage, const BakeOptions& opt) {
  const std::optional<Mesh> moved_cage = cage ? std::optional<Mesh>(with_origin(*cage, low.origin)) : std::nullopt;
  const auto moved_high = std::make_shared<const Mesh>(with_origin(high, low.origin));
  Result result = bake(low, *moved_high, moved_cage ? &*moved_cage : nullptr, opt);
  result.trace_inputs = holding(std::move(result.trace_inputs), moved_high);
  return result;
}

// How select_and_build got the BVH: built for this bake alone, built over every triangle and kept
// in an empty BvhCache, or reused from the cache.
enum class BvhSource { built, kept, reused };

// The select and BVH stages, on in.s: in.selection and in.scene. The BVH a BakeOptions::bvh_cache
// keeps for this content (find_kept_bvh) is reused with its selection; otherwise the triangles some
// ray can reach before the distances are known (within the probes' reach `mode.reach`, or the
// distances given; all of them without cull_far or for a BVH to keep), less duplicate floods
// (select_high), in a BVH of the quality bvh_quality_for picks, kept by an empty cache. Sets
// st.select.high_duplicates_skipped and st.bvh.reused; `stage` names the build.
BvhSource select_and_build(const Mesh& high, const ReachMode& mode, const BakeOptions& opt, int threads, TraceInputs& in,
                           BakeStats& st, std::string& stage);

// The narrow stage, after the distances (result.stats.front, rear, result.vertex_search): the
// selection narrowed to what the rays reach (narrow_high) and the BVH rebuilt over it when that
// leaves out a fifth of it or more. For a BVH built for this bake alone.
void narrow_and_rebuild(const Mesh& high, const ReachMode& mode, const BakeOptions& opt, int threads, const BakeResult& result,
                        TraceInputs& in);

// Texels per side of the trace's bins for these options (TileBins::side).
int trace_tile_side(const BakeOptions& opt);

// One map's output buffers at opt's size: result.map (pages touched, values unset), coverage
// (zeros), the miss mask when asked, and `disagree` (zeros) with several samples. Made at the
// trace's start on `threads` threads: the system zeroes each fresh page at its first touch, work
// that would otherwise fall between the trace's rays. (On a helper thread beside the stages before,
// as it was, it took a core those stages use, and ran even at --threads 1.)
void allocate_outputs(const BakeOptions& opt, BakeResult& result, std::vector<std::uint8_t>& disagree, int threads);

// Runs `allocate` (the texture set's other maps' buffers and the curvature) on a helper thread
// while the caller prepares. wait() rethrows what `allocate` threw.
class OutputAllocation {
 public:
  explicit OutputAllocation(std::function<void()> allocate)
      : thread_([this, allocate = std::move(allocate)] {
          try {
            allocate();
          } catch (...) {
            error_ = std::current_exception();
          }
        }) {}
  ~OutputAllocation() {
    if (thread_.joinable()) thread_.join();
  }
  OutputAllocation(const OutputAllocation&) = delete;
  OutputAllocation& operator=(const OutputAllocation&) = delete;
  void wait() {  // again: returns at once (or throws the same error)
    if (thread_.joinable()) thread_.join();
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace nmbake
