// Output formats (issue 20, item 5): TGA (8-bit), EXR compressed by default (ZIP, lossless) with
// --compression passed through, and --dither for 8-bit output (one step of triangular noise,
// seeded per texel: the same map whatever the thread count, and the float value on average).
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "io/image_io.h"
#include "test_support.h"

namespace nmbake {
namespace {

using test::contains;
using test::run_nmbake;

Image gradient(int w, int h) {
  Image im(w, h, 3, 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) im.pixels[(std::size_t(y) * w + x) * 3 + c] = float(x + 3 * y + 7 * c) / float(w + 3 * h + 14);
  return im;
}

TEST(FormatsOut, TgaHoldsThePngValues) {
  const std::string dir = test::scratch_dir();
  const Image im = gradient(37, 23);
  write_image(dir + "/m.tga", im);
  write_image(dir + "/m.png", im);
  const Image tga = read_image(dir + "/m.tga"), png = read_image(dir + "/m.png");
  ASSERT_EQ(tga.width, 37);
  ASSERT_EQ(tga.height, 23);
  ASSERT_GE(tga.channels, 3);
  for (int i = 0; i < 37 * 23; ++i)
    for (int c = 0; c < 3; ++c)
      ASSERT_EQ(tga.pixels[std::size_t(i) * tga.channels + c], png.pixels[std::size_t(i) * png.channels + c]);
  EXPECT_EQ(default_bits_for("a.TGA"), 8);
  EXPECT_THROW(check_output_format("a.tga", 16), UsageError);
  EXPECT_NO_THROW(check_output_format("a.tga", 8));
}

TEST(FormatsOut, ExrIsZipByDefaultAndTakesTheCompressionGiven) {
  const std::string dir = test::scratch_dir();
  const Image im = gradient(64, 64);
  write_image(dir + "/zip.exr", im);
  EXPECT_EQ(read_image_metadata(dir + "/zip.exr")["compression"], "zip");
  for (const char* c : {"none", "piz", "zip", "dwaa"}) {
    WriteOptions o;
    o.compression = c;
    write_image(dir + "/" + c + ".exr", im, o);
    EXPECT_EQ(read_image_metadata(dir + "/" + c + ".exr")["compression"], c);
  }
  // Lossless: the values come back exactly.
  EXPECT_TRUE(read_image(dir + "/zip.exr").pixels == im.pixels);
  EXPECT_TRUE(read_image(dir + "/piz.exr").pixels == im.pixels);
}

TEST(FormatsOut, CompressionAndDitherAreCheckedAgainstTheOutput) {
  const test::CliRun png = run_nmbake(test::sample_low() + " " + test::sample_high() + " -o m.png --size 16 --compression zip");
  EXPECT_EQ(png.code, 1) << png.err;
  EXPECT_TRUE(contains(png.err, "--compression zip applies to EXR output")) << png.err;
  const test::CliRun lzw = run_nmbake(test::sample_low() + " " + test::sample_high() + " -o m.exr --size 16 --compression lzw");
  EXPECT_EQ(lzw.code, 1) << lzw.err;
  const test::CliRun exr = run_nmbake(test::sample_low() + " " + test::sample_high() + " -o m.exr --size 16 --dither");
  EXPECT_EQ(exr.code, 1) << exr.err;
  EXPECT_TRUE(contains(exr.err, "--dither applies to 8-bit output")) << exr.err;
  const test::CliRun tga16 = run_nmbake(test::sample_low() + " " + test::sample_high() + " -o m.tga --size 16 --bits 16");
  EXPECT_EQ(tga16.code, 1) << tga16.err;
  const test::CliRun ok =
      run_nmbake(test::sample_low() + " " + test::sample_high() + " -o m.exr --size 16 --compression piz --report r.json");
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_EQ(ok.report["options"]["compression"], "piz");
  EXPECT_EQ(read_image_metadata(ok.dir + "/m.exr")["compression"], "piz");
}

// A flat value between two steps: without dither every texel rounds the same way; with it the
// texels take the two neighbouring steps and their mean is the float value.
TEST(FormatsOut, DitherKeepsTheValueOnAverage) {
  const std::string dir = test::scratch_dir();
  const float value = (128.0f + 0.3f) / 255.0f;
  const Image flat(256, 256, 3, value);
  WriteOptions dithered;
  dithered.dither = true;
  write_image(dir + "/plain.png", flat);
  write_image(dir + "/dither.png", flat, dithered);
  write_image(dir + "/again.png", flat, dithered);
  EXPECT_TRUE(test::read_file(dir + "/dither.png") == test::read_file(dir + "/again.png"));
  const Image plain = read_image(dir + "/plain.png"), noisy = read_image(dir + "/dither.png");
  double sum = 0.0;
  for (std::size_t i = 0; i < noisy.pixels.size(); ++i) {
    EXPECT_EQ(plain.pixels[i], 128.0f / 255.0f);
    const double step = double(noisy.pixels[i]) * 255.0;
    ASSERT_GE(step, 127.0 - 1e-3);
    ASSERT_LE(step, 130.0 + 1e-3);
    sum += step;
  }
  EXPECT_NEAR(sum / double(noisy.pixels.size()), 128.3, 0.01);
}

TEST(FormatsOut, DitheredMapIsTheSameWhateverTheThreads) {
  const std::string dir = test::scratch_dir();
  const test::CliRun one =
      run_nmbake(test::sample_low() + " " + test::sample_high() + " -o one.png --size 128 --dither --threads 1", "", dir);
  const test::CliRun two =
      run_nmbake(test::sample_low() + " " + test::sample_high() + " -o two.png --size 128 --dither --threads 2", "", dir);
  const test::CliRun plain =
      run_nmbake(test::sample_low() + " " + test::sample_high() + " -o plain.png --size 128 --threads 2", "", dir);
  ASSERT_EQ(one.code, 0) << one.err;
  ASSERT_EQ(two.code, 0) << two.err;
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_TRUE(test::read_file(dir + "/one.png") == test::read_file(dir + "/two.png"))
      << "the thread count changed the dithered map";
  EXPECT_TRUE(test::read_file(dir + "/one.png") != test::read_file(dir + "/plain.png")) << "--dither changed nothing";
}

}  // namespace
}  // namespace nmbake
