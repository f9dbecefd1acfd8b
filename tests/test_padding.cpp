#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/padding.h"
#include "pipeline/pad.h"

using namespace nmbake;

namespace {

// Pads a W x H map of covered texels drawn with probability `density` (each holding its own index)
// by `pad`, and checks every texel against a search of all covered texels: kept where covered,
// filled from a covered texel at exactly the nearest distance where that is within `pad`, left
// alone beyond it.
void check_against_brute_force(std::mt19937& rng, int W, int H, double density, int pad) {
  Image img(W, H, 1, -1.0f);
  std::vector<std::uint8_t> cov(std::size_t(W) * H, 0);
  std::bernoulli_distribution on(density);
  std::vector<int> covered;
  for (int i = 0; i < W * H; ++i)
    if (on(rng)) {
      cov[i] = 1;
      img.pixels[i] = float(i);
      covered.push_back(i);
    }
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
      for (int j : covered) {
        const long dx = j % W - x, dy = j / W - y, d = dx * dx + dy * dy;
        if (best < 0 || d < best) best = d;
      }
      if (best < 0 || best > long(pad) * pad) {
        ASSERT_EQ(out.pixels[i], -1.0f) << "texel beyond the padding was filled, pad " << pad;
      } else {
        // Filled from some covered texel at exactly the nearest distance.
        const int src = int(out.pixels[i]);
        ASSERT_GE(src, 0) << "pad " << pad;
        ASSERT_TRUE(cov[src]);
        const long dx = src % W - x, dy = src / W - y;
        ASSERT_EQ(dx * dx + dy * dy, best) << "pad " << pad;
      }
    }
}

}  // namespace

TEST(Padding, MatchesBruteForceNearestTexel) {
  std::mt19937 rng(99);
  for (int trial = 0; trial < 20; ++trial) check_against_brute_force(rng, 23 + trial, 17 + 2 * trial, 0.03, 1 + trial % 7);
}

// Paddings to 126 keep the column pass's offsets in a byte, larger ones in an int (padding.cpp):
// both sides of that line, on sparse maps where covered texels lie hundreds of texels apart.
TEST(Padding, MatchesBruteForceNearestTexelForPaddingsAroundAByte) {
  std::mt19937 rng(7);
  for (int pad : {100, 126, 127, 128, 200, 400}) check_against_brute_force(rng, 300, 260, 0.0002, pad);
}

// Within a column (a map one texel wide), a texel halfway between two covered ones takes the upper
// one's value (the smaller row), as the exact transform's lower envelope does.
TEST(Padding, ATieInAColumnGoesToTheUpperTexel) {
  std::mt19937 rng(41);
  for (int trial = 0; trial < 50; ++trial) {
    const int H = 30 + trial;
    Image img(1, H, 1, -1.0f);
    std::vector<std::uint8_t> cov(std::size_t(H), 0);
    std::bernoulli_distribution on(0.15);
    for (int y = 0; y < H; ++y)
      if (on(rng)) cov[std::size_t(y)] = 1, img.pixels[std::size_t(y)] = float(y);
    pad_islands(img, cov, H);
    for (int y = 0; y < H; ++y) {
      if (cov[std::size_t(y)]) continue;
      int up = y, down = y;
      while (up >= 0 && !cov[std::size_t(up)]) --up;
      while (down < H && !cov[std::size_t(down)]) ++down;
      const int want = up < 0 && down >= H ? -1 : down >= H || (up >= 0 && y - up <= down - y) ? up : down;
      EXPECT_EQ(img.pixels[std::size_t(y)], float(want)) << "trial " << trial << " row " << y;
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

// The pad stage (pipeline/pad.h) against a plain count of what it is documented to do: the
// background set to the flat normal, texels facing away and suspect texels counted, the mask
// written, the region found, and all of it the same on 1, 2 and 3 threads.
TEST(Padding, PadMapCountsMatchAPlainCountOnAnyThreads) {
  std::mt19937 rng(23);
  BakeOptions o;
  o.width = 211;
  o.height = 150;  // more bands than threads, the last one short
  o.samples = 4;
  o.padding = 5;
  o.suspect_mask = true;
  const std::size_t n = std::size_t(o.width) * o.height;
  BakeResult in;
  in.map = Image(o.width, o.height, 3, -7.0f);
  in.coverage.assign(n, 0);
  std::vector<std::uint8_t> disagree(n, 0);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (std::size_t i = 0; i < n; ++i) {
    const int x = int(i % std::size_t(o.width)), y = int(i / std::size_t(o.width));
    if ((x - 150) * (x - 150) + (y - 40) * (y - 40) > 900 && x > 20) continue;  // a disc and a strip: the rest background
    in.coverage[i] = 1;
    for (int c = 0; c < 3; ++c) in.map.pixels[3 * i + c] = unit(rng);
    disagree[i] = unit(rng) < 0.05f;
    in.stats.trace.texels_covered++;
  }
  const float z_limit = float(0.5 + 0.5 * std::cos(kSuspectTiltDeg * 3.14159265358979323846 / 180.0));
  std::size_t facing = 0, suspect = 0, cell[8][8] = {};
  for (std::size_t i = 0; i < n; ++i) {
    if (!in.coverage[i]) continue;
    const float z = in.map.pixels[3 * i + 2];
    facing += z < 0.5f;
    if (z < z_limit || disagree[i]) {
      ++suspect;
      ++cell[8 * (i / std::size_t(o.width)) / std::size_t(o.height)][8 * (i % std::size_t(o.width)) / std::size_t(o.width)];
    }
  }
  ASSERT_GT(suspect, 100u);
  std::size_t best = 0;
  for (auto& row : cell)
    for (std::size_t c : row) best = std::max(best, c);
  for (int threads : {1, 2, 3}) {
    BakeResult r = in;
    pad_map(o, disagree, threads, r);
    EXPECT_EQ(r.stats.pad.texels_facing_away, facing);
    EXPECT_EQ(r.stats.pad.suspect_texels, suspect);
    EXPECT_EQ(r.stats.pad.suspect_region_share, double(best) / double(suspect));
    std::size_t marked = 0, flat = 0;  // flat: background texels that are not (0.5, 0.5, 1)
    for (std::size_t i = 0; i < n; ++i) {
      marked += r.suspect_mask.pixels[i] == 1.0f;
      EXPECT_TRUE(r.suspect_mask.pixels[i] == 0.0f || r.suspect_mask.pixels[i] == 1.0f);
      if (!in.coverage[i]) continue;
      for (int c = 0; c < 3; ++c) ASSERT_EQ(r.map.pixels[3 * i + c], in.map.pixels[3 * i + c]) << "a covered texel moved";
    }
    EXPECT_EQ(marked, suspect);
    // Beyond the padding's reach (x > 26 and away from the disc): the flat normal.
    for (std::size_t i = 0; i < n; ++i) {
      const int x = int(i % std::size_t(o.width)), y = int(i / std::size_t(o.width));
      if (x > 26 && (x - 150) * (x - 150) + (y - 40) * (y - 40) > 36 * 36) {
        flat += !(r.map.pixels[3 * i] == 0.5f && r.map.pixels[3 * i + 1] == 0.5f && r.map.pixels[3 * i + 2] == 1.0f);
      }
    }
    EXPECT_EQ(flat, 0u) << "a background texel is not (0.5, 0.5, 1)";
    EXPECT_GT(r.stats.pad.texels_padded, 0u);
  }
}
