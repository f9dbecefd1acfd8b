#include "io/image_write.h"

#include <fcntl.h>
#include <unistd.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <system_error>
#include <type_traits>

#include "core/errors.h"
#include "core/parallel.h"
#include "io/text_file.h"

namespace nmbake::image_write {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kQuantizeChunk = std::size_t(1) << 18;  // values per chunk

// value * scale rounded half away from zero, clamped to [0, scale]; NaN becomes 0.
// For v = value * scale >= 0, round(v) == trunc(v + 0.5) exactly: v is a float times at most
// 65535, so v + 0.5 is exact in double wherever it can reach 1. Negative and NaN values clamp to 0
// either way.
template <typename T>
void quantize_values(const float* values, std::size_t n, double scale, T* out) {
  for (std::size_t i = 0; i < n; ++i) {
    double v = static_cast<double>(values[i]) * scale + 0.5;
    if (!(v > 0.0)) v = 0.0;
    if (v > scale) v = scale;
    out[i] = static_cast<T>(v);  // truncation of a value in [0, scale]
  }
}

// quantize_values for 8 bits, 16 values at a time in SSE2 (the same IEEE steps lane by lane: the
// float widened, times 255, plus 0.5; max against 0 gives 0 for NaN and v <= 0 as !(v > 0) does,
// min against 255 clamps; then truncation), the rest one by one.
void quantize_values8(const float* values, std::size_t n, std::uint8_t* out) {
  std::size_t i = 0;
#if defined(__SSE2__)
  const __m128d scale = _mm_set1_pd(255.0), half = _mm_set1_pd(0.5), zero = _mm_setzero_pd();
  const auto four = [&](const float* v) {  // 4 values to 4 int32 lanes
    const __m128 f = _mm_loadu_ps(v);
    __m128d lo = _mm_add_pd(_mm_mul_pd(_mm_cvtps_pd(f), scale), half);
    __m128d hi = _mm_add_pd(_mm_mul_pd(_mm_cvtps_pd(_mm_movehl_ps(f, f)), scale), half);
    lo = _mm_min_pd(_mm_max_pd(lo, zero), scale);
    hi = _mm_min_pd(_mm_max_pd(hi, zero), scale);
    return _mm_unpacklo_epi64(_mm_cvttpd_epi32(lo), _mm_cvttpd_epi32(hi));
  };
  for (; i + 16 <= n; i += 16) {
    const __m128i a = _mm_packs_epi32(four(values + i), four(values + i + 4));
    const __m128i b = _mm_packs_epi32(four(values + i + 8), four(values + i + 12));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), _mm_packus_epi16(a, b));
  }
#endif
  quantize_values(values + i, n - i, 255.0, out + i);
}

template <typename T>
Samples<T> quantize(const Image::Pixels& values, double scale, int threads) {
  Samples<T> out(values.size());  // left unset: every value is written below, on every core
  parallel_chunks(threads, values.size(), kQuantizeChunk, [&](std::size_t begin, std::size_t end) {
    if constexpr (std::is_same_v<T, std::uint8_t>) quantize_values8(values.data() + begin, end - begin, out.data() + begin);
    else quantize_values(values.data() + begin, end - begin, scale, out.data() + begin);
  });
  return out;
}

// A value in [0, 1) from a 64-bit key (splitmix64's finaliser): the same for a texel and channel
// whatever thread writes it.
double unit_hash(std::uint64_t key) {
  key += 0x9E3779B97F4A7C15ull;
  key = (key ^ (key >> 30)) * 0xBF58476D1CE4E5B9ull;
  key = (key ^ (key >> 27)) * 0x94D049BB133111EBull;
  key ^= key >> 31;
  return double(key >> 11) * (1.0 / 9007199254740992.0);
}

// 8-bit values with triangular noise of one step added before rounding (WriteOptions::dither):
// the sum of two uniform values in [0, 1) minus 1, seeded by the value's index, so that a gradient
// finer than a step shows no bands and the average over many texels keeps the float value.
void quantize_dithered(const float* values, std::size_t first, std::size_t n, std::uint8_t* out) {
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = first + k;
    const double noise = unit_hash(2 * std::uint64_t(i)) + unit_hash(2 * std::uint64_t(i) + 1) - 1.0;
    double v = static_cast<double>(values[k]) * 255.0 + 0.5 + noise;
    if (!(v > 0.0)) v = 0.0;
    if (v > 255.0) v = 255.0;
    out[k] = static_cast<std::uint8_t>(v);
  }
}

