#include <random>

#include <gtest/gtest.h>

#include "core/padding.h"

using namespace nmbake;

TEST(Padding, MatchesBruteForceNearestTexel) {
  std::mt19937 rng(99);
  for (int trial = 0; trial < 20; ++trial) {
    const int W = 23 + trial, H = 17 + 2 * trial;
    Image img(W, H, 1, -1.0f);
    std::vector<std::uint8_t> cov(std::size_t(W) * H, 0);
    std::bernoulli_distribution on(0.03);
    for (int i = 0; i < W * H; ++i)
      if (on(rng)) {
        cov[i] = 1;
        img.pixels[i] = float(i);
      }
    const int pad = 1 + trial % 7;
    Image out = img;
    pad_islands(out, cov, pad);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const int i = y * W + x;
        if (cov[i]) {
          EXPECT_EQ(out.pixels[i], img.pixels[i]);
          continue;
        }
        long best = -1;
        for (int j = 0; j < W * H; ++j)
          if (cov[j]) {
            const long dx = j % W - x, dy = j / W - y, d = dx * dx + dy * dy;
            if (best < 0 || d < best) best = d;
          }
        if (best < 0 || best > long(pad) * pad) {
          EXPECT_EQ(out.pixels[i], -1.0f) << "texel beyond the padding was filled";
        } else {
          // Filled from some covered texel at exactly the nearest distance.
          const int src = int(out.pixels[i]);
          ASSERT_GE(src, 0);
          ASSERT_TRUE(cov[src]);
          const long dx = src % W - x, dy = src / W - y;
          EXPECT_EQ(dx * dx + dy * dy, best);
        }
      }
  }
}

TEST(Padding, ZeroPaddingAndEmptyCoverageChangeNothing) {
  Image img(8, 8, 3, 0.25f);
  std::vector<std::uint8_t> none(64, 0);
  EXPECT_EQ(pad_islands(img, none, 16), 0u);
  std::vector<std::uint8_t> one(64, 0);
  one[10] = 1;
  EXPECT_EQ(pad_islands(img, one, 0), 0u);
  for (float v : img.pixels) EXPECT_EQ(v, 0.25f);
}

TEST(Padding, SameResultWithOneOrTwoThreads) {
  // Wider than one column block and taller than one row part, so both threads get work.
  std::mt19937 rng(7);
  const int W = 197, H = 133;
  Image img(W, H, 3, 0.25f);
  std::vector<std::uint8_t> cov(std::size_t(W) * H, 0);
  std::bernoulli_distribution on(0.01);
  for (int i = 0; i < W * H; ++i)
    if (on(rng)) {
      cov[i] = 1;
      for (int c = 0; c < 3; ++c) img.pixels[3 * std::size_t(i) + c] = float(i * 3 + c);
    }
  Image one = img, two = img;
  const std::size_t n1 = pad_islands(one, cov, 12, 1), n2 = pad_islands(two, cov, 12, 2);
  EXPECT_GT(n1, 0u);
  EXPECT_EQ(n1, n2);
  EXPECT_TRUE(one.pixels == two.pixels);
}
