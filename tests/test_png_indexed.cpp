// The PNG writer's indexed layout (io/png_write.cpp): an 8-bit RGB image of at most 256 colours
// (the ID maps' flat colours) is stored as palette indices of 1, 2, 4 or 8 bits. It must read back
// as exactly the samples the RGB layout stores (quantize8 of the floats), give the same bytes on
// any number of threads, and not be used for 257 colours or with dither.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "io/image_io.h"
#include "io/image_write.h"
#include "io/png_write.h"
#include "test_support.h"

namespace {

using nmbake::Image;

// `colours` distinct colours in flat patches (runs along rows, islands, single texels), some
// values off the 8-bit steps (they quantize to the step) and a NaN (it quantizes to 0).
Image patch_image(int width, int height, int colours) {
  Image img(width, height, 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const int id = ((x / 3) * 31 + (y / 3) * 17 + (x == y ? 3 : 0)) % colours;
      float* p = img.at(x, y);
      p[0] = float(id % 16) * 17.0f / 255.0f + 0.0004f;  // off the step, rounds back to it
      p[1] = float(id / 16) * 17.0f / 255.0f;
      p[2] = float((id * 37) % 256) / 255.0f;
    }
  return img;
}

// The IHDR's bit depth and colour type (bytes 24 and 25 of the file).
std::pair<int, int> png_depth_and_type(const std::string& bytes) {
  return {static_cast<unsigned char>(bytes[24]), static_cast<unsigned char>(bytes[25])};
}

}  // namespace

TEST(PngIndexed, FlatColoursReadBackExactlyOnAnyThreadCount) {
  const std::string path = nmbake::test::scratch_dir() + "/indexed.png";
  const std::pair<int, int> cases[] = {{1, 1}, {2, 1}, {3, 2}, {4, 2}, {5, 4}, {16, 4}, {17, 8}, {256, 8}};
  for (const auto& [colours, depth] : cases)
    for (const auto& [w, h] : {std::pair{131, 67}, std::pair{1, 9}, std::pair{9, 1}}) {
      const Image img = patch_image(w, h, colours);
      if (w * h < colours) continue;
      const auto want = nmbake::image_write::quantize8(img.pixels, false, 1);
      std::string first;
      for (int threads : {1, 2, 3}) {
        nmbake::WriteOptions o(8);
        o.threads = threads;
        o.indexed = true;
        nmbake::write_image(path, img, o);
        const std::string bytes = nmbake::test::read_file(path);
        const std::string what = std::to_string(colours) + " colours " + std::to_string(w) + "x" + std::to_string(h) + ", " +
                                 std::to_string(threads) + " threads";
        if (threads == 1) first = bytes;
        else EXPECT_TRUE(bytes == first) << what << ": the bytes depend on the threads";
        const auto [got_depth, type] = png_depth_and_type(bytes);
        EXPECT_EQ(type, 3) << what;
        // Fewer colours than the depth's room may still need it (the image's own count decides).
        EXPECT_LE(got_depth, depth) << what;
        const Image back = nmbake::read_image(path);
        ASSERT_EQ(back.channels, 3) << what;
        ASSERT_EQ(back.pixels.size(), want.size()) << what;
        std::size_t differ = 0;
        for (std::size_t i = 0; i < want.size(); ++i) differ += std::lround(back.pixels[i] * 255.0f) != long(want[i]);
        EXPECT_EQ(differ, 0u) << what;
      }
    }
}

TEST(PngIndexed, ManyColoursOrDitherKeepTheRgbLayout) {
  const std::string path = nmbake::test::scratch_dir() + "/rgb.png";
  for (bool dither : {false, true}) {
    const Image img = patch_image(97, 61, dither ? 2 : 257);
    nmbake::WriteOptions o(8);
    o.dither = dither;
    o.threads = 2;
    o.indexed = true;
    nmbake::write_image(path, img, o);
    const std::string bytes = nmbake::test::read_file(path);
    const auto q = nmbake::image_write::quantize8(img.pixels, dither, 1);
    if (!dither) {  // the image does have 257 colours
      std::vector<int> seen;
      for (std::size_t i = 0; i < q.size(); i += 3) seen.push_back(q[i] << 16 | q[i + 1] << 8 | q[i + 2]);
      std::sort(seen.begin(), seen.end());
      ASSERT_EQ(std::unique(seen.begin(), seen.end()) - seen.begin(), 257);
    }
    std::string error;
    const std::vector<unsigned char> want = nmbake::encode_png(q.data(), 97, 61, 3, 8, {}, nmbake::PngSettings{}, 1, &error);
    ASSERT_FALSE(want.empty()) << error;
    EXPECT_EQ(png_depth_and_type(bytes), std::make_pair(8, 2)) << "dither " << dither;
    EXPECT_TRUE(bytes == std::string(want.begin(), want.end())) << "dither " << dither;
  }
}

