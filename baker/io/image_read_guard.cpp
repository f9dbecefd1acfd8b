#include "io/image_read_guard.h"

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>

#include "core/errors.h"

namespace nmbake {
namespace {

constexpr std::uint64_t kUnknown = std::numeric_limits<std::uint64_t>::max();

// Deflate (zlib: PNG, EXR zip, TIFF deflate) at best codes its longest match, 258 bytes, with a
// 1-bit length code and a 1-bit distance code: 1032 bytes per byte of stream.
constexpr double kDeflate = 1032.0;

// Pixel bytes a file may hold beyond its ratio: block and table overhead make small files compress
// worse, never better, so this only lets tiny files claim small images, which are harmless.
constexpr double kSlackBytes = 1 << 20;

const char* file_kind(mode_t mode) {
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a file";
}

}  // namespace

namespace {

// EXR (OpenEXR's compressors, by OpenImageIO's names).
double exr_ratio(const std::string& c) {
  if (c == "none" || c.empty()) return 1.0;
  if (c == "rle") return 64.0;  // a count byte and a value byte give at most 128 bytes
  // piz: a wavelet, then a Huffman coder whose codes take at least 1 bit and whose run code
  // repeats a 16-bit value at most 255 times in about 10 bits (~410:1), below deflate's bound.
  if (c == "zip" || c == "zips" || c == "piz") return kDeflate;
  if (c == "pxr24") return kDeflate * 4.0 / 3.0;  // 32-bit floats cut to 24 bits, then deflate
  // b44: 4x4 half values (32 bytes) in 14 bytes, or 3 when all equal (b44a); float channels as is.
  if (c == "b44" || c == "b44a") return 32.0 / 3.0;
  // dwaa, dwab: some channels are run-length coded, then deflated; the DCT channels' DC values
  // are deflated and their AC values Huffman coded (as piz), which stays below that.
  if (c == "dwaa" || c == "dwab") return 64.0 * kDeflate;
  return 0.0;
}

// TIFF (libtiff's compressors, by OpenImageIO's names). JPEG, zstd, lzma, CCITT and the rest can
// pack some images far tighter (zstd codes a 128 KiB run in 4 bytes): no bound for them.
double tiff_ratio(const std::string& c) {
  if (c == "none" || c.empty()) return 1.0;
  if (c == "packbits") return 64.0;  // a count byte and a value byte give at most 128 bytes
  // LZW codes take at least 9 bits and a code stands for at most 4096 bytes (its table's size).
  if (c == "lzw") return 4096.0 * 8.0 / 9.0;
  if (c == "zip" || c == "deflate" || c == "adobe_deflate") return kDeflate;
  return 0.0;
}

}  // namespace

std::uint64_t regular_file_size(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR) throw InputError(path + ": cannot read image: no such file");
    throw InputError(path + ": cannot read image: " + std::strerror(errno));
  }
  if (S_ISDIR(st.st_mode)) throw InputError(path + ": cannot read image: it is a folder");
  if (!S_ISREG(st.st_mode)) throw InputError(path + ": not a regular file (" + file_kind(st.st_mode) + ")");
  return std::uint64_t(st.st_size);
}

double max_pixel_bytes_per_file_byte(const ImageHeader& h) {
  if (h.format == "png") return kDeflate;
  if (h.format == "openexr") return exr_ratio(h.compression);
  if (h.format == "tiff") return tiff_ratio(h.compression);
  if (h.format == "pnm") return 1.0;      // binary samples as stored; ASCII ones take more
  if (h.format == "targa") return 128.0;  // a run-length packet: one byte, then one pixel for up to 128
  // BMP (run-length codes may skip pixels), JPEG, HDR (old-style runs multiply) and the rest.
  return 0.0;
}

std::uint64_t image_read_bytes(const ImageHeader& h) {
  const double pixels = double(h.width) * double(h.height) * double(h.channels);
  const double bytes = pixels * (4.0 + std::max(1, h.bits_per_sample) / 8.0);
  return bytes >= 1.8e19 ? kUnknown : std::uint64_t(bytes);
}

void check_image_header(const std::string& path, const ImageHeader& h, std::uint64_t file_size, std::uint64_t budget) {
  const std::string says = "header says " + std::to_string(h.width) + "x" + std::to_string(h.height) + " pixels";
  const double floats = double(h.width) * double(h.height) * double(h.channels) * 4.0;
  const double ratio = max_pixel_bytes_per_file_byte(h);
  const double stored = double(h.width) * double(h.height) * double(h.palette ? 1 : h.channels) * h.bits_per_sample / 8.0;
  if (ratio > 0 && stored > ratio * double(file_size) + kSlackBytes)
    throw ResourceError(path + ": " + says + " (" + format_bytes(floats) + ") but the file has " + std::to_string(file_size) +
                        " bytes");
  const std::uint64_t needed = image_read_bytes(h);
  if (needed > budget)
    throw ResourceError(path + ": " + says + " (" + format_bytes(floats) + "; " + format_bytes(double(needed)) +
                        " to read), which exceeds the memory budget of " + format_bytes(double(budget)) +
                        " (available memory, ulimit -v)");
}

}  // namespace nmbake
