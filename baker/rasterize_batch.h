// Coverage of a tile's samples by one triangle, several samples at a time.
//
// It computes, lane by lane, exactly the operations of covers() (rasterize.h) in the same order,
// so every claimed sample and every barycentric is bit-identical to the one-sample-at-a-time
// code; only the instruction count changes (4 samples per vector operation).
#pragma once

#include <cstddef>
#include <cstdint>

#include "rasterize.h"

namespace nmbake {

// A tile's samples: kTile x kTile texels, `samples` per texel, slot (y * tile + x) * samples + k.
struct TileSlots {
  std::int32_t* tri;  // per slot: the claiming triangle, or -1
  double* bary;       // per slot: 3 barycentrics of the claiming triangle
};

// Where triangle `t` (texel setup `tt`, valid) covers sample k of texel (x, y) for x in [x0, x1],
// y in [y0, y1] (image coordinates inside the tile whose corner is (tx0, ty0), `tile` texels wide),
// and the slot is unclaimed: claims it for `t` with covers()' barycentrics. Covered slots claimed
// already (overlapping islands) are counted in the return value. `ox`, `oy`: the sample offsets.
std::uint64_t cover_tile(const TexelTriangle& tt, std::int32_t t, int tx0, int ty0, int tile, int x0, int x1, int y0,
                         int y1, const double* ox, const double* oy, int samples, const TileSlots& slots);

}  // namespace nmbake
