// write_image's PNG path quantizes each row inside the bands' encoders (io/png_write.cpp): its
// file must be, byte for byte, encode_png of the whole image quantized first (quantize8 with and
// without dither, quantize16), for values out of range, NaN, odd sizes and 1 to 4 channels, on
// one thread and on several.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "io/image_io.h"
#include "io/image_write.h"
#include "io/png_write.h"
#include "test_support.h"

namespace {

nmbake::Image ramp_image(int w, int h, int channels, unsigned seed) {
  nmbake::Image img(w, h, channels, 0.0f);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> noise(-0.01f, 0.01f);
  for (std::size_t i = 0; i < img.pixels.size(); ++i)
    img.pixels[i] = float(i % 331) / 300.0f - 0.05f + noise(rng);  // below 0 and above 1 at the ends
  img.pixels[7 % img.pixels.size()] = std::numeric_limits<float>::quiet_NaN();
  return img;
}

}  // namespace

TEST(PngRows, WriteImageMatchesQuantizeThenEncode) {
  const std::vector<std::pair<std::string, std::string>> meta = {{"nmbake:map", "test"}, {"DateTime", "2020:01:02 03:04:05"}};
  const std::string path = nmbake::test::scratch_dir() + "/rows.png";
  int compared = 0;
  for (int channels = 1; channels <= 4; ++channels)
    for (const auto& [w, h] : {std::pair{37, 19}, std::pair{1, 5}, std::pair{64, 64}})
      for (int bits : {8, 16})
        for (bool dither : {false, true}) {
          if (bits == 16 && dither) continue;  // dither is for 8 bits only
          const nmbake::Image img = ramp_image(w, h, channels, unsigned(w * 100 + channels));
          std::string error;
          std::vector<unsigned char> want;
          if (bits == 8) {
            const auto q = nmbake::image_write::quantize8(img.pixels, dither, 1);
            want = nmbake::encode_png(q.data(), w, h, channels, 8, meta, nmbake::PngSettings{}, 1, &error);
          } else {
            const auto q = nmbake::image_write::quantize16(img.pixels, 1);
            want = nmbake::encode_png(q.data(), w, h, channels, 16, meta, nmbake::PngSettings{}, 1, &error);
          }
          ASSERT_FALSE(want.empty()) << error;
          for (int threads : {1, 3}) {
            nmbake::WriteOptions o(bits, meta);
            o.dither = dither;
            o.threads = threads;
            nmbake::write_image(path, img, o);
            const std::string got = nmbake::test::read_file(path);
            EXPECT_TRUE(got == std::string(want.begin(), want.end())) << channels << " channels " << w << "x" << h << " " << bits
                                                                      << " bits dither " << dither << " threads " << threads;
            ++compared;
          }
        }
  EXPECT_EQ(compared, 4 * 3 * 3 * 2);
}

// quantize8's vector path (16 values at a time) against the scalar rule it mirrors, value for
// value: NaN, infinities, -0, negatives, values above 1, the half steps (k + 0.5) / 255 and their
// float neighbours, and a length that leaves a scalar tail.
TEST(PngRows, Quantize8MatchesTheScalarRule) {
  std::vector<float> v = {std::numeric_limits<float>::quiet_NaN(),
                          std::numeric_limits<float>::infinity(),
                          -std::numeric_limits<float>::infinity(),
                          -0.0f,
                          0.0f,
                          -1e-30f,
                          1e-30f,
                          1.0f,
                          1.5f,
                          -2.0f,
                          3e38f};
  for (int k = 0; k <= 256; ++k) {
    const float half = float((k + 0.5) / 255.0);
    v.insert(v.end(), {half, std::nextafter(half, 0.0f), std::nextafter(half, 2.0f), float(k / 255.0)});
  }
  std::mt19937 rng(12111);
  std::uniform_real_distribution<float> any(-0.1f, 1.1f);
  while (v.size() % 16 != 7) v.push_back(any(rng));
  for (int i = 0; i < 5000; ++i) v.push_back(any(rng));
  nmbake::Image::Pixels pixels(v.begin(), v.end());
  const auto got = nmbake::image_write::quantize8(pixels, false, 1);
  std::vector<std::uint8_t> run(v.size());
  nmbake::image_write::quantize8_run(v.data(), 0, v.size(), false, run.data());
  ASSERT_EQ(got.size(), v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    double want = double(v[i]) * 255.0 + 0.5;
    if (!(want > 0.0)) want = 0.0;
    if (want > 255.0) want = 255.0;
    EXPECT_EQ(int(got[i]), int(std::uint8_t(want))) << "value " << v[i] << " at " << i;
    EXPECT_EQ(int(run[i]), int(std::uint8_t(want))) << "value " << v[i] << " at " << i;
  }
}
