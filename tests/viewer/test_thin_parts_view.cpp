// nmview --compare on the thin-parts family (tests/procedural/thin_parts.h, issue 34 item 1): the
// map of the automatic cage renders no worse than the map of the best fixed ray distance of a
// sweep, by at most kMarginDb of the interior PSNR. Headless (llvmpipe), in this process.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "gl_context.h"
#include "io/mesh_io.h"
#include "test_support.h"
#include "thin_parts.h"
#include "tool_run.h"

namespace {

// The sweep, as shares of the scene diagonal (front = rear), and Blender's usual 1.5% / 3%.
constexpr double kSweep[] = {0.01, 0.015, 0.02, 0.03, 0.05};
// How much lower the automatic cage's figure may be than the best fixed distance's, dB: on the
// three-sided tripods the best fixed distance (about 5% of the diagonal) renders 0.14 dB better at
// this size, with 35 times the automatic cage's suspect texels (0.104% against 0.003%); on the
// others the automatic cage renders 0.01-0.13 dB better.
constexpr double kMarginDb = 0.2;

// The interior PSNR of `map` as `nmview LOW MAP HIGH --compare --size 300x300` measures it (its
// last line's psnr=), run in this process (tool_run.h compare_interior) in the test's one headless
// context, without a process start per map.
double compare_psnr(const std::string& dir, const std::string& name, const std::string& map) {
  return nmview::test::compare_interior(dir + "/" + name + "_low.obj", dir + "/" + map, dir + "/" + name + "_high.obj", 150, 300,
                                        {true})
      .at(0)
      .psnr();
}

TEST(ThinPartsView, AutomaticCageRendersNoWorseThanTheBestFixedDistance) {
  nmview::test::make_headless();
  const nmview::HeadlessContext context;
  const std::string dir = nmbake::test::scratch_dir();
  for (const nmbake::procedural::ThinPartsSpec& spec : nmbake::procedural::thin_parts_family()) {
    const nmbake::procedural::ThinParts p = nmbake::procedural::make_thin_parts(spec);
    nmbake::test::write_file(dir + "/" + spec.name + "_low.obj", nmbake::obj_text(p.low, spec.name));
    nmbake::test::write_file(dir + "/" + spec.name + "_high.obj", nmbake::obj_text(p.high, spec.name));
    const std::string inputs = spec.name + "_low.obj " + spec.name + "_high.obj --size 256 --quiet --report r.json -o ";
    auto bake = [&](const std::string& map, const std::string& options) {
      const nmbake::test::CliRun r = nmbake::test::run_nmbake(inputs + map + options, "", dir);
      EXPECT_EQ(r.code, 0) << r.err;
      return r.report;
    };
    bake("auto.png", "");
    const double auto_psnr = compare_psnr(dir, spec.name, "auto.png");
    ASSERT_GT(auto_psnr, 0.0) << spec.name;
    double best = -1.0;
    std::string best_label;
    auto fixed = [&](double front, double rear) {
      const std::string label = std::to_string(front) + "/" + std::to_string(rear);
      bake("fixed.png", " --front " + std::to_string(front) + " --rear " + std::to_string(rear));
      const double psnr = compare_psnr(dir, spec.name, "fixed.png");
      std::printf("measured: %s fixed %s psnr %.2f dB\n", spec.name.c_str(), label.c_str(), psnr);
      if (psnr > best) best = psnr, best_label = label;
    };
    const double d = nmbake::procedural::diagonal(p);
    for (double s : kSweep) fixed(s * d, s * d);
    fixed(0.015 * d, 0.03 * d);
    std::printf("measured: %s automatic psnr %.2f dB, best fixed %s %.2f dB\n", spec.name.c_str(), auto_psnr, best_label.c_str(),
                best);
    EXPECT_GE(auto_psnr, best - kMarginDb) << spec.name;
  }
}

}  // namespace
