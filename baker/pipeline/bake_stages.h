// The stages of bake_normal_map (bake.cpp) that another entry point over the same scene reuses:
// the input checks, the stages before the trace (prepare, select, BVH, distances) and the output
// buffers. Internal to the pipeline; bake.h is the public interface. udim.cpp bakes several maps
// with one run of the stages before the trace.
#pragma once

#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/bake.h"
#include "pipeline/bvh.h"
#include "pipeline/prepare.h"
#include "pipeline/rays.h"

namespace nmbake {

// Process CPU time in seconds (all threads), for BakeStats::cpu_seconds_trace.
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
  HighScene scene;
  RaySetup rays;
};

// Prepare, select, BVH, distances (and a narrower selection once they are known): fills `in`,
// result.stats (the stages' stats) and result's cage_positions, vertex_rear, vertex_search.
// `stage` says what runs, for an out-of-memory message.
void prepare_trace(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& opt, int threads, TraceInputs& in,
                   BakeResult& result, std::string& stage);

// `inputs` made to hold `high` too: a high-poly moved to the low-poly's origin for the bake, which
// they read (BakeResult::trace_inputs). Null stays null.
std::shared_ptr<const TraceInputs> holding(std::shared_ptr<const TraceInputs> inputs, std::shared_ptr<const Mesh> high);

// Texels per side of the trace's bins for these options (TileBins::side).
int trace_tile_side(const BakeOptions& opt);

// One map's output buffers at opt's size: result.map (pages touched, values unset), coverage
// (zeros), the miss mask when asked, and `disagree` (zeros) with several samples.
void allocate_outputs(const BakeOptions& opt, BakeResult& result, std::vector<std::uint8_t>& disagree);

// Runs `allocate` on a helper thread while the caller prepares: the system zeroes each fresh page
// at its first touch (18-40 ms for a 2048^2 map on our 2-core VM), work that would otherwise fall
// between the trace's rays. Starting a thread waits while another thread of the process is loading
// a shared library (glibc's loader lock; the CLI loads its image module in the background, up to
// 0.2 s): in prepare's time, where it shows. wait() rethrows what `allocate` threw.
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
  void wait() {
    thread_.join();
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::exception_ptr error_;
  std::thread thread_;
};

}  // namespace nmbake
