// libpng's own encoder, one stream on one thread: the reference that PNG settings are measured
// against (bench section 9) and that tests/test_png_parallel.cpp compares nmbake's PNG encoder
// (io/png_write.h) with. Not in the product.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "io/png_write.h"

namespace nmbake::bench {

// encode_png's contract (io/png_write.h) on one thread, for any filter mask libpng takes (0xF8:
// its adaptive choice among all five). Errors carry libpng's message ("insufficient memory" when
// memory ran out).
std::vector<unsigned char> encode_png_libpng(const void* rows, int width, int height, int channels, int bits,
                                             const std::vector<std::pair<std::string, std::string>>& metadata,
                                             const PngSettings& settings, std::string* error);

}  // namespace nmbake::bench
