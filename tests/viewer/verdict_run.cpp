#include "verdict_run.h"

#include <cstdio>
#include <cstdlib>

#include <gtest/gtest.h>

#include "core/image.h"
#include "io/image_io.h"
#include "test_support.h"
#include "tool_run.h"
#include "verdict.h"
#include "build_paths.h"

namespace nmview::test {

VerdictRun compare_verdict(const std::string& dir, const std::string& low, const std::string& map, const std::string& high,
                           const std::string& size) {
  const ToolRun r = nmview(dir, quote(low) + " " + quote(map) + " " + quote(high) + " --compare --size " + size);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  std::string last = r.out;
  while (!last.empty() && last.back() == '\n') last.pop_back();
  last = last.substr(last.rfind('\n') + 1);
  VerdictRun v;
  const auto field = [&](const std::string& name) {
    const std::size_t at = last.find(" " + name + "=");
    EXPECT_NE(at, std::string::npos) << name << " in: " << last;
    return at == std::string::npos ? std::string()
                                   : last.substr(at + name.size() + 2, last.find(' ', at + 1) - at - name.size() - 2);
  };
  EXPECT_EQ(last.rfind("psnr=", 0), 0u) << last;  // the old fields first, as before
  v.verdict = field("verdict");
  v.removes = std::atof(field("map_removes").c_str());
  v.with_map = std::atof(field("angle_mean").c_str());
  v.no_map = std::atof(field("no_map_angle_mean").c_str());
  std::printf("%s: %s\n", map.substr(map.rfind('/') + 1).c_str(), last.substr(last.find("angle_mean")).c_str());
  return v;
}

void expect_verdicts(const std::string& low, const std::string& high, int map_size, const std::string& size) {
  const std::string dir = nmbake::test::scratch_dir(), map = dir + "/map.png";
  const ToolRun bake =
      run_tool(dir, nmbake::build::nmbake_exe(),
               quote(low) + " " + quote(high) + " -o " + quote(map) + " --size " + std::to_string(map_size) + " --quiet");
  ASSERT_EQ(bake.exit_code, 0) << bake.err;
  nmbake::Image flipped = nmbake::read_image(map), flat = flipped;
  for (std::size_t i = 0; i < flipped.pixels.size(); i += std::size_t(flipped.channels)) {
    flipped.pixels[i + 1] = 1.0f - flipped.pixels[i + 1];
    flat.pixels[i] = flat.pixels[i + 1] = 0.5f;
    flat.pixels[i + 2] = 1.0f;
  }
  nmbake::write_image(dir + "/flipped.png", flipped);
  nmbake::write_image(dir + "/flat.png", flat);

  const VerdictRun right = compare_verdict(dir, low, map, high, size);
  EXPECT_EQ(right.verdict, "good");
  EXPECT_GE(right.removes, kMinRemoved + 0.05);  // clear of the threshold
  EXPECT_NEAR(right.removes, 1.0 - right.with_map / right.no_map, 1e-3);
  EXPECT_EQ(compare_verdict(dir, low, dir + "/flipped.png", high, size).verdict, "green_flipped");
  const VerdictRun none = compare_verdict(dir, low, dir + "/flat.png", high, size);
  EXPECT_EQ(none.verdict, "barely_helps");
  EXPECT_NEAR(none.with_map, none.no_map, 0.05);  // a flat map is the interpolated normal (8-bit 128 = +0.002)
}

}  // namespace nmview::test
