// PNG maps and masks, written without OpenImageIO. The rows are cut into bands (their number fixed by the height);
// each band is filtered and deflated on its own, on every core (zlib, raw deflate ended by a sync
// flush, so the bands' streams join into one), and the file is assembled around the joined stream:
// IHDR, one tEXt per metadata item ("ImageDescription" as "Description", which OpenImageIO reads
// back under its own name), "DateTime" as tIME, the IDAT chunks, IEND. The bands do not depend on
// the thread count, so neither do the bytes.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "core/image.h"
#include "io/image_io.h"

namespace nmbake {

// The encoder's settings. The defaults were chosen by measurement (bench section 9, docs/bench.md):
// zlib's RLE strategy after the Paeth filter, about as small as libpng's defaults at the speed of
// zlib's fastest level. A normal map's rows differ little from their neighbours, so after Paeth
// prediction most bytes repeat the one before: what RLE codes, and it searches for nothing else.
struct PngSettings {
  int level = 1;       // zlib level 0-9 (with the RLE strategy any level from 1 codes the same)
  int filters = 0x80;  // one PNG filter: 0x08 none, 0x10 sub, 0x20 up, 0x40 average, 0x80 Paeth (libpng's PNG_FILTER_*)
  int strategy = 3;    // zlib strategy: 0 default, 1 filtered, 2 Huffman only, 3 RLE
};

// The PNG file's bytes for `rows` (height rows of width * channels samples, 1 byte each for
// bits 8, native-endian uint16 for bits 16; channels 1 to 4: grey, grey + alpha, RGB, RGBA), on
// `threads` threads (0: all cores). Empty, with *error set ("insufficient memory" when memory ran
// out), on failure: a size, channel count, bit depth, filter or keyword PNG does not take.
std::vector<unsigned char> encode_png(const void* rows, int width, int height, int channels, int bits,
                                      const std::vector<std::pair<std::string, std::string>>& metadata,
                                      const PngSettings& settings, int threads, std::string* error);

// write_image (image_io.h) for a .png path: quantized as every writer does, encoded with the
// default PngSettings on options.threads threads, written to the temporary file and renamed as
// write_image documents. With options.indexed, an 8-bit RGB image of at most 256 colours without
// dither (a map of flat colours: the ID maps) is stored indexed (colour type 3, palette in order of first use, indices
// of 1, 2, 4 or 8 bits, filter up, RLE): a reader expands it to the very samples the RGB layout
// would store, and it is a fraction of the bytes to filter and deflate.
void write_png_image(const std::string& path, const Image& image, const WriteOptions& options);

}  // namespace nmbake
