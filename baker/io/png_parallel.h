// PNG encoding on several threads, for the maps nmbake writes. libpng filters and compresses a
// file's rows in one stream, on one thread: 0.11 s of the 1M sculpt's 2048^2 command. Here the rows
// are cut into a fixed number of bands; each band is filtered and deflated on its own (zlib, raw
// deflate ended by a sync flush, so the bands' streams join into one), and the file is assembled
// around the joined stream: IHDR, tEXt per metadata item and tIME as png_write.cpp writes them, the
// IDAT chunks, IEND. The bands do not depend on the thread count, so neither do the bytes.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "io/png_write.h"

namespace nmbake {

// encode_png's contract (png_write.h) with `threads` threads (0: all cores), for settings whose
// `filters` name one filter (0x08 none, 0x10 sub, 0x20 up, 0x40 average, 0x80 Paeth): the same
// pixels, a valid PNG. Other filter masks (libpng's adaptive choice) go to encode_png.
std::vector<unsigned char> encode_png_parallel(const void* rows, int width, int height, int channels, int bits,
                                               const std::vector<std::pair<std::string, std::string>>& metadata,
                                               const PngSettings& settings, int threads, std::string* error);

}  // namespace nmbake
