// What every image writer shares (image_io.cpp through OpenImageIO, png_write.cpp through zlib):
// the checks before a write, quantization to the stored integers, the temporary file and its
// rename, and the one-line errors. Internal to io/.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/image.h"
#include "io/image_io.h"
#include "io/text_file.h"

namespace nmbake::image_write {

// Refuses what no writer takes (check_output_format; an empty image) and a folder that does not
// exist or is not writable; returns the bit depth to store (options.bits, else the path's default).
int check_write(const std::string& path, const Image& image, const WriteOptions& options);

// value * 255 (or 65535) rounded half away from zero, clamped; NaN becomes 0. quantize8 adds one
// step of triangular noise first when `dither` is set, seeded by the value's index. On `threads`
// threads (<= 0: every core); the values do not depend on them.
template <typename T>
using Samples = std::vector<T, DefaultInitAllocator<T>>;
Samples<std::uint8_t> quantize8(const Image::Pixels& values, bool dither, int threads = 1);
Samples<std::uint16_t> quantize16(const Image::Pixels& values, int threads = 1);
// The same for a run of `n` values, the first of them value number `first` of its image (dither's
// seed): what quantize8 and quantize16 give those values.
void quantize8_run(const float* values, std::size_t first, std::size_t n, bool dither, std::uint8_t* out);
void quantize16_run(const float* values, std::size_t n, std::uint16_t* out);

// A TIFF's description tag: the given ImageDescription, then every other item as "key=value",
// "; " between them (the TIFF format has no place for them; read_image_metadata reads them back).
std::string tiff_description(const std::vector<std::pair<std::string, std::string>>& metadata);

// "YYYY:MM:DD HH:MM:SS" (UTC) of SOURCE_DATE_EPOCH, or "" when it is unset or malformed.
std::string reproducible_date_time();

// "YYYY:MM:DD HH:MM:SS" (the DateTime metadata item) as year, month, day, hour, minute, second;
// false when it is not that. The PNG writers store it as a tIME chunk.
bool date_time_fields(const std::string& text, int fields[6]);

// Throws OutputError "<path>: cannot write: <reason>", or ResourceError (exit 4) when the reason is
// memory running out.
[[noreturn]] void fail_write(const std::string& path, const std::string& reason);

// A temporary beside `path` for a write without WriteOptions::temp_path (nmdiff, the tests).
std::string temp_path_for(const std::string& path);

// The spans' bytes, in order, to the temporary (options.temp_path, else temp_path_for(path)), flushed to disk (fsync),
// then renamed to `path` unless options.temp_path is given (the caller renames it). Errors name
// `path` and remove the temporary.
void write_file_spans(const std::string& path, const std::vector<ByteSpan>& spans, const WriteOptions& options);

}  // namespace nmbake::image_write
