// PNG on several threads (io/png_write.cpp): for every single filter, strategy, channel count and
// bit depth, the file reads back (through OpenImageIO) as exactly the rows given, as libpng's own
// encoding of them does (bench/png_libpng.cpp); its bytes are the same on 1, 2 and 3 threads;
// images shorter than its bands, one texel wide, or one texel at all work; settings it does not
// take and malformed input are an error, not a file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "io/image_io.h"
#include "io/image_write.h"
#include "io/png_write.h"
#include "png_libpng.h"
#include "test_support.h"

namespace {

// Rows of smooth ramps with noise (what a normal map's rows are like, so RLE finds runs), as the
// encoders take them: bytes for 8 bits, native uint16 for 16.
std::vector<unsigned char> sample_rows(int w, int h, int channels, int bits, unsigned seed) {
  std::mt19937 rng(seed);
  const std::size_t n = std::size_t(w) * std::size_t(h) * std::size_t(channels);
  std::vector<unsigned char> bytes(n * std::size_t(bits / 8));
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned v = unsigned(i / std::size_t(channels)) % 97u * 300u + (rng() % 4 == 0 ? unsigned(rng() % 700u) : 0u);
    if (bits == 8) {
      bytes[i] = static_cast<unsigned char>(v >> 4);
    } else {
      const auto s = static_cast<std::uint16_t>(v);
      std::memcpy(&bytes[2 * i], &s, 2);
    }
  }
  return bytes;
}

// The samples read back from a PNG file's bytes, scaled to the stored integers.
std::vector<long> read_back(const std::vector<unsigned char>& png, int bits) {
  const std::string path = nmbake::test::scratch_dir() + "/p.png";
  nmbake::test::write_file(path, std::string(png.begin(), png.end()));
  const nmbake::Image img = nmbake::read_image(path);
  std::vector<long> v(img.pixels.size());
  const double scale = bits == 8 ? 255.0 : 65535.0;
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::lround(double(img.pixels[i]) * scale);
  return v;
}

std::vector<long> expected(const std::vector<unsigned char>& rows, int bits) {
  std::vector<long> v(rows.size() / std::size_t(bits / 8));
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (bits == 8) {
      v[i] = rows[i];
    } else {
      std::uint16_t s;
      std::memcpy(&s, &rows[2 * i], 2);
      v[i] = s;
    }
  }
  return v;
}

}  // namespace

TEST(PngParallel, EveryFilterReadsBackAsTheRowsOnAnyThreadCount) {
  const int sizes[][2] = {{37, 23}, {1, 1}, {5, 3}, {1, 40}, {64, 9}};
  int files = 0;
  for (const auto& size : sizes)
    for (int channels = 1; channels <= 4; ++channels)
      for (int bits : {8, 16})
        for (int filters : {0x08, 0x10, 0x20, 0x40, 0x80})
          for (int strategy : {0, 3}) {
            const int w = size[0], h = size[1];
            const std::vector<unsigned char> rows = sample_rows(w, h, channels, bits, unsigned(w * 31 + channels + filters));
            const nmbake::PngSettings s{strategy == 3 ? 1 : 6, filters, strategy};
            const std::vector<std::pair<std::string, std::string>> meta = {{"nmbake:green", "up"},
                                                                           {"DateTime", "2023:11:14 22:13:20"}};
            std::string error;
            const std::vector<unsigned char> one = nmbake::encode_png(rows.data(), w, h, channels, bits, meta, s, 1, &error);
            const std::string what = std::to_string(w) + "x" + std::to_string(h) + ", " + std::to_string(channels) +
                                     " channels, " + std::to_string(bits) + " bits, filters " + std::to_string(filters) +
                                     ", strategy " + std::to_string(strategy);
            ASSERT_FALSE(one.empty()) << what << ": " << error;
            for (int threads : {2, 3})
              EXPECT_TRUE(nmbake::encode_png(rows.data(), w, h, channels, bits, meta, s, threads, &error) == one)
                  << what << ", " << threads << " threads";
            ASSERT_EQ(read_back(one, bits), expected(rows, bits)) << what;
            ++files;
          }
  EXPECT_EQ(files, 5 * 4 * 2 * 5 * 2);
  // Against libpng's encoding of the same rows: the same samples (and a similar size).
  const std::vector<unsigned char> rows = sample_rows(256, 128, 3, 8, 5);
  std::string error;
  const auto ours = nmbake::encode_png(rows.data(), 256, 128, 3, 8, {}, nmbake::PngSettings{}, 0, &error);
  const auto theirs = nmbake::bench::encode_png_libpng(rows.data(), 256, 128, 3, 8, {}, nmbake::PngSettings{}, &error);
  EXPECT_EQ(read_back(ours, 8), read_back(theirs, 8));
  EXPECT_LT(double(ours.size()), 1.05 * double(theirs.size()) + 200.0);
}

