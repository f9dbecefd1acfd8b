// Section 8 of the bake bench: a batch of 20 jobs that share one high-poly (nmbake --batch) against
// the same 20 bakes as separate commands, alternated batch, commands, batch, ... over the rounds.
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "bench_bake.h"
#include "bench_support.h"

namespace nmbake::bench {

namespace {

constexpr int kJobs = 20;

// Wall seconds of a shell command, or -1 when it fails.
double time_command(const std::string& cmd) {
  const auto t0 = Clock::now();
  const int rc = std::system(cmd.c_str());
  const double wall = since(t0);
  if (rc != 0) {
    std::fprintf(stderr, "bench: command failed (%d): %s\n", rc, cmd.c_str());
    return -1.0;
  }
  return wall;
}

}  // namespace

void run_batch(BenchRun& run, const Scenes& scenes) {
  const Args& args = run.args;
  const int side = args.quick ? 256 : 512;
  std::printf("## 8. Batch (suz_L3: %d jobs at %d^2 from one high-poly, one --batch against %d commands)\n\n", kJobs, side,
              kJobs);
  std::printf("Load average %s.\n\n", load_average().c_str());
  const std::string low = scenes.s3 + "/low.obj", high = scenes.s3 + "/high.ply";
  std::string jobs = "{\"defaults\": {\"size\": " + std::to_string(side) + "}, \"jobs\": [\n";
  std::string commands;
  for (int j = 0; j < kJobs; ++j) {
    const std::string out = run.run_dir + "/batch_" + std::to_string(j) + ".png";
    // Every fourth job with 4 samples, as a pipeline's mixed settings.
    const std::string samples = j % 4 == 3 ? "4" : "1";
    jobs += std::string(j ? ",\n" : "") + "{\"low\": \"" + low + "\", \"highs\": [\"" + high + "\"], \"output\": \"" + out +
            "_b.png\", \"options\": {\"samples\": " + samples + "}}";
    commands += args.exe + " " + low + " " + high + " -o " + out + "_c.png --size " + std::to_string(side) + " --samples " +
                samples + " --quiet && ";
  }
  jobs += "\n]}\n";
  const std::string jobs_path = run.run_dir + "/jobs.json";
  std::ofstream(jobs_path) << jobs;
  commands += "true";
  std::vector<double> batch, separate;
  for (int round = 0; round < args.rounds; ++round) {
    const double b = time_command(args.exe + " --batch " + jobs_path + " --quiet");
    const double c = time_command(commands);
    if (b < 0 || c < 0) break;
    batch.push_back(b);
    separate.push_back(c);
    std::printf("- round %d: batch %.2f s, %d commands %.2f s\n", round + 1, b, kJobs, c);
    flush();
  }
  const std::string what = std::to_string(kJobs) + " jobs sharing one high-poly: batch / separate commands";
  if (batch.empty()) {
    std::printf("\nA command failed (see stderr).\n\n");
    run.skip_target(what, "< 1", "command failed");
    return;
  }
  const double ratio = median(batch) / median(separate);
  std::printf("\n| | median wall s | per job s |\n|---|---|---|\n| --batch | %.2f | %.3f |\n| %d commands | %.2f | %.3f |\n\n",
              median(batch), median(batch) / kJobs, kJobs, median(separate), median(separate) / kJobs);
  std::printf("Ratio batch / commands: %.2f.\n\n", ratio);
  run.add_target(what, "< 1", fmt("%.2f", ratio), ratio < 1.0);
  flush();
}

}  // namespace nmbake::bench
