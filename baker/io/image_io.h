// Reading and writing images: PNG is written by png_write.cpp, everything else goes through
// OpenImageIO, in a module loaded on first use (oiio_module.h: image_io_oiio.cpp and
// image_read.cpp are the only code that includes it).
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/image.h"

namespace nmbake {

// Bit depth implied by a file name: .png, .tga -> 8, .tif/.tiff -> 16, .exr -> 32 (float), others 8.
int default_bits_for(const std::string& path);

// Throws UsageError when the extension is not one we write (.png, .tga, .tif, .tiff, .exr), or the
// format cannot hold `bits` (8, 16 or 32; 32 means float: EXR and TIFF only; EXR with 16 is half
// float; TGA 8 only).
void check_output_format(const std::string& path, int bits);

struct WriteOptions {
  // Also {bits, metadata}: written as an aggregate before temp_path was added.
  WriteOptions(int bits_ = 0, std::vector<std::pair<std::string, std::string>> metadata_ = {})
      : bits(bits_), metadata(std::move(metadata_)) {}
  int bits = 0;                                               // 8, 16 or 32 (float); 0 = default_bits_for(path)
  std::vector<std::pair<std::string, std::string>> metadata;  // written as string attributes
  // "" = write to a temporary file beside `path` and rename it into place; else write this file
  // only (created or emptied, never through a symbolic link) and leave the rename to the caller,
  // which commits several outputs together (the nmbake command's OutputSet).
  std::string temp_path;
  // EXR compression as OpenImageIO names it ("none", "zip", "piz", "dwaa", ...); "" = ZIP (lossless).
  std::string compression;
  // 8-bit output: triangular noise of one step before rounding, the same for a texel whatever
  // thread or run writes it.
  bool dither = false;
  // PNG: an 8-bit RGB image of at most 256 colours (without dither) is stored indexed (colour type
  // 3, png_write.h), the same samples to a reader in a fraction of the bytes. For maps of flat
  // colours (the ID maps); other maps stay RGB, as the tools that read normal maps expect them.
  bool indexed = false;
  // Not empty: `image` is 1 channel of indices into this palette (core/image.h expand_palette: 0
  // black, k palette[k - 1]) and the file is the RGB image they stand for. A PNG of 8 bits without
  // dither stores them indexed (as `indexed` would the RGB image) while they fit in 256 colours.
  std::vector<glm::vec3> palette;
  // Threads an encoder may use (the quantization to 8 or 16 bits, PNG's bands, png_write.h): 0 =
  // all cores. The bytes written do not depend on it.
  int threads = 0;
};

// Writes `image` (values in [0,1] for integer formats, rounded to nearest) to a temporary file,
// flushed to disk (fsync), and renames it into place (unless options.temp_path is given), so
// `path` is either the old file or the complete new one. `path` chooses the format and names the
// file in errors. Throws OutputError "<path>: cannot write: <reason>", one short line (the
// system's reason where a write failed: "No space left on device"), the temporary removed.
void write_image(const std::string& path, const Image& image, const WriteOptions& options = {});

// Starts loading what writing `path` needs, on a thread of its own, so that it runs beside the
// caller's work (a bake): OpenImageIO's module for a format other than PNG and TIFF, 0.3 s of one core.
// write_image waits for it. Does nothing for PNG; starts no thread when "all cores" is one thread
// (nmbake --threads 1: no thread beside the stages). Throws OutputError naming `path` when the
// module is not to be found, so that a command fails before its work rather than at the write.
void prepare_write(const std::string& path);

// Reads any format OpenImageIO reads, converted to float (integer formats scaled to [0,1]).
// Throws InputError naming the file when it cannot be read.
Image read_image(const std::string& path);

// The string attributes stored with an image (e.g. "nmbake:green" -> "down", as the baker writes
// them with WriteOptions::metadata), including "nmbake:key=value" items of the description tag,
// where TIFF keeps them. Reads the header only. Throws InputError naming the file when it cannot
// be opened.
std::map<std::string, std::string> read_image_metadata(const std::string& path);

// OpenImageIO's and OpenEXR's own thread pools, as the last read or write set them: each sizes
// both to the process's "all cores" (--threads), not the machine's. {OpenImageIO's "threads"
// (its workers and the caller), OpenEXR's workers}. Loads the module (for tests).
std::pair<int, int> image_library_threads();

namespace image_io_detail {
std::string lower_extension(const std::string& path);  // ".png" for "A/b.PNG"
bool is_tiff(const std::string& ext);                  // ".tif" or ".tiff" (a lower_extension)
}  // namespace image_io_detail

}  // namespace nmbake
