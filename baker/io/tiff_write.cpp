#include "io/tiff_write.h"

#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <limits>
#include <new>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "io/image_write.h"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the TIFF writer stores its samples as the host orders them");

namespace nmbake {
namespace {

constexpr int kRowsPerStrip = 32;
constexpr int kLevel = 6;  // zlib's default, as libtiff and OpenImageIO use

// Tag types (TIFF 6.0, section 2).
constexpr std::uint16_t kAscii = 2, kShort = 3, kLong = 4;

// One IFD entry: its value's bytes (little-endian), in the entry when 4 bytes or fewer.
struct Entry {
  std::uint16_t tag, type;
  std::uint32_t count;
  std::vector<unsigned char> value;
};

Entry shorts(std::uint16_t tag, const std::vector<std::uint16_t>& v) {
  Entry e{tag, kShort, std::uint32_t(v.size()), std::vector<unsigned char>(2 * v.size())};
  std::memcpy(e.value.data(), v.data(), e.value.size());
  return e;
}

Entry longs(std::uint16_t tag, const std::vector<std::uint32_t>& v) {
  Entry e{tag, kLong, std::uint32_t(v.size()), std::vector<unsigned char>(4 * v.size())};
  std::memcpy(e.value.data(), v.data(), e.value.size());
  return e;
}

// A SHORT when it fits, as OpenImageIO writes the sizes, else a LONG.
Entry short_or_long(std::uint16_t tag, std::uint32_t v) {
  return v <= 0xffffu ? shorts(tag, {std::uint16_t(v)}) : longs(tag, {v});
}

Entry ascii(std::uint16_t tag, const std::string& text) {
  Entry e{tag, kAscii, std::uint32_t(text.size() + 1), std::vector<unsigned char>(text.begin(), text.end())};
  e.value.push_back(0);
  return e;
}

void put16(std::vector<unsigned char>& out, std::size_t at, std::uint32_t v) {
  out[at] = static_cast<unsigned char>(v & 0xffu);
  out[at + 1] = static_cast<unsigned char>(v >> 8 & 0xffu);
}

void put32(std::vector<unsigned char>& out, std::size_t at, std::uint32_t v) {
  put16(out, at, v & 0xffffu);
  put16(out, at + 2, v >> 16);
}

// The bytes of a value that does not fit in its entry: its own, then one to keep the next even
// (value offsets are).
std::size_t out_of_line_bytes(const Entry& e) { return e.value.size() > 4 ? (e.value.size() + 1) & ~std::size_t(1) : 0; }

// Where the IFD of n entries ends: the 8-byte header, its count, its entries, the next IFD's offset.
std::size_t ifd_end(std::size_t n) { return 8 + 2 + 12 * n + 4; }

// How many bytes header_and_ifd makes of `entries`: where the strips follow.
std::size_t header_bytes(const std::vector<Entry>& entries) {
  std::size_t size = ifd_end(entries.size());
  for (const Entry& e : entries) size += out_of_line_bytes(e);
  return size;
}

// The header, the one IFD (entries in tag order) and the values that do not fit in their entries,
// as the file's first bytes.
std::vector<unsigned char> header_and_ifd(std::vector<Entry> entries) {
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.tag < b.tag; });
  std::vector<unsigned char> out(header_bytes(entries), 0);
  out[0] = out[1] = 'I';
  put16(out, 2, 42);
  put32(out, 4, 8);
  put16(out, 8, std::uint32_t(entries.size()));
  std::size_t at = 10, values = ifd_end(entries.size());
  for (const Entry& e : entries) {
    put16(out, at, e.tag);
    put16(out, at + 2, e.type);
    put32(out, at + 4, e.count);
    if (e.value.size() <= 4) {
      std::copy(e.value.begin(), e.value.end(), out.begin() + std::ptrdiff_t(at + 8));
    } else {
      put32(out, at + 8, std::uint32_t(values));
      std::copy(e.value.begin(), e.value.end(), out.begin() + std::ptrdiff_t(values));
      values += out_of_line_bytes(e);
    }
    at += 12;
  }
  // The next IFD's offset (none) is already 0.
  return out;
}

// Horizontal differencing (predictor 2) of one row of `n` samples, `spp` per pixel, in place.
template <typename T>
void difference(T* row, std::size_t n, std::size_t spp) {
  for (std::size_t i = n; i-- > spp;) row[i] = static_cast<T>(row[i] - row[i - spp]);
}

