#include "pipeline/pad.h"

#include <algorithm>
#include <cmath>

#include "core/padding.h"

namespace nmbake {

namespace {

// Suspect texels (BakeStats::suspect_texels) from the map before padding and the texels whose
// samples disagree; their mask and the UV region most of them lie in.
void find_suspects(const BakeOptions& opt, const std::vector<std::uint8_t>& disagree, BakeResult& result) {
  BakeStats& st = result.stats;
  const int W = opt.width, H = opt.height;
  // The encoded z of a tangent-space normal tilted kSuspectTiltDeg from (0, 0, 1).
  const float z_limit = float(0.5 + 0.5 * std::cos(kSuspectTiltDeg * 3.14159265358979323846 / 180.0));
  if (opt.suspect_mask) result.suspect_mask = Image(W, H, 1, 0.0f);
  std::size_t cells[8][8] = {};
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const std::size_t i = std::size_t(y) * W + std::size_t(x);
      if (!result.coverage[i]) continue;
      const bool tilted = opt.space == NormalSpace::tangent && result.map.pixels[3 * i + 2] < z_limit;
      if (!tilted && (disagree.empty() || !disagree[i])) continue;
      ++st.suspect_texels;
      if (opt.suspect_mask) result.suspect_mask.pixels[i] = 1.0f;
      ++cells[std::min(7, 8 * y / H)][std::min(7, 8 * x / W)];  // row 0 is the top: v = 1
    }
  if (!st.suspect_texels) return;
  st.suspect_share = st.texels_covered ? double(st.suspect_texels) / double(st.texels_covered) : 0.0;
  int best_r = 0, best_c = 0;
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 8; ++c)
      if (cells[r][c] > cells[best_r][best_c]) best_r = r, best_c = c;
  st.suspect_region[0] = best_c / 8.0;
  st.suspect_region[1] = 1.0 - (best_r + 1) / 8.0;
  st.suspect_region[2] = (best_c + 1) / 8.0;
  st.suspect_region[3] = 1.0 - best_r / 8.0;
  st.suspect_region_share = double(cells[best_r][best_c]) / double(st.suspect_texels);
}

}  // namespace

void pad_map(const BakeOptions& opt, const std::vector<std::uint8_t>& disagree, int threads, BakeResult& result) {
  BakeStats& st = result.stats;
  const float flat[3] = {0.5f, 0.5f, opt.space == NormalSpace::tangent ? 1.0f : 0.5f};
  for (std::size_t i = 0; i < result.coverage.size(); ++i)
    if (!result.coverage[i])
      for (int c = 0; c < 3; ++c) result.map.pixels[3 * i + c] = flat[c];
  if (opt.space == NormalSpace::tangent)
    for (std::size_t i = 0; i < result.coverage.size(); ++i)
      st.texels_facing_away += result.coverage[i] && result.map.pixels[3 * i + 2] < 0.5f;
  find_suspects(opt, disagree, result);
  st.texels_padded = pad_islands(result.map, result.coverage, opt.padding, threads);
}

}  // namespace nmbake
