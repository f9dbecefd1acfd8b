#include "pipeline/pad.h"

#include <algorithm>
#include <cmath>

#include "core/padding.h"
#include "core/parallel.h"

namespace nmbake {

namespace {

constexpr int kBandRows = 32;  // rows per part of the pass before padding

// What one band of rows holds: counts summed over the bands in order, so the same whichever
// thread took which band.
struct BandCounts {
  std::size_t facing_away = 0;
  std::size_t suspect = 0;
  std::size_t cells[8][8] = {};  // suspect texels per cell of an 8 x 8 grid, row 0 the top (v = 1)
};

// One band: the background set to the flat normal, and the suspect texels (BakeStats::
// suspect_texels: tilted past kSuspectTiltDeg, or samples disagreeing) counted and marked.
void scan_band(const BakeOptions& opt, const std::vector<std::uint8_t>& disagree, int band, BakeResult& result, BandCounts& out) {
  const int W = opt.width, H = opt.height;
  const bool tangent = opt.space == NormalSpace::tangent;
  const float flat[3] = {0.5f, 0.5f, tangent ? 1.0f : 0.5f};
  // The encoded z of a tangent-space normal tilted kSuspectTiltDeg from (0, 0, 1).
  const float z_limit = float(0.5 + 0.5 * std::cos(kSuspectTiltDeg * 3.14159265358979323846 / 180.0));
  float* const map = result.map.pixels.data();
  float* const mask = opt.suspect_mask ? result.suspect_mask.pixels.data() : nullptr;
  for (int y = band * kBandRows; y < std::min(H, (band + 1) * kBandRows); ++y) {
    const int cell_row = std::min(7, 8 * y / H);
    for (int x = 0; x < W; ++x) {
      const std::size_t i = std::size_t(y) * W + std::size_t(x);
      float* const texel = map + 3 * i;
      bool suspect = false;
      if (!result.coverage[i]) {
        texel[0] = flat[0], texel[1] = flat[1], texel[2] = flat[2];
      } else {
        out.facing_away += tangent && texel[2] < 0.5f;
        suspect = (tangent && texel[2] < z_limit) || (!disagree.empty() && disagree[i]);
        if (suspect) {
          ++out.suspect;
          ++out.cells[cell_row][std::min(7, 8 * x / W)];
        }
      }
      if (mask) mask[i] = suspect ? 1.0f : 0.0f;
    }
  }
}

// The sums of the bands, and the UV region most suspect texels lie in.
void sum_bands(const std::vector<BandCounts>& bands, BakeStats& st) {
  std::size_t cells[8][8] = {};
  for (const BandCounts& b : bands) {
    st.pad.texels_facing_away += b.facing_away;
    st.pad.suspect_texels += b.suspect;
    for (int r = 0; r < 8; ++r)
      for (int c = 0; c < 8; ++c) cells[r][c] += b.cells[r][c];
  }
  if (!st.pad.suspect_texels) return;
  st.pad.suspect_share = st.trace.texels_covered ? double(st.pad.suspect_texels) / double(st.trace.texels_covered) : 0.0;
  int best_r = 0, best_c = 0;
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 8; ++c)
      if (cells[r][c] > cells[best_r][best_c]) best_r = r, best_c = c;
  st.pad.suspect_region[0] = best_c / 8.0;
  st.pad.suspect_region[1] = 1.0 - (best_r + 1) / 8.0;
  st.pad.suspect_region[2] = (best_c + 1) / 8.0;
  st.pad.suspect_region[3] = 1.0 - best_r / 8.0;
  st.pad.suspect_region_share = double(cells[best_r][best_c]) / double(st.pad.suspect_texels);
}

}  // namespace

void pad_map(const BakeOptions& opt, const std::vector<std::uint8_t>& disagree, int threads, BakeResult& result) {
  BakeStats& st = result.stats;
  if (opt.suspect_mask) result.suspect_mask = Image(opt.width, opt.height, 1, Image::Unset{});  // scan_band writes each
  std::vector<BandCounts> bands(std::size_t((opt.height + kBandRows - 1) / kBandRows));
  parallel_chunks(threads, bands.size(), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t b = begin; b < end; ++b) scan_band(opt, disagree, int(b), result, bands[b]);
  });
  sum_bands(bands, st);
  // The normal map and the set's other maps padded together: the nearest covered texels found once.
  std::vector<Image*> images{&result.map};
  for (BakedMap& m : result.maps)
    if (!m.image.pixels.empty()) images.push_back(&m.image);
  st.pad.texels_padded = pad_islands(images, result.coverage, opt.padding, threads);
}

}  // namespace nmbake