// A tall image is cut into many bands (one per 64 rows), and each thread writes the streams of the
// bands it takes one after another into its own output blocks of 8 MiB (io/png_write.cpp): noise
// that deflate cannot shrink fills several blocks per thread, a band's stream then starting a new
// block. The file is the same on 1, 2, 3 and 5 threads and reads back as the rows.
TEST(PngParallel, TallNoiseOverSeveralOutputBlocksReadsBackOnAnyThreadCount) {
  const int w = 1500, h = 1000, channels = 4, bits = 16;  // 12 MB of rows: 16 bands, about 750 KB each
  std::mt19937 rng(11);
  std::vector<unsigned char> rows(std::size_t(w) * std::size_t(h) * std::size_t(channels) * 2);
  for (unsigned char& b : rows) b = static_cast<unsigned char>(rng());
  std::string error;
  const nmbake::PngSettings s{};
  const std::vector<unsigned char> one = nmbake::encode_png(rows.data(), w, h, channels, bits, {}, s, 1, &error);
  ASSERT_FALSE(one.empty()) << error;
  EXPECT_GT(one.size(), rows.size());  // noise: stored, not compressed, so more than one block's worth
  for (int threads : {2, 3, 5})
    EXPECT_TRUE(nmbake::encode_png(rows.data(), w, h, channels, bits, {}, s, threads, &error) == one) << threads << " threads";
  EXPECT_EQ(read_back(one, bits), expected(rows, bits));
}

TEST(PngParallel, MetadataReadsBack) {
  const std::vector<unsigned char> rows = sample_rows(9, 12, 3, 8, 3);
  std::string error;
  const auto png = nmbake::encode_png(
      rows.data(), 9, 12, 3, 8,
      {{"nmbake:space", "tangent"}, {"ImageDescription", "a tangent-space normal map"}, {"DateTime", "2023:11:14 22:13:20"}},
      nmbake::PngSettings{}, 2, &error);
  ASSERT_FALSE(png.empty()) << error;
  const std::string path = nmbake::test::scratch_dir() + "/m.png";
  nmbake::test::write_file(path, std::string(png.begin(), png.end()));
  const auto metadata = nmbake::read_image_metadata(path);
  EXPECT_EQ(metadata.at("nmbake:space"), "tangent");
  EXPECT_EQ(metadata.at("ImageDescription"), "a tangent-space normal map");
  EXPECT_EQ(metadata.at("DateTime"), "2023:11:14 22:13:20");
}

TEST(PngParallel, OtherSettingsAndBadInputAreAnError) {
  const std::vector<unsigned char> rows = sample_rows(16, 16, 3, 8, 4);
  std::string error;
  const nmbake::PngSettings adaptive{6, 0xF8, 0};
  EXPECT_TRUE(nmbake::encode_png(rows.data(), 16, 16, 3, 8, {}, adaptive, 2, &error).empty());
  EXPECT_NE(error.find("filters"), std::string::npos) << error;
  for (const auto& bad : {std::vector<int>{0, 16, 3, 8}, std::vector<int>{16, 0, 3, 8}, std::vector<int>{16, 16, 5, 8},
                          std::vector<int>{16, 16, 3, 12}}) {
    error.clear();
    EXPECT_TRUE(nmbake::encode_png(rows.data(), bad[0], bad[1], bad[2], bad[3], {}, {}, 2, &error).empty());
    EXPECT_NE(error.find("IHDR"), std::string::npos) << error;
  }
  error.clear();
  EXPECT_TRUE(nmbake::encode_png(rows.data(), 16, 16, 3, 8, {}, nmbake::PngSettings{12, 0x80, 3}, 2, &error).empty());
  EXPECT_FALSE(error.empty());
  error.clear();
  EXPECT_TRUE(nmbake::encode_png(rows.data(), 16, 16, 3, 8, {{" bad", "x"}}, {}, 2, &error).empty());
  EXPECT_NE(error.find("keyword"), std::string::npos) << error;
}

// Quantization on any number of threads: the values of a plain loop (8 and 16 bits, rounded half
// away from zero, clamped, NaN to 0), and the dithered ones the same on 1, 2 and 3 threads.
TEST(PngParallel, QuantizationDoesNotDependOnTheThreads) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> value(-0.2f, 1.2f);
  nmbake::Image::Pixels values(700001);  // several chunks and a short last one
  for (float& v : values) v = value(rng);
  values[0] = std::numeric_limits<float>::quiet_NaN();
  values[1] = 0.5f / 255.0f;
  values[2] = 1.0f;
  for (int threads : {1, 2, 3}) {
    const auto q8 = nmbake::image_write::quantize8(values, false, threads);
    const auto q16 = nmbake::image_write::quantize16(values, threads);
    ASSERT_EQ(q8.size(), values.size());
    for (std::size_t i = 0; i < values.size(); ++i) {
      const double v = std::isnan(values[i]) ? 0.0 : std::clamp(double(values[i]), 0.0, 1.0);
      ASSERT_EQ(q8[i], std::uint8_t(std::floor(v * 255.0 + 0.5))) << i;
      ASSERT_EQ(q16[i], std::uint16_t(std::floor(v * 65535.0 + 0.5))) << i;
    }
    EXPECT_TRUE(nmbake::image_write::quantize8(values, true, threads) == nmbake::image_write::quantize8(values, true, 1));
  }
}