// Without WriteOptions::indexed (every map but the IDs) a few flat colours stay RGB: a normal map
// of one colour is still the 8-bit RGB file the tools that read normal maps expect.
TEST(PngIndexed, OnlyWhenAskedFor) {
  const std::string path = nmbake::test::scratch_dir() + "/flat.png";
  const Image img = patch_image(33, 17, 2);
  nmbake::WriteOptions o(8);
  nmbake::write_image(path, img, o);
  EXPECT_EQ(png_depth_and_type(nmbake::test::read_file(path)), std::make_pair(8, 2));
  o.indexed = true;
  nmbake::write_image(path, img, o);
  EXPECT_EQ(png_depth_and_type(nmbake::test::read_file(path)).second, 3);
}

// An image of palette indices (WriteOptions::palette, how the ID maps are held) is written as the
// RGB image expand_palette makes of it: the same samples as that image written with `indexed` (in
// a PNG the same bytes), in PNG, TIFF and EXR, with dither, and past 256 colours. Indices 0, out of range, fractional
// near a step, and NaN are black or their colour as expand_palette says; two indices of one colour
// and a palette colour equal to black share an entry.
TEST(PngIndexed, PaletteIndicesWriteAsTheirColours) {
  const std::string dir = nmbake::test::scratch_dir();
  for (int colours : {1, 3, 40, 255, 300}) {
    std::vector<glm::vec3> palette;
    for (int k = 0; k < colours; ++k)
      palette.push_back(glm::vec3(float(k % 7) * 36.0f, float((k / 7) % 7) * 36.0f, float(k * 13 % 256)) / 255.0f);
    if (colours > 2) palette[2] = palette[1];  // two names, one colour
    if (colours > 3) palette[3] = glm::vec3(0.0f);
    Image index(83, 47, 1);
    for (int y = 0; y < index.height; ++y)
      for (int x = 0; x < index.width; ++x) {
        const int v = ((x / 4) * 29 + (y / 3) * 11) % (colours + 3);  // colours + 1, + 2: out of range
        *index.at(x, y) = float(v) + (x % 5 == 1 ? -0.25f : x % 5 == 2 ? 0.25f : 0.0f);
      }
    *index.at(5, 5) = std::nanf("");
    *index.at(6, 5) = -1.0f;
    const Image rgb = nmbake::expand_palette(index, palette);
    for (const char* ext : {".png", ".tif", ".exr"})
      for (bool dither : {false, true}) {
        if (dither && std::string(ext) != ".png") continue;
        nmbake::WriteOptions o(std::string(ext) == ".png" ? 8 : 0);
        o.dither = dither;
        o.indexed = true;
        nmbake::write_image(dir + "/want" + ext, rgb, o);
        o.palette = palette;
        nmbake::write_image(dir + "/got" + ext, index, o);
        const std::string what = std::to_string(colours) + " colours, " + ext + (dither ? ", dither" : "");
        if (std::string(ext) == ".png") {  // no time stamp unless SOURCE_DATE_EPOCH gives one: the bytes
          EXPECT_TRUE(nmbake::test::read_file(dir + "/got" + ext) == nmbake::test::read_file(dir + "/want" + ext)) << what;
        }
        const Image got = nmbake::read_image(dir + "/got" + ext), want = nmbake::read_image(dir + "/want" + ext);
        EXPECT_EQ(got.channels, 3) << what;
        EXPECT_TRUE(got.pixels == want.pixels) << what;
      }
  }
}
