// nmdiff on the texture set's other maps: known answers in the maps' own units (height and
// position in scene units decoded with each file's range, curvature in 1/scene units, ao as a
// share), ID maps by exact colour, the kind from nmbake:map metadata, and the exit status.
// Maps are written to files with their metadata and read back, as nmdiff reads them.
#include "map_diff.h"

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "io/image_io.h"
#include "test_support.h"
#include "build_paths.h"

using nmbake::Image;
using nmbake::MapKind;
namespace diff = nmbake::diff;

namespace {

using Metadata = std::vector<std::pair<std::string, std::string>>;

// A one-channel map with the value fn(x, y) in [0,1].
Image grey_map(int w, int h, const std::function<double(int, int)>& fn) {
  Image img(w, h, 1, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.at(x, y)[0] = float(fn(x, y));
  return img;
}

// Writes `img` with `metadata` to <scratch>/<name> and returns the path.
std::string write_map(const std::string& dir, const std::string& name, const Image& img, const Metadata& metadata) {
  const std::string path = dir + "/" + name;
  nmbake::write_image(path, img, nmbake::WriteOptions(0, metadata));
  return path;
}

// Reads two map files as nmdiff does and compares them with the default tolerances for their
// kind (from their metadata), `adjust` changing the options first.
diff::MapDiffStats compare_files(const std::string& a, const std::string& b,
                                 const std::function<void(diff::MapDiffOptions&)>& adjust = {}) {
  const auto ma = nmbake::read_image_metadata(a), mb = nmbake::read_image_metadata(b);
  const MapKind kind = diff::resolve_map_kind("", ma.count("nmbake:map") ? ma.at("nmbake:map") : "",
                                              mb.count("nmbake:map") ? mb.at("nmbake:map") : "", a, b);
  diff::MapDiffOptions o;
  o.decoding_a = diff::map_decoding(kind, ma, a);
  o.decoding_b = diff::map_decoding(kind, mb, b);
  o.tolerances = diff::default_map_tolerances(o.decoding_a);
  if (adjust) adjust(o);
  return diff::compare_maps(nmbake::read_image(a), nmbake::read_image(b), o);
}

// A smooth signed distance field in [-0.3, 0.3] scene units.
double distance_at(int x, int y) { return 0.3 * std::sin(0.7 * x) * std::cos(0.4 * y); }

// Runs the nmdiff binary in `dir`; returns its exit code, stdout in `out`, stderr in `err`.
int run_nmdiff(const std::string& dir, const std::string& args, std::string& out, std::string& err) {
  const std::string exe = std::string(nmbake::build::binary_dir()) + "/nmdiff/nmdiff";
  const std::string cmd = "cd '" + dir + "' && '" + exe + "' " + args + " >out.txt 2>err.txt";
  const int status = std::system(cmd.c_str());
  out = nmbake::test::read_file(dir + "/out.txt");
  err = nmbake::test::read_file(dir + "/err.txt");
  std::printf("$ nmdiff %s\n-> exit %d\n%s%s", args.c_str(), WIFEXITED(status) ? WEXITSTATUS(status) : -1, out.c_str(),
              err.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

using nmbake::test::scratch_dir;

TEST(NmdiffMaps, EqualGreyMapsAreZero) {
  const std::string dir = scratch_dir();
  const Image ao = grey_map(16, 8, [](int x, int y) { return (x + 3 * y) / 40.0; });
  const std::string a = write_map(dir, "a_ao.png", ao, {{"nmbake:map", "ao"}});
  const std::string b = write_map(dir, "b_ao.png", ao, {{"nmbake:map", "ao"}});
  const diff::MapDiffStats s = compare_files(a, b);
  EXPECT_EQ(s.kind, MapKind::ao);
  EXPECT_EQ(s.units, "share");
  EXPECT_EQ(s.texels_compared, 128u);
  EXPECT_EQ(s.mean, 0.0);
  EXPECT_EQ(s.max, 0.0);
  EXPECT_TRUE(s.within);
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(diff::map_summary_line(s), "map=ao units=share mean=0 p99=0 max=0 texels=128 within=1");
}

TEST(NmdiffMaps, HeightWithDifferentRangesComparesInSceneUnits) {
  // The same distances written with two ranges: the stored values differ everywhere, the distances
  // agree (float EXR: only float rounding of v, ~1e-7 of the range, is left).
  const std::string dir = scratch_dir();
  const auto heights = [](double lo, double hi) {
    return grey_map(24, 12, [=](int x, int y) { return (distance_at(x, y) - lo) / (hi - lo); });
  };
  const std::string a =
      write_map(dir, "a.exr", heights(-0.5, 0.5), {{"nmbake:map", "height"}, {"nmbake:height_range", "-0.5:0.5"}});
  const std::string b = write_map(dir, "b.exr", heights(-1.0, 2.0), {{"nmbake:map", "height"}, {"nmbake:height_range", "-1:2"}});
  const diff::MapDiffStats s = compare_files(a, b);
  EXPECT_EQ(s.units, "scene units");
  EXPECT_LT(s.max, 1e-6);
  EXPECT_TRUE(s.within);
  // Read as stored values (--map height on files without ranges) they are far apart.
  diff::MapDiffOptions raw;
  raw.decoding_a = raw.decoding_b = diff::map_decoding(MapKind::height, {}, "no metadata");
  raw.tolerances = diff::default_map_tolerances(raw.decoding_a);
  const diff::MapDiffStats r = diff::compare_maps(nmbake::read_image(a), nmbake::read_image(b), raw);
  EXPECT_EQ(r.units, "value");
  EXPECT_GT(r.max, 0.05);
  EXPECT_FALSE(r.within);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_TRUE(nmbake::test::contains(r.warnings[0], "neither map has nmbake:height_range"));
}

TEST(NmdiffMaps, AKnownOffsetIsTheMean) {
  const std::string dir = scratch_dir();
  const Metadata range{{"nmbake:map", "height"}, {"nmbake:height_range", "-0.5:0.5"}};
  const std::string a = write_map(dir, "a.exr", grey_map(20, 10, [](int x, int y) { return 0.5 + distance_at(x, y); }), range);
  const std::string b =
      write_map(dir, "b.exr", grey_map(20, 10, [](int x, int y) { return 0.5 + distance_at(x, y) + 0.004; }), range);
  const diff::MapDiffStats s = compare_files(a, b);
  EXPECT_NEAR(s.mean, 0.004, 1e-6);
  EXPECT_NEAR(s.p99, 0.004, 1e-6);
  EXPECT_NEAR(s.max, 0.004, 1e-6);
  EXPECT_TRUE(s.within);  // defaults for a range of 1: mean 0.005, p99 0.01, max 0.02

  // Curvature: 0.01 of the stored value is 0.02 S in 1/scene units.
  const Metadata curv{{"nmbake:map", "curvature"}, {"nmbake:curvature_scale", "3"}};
  const std::string ca = write_map(dir, "ca.exr", grey_map(8, 8, [](int x, int) { return 0.3 + 0.05 * x; }), curv);
  const std::string cb = write_map(dir, "cb.exr", grey_map(8, 8, [](int x, int) { return 0.31 + 0.05 * x; }), curv);
  const diff::MapDiffStats c = compare_files(ca, cb);
  EXPECT_EQ(c.units, "1/scene units");
  EXPECT_NEAR(c.mean, 0.06, 1e-5);

  // Position: the largest axis difference per texel, each axis in its box's units.
  const Metadata box{{"nmbake:map", "position"}, {"nmbake:position_box", "-1,0,10:1,4,11"}};
  Image pa(6, 4, 3, 0.5f), pb(6, 4, 3, 0.5f);
  for (int x = 0; x < 6; ++x) {
    pb.at(x, 0)[0] += 0.1f;  // x: 0.1 of 2 = 0.2 scene units
    pb.at(x, 0)[2] += 0.1f;  // z: 0.1 of 1 = 0.1, smaller
    pb.at(x, 1)[1] -= 0.1f;  // y: 0.1 of 4 = 0.4
  }
  const std::string qa = write_map(dir, "pa.exr", pa, box);
  const std::string qb = write_map(dir, "pb.exr", pb, box);
  const diff::MapDiffStats p = compare_files(qa, qb);
  EXPECT_EQ(p.units, "scene units");
  EXPECT_NEAR(p.mean, (6 * 0.2 + 6 * 0.4) / 24.0, 1e-5);
  EXPECT_NEAR(p.max, 0.4, 1e-5);
  EXPECT_EQ(p.worst_y, 1);
}

TEST(NmdiffMaps, IdMapsCountTexelsOfAnotherColour) {
  const std::string dir = scratch_dir();
  Image ids(16, 8, 3, 0.0f);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x) {
      float* p = ids.at(x, y);
      p[0] = x < 8 ? 200 / 255.0f : 17 / 255.0f, p[1] = 90 / 255.0f, p[2] = y < 4 ? 1.0f : 0.0f;
    }
  Image other = ids;
  const int k = 5;
  for (int i = 0; i < k; ++i) other.at(3 * i, i)[1] = 91 / 255.0f;  // one 8-bit step in green
  const Metadata meta{{"nmbake:map", "object-id"}};
  const std::string a = write_map(dir, "a.png", ids, meta);
  const std::string b = write_map(dir, "b.png", other, meta);
  const std::string b16 = write_map(dir, "b.tif", other, meta);  // 16 bits: the same 8-bit steps
  const diff::MapDiffStats s = compare_files(a, b);
  EXPECT_EQ(s.units, "texels");
  EXPECT_EQ(s.texels_compared, 128u);
  EXPECT_EQ(s.texels_differing, std::size_t(k));
  EXPECT_DOUBLE_EQ(s.share_differing, k / 128.0);
  EXPECT_EQ(s.worst_x, 0);
  EXPECT_EQ(s.worst_y, 0);
  EXPECT_FALSE(s.within);  // default --max-share 0
  EXPECT_EQ(compare_files(a, b16).texels_differing, std::size_t(k));
  EXPECT_TRUE(compare_files(a, b, [](diff::MapDiffOptions& o) { o.tolerances.max_share = 0.04; }).within);
  EXPECT_FALSE(compare_files(a, b, [](diff::MapDiffOptions& o) { o.tolerances.max_share = 0.03; }).within);
  EXPECT_EQ(diff::map_summary_line(s), "map=object-id units=texels differing=5 share=0.0390625 texels=128 within=0");
}

TEST(NmdiffMaps, KindsComeFromMetadataAndMustAgree) {
  EXPECT_EQ(diff::resolve_map_kind("", "", "", "a.png", "b.png"), MapKind::normal);
  EXPECT_EQ(diff::resolve_map_kind("", "ao", "", "a.png", "b.png"), MapKind::ao);
  EXPECT_EQ(diff::resolve_map_kind("", "", "material-id", "a.png", "b.png"), MapKind::material_id);
  EXPECT_EQ(diff::resolve_map_kind("thickness", "ao", "height", "a.png", "b.png"), MapKind::thickness);  // --map decides
  try {
    diff::resolve_map_kind("", "ao", "height", "a.png", "b.png");
    ADD_FAILURE() << "different kinds compared";
  } catch (const nmbake::InputError& e) {
    const std::string m = e.what();
    EXPECT_TRUE(nmbake::test::contains(m, "a.png is an ao map, b.png a height map")) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos);
  }
  EXPECT_THROW(diff::resolve_map_kind("", "opacity", "", "a.png", "b.png"), nmbake::InputError);
  EXPECT_THROW(diff::map_decoding(MapKind::height, {{"nmbake:height_range", "0:nan"}}, "a.png"), nmbake::InputError);
  EXPECT_THROW(diff::map_decoding(MapKind::position, {{"nmbake:position_box", "0,0,0:1,1"}}, "a.png"), nmbake::InputError);
  EXPECT_EQ(diff::map_family(MapKind::bent_normal), diff::MapFamily::normal);
  EXPECT_EQ(diff::map_family(MapKind::vertex_color), diff::MapFamily::grey);
  // A grey map with too few channels for its kind.
  diff::MapDiffOptions o;
  o.decoding_a = o.decoding_b = diff::map_decoding(MapKind::position, {}, "a");
  EXPECT_THROW(diff::compare_maps(Image(4, 4, 1, 0.5f), Image(4, 4, 1, 0.5f), o), nmbake::InputError);
}

TEST(NmdiffMaps, TolerancesMaskAndAlphaDecide) {
  // AO (a share): one texel 0.3 darker in a 10x10 map: mean 0.003, p99 0 (nearest rank 99 of 100), max 0.3.
  Image a = grey_map(10, 10, [](int, int) { return 0.8; });
  Image b = a;
  b.at(7, 2)[0] = 0.5f;
  diff::MapDiffOptions o;
  o.decoding_a = o.decoding_b = diff::map_decoding(MapKind::ao, {}, "a");
  o.tolerances = diff::default_map_tolerances(o.decoding_a);
  diff::MapDiffStats s = diff::compare_maps(a, b, o);
  EXPECT_NEAR(s.mean, 0.003, 1e-6);
  EXPECT_EQ(s.p99, 0.0);
  EXPECT_NEAR(s.max, 0.3, 1e-6);
  EXPECT_FALSE(s.within);  // max over 0.02
  o.tolerances.max_abs = 0.31;
  EXPECT_TRUE(diff::compare_maps(a, b, o).within);
  o.tolerances.max_mean = 0.002;
  EXPECT_FALSE(diff::compare_maps(a, b, o).within);
  // Masked out, the texel is not compared.
  o.tolerances = diff::default_map_tolerances(o.decoding_a);
  o.mask.assign(100, 1);
  o.mask[2 * 10 + 7] = 0;
  s = diff::compare_maps(a, b, o);
  EXPECT_EQ(s.skipped_mask, 1u);
  EXPECT_EQ(s.max, 0.0);
  EXPECT_TRUE(s.within);
  o.include_padding = true;
  EXPECT_FALSE(diff::compare_maps(a, b, o).within);
  // Grey + alpha: alpha < 0.5 is not compared; a NaN texel makes the maps differ.
  Image ga(2, 1, 2, 1.0f), gb(2, 1, 2, 1.0f);
  gb.at(0, 0)[0] = 0.0f;
  gb.at(0, 0)[1] = 0.0f;
  diff::MapDiffOptions g;
  g.decoding_a = g.decoding_b = diff::map_decoding(MapKind::thickness, {}, "a");
  g.tolerances = diff::default_map_tolerances(g.decoding_a);
  s = diff::compare_maps(ga, gb, g);
  EXPECT_EQ(s.skipped_alpha, 1u);
  EXPECT_TRUE(s.within);
  gb.at(1, 0)[0] = std::nanf("");
  s = diff::compare_maps(ga, gb, g);
  EXPECT_EQ(s.nonfinite_texels, 1u);
  EXPECT_FALSE(s.within);
  EXPECT_EQ(s.mean, 0.0);  // never NaN
}

TEST(NmdiffMaps, CommandLineNamesKindUnitsAndExitsByTolerance) {
  const std::string dir = scratch_dir();
  const Metadata range{{"nmbake:map", "height"}, {"nmbake:height_range", "-0.5:0.5"}};
  write_map(dir, "a.exr", grey_map(20, 10, [](int x, int y) { return 0.5 + distance_at(x, y); }), range);
  write_map(dir, "b.exr", grey_map(20, 10, [](int x, int y) { return 0.5 + distance_at(x, y) + 0.004; }), range);
  write_map(dir, "ao.png", grey_map(20, 10, [](int, int) { return 1.0; }), {{"nmbake:map", "ao"}});
  std::string out, err;

  // Within the defaults; --json carries the kind, units and statistics.
  EXPECT_EQ(run_nmdiff(dir, "a.exr b.exr --json r.json", out, err), 0);
  // (the float EXR leaves ~4e-8 of rounding in p99 and max)
  EXPECT_TRUE(nmbake::test::contains(out, "\nmap=height units=scene-units mean=0.004 p99=0.004")) << out;
  EXPECT_TRUE(nmbake::test::contains(out, " texels=200 within=1\n")) << out;
  const nlohmann::json j = nlohmann::json::parse(nmbake::test::read_file(dir + "/r.json"));
  EXPECT_EQ(j["map"], "height");
  EXPECT_EQ(j["units"], "scene units");
  EXPECT_NEAR(j["mean"].get<double>(), 0.004, 1e-6);
  EXPECT_EQ(j["within"], true);

  // A tighter --max-abs: outside (exit 1); --max-deg is not a height map's tolerance (exit 2).
  EXPECT_EQ(run_nmdiff(dir, "a.exr b.exr --max-abs 0.003", out, err), 1);
  EXPECT_TRUE(nmbake::test::contains(out, "within=0\n")) << out;
  EXPECT_EQ(run_nmdiff(dir, "a.exr b.exr --max-deg 1", out, err), 2);

  // Different kinds: one line naming both files and kinds (exit 2).
  EXPECT_EQ(run_nmdiff(dir, "a.exr ao.png", out, err), 2);
  EXPECT_TRUE(nmbake::test::contains(err, "a.exr is a height map, ao.png an ao map")) << err;
  EXPECT_EQ(err.find('\n'), err.size() - 1) << err;
}

TEST(NmdiffMaps, VertexColorIsTheLargestChannelDifferenceInRgb) {
  Image a(4, 2, 3, 0.25f), b(4, 2, 3, 0.25f);
  b.at(1, 1)[0] = 0.35f;  // red 0.1
  b.at(1, 1)[2] = 0.45f;  // blue 0.2: this texel differs by 0.2
  diff::MapDiffOptions o;
  o.decoding_a = o.decoding_b = diff::map_decoding(MapKind::vertex_color, {}, "a");
  o.tolerances = diff::default_map_tolerances(o.decoding_a);
  const diff::MapDiffStats s = diff::compare_maps(a, b, o);
  EXPECT_EQ(s.units, "rgb");
  EXPECT_NEAR(s.max, 0.2, 1e-6);
  EXPECT_NEAR(s.mean, 0.2 / 8, 1e-6);
  EXPECT_EQ(s.worst_x, 1);
  EXPECT_EQ(s.worst_y, 1);
  EXPECT_FALSE(s.within);
}
