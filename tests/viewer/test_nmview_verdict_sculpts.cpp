// --compare's verdict (issue 36, item 1) on the shared sculpts the bench and the tests use
// (NMBAKE_SHARED_DATA_DIR, /work/shared/data/README: sculpts/), each baked at 256^2 by the real
// nmbake: the right map is "good", the same pixels with green flipped "green_flipped", a flat map
// (no map) "barely_helps". suz_L3 is in test_nmview_angles.cpp; torus_demo is the bundled sample
// (data/sample/torus_*: the same files), also there. Each test skips when its sculpt is absent.
//
// Measured (llvmpipe, 256^2 map, --size 300x150; mean angle in degrees with the map / no map /
// flipped / swapped, the share the map removes): torus_s3 12.41 / 16.45 / 19.62 / 19.40, 24.6 %
// (a 512^2 map 24.8 %, --size 800x400 23.1 %); suz_L4 10.80 / 16.22 / 19.75 / 19.61, 33.5 %.
#include <string>

#include <gtest/gtest.h>

#include "test_support.h"
#include "verdict_run.h"

namespace {

void expect_sculpt_verdicts(const std::string& name) {
  const std::string low = nmbake::test::shared_data_path("sculpts/" + name + "/low.obj");
  const std::string high = nmbake::test::shared_data_path("sculpts/" + name + "/high.ply");
  if (!nmbake::test::exists(low) || !nmbake::test::exists(high))
    GTEST_SKIP() << "sculpts/" << name << " is absent (NMBAKE_SHARED_DATA_DIR)";
  nmview::test::expect_verdicts(low, high, 256);
}

}  // namespace

TEST(NmviewSculptVerdict, TorusS3RightFlippedFlat) { expect_sculpt_verdicts("torus_s3"); }

TEST(NmviewSculptVerdict, SuzL4RightFlippedFlat) { expect_sculpt_verdicts("suz_L4"); }
