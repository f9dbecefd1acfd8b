// The PNG writer (io/png_write.cpp, without OpenImageIO) against OpenImageIO: every sample a PNG
// holds reads back as the TIFF writer (through OpenImageIO) stores it, for every channel count
// and both bit depths; the encoder's settings change the bytes, never the pixels; the metadata and
// the reproducible time read back under OpenImageIO's names.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>

#include "core/errors.h"
#include "io/image_io.h"
#include "io/png_write.h"
#include "test_support.h"

namespace {

using nmbake::Image;

// Odd sizes (rows not a multiple of 4 bytes), values outside [0, 1] and NaN included.
Image noisy_image(int width, int height, int channels, unsigned seed) {
  Image img(width, height, channels);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.1f, 1.1f);
  for (float& v : img.pixels) v = u(rng);
  img.pixels[0] = std::numeric_limits<float>::quiet_NaN();
  img.pixels[1] = 0.5f;
  return img;
}

TEST(PngWrite, SamplesEqualWhatTheTiffWriterStores) {
  const std::string dir = nmbake::test::scratch_dir();
  for (int channels = 1; channels <= 4; ++channels)
    for (int bits : {8, 16})
      for (bool dither : {false, true}) {
        if (dither && bits != 8) continue;
        const Image img = noisy_image(37, 23, channels, unsigned(10 * channels + bits));
        nmbake::WriteOptions o(bits);
        o.dither = dither;
        nmbake::write_image(dir + "/a.png", img, o);
        nmbake::write_image(dir + "/a.tif", img, o);
        const Image png = nmbake::read_image(dir + "/a.png"), tif = nmbake::read_image(dir + "/a.tif");
        const std::string what =
            std::to_string(channels) + " channels, " + std::to_string(bits) + " bits" + (dither ? ", dithered" : "");
        ASSERT_EQ(png.width, 37) << what;
        ASSERT_EQ(png.height, 23) << what;
        ASSERT_EQ(png.channels, channels) << what;
        ASSERT_EQ(png.pixels.size(), tif.pixels.size()) << what;
        std::size_t differ = 0;
        for (std::size_t i = 0; i < png.pixels.size(); ++i) differ += png.pixels[i] != tif.pixels[i];
        EXPECT_EQ(differ, 0u) << what;
      }
}

TEST(PngWrite, SettingsChangeTheBytesNotThePixels) {
  const std::string dir = nmbake::test::scratch_dir();
  const Image img = noisy_image(64, 48, 3, 7);
  std::vector<std::uint8_t> rows(img.pixels.size());
  for (std::size_t i = 0; i < rows.size(); ++i) rows[i] = std::uint8_t(i * 7 % 251);
  Image reference;
  std::size_t sizes = 0;
  for (const nmbake::PngSettings s : {nmbake::PngSettings{0, 0x08, 0}, nmbake::PngSettings{1, 0x20, 0},
                                      nmbake::PngSettings{6, 0x40, 1}, nmbake::PngSettings{9, 0x80, 3}}) {
    std::string error;
    const std::vector<unsigned char> bytes = nmbake::encode_png(rows.data(), 64, 48, 3, 8, {}, s, 2, &error);
    ASSERT_FALSE(bytes.empty()) << error;
    nmbake::test::write_file(dir + "/s.png", std::string(bytes.begin(), bytes.end()));
    const Image back = nmbake::read_image(dir + "/s.png");
    ASSERT_EQ(back.pixels.size(), rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i) ASSERT_EQ(std::lround(back.pixels[i] * 255.0f), rows[i]) << i;
    sizes += bytes.size();
  }
  EXPECT_GT(sizes, 0u);
}

TEST(PngWrite, MetadataAndTheReproducibleTimeReadBack) {
  const std::string path = nmbake::test::scratch_dir() + "/meta.png";
  ::setenv("SOURCE_DATE_EPOCH", "1700000000", 1);
  nmbake::write_image(path, Image(3, 2, 3, 0.5f),
                      {8, {{"nmbake:green", "down"}, {"ImageDescription", "a tangent-space normal map"}}});
  ::unsetenv("SOURCE_DATE_EPOCH");
  const auto metadata = nmbake::read_image_metadata(path);
  EXPECT_EQ(metadata.at("nmbake:green"), "down");
  EXPECT_EQ(metadata.at("ImageDescription"), "a tangent-space normal map");
  EXPECT_EQ(metadata.at("DateTime"), "2023:11:14 22:13:20");
  // Without SOURCE_DATE_EPOCH, no time: two writes give the same bytes.
  nmbake::write_image(path, Image(3, 2, 3, 0.5f));
  const std::string first = nmbake::test::read_file(path);
  nmbake::write_image(path, Image(3, 2, 3, 0.5f));
  EXPECT_TRUE(first == nmbake::test::read_file(path));
}

}  // namespace
