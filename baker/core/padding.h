// Padding (edge dilation): texels outside the UV layout take the value of the nearest covered
// texel, so mip-maps and bilinear filtering do not pull background colour into the islands.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/image.h"

namespace nmbake {

// Fills every uncovered texel whose Euclidean distance (in texels, centre to centre) to the nearest
// covered texel is at most `padding` with that texel's value. `covered` has width*height entries
// (nonzero = covered). padding <= 0 does nothing; ties between equally near texels are broken
// deterministically. Returns the number of texels filled. `threads` share the work (0 = all cores);
// the result does not depend on it.
std::size_t pad_islands(Image& image, const std::vector<std::uint8_t>& covered, int padding, int threads = 0);
// The same for several images of one size (the maps of a texture set), the nearest texels found once.
std::size_t pad_islands(const std::vector<Image*>& images, const std::vector<std::uint8_t>& covered, int padding,
                        int threads = 0);

}  // namespace nmbake