// The floating-point predictor (3) of one row of `n` floats, `spp` per pixel: the bytes of its
// values regrouped by significance (every value's most significant byte first, then the next ...),
// then each byte less the one `spp` before it. `scratch` holds 4 n bytes.
void float_difference(unsigned char* row, std::size_t n, std::size_t spp, unsigned char* scratch) {
  std::memcpy(scratch, row, 4 * n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t b = 0; b < 4; ++b) row[(3 - b) * n + i] = scratch[4 * i + b];  // the host's bytes, least first
  for (std::size_t j = 4 * n; j-- > spp;) row[j] = static_cast<unsigned char>(row[j] - row[j - spp]);
}

// Bytes written whole before they are read: not zeroed first.
using Bytes = std::vector<unsigned char, DefaultInitAllocator<unsigned char>>;

// One thread's strip encoder: its zlib stream and strip buffers made once, reset per strip.
class StripEncoder {
 public:
  StripEncoder(std::size_t row_bytes, std::size_t values_per_row)
      : init_(deflateInit(&zs_, kLevel)), raw_(kRowsPerStrip * row_bytes), scratch_(4 * values_per_row) {}
  StripEncoder(const StripEncoder&) = delete;
  StripEncoder& operator=(const StripEncoder&) = delete;
  ~StripEncoder() {
    if (init_ == Z_OK) deflateEnd(&zs_);
  }

  // Rows y0 .. y1 - 1 of `image` as `bits`-bit samples, predicted and compressed into `out`.
  // Returns null, or why it failed.
  const char* encode(const Image& image, int bits, bool dither, int y0, int y1, Bytes& out) {
    if (init_ != Z_OK) return init_ == Z_MEM_ERROR ? "insufficient memory" : "invalid compression settings";
    if (deflateReset(&zs_) != Z_OK) return "insufficient memory";
    const std::size_t values = std::size_t(image.width) * std::size_t(image.channels);
    const std::size_t spp = std::size_t(image.channels), row_bytes = values * std::size_t(bits / 8);
    for (int y = y0; y < y1; ++y) {
      unsigned char* row = raw_.data() + std::size_t(y - y0) * row_bytes;
      const std::size_t first = std::size_t(y) * values;
      const float* in = image.pixels.data() + first;
      if (bits == 8) {
        image_write::quantize8_run(in, first, values, dither, row);
        difference(row, values, spp);
      } else if (bits == 16) {
        auto* samples = reinterpret_cast<std::uint16_t*>(row);
        image_write::quantize16_run(in, values, samples);
        difference(samples, values, spp);
      } else {
        std::memcpy(row, in, 4 * values);
        float_difference(row, values, spp, scratch_.data());
      }
    }
    const std::size_t raw = std::size_t(y1 - y0) * row_bytes;
    packed_.resize(deflateBound(&zs_, uLong(raw)));
    zs_.next_in = raw_.data();
    zs_.avail_in = uInt(raw);
    zs_.next_out = packed_.data();
    zs_.avail_out = uInt(packed_.size());
    if (deflate(&zs_, Z_FINISH) != Z_STREAM_END) return "insufficient memory";  // deflateBound's room suffices
    out.assign(packed_.data(), zs_.next_out);                                   // the strip's own block, no larger than its bytes
    return nullptr;
  }

 private:
  z_stream zs_{};
  int init_;
  Bytes raw_, scratch_, packed_;  // a strip's samples, a row's bytes, a strip compressed
};

}  // namespace