// A reason that is memory running out (the PNG encoder's "insufficient memory", ENOMEM): exit 4, not 3.
bool memory_reason(const std::string& reason) {
  return reason.find("insufficient memory") != std::string::npos || reason.find("out of memory") != std::string::npos ||
         reason.find("Out of memory") != std::string::npos || reason == std::strerror(ENOMEM);
}

}  // namespace

int check_write(const std::string& path, const Image& image, const WriteOptions& options) {
  const int bits = options.bits ? options.bits : default_bits_for(path);
  check_output_format(path, bits);
  if (image.width <= 0 || image.height <= 0 || image.channels <= 0 ||
      image.pixels.size() != std::size_t(image.width) * std::size_t(image.height) * std::size_t(image.channels))
    fail_write(path, "empty image (" + std::to_string(image.width) + "x" + std::to_string(image.height) + "x" +
                         std::to_string(image.channels) + ")");
  // The folder first: an encoder would only name the temporary file.
  const fs::path target(path);
  const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) fail_write(path, "folder '" + folder.string() + "' does not exist");
  if (::access(folder.c_str(), W_OK) != 0)
    fail_write(path, "folder '" + folder.string() + "' is not writable (" + std::strerror(errno) + ")");
  return bits;
}

Samples<std::uint8_t> quantize8(const Image::Pixels& values, bool dither, int threads) {
  if (!dither) return quantize<std::uint8_t>(values, 255.0, threads);
  Samples<std::uint8_t> out(values.size());
  parallel_chunks(threads, values.size(), kQuantizeChunk, [&](std::size_t begin, std::size_t end) {
    quantize_dithered(values.data() + begin, begin, end - begin, out.data() + begin);
  });
  return out;
}

void quantize8_run(const float* values, std::size_t first, std::size_t n, bool dither, std::uint8_t* out) {
  if (dither) quantize_dithered(values, first, n, out);
  else quantize_values8(values, n, out);
}

void quantize16_run(const float* values, std::size_t n, std::uint16_t* out) { quantize_values(values, n, 65535.0, out); }

Samples<std::uint16_t> quantize16(const Image::Pixels& values, int threads) {
  return quantize<std::uint16_t>(values, 65535.0, threads);
}

// The EXR and TIFF writers stamp the current time into "DateTime", so two identical bakes differ
// in a few bytes. With SOURCE_DATE_EPOCH set (seconds since 1970, the reproducible-builds
// convention) that time is used instead and identical bakes give identical files.
bool date_time_fields(const std::string& text, int fields[6]) {
  int* f = fields;
  return std::sscanf(text.c_str(), "%d:%d:%d %d:%d:%d", &f[0], &f[1], &f[2], &f[3], &f[4], &f[5]) == 6;
}

std::string tiff_description(const std::vector<std::pair<std::string, std::string>>& metadata) {
  std::string text;
  for (const auto& [key, value] : metadata)
    if (key == "ImageDescription") text = value;
  for (const auto& [key, value] : metadata)
    if (key != "ImageDescription") text += (text.empty() ? "" : "; ") + key + "=" + value;
  return text;
}

std::string reproducible_date_time() {
  const char* epoch = std::getenv("SOURCE_DATE_EPOCH");
  if (!epoch || !*epoch) return "";
  char* end = nullptr;
  const long long seconds = std::strtoll(epoch, &end, 10);
  if (*end != '\0' || seconds < 0) return "";
  const std::time_t t = static_cast<std::time_t>(seconds);
  std::tm utc{};
  if (!gmtime_r(&t, &utc)) return "";
  char text[32];
  std::strftime(text, sizeof text, "%Y:%m:%d %H:%M:%S", &utc);
  return text;
}

[[noreturn]] void fail_write(const std::string& path, const std::string& reason) {
  if (memory_reason(reason)) throw ResourceError(path + ": cannot write: out of memory (" + reason + ")");
  throw OutputError(path + ": cannot write: " + reason);
}

std::string temp_path_for(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const fs::path target(path);
  std::string name = "." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) +
                     target.extension().string();
  return (target.parent_path() / name).string();
}

void write_file_spans(const std::string& path, const std::vector<ByteSpan>& spans, const WriteOptions& options) {
  const std::string temp = options.temp_path.empty() ? temp_path_for(path) : options.temp_path;
  write_spans_file(path, temp, spans);     // the temporary removed on an error
  if (!options.temp_path.empty()) return;  // the caller renames it
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    std::string reason = std::strerror(errno);
    std::error_code ec;
    if (fs::is_directory(path, ec)) reason = "a folder of that name exists";
    ::unlink(temp.c_str());
    fail_write(path, reason);
  }
}

}  // namespace nmbake::image_write
