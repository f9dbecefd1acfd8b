// Checks read_image makes before it allocates anything for an image's pixels: the path names a
// regular file (a FIFO or a device would block or never end), and the size the file's header
// states is possible for a file of that many bytes and fits in memory. No OpenImageIO here: the
// header's values come in as plain numbers, so the bounds are tested without image files.
#pragma once

#include <cstdint>
#include <string>

#include "core/memory_budget.h"  // format_bytes

namespace nmbake {

// What an image's header says, as read_image needs it before reading the pixels.
struct ImageHeader {
  std::int64_t width = 0, height = 0, channels = 0;
  int bits_per_sample = 8;  // as stored in the file (PNG may store 1, 2 or 4; EXR half 16, float 32)
  std::string format;       // OpenImageIO's format name: "png", "openexr", "tiff", ...
  std::string compression;  // the header's "compression" attribute ("zip", "piz", "lzw", ...), or ""
  bool palette = false;     // pixels may be stored as one index each (PNG, TIFF): channels then bound nothing
};

// The size in bytes of the regular file `path` (a symbolic link is followed). Throws InputError:
// "<path>: cannot read image: no such file", "...: it is a folder", or "<path>: not a regular file
// (a FIFO)" for anything else (FIFO, socket, character or block device).
std::uint64_t regular_file_size(const std::string& path);

// The most pixel bytes (width * height * channels * bits_per_sample / 8, channels 1 when
// `palette`) one byte of a valid file of this format and compression can hold; 0 when no sound
// bound is known (then only the memory budget applies).
double max_pixel_bytes_per_file_byte(const ImageHeader& header);

// Bytes read_image needs at its peak for `header`: the float image it returns and the reader's
// buffer in the stored type (the PNG reader decodes the whole image before converting it).
std::uint64_t image_read_bytes(const ImageHeader& header);

// Throws ResourceError naming `path` when the header's pixels cannot be in a file of `file_size`
// bytes ("big.png: header says 20000x20000 pixels (4.8 GB) but the file has 812 bytes") or their
// reading needs more than `budget` bytes.
void check_image_header(const std::string& path, const ImageHeader& header, std::uint64_t file_size, std::uint64_t budget);

}  // namespace nmbake