bool write_tiff_image(const std::string& path, const Image& image, const WriteOptions& options, int bits) {
  const int channels = image.channels;
  if (channels < 1 || channels > 4 || (bits != 8 && bits != 16 && bits != 32)) return false;
  const std::size_t values = std::size_t(image.width) * std::size_t(channels);
  const std::size_t row_bytes = values * std::size_t(bits / 8);
  const std::size_t strip_raw = kRowsPerStrip * row_bytes;
  if (row_bytes == 0 || strip_raw > std::numeric_limits<uInt>::max() / 2) return false;
  const int strips = (image.height + kRowsPerStrip - 1) / kRowsPerStrip;

  // The strips, on every thread, each thread's encoder kept from strip to strip.
  std::vector<Bytes> data(static_cast<std::size_t>(strips));
  std::atomic<int> next{0};
  std::atomic<const char*> error{nullptr};
  const int threads = std::max(1, std::min(worker_threads(options.threads), strips));
  run_on_threads(threads, [&](int) {
    try {
      StripEncoder encoder(row_bytes, values);
      for (int s; !error.load() && (s = next++) < strips;) {
        const int y0 = s * kRowsPerStrip, y1 = std::min(image.height, y0 + kRowsPerStrip);
        if (const char* why = encoder.encode(image, bits, options.dither, y0, y1, data[std::size_t(s)])) error = why;
      }
    } catch (const std::bad_alloc&) {
      error = "insufficient memory";
    }
  });
  if (const char* why = error.load()) image_write::fail_write(path, why);

  // The tags.
  std::vector<Entry> entries;
  const auto spp = std::uint16_t(channels);
  entries.push_back(short_or_long(256, std::uint32_t(image.width)));
  entries.push_back(short_or_long(257, std::uint32_t(image.height)));
  entries.push_back(shorts(258, std::vector<std::uint16_t>(spp, std::uint16_t(bits))));
  entries.push_back(shorts(259, {std::uint16_t(8)}));                                 // Adobe Deflate
  entries.push_back(shorts(262, {std::uint16_t(channels >= 3 ? 2 : 1)}));             // RGB, or grey (0 black)
  entries.push_back(longs(273, std::vector<std::uint32_t>(std::size_t(strips), 0)));  // offsets: below
  entries.push_back(shorts(274, {std::uint16_t(1)}));                                 // row 0 at the top, column 0 at the left
  entries.push_back(shorts(277, {spp}));
  entries.push_back(short_or_long(278, std::uint32_t(kRowsPerStrip)));
  std::vector<std::uint32_t> counts(static_cast<std::size_t>(strips));
  for (std::size_t s = 0; s < counts.size(); ++s) counts[s] = std::uint32_t(data[s].size());
  entries.push_back(longs(279, counts));
  entries.push_back(shorts(284, {std::uint16_t(1)}));                   // samples interleaved
  entries.push_back(shorts(317, {std::uint16_t(bits == 32 ? 3 : 2)}));  // floating-point, or horizontal, predictor
  if (channels == 2 || channels == 4) entries.push_back(shorts(338, {std::uint16_t(2)}));              // unassociated alpha
  entries.push_back(shorts(339, std::vector<std::uint16_t>(spp, std::uint16_t(bits == 32 ? 3 : 1))));  // float, or unsigned
  const std::vector<std::pair<std::string, std::string>>& metadata = options.metadata;
  const std::string description = image_write::tiff_description(metadata);
  if (!description.empty()) entries.push_back(ascii(270, description));
  std::string date = image_write::reproducible_date_time();
  constexpr std::pair<std::uint16_t, const char*> kTextTags[] = {
      {269, "DocumentName"}, {305, "Software"}, {315, "Artist"}, {316, "HostComputer"}, {33432, "Copyright"}};
  for (const auto& [key, value] : metadata) {
    if (key == "DateTime") date = value;
    for (const auto& [tag, name] : kTextTags)
      if (key == name) entries.push_back(ascii(tag, value));
  }
  int fields[6];
  if (image_write::date_time_fields(date, fields)) entries.push_back(ascii(306, date));

  // Where each strip goes (after the header, whose size the offsets' values do not change); a file
  // past a classic TIFF's 4 GiB is OpenImageIO's (BigTIFF).
  std::uint64_t at = header_bytes(entries);
  std::vector<std::uint32_t> offsets(static_cast<std::size_t>(strips));
  for (std::size_t s = 0; s < offsets.size(); ++s) {
    offsets[s] = std::uint32_t(at);
    at += data[s].size();
  }
  if (at > std::numeric_limits<std::uint32_t>::max()) return false;
  for (Entry& e : entries)
    if (e.tag == 273) e = longs(273, offsets);
  const std::vector<unsigned char> head = header_and_ifd(std::move(entries));

  std::vector<ByteSpan> spans{{head.data(), head.size()}};
  for (const auto& d : data) spans.push_back({d.data(), d.size()});
  image_write::write_file_spans(path, spans, options);
  return true;
}

}  // namespace nmbake
