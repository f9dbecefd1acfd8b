// Golden maps: the bundled sample baked now against the map checked in under data/golden, compared
// with nmdiff's library over the UV layout (padding ignored). NMBAKE_REGENERATE=1 rewrites the
// golden maps instead; a failure writes a heatmap of the difference next to the fresh bake.
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "pipeline/bake.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "nmdiff.h"
#include "test_support.h"

using namespace nmbake;

namespace {

void check_golden(const std::string& name, const BakeOptions& options) {
  const std::string golden = test::data_path("golden/" + name);
  LoadOptions lo;
  lo.require_uvs = true;
  const Mesh low = load_mesh(test::data_path("sample/torus_low.obj"), lo);
  const Mesh high = load_mesh(test::data_path("sample/torus_high.ply"));
  const BakeResult r = bake_normal_map(low, high, nullptr, options);
  const std::string fresh = test::scratch_dir() + "/" + name;
  write_image(fresh, r.map);
  const char* regen = std::getenv("NMBAKE_REGENERATE");
  if (regen && std::string(regen) == "1") {
    std::filesystem::copy_file(fresh, golden, std::filesystem::copy_options::overwrite_existing);
    GTEST_SKIP() << "regenerated " << golden;
  }
  ASSERT_TRUE(test::exists(golden)) << golden << " is missing; run with NMBAKE_REGENERATE=1 to create it";
  // Same code, same data: equal maps are expected. The tolerance only absorbs a different libm or
  // Embree build flipping an 8-bit rounding (at most 0.78 deg for one texel; see nmdiff.h).
  diff::DiffOptions d;
  d.mask = diff::uv_layout_mask(low, options.width, options.height);
  d.tolerances = {0.01, 0.5, 1.0};
  diff::AngleField field;
  const diff::DiffStats s = diff::compare_normal_maps(read_image(fresh), read_image(golden), d, &field);
  std::printf("%s against golden: %s\n", name.c_str(), diff::summary_line(s).c_str());
  EXPECT_GT(s.texels_compared, std::size_t(options.width) * options.height / 2);
  if (!s.within) {
    const std::string heat = fresh + ".diff.png";
    write_image(heat, diff::render_heatmap(field, diff::auto_heatmap_scale(s, d.tolerances)));
    ADD_FAILURE() << name << " differs from " << golden << ": " << diff::summary_line(s) << "; worst texel (" << s.worst_x << ","
                  << s.worst_y << "); heatmap " << heat << "; fresh bake " << fresh;
  }
}

}  // namespace

TEST(Golden, TorusSample256) {
  BakeOptions o;
  o.width = o.height = 256;
  check_golden("torus_256.png", o);
}

TEST(Golden, TorusSample128With4SamplesGreenDown) {
  BakeOptions o;
  o.width = o.height = 128;
  o.samples = 4;
  o.green_down = true;
  o.padding = 4;
  check_golden("torus_128_s4_green_down.png", o);
}
