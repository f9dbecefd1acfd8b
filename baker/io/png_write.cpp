// PNG in bands on every core (png_write.h).
#include "io/png_write.h"

#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <new>

#include "core/parallel.h"
#include "io/image_write.h"

namespace nmbake {
namespace {

// Bands of rows compressed apart: fixed by the image's height, so the file's bytes do not depend on
// the threads. Bands of kBandRows rows (at least kMinBands of them) let every core of a workstation
// take a share and keep them all busy to the end (bands differ in cost: a map's background rows are
// cheap); each costs a few bytes (a sync flush, and RLE's first run of a band). Eight bands of a
// 4096-row map left one of two cores deflating alone for a tenth of the encode.
constexpr int kBandRows = 64;
constexpr int kMinBands = 8;
constexpr int kMaxBands = 1024;

int band_count(int height) {
  return std::max(1, std::min(height, std::clamp((height + kBandRows - 1) / kBandRows, kMinBands, kMaxBands)));
}
constexpr std::size_t kIdatBytes = std::size_t(1) << 18;  // IDAT chunks of 256 KiB

// The PNG filter type byte of a single-filter mask, or -1.
int filter_type(int mask) {
  switch (mask) {
    case 0x08: return 0;
    case 0x10: return 1;
    case 0x20: return 2;
    case 0x40: return 3;
    case 0x80: return 4;
    default: return -1;
  }
}

// Row y's bytes as PNG stores them (row_bytes of them; 16-bit samples big-endian), into `out`.
using RowSource = std::function<void(int y, unsigned char* out)>;

// Native-endian 16-bit samples to PNG's big-endian bytes, in place.
void big_endian16(unsigned char* bytes, std::size_t n) {
  for (std::size_t i = 0; i < n; i += 2) {
    std::uint16_t v;
    std::memcpy(&v, bytes + i, 2);
    bytes[i] = static_cast<unsigned char>(v >> 8);
    bytes[i + 1] = static_cast<unsigned char>(v & 0xffu);
  }
}

// Row `cur` filtered against `prior` (zeros above the first row): type byte, then the bytes.
void filter_row(int type, const unsigned char* cur, const unsigned char* prior, std::size_t n, std::size_t bpp,
                unsigned char* out) {
  out[0] = static_cast<unsigned char>(type);
  unsigned char* o = out + 1;
  const auto u8 = [](int v) { return static_cast<unsigned char>(v); };
  const std::size_t first = std::min(bpp, n);  // the first pixel: a = c = 0
  switch (type) {
    case 0: std::memcpy(o, cur, n); break;
    case 1:
      std::memcpy(o, cur, first);
      for (std::size_t i = first; i < n; ++i) o[i] = u8(cur[i] - cur[i - bpp]);
      break;
    case 2:
      for (std::size_t i = 0; i < n; ++i) o[i] = u8(cur[i] - prior[i]);
      break;
    case 3:
      for (std::size_t i = 0; i < first; ++i) o[i] = u8(cur[i] - prior[i] / 2);
      for (std::size_t i = first; i < n; ++i) o[i] = u8(cur[i] - (cur[i - bpp] + prior[i]) / 2);
      break;
    default:                                                                 // 4, Paeth
      for (std::size_t i = 0; i < first; ++i) o[i] = u8(cur[i] - prior[i]);  // Paeth of (0, b, 0) is b
      // Paeth's predictor of (a, b, c) in 16-bit lanes without branches (what the compiler vectorizes): |p - a|,
      // |p - b|, |p - c| are |b - c|, |a - c|, |a + b - 2c|, and b or c, the nearer, then a if nearer still.
      for (std::size_t i = first; i < n; ++i) {
        const short a = cur[i - bpp], b = prior[i], c = prior[i - bpp];
        short pa = short(b - c), pb = short(a - c), pc = short(a + b - 2 * c);
        pa = pa < 0 ? short(-pa) : pa;
        pb = pb < 0 ? short(-pb) : pb;
        pc = pc < 0 ? short(-pc) : pc;
        const short bc = pb <= pc ? b : c, pbc = pb <= pc ? pb : pc;
        o[i] = u8(cur[i] - (pa <= pbc ? a : bc));
      }
      break;
  }
}

// One band's raw deflate stream (ended by a sync flush, or finished for the last band), in its
// thread's output blocks, and the Adler-32 of what it compresses.
struct Band {
  const unsigned char* bytes = nullptr;
  std::size_t size = 0;
  uLong adler = 1;
  std::size_t length = 0;  // bytes compressed
};

using Block = std::unique_ptr<unsigned char[]>;  // not zeroed

// A thread's output blocks hold the streams of the bands it takes one after another, so the pages
// touched are about the compressed bytes. Blocks of kBlockBytes come on huge pages (large_pages.cpp:
// one page fault per 2 MiB where 4 KiB pages cost one each), which a block per band of a tall map
// (a few hundred KiB) would not.
constexpr std::size_t kBlockBytes = std::size_t(8) << 20;

// One thread's band encoder: its zlib stream and row buffers made once and reset for each band it
// takes (a stream's state is a few hundred KiB, fresh pages each time if made per band).
class BandEncoder {
 public:
  // block_bytes: the size of its output blocks (larger ones where a band needs more room).
  BandEncoder(const PngSettings& settings, std::size_t row_bytes, std::size_t block_bytes)
      : init_(deflateInit2(&zs_, settings.level, Z_DEFLATED, -15, 8, settings.strategy)),
        block_bytes_(block_bytes),
        prior_(row_bytes),
        cur_(row_bytes),
        filtered_(row_bytes + 1) {}
  BandEncoder(const BandEncoder&) = delete;
  BandEncoder& operator=(const BandEncoder&) = delete;
  ~BandEncoder() {
    if (init_ == Z_OK) deflateEnd(&zs_);
  }

  // Rows y0 .. y1 - 1 into `band`. Returns null, or zlib's reason it failed.
  const char* encode(const RowSource& row, std::size_t bpp, int type, int y0, int y1, bool last, Band& band) {
    if (init_ == Z_MEM_ERROR) return "insufficient memory";
    if (init_ != Z_OK) return "invalid compression settings";
    if (deflateReset(&zs_) != Z_OK) return "insufficient memory";
    const std::size_t row_bytes = cur_.size();
    if (y0 > 0) row(y0 - 1, prior_.data());
    else std::fill(prior_.begin(), prior_.end(), static_cast<unsigned char>(0));
    room(deflateBound(&zs_, uLong(std::size_t(y1 - y0) * (row_bytes + 1))) + 64, 0);
    bool ok = true;
    for (int y = y0; y < y1 && ok; ++y) {
      row(y, cur_.data());
      filter_row(type, cur_.data(), prior_.data(), row_bytes, bpp, filtered_.data());
      band.adler = adler32(band.adler, filtered_.data(), uInt(filtered_.size()));
      band.length += filtered_.size();
      zs_.next_in = filtered_.data();
      zs_.avail_in = uInt(filtered_.size());
      const int flush = y + 1 < y1 ? Z_NO_FLUSH : last ? Z_FINISH : Z_SYNC_FLUSH;
      while (ok) {
        if (zs_.avail_out == 0) {  // deflateBound's room used up (it should not be): twice as much
          const std::size_t used = std::size_t(zs_.next_out - band_start_);
          room(2 * used, used);
        }
        const int r = deflate(&zs_, flush);
        ok = r == Z_OK || r == Z_STREAM_END || r == Z_BUF_ERROR;
        if (flush == Z_FINISH ? r == Z_STREAM_END : (zs_.avail_in == 0 && zs_.avail_out > 0)) break;
      }
      std::swap(prior_, cur_);
    }
    band.bytes = band_start_;
    band.size = std::size_t(zs_.next_out - band_start_);
    used_ += band.size;
    return ok ? nullptr : "insufficient memory";  // deflate fails only for want of memory here
  }

  // The blocks holding this encoder's bands, for the caller to keep.
  std::vector<Block>& blocks() { return blocks_; }

 private:
  // `need` bytes of room for the band under way, whose first `kept` bytes are already written
  // (moved to a new block when the room is not there).
  void room(std::size_t need, std::size_t kept) {
    if (blocks_.empty() || used_ + need > block_size_) {
      const std::size_t size = std::max(block_bytes_, need);
      blocks_.push_back(Block(new unsigned char[size]));
      if (kept) std::memcpy(blocks_.back().get(), band_start_, kept);
      block_size_ = size;
      used_ = 0;
    }
    band_start_ = blocks_.back().get() + used_;
    zs_.next_out = band_start_ + kept;
    zs_.avail_out = uInt(need - kept);
  }

  z_stream zs_{};
  int init_;
  std::size_t block_bytes_;
  std::vector<Block> blocks_;
  std::size_t block_size_ = 0, used_ = 0;  // the last block's size and bytes taken by finished bands
  unsigned char* band_start_ = nullptr;
  std::vector<unsigned char> prior_, cur_, filtered_;
};

void put32(std::vector<unsigned char>& out, std::uint32_t v) {
  const unsigned char b[4] = {static_cast<unsigned char>(v >> 24), static_cast<unsigned char>(v >> 16),
                              static_cast<unsigned char>(v >> 8), static_cast<unsigned char>(v)};
  out.insert(out.end(), b, b + 4);
}

// A chunk's bytes before its data, appended to `out`: length and type.
void chunk_head(std::vector<unsigned char>& out, const char type[5], std::size_t n) {
  put32(out, std::uint32_t(n));
  out.insert(out.end(), type, type + 4);
}

void chunk(std::vector<unsigned char>& out, const char type[5], const unsigned char* data, std::size_t n) {
  chunk_head(out, type, n);
  const std::size_t at = out.size() - 4;
  if (n) out.insert(out.end(), data, data + n);
  put32(out, std::uint32_t(crc32(0, out.data() + at, uInt(4 + n))));
}

// A tEXt keyword PNG allows: 1 to 79 printable Latin-1 characters, no leading, trailing or double
// space (libpng refuses the others too).
bool valid_keyword(const std::string& key) {
  if (key.empty() || key.size() > 79 || key.front() == ' ' || key.back() == ' ') return false;
  for (std::size_t i = 0; i < key.size(); ++i) {
    const auto c = static_cast<unsigned char>(key[i]);
    if (c < 32 || (c > 126 && c < 161) || (c == ' ' && key[i + 1] == ' ')) return false;
  }
  return true;
}

// "YYYY:MM:DD HH:MM:SS" as a tIME chunk's 7 bytes; false when it is not that.
bool time_bytes(const std::string& text, unsigned char t[7]) {
  int f[6];
  if (!image_write::date_time_fields(text, f)) return false;
  const int v[7] = {f[0] >> 8, f[0] & 0xff, f[1], f[2], f[3], f[4], f[5]};
  for (int k = 0; k < 7; ++k) t[k] = static_cast<unsigned char>(v[k]);
  return true;
}

// How the rows are stored: PNG's colour type and bit depth, the bytes of a row, the bytes the
// filters step back by (a pixel's, at least 1), and for indexed colour the palette (RGB triples).
struct Layout {
  int color_type = 2;
  int depth = 8;
  std::size_t row_bytes = 0, bpp = 1;
  std::vector<unsigned char> palette;
};

// The layout of `channels` samples of `bits` bits (grey, grey + alpha, RGB, RGBA).
Layout sample_layout(int width, int channels, int bits) {
  static constexpr unsigned char kColorTypes[] = {0, 4, 2, 6};
  Layout l;
  l.color_type = kColorTypes[channels - 1];
  l.depth = bits;
  l.bpp = std::size_t(channels) * std::size_t(bits / 8);
  l.row_bytes = std::size_t(width) * l.bpp;
  return l;
}

// Whether PNG can store the image; if not, why, in `error`.
bool valid_sizes(int width, int height, int channels, int bits, std::string* error) {
  if (width > 0 && height > 0 && width <= 0x7fffffff / 8 && channels >= 1 && channels <= 4 && (bits == 8 || bits == 16))
    return true;
  *error = "invalid IHDR data (size, channels or bit depth)";
  return false;
}

// An encoded file as spans in order: bytes of its own (the signature, the chunks' headers, text
// and checksums, the zlib stream's header and Adler-32) and the bands' deflate streams, which are
// written out where they are, not joined into one buffer first (on a file of some MiB, the copies
// and the fresh pages they fill cost as much as a band's encoding, on one thread).
struct Encoded {
  std::vector<Band> bands;
  std::vector<Block> blocks;  // the bands' bytes
  std::vector<unsigned char> own;
  struct Piece {
    int band;  // -1: own
    std::size_t at, size;
  };
  std::vector<Piece> pieces;

  void add_own(const std::vector<unsigned char>& bytes) {
    pieces.push_back({-1, own.size(), bytes.size()});
    own.insert(own.end(), bytes.begin(), bytes.end());
  }
  const unsigned char* data(const Piece& p) const { return (p.band < 0 ? own.data() : bands[std::size_t(p.band)].bytes) + p.at; }
  std::vector<ByteSpan> spans() const {
    std::vector<ByteSpan> out;
    out.reserve(pieces.size());
    for (const Piece& p : pieces) out.push_back({data(p), p.size});
    return out;
  }
  std::vector<unsigned char> joined() const {
    std::size_t n = 0;
    for (const Piece& p : pieces) n += p.size;
    std::vector<unsigned char> out;
    out.reserve(n);
    for (const Piece& p : pieces) out.insert(out.end(), data(p), data(p) + p.size);
    return out;
  }
};

// The zlib stream (header, the bands' streams, Adler-32) cut into IDAT chunks of kIdatBytes, as
// pieces of `e`, then IEND. The chunks' CRCs are worked out on `threads` threads, each over its
// own chunk's pieces.
void add_idat_chunks(Encoded& e, uLong adler, int threads) {
  // The stream as (piece) segments.
  std::vector<Encoded::Piece> stream;
  const std::size_t header_at = e.own.size();
  e.own.insert(e.own.end(), {0x78, 0x01});  // deflate, 32K window, no preset dictionary; check bits
  stream.push_back({-1, header_at, 2});
  for (std::size_t b = 0; b < e.bands.size(); ++b)
    if (e.bands[b].size) stream.push_back({int(b), 0, e.bands[b].size});
  const std::size_t adler_at = e.own.size();
  put32(e.own, std::uint32_t(adler));
  stream.push_back({-1, adler_at, 4});
  std::size_t total = 0;
  for (const Encoded::Piece& p : stream) total += p.size;

  struct Chunk {
    std::size_t first_piece, pieces, crc_at;  // its data's pieces in e.pieces; its CRC in e.own
  };
  std::vector<Chunk> chunks;
  std::size_t seg = 0, seg_used = 0;  // the next byte of the stream: segment, bytes of it used
  for (std::size_t at = 0; at < total; at += kIdatBytes) {
    const std::size_t n = std::min(kIdatBytes, total - at);
    std::vector<unsigned char> head;
    chunk_head(head, "IDAT", n);
    e.add_own(head);
    Chunk c{e.pieces.size(), 0, 0};
    for (std::size_t left = n; left > 0;) {
      const Encoded::Piece& s = stream[seg];
      const std::size_t take = std::min(left, s.size - seg_used);
      e.pieces.push_back({s.band, s.at + seg_used, take});
      ++c.pieces;
      left -= take;
      seg_used += take;
      if (seg_used == s.size) ++seg, seg_used = 0;
    }
    c.crc_at = e.own.size();
    e.pieces.push_back({-1, c.crc_at, 4});
    e.own.insert(e.own.end(), 4, 0);
    chunks.push_back(c);
  }
  std::vector<unsigned char> iend;
  chunk(iend, "IEND", nullptr, 0);
  e.add_own(iend);
  // `own` is complete: the pieces' addresses stay put from here.
  parallel_chunks(threads, chunks.size(), 1, [&](std::size_t i, std::size_t) {
    const Chunk& c = chunks[i];
    uLong crc = crc32(0, reinterpret_cast<const Bytef*>("IDAT"), 4);
    for (std::size_t k = c.first_piece; k < c.first_piece + c.pieces; ++k)
      crc = crc32(crc, e.data(e.pieces[k]), uInt(e.pieces[k].size));
    const unsigned char v[4] = {static_cast<unsigned char>(crc >> 24), static_cast<unsigned char>(crc >> 16),
                                static_cast<unsigned char>(crc >> 8), static_cast<unsigned char>(crc)};
    std::memcpy(e.own.data() + c.crc_at, v, 4);
  });
}

// encode_png with its rows from `row` (layout.row_bytes each), called from every thread (each row
// of a band in order). False, with *error set, on failure.
bool encode_rows(const RowSource& row, int width, int height, const Layout& layout,
                 const std::vector<std::pair<std::string, std::string>>& metadata, const PngSettings& settings, int threads,
                 Encoded& e, std::string* error) {
  const int type = filter_type(settings.filters);
  if (type < 0) {
    *error = "filters: one of 0x08, 0x10, 0x20, 0x40, 0x80 expected, not " + std::to_string(settings.filters);
    return false;
  }
  for (const auto& item : metadata)
    if (item.first != "DateTime" && !valid_keyword(item.first)) {
      *error = "tEXt: invalid keyword \"" + item.first + "\"";
      return false;
    }
  const std::size_t bpp = layout.bpp, row_bytes = layout.row_bytes;
  try {
    const int bands = band_count(height);
    e.bands.assign(static_cast<std::size_t>(bands), Band{});
    std::vector<const char*> failed(e.bands.size(), nullptr);
    std::atomic<std::size_t> next{0};  // the bands in order, each to the first thread free
    const int workers = std::min(worker_threads(threads), bands);
    std::vector<std::vector<Block>> blocks(static_cast<std::size_t>(workers));
    // No larger than the whole image's room needs: a small image's blocks stay small.
    const std::size_t block_bytes = std::min(kBlockBytes, std::size_t(height) * (row_bytes + 1) + std::size_t(bands) * 64);
    run_on_threads(workers, [&](int id) {
      BandEncoder encoder(settings, row_bytes, block_bytes);
      for (std::size_t b; (b = next.fetch_add(1)) < e.bands.size();) {
        const int y0 = int(std::int64_t(height) * std::int64_t(b) / bands),
                  y1 = int(std::int64_t(height) * std::int64_t(b + 1) / bands);
        failed[b] = encoder.encode(row, bpp, type, y0, y1, b + 1 == e.bands.size(), e.bands[b]);
      }
      blocks[std::size_t(id)] = std::move(encoder.blocks());
    });
    for (std::vector<Block>& own_blocks : blocks)
      for (Block& block : own_blocks) e.blocks.push_back(std::move(block));
    for (const char* f : failed)
      if (f) {
        *error = f;
        return false;
      }
    // The Adler-32 of everything the bands compress.
    uLong adler = 1;
    for (const Band& b : e.bands) adler = adler32_combine(adler, b.adler, z_off_t(b.length));

    std::vector<unsigned char> head = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    std::vector<unsigned char> ihdr;
    put32(ihdr, std::uint32_t(width));
    put32(ihdr, std::uint32_t(height));
    ihdr.insert(ihdr.end(), {static_cast<unsigned char>(layout.depth), static_cast<unsigned char>(layout.color_type), 0, 0, 0});
    chunk(head, "IHDR", ihdr.data(), ihdr.size());
    if (layout.color_type == 3) chunk(head, "PLTE", layout.palette.data(), layout.palette.size());
    unsigned char when[7];
    bool has_time = false;
    for (const auto& [key, value] : metadata) {
      if (key == "DateTime") {
        has_time = time_bytes(value, when);
        continue;
      }
      std::string text = key == "ImageDescription" ? "Description" : key;
      text.push_back('\0');
      text += value;
      chunk(head, "tEXt", reinterpret_cast<const unsigned char*>(text.data()), text.size());
    }
    if (has_time) chunk(head, "tIME", when, 7);
    e.add_own(head);
    add_idat_chunks(e, adler, threads);
    return true;
  } catch (const std::bad_alloc&) {
    *error = "insufficient memory";
    return false;
  }
}

// Indexed colour (PNG colour type 3) for a map of flat colours (the ID maps): at most 256 colours
// after 8-bit quantization, each texel stored as its palette index in 1, 2, 4 or 8 bits. A reader
// expands the indices to the same RGB bytes the RGB layout stores, and there are 3 to 24 times
// fewer bytes to filter and deflate.
struct IndexedColors {
  std::vector<std::uint8_t, DefaultInitAllocator<std::uint8_t>> index;  // per texel
  std::vector<unsigned char> palette;                                   // RGB per entry, in order of first use
  int depth = 8;                                                        // bits per index
};

// Flat colours compress best filtered against the row above (mostly zeros: what RLE codes); the
// filter is also the cheapest after none.
constexpr PngSettings kIndexedSettings{1, 0x20, 3};

// Whether the 8-bit RGB image (no dither) has at most 256 colours; if so, its indices and palette.
// One pass in texel order (a run of equal floats looked up once), so the palette's order, and the
// bytes, do not depend on the threads. A map of many colours stops at its 257th.
bool index_colors(const Image& image, IndexedColors& out) {
  constexpr int kSlots = 1024;  // open addressing over the 24-bit colours, at most 256 used
  std::int32_t slot_color[kSlots];
  std::uint8_t slot_index[kSlots];
  std::fill(slot_color, slot_color + kSlots, -1);
  const std::size_t n = std::size_t(image.width) * std::size_t(image.height);
  out.index.resize(n);
  out.palette.clear();
  const float* px = image.pixels.data();
  std::uint8_t last = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const float* p = px + 3 * i;
    if (i > 0 && std::memcmp(p, p - 3, 3 * sizeof(float)) == 0) {
      out.index[i] = last;
      continue;
    }
    std::uint8_t rgb[3];
    image_write::quantize8_run(p, 3 * i, 3, false, rgb);
    const std::int32_t color = std::int32_t(rgb[0]) << 16 | std::int32_t(rgb[1]) << 8 | rgb[2];
    std::uint32_t h = (std::uint32_t(color) * 2654435761u) >> 22;  // 10 bits: kSlots
    while (slot_color[h] >= 0 && slot_color[h] != color) h = (h + 1) & (kSlots - 1);
    if (slot_color[h] < 0) {
      const std::size_t entries = out.palette.size() / 3;
      if (entries == 256) return false;
      slot_color[h] = color;
      slot_index[h] = std::uint8_t(entries);
      out.palette.insert(out.palette.end(), rgb, rgb + 3);
    }
    last = out.index[i] = slot_index[h];
  }
  const std::size_t entries = out.palette.size() / 3;
  out.depth = entries <= 2 ? 1 : entries <= 4 ? 2 : entries <= 16 ? 4 : 8;
  return true;
}

// The same from an image of palette indices (WriteOptions::palette): each index's colour found
// once, in texel order, and a colour that two indices share (or that black repeats) one entry, so
// the palette and the indices are those index_colors finds in the RGB image they stand for (the
// same bytes). False past 256 colours.
bool index_palette(const Image& image, const std::vector<glm::vec3>& palette, IndexedColors& out) {
  const std::size_t n = std::size_t(image.width) * std::size_t(image.height);
  out.index.resize(n);
  out.palette.clear();
  std::vector<std::int16_t> slot(palette.size() + 1, -1);  // per index (0: black), its entry
  const float* px = image.pixels.data();
  std::uint8_t last = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0 && px[i] == px[i - 1]) {
      out.index[i] = last;
      continue;
    }
    const std::size_t k = palette_entry(px[i], palette.size());
    if (slot[k] < 0) {
      const glm::vec3 c = k ? palette[k - 1] : glm::vec3(0.0f);
      std::uint8_t rgb[3];
      image_write::quantize8_run(&c[0], 0, 3, false, rgb);
      std::size_t e = 0;
      const std::size_t entries = out.palette.size() / 3;
      while (e < entries && std::memcmp(&out.palette[3 * e], rgb, 3) != 0) ++e;
      if (e == entries) {
        if (entries == 256) return false;
        out.palette.insert(out.palette.end(), rgb, rgb + 3);
      }
      slot[k] = std::int16_t(e);
    }
    last = out.index[i] = std::uint8_t(slot[k]);
  }
  const std::size_t entries = out.palette.size() / 3;
  out.depth = entries <= 2 ? 1 : entries <= 4 ? 2 : entries <= 16 ? 4 : 8;
  return true;
}

// `width` indices of `depth` bits packed into bytes, the first in the high bits (PNG's order), the
// last byte's unused bits 0.
void pack_indices(const std::uint8_t* index, int width, int depth, unsigned char* out) {
  if (depth == 8) {
    std::memcpy(out, index, std::size_t(width));
    return;
  }
  const int per_byte = 8 / depth;
  for (int x = 0, b = 0; x < width; x += per_byte, ++b) {
    unsigned v = 0;
    for (int k = 0; k < per_byte; ++k) v = v << depth | (x + k < width ? index[x + k] : 0u);
    out[b] = static_cast<unsigned char>(v);
  }
}

}  // namespace

std::vector<unsigned char> encode_png(const void* rows, int width, int height, int channels, int bits,
                                      const std::vector<std::pair<std::string, std::string>>& metadata,
                                      const PngSettings& settings, int threads, std::string* error) {
  const auto* in = static_cast<const unsigned char*>(rows);
  const std::size_t row_bytes = std::size_t(std::max(width, 0)) * std::size_t(std::max(channels, 0)) * std::size_t(bits / 8);
  const RowSource row = [&](int y, unsigned char* out) {
    std::memcpy(out, in + std::size_t(y) * row_bytes, row_bytes);
    if (bits == 16) big_endian16(out, row_bytes);
  };
  if (!valid_sizes(width, height, channels, bits, error)) return {};
  Encoded e;
  if (!encode_rows(row, width, height, sample_layout(width, channels, bits), metadata, settings, threads, e, error)) return {};
  try {
    return e.joined();
  } catch (const std::bad_alloc&) {
    *error = "insufficient memory";
    return {};
  }
}

// The image's float values are quantized row by row inside the bands' encoders (the values
// quantize8 / quantize16 give), not into a whole 8- or 16-bit copy first: one pass over the image
// and no buffer of its size.
void write_png_image(const std::string& path, const Image& image, const WriteOptions& options) {
  const int bits = image_write::check_write(path, image, options);
  std::vector<std::pair<std::string, std::string>> metadata = options.metadata;
  if (const std::string date = image_write::reproducible_date_time(); !date.empty()) {
    bool given = false;
    for (const auto& item : metadata) given = given || item.first == "DateTime";
    if (!given) metadata.emplace_back("DateTime", date);
  }
  std::string error;
  if (!valid_sizes(image.width, image.height, image.channels, bits, &error)) image_write::fail_write(path, error);
  Encoded encoded;
  bool encoded_ok;
  IndexedColors indexed;
  bool use_index;
  if (!options.palette.empty()) {  // an image of indices: indexed while it can be, else its RGB image
    use_index = bits == 8 && image.channels == 1 && !options.dither && index_palette(image, options.palette, indexed);
    if (!use_index) {
      WriteOptions rgb = options;
      rgb.palette.clear();
      return write_png_image(path, expand_palette(image, options.palette), rgb);
    }
  } else {
    use_index = options.indexed && bits == 8 && image.channels == 3 && !options.dither && index_colors(image, indexed);
  }
  if (use_index) {
    Layout layout;
    layout.color_type = 3;
    layout.depth = indexed.depth;
    layout.row_bytes = (std::size_t(image.width) * std::size_t(indexed.depth) + 7) / 8;
    layout.palette = std::move(indexed.palette);
    const RowSource row = [&](int y, unsigned char* out) {
      pack_indices(indexed.index.data() + std::size_t(y) * std::size_t(image.width), image.width, indexed.depth, out);
    };
    encoded_ok =
        encode_rows(row, image.width, image.height, layout, metadata, kIndexedSettings, options.threads, encoded, &error);
  } else {
    const std::size_t values = std::size_t(image.width) * std::size_t(image.channels);
    const RowSource row = [&](int y, unsigned char* out) {
      const std::size_t first = std::size_t(y) * values;
      if (bits == 8) {
        image_write::quantize8_run(image.pixels.data() + first, first, values, options.dither, out);
        return;
      }
      std::uint16_t* samples = reinterpret_cast<std::uint16_t*>(out);  // row_bytes = 2 * values
      image_write::quantize16_run(image.pixels.data() + first, values, samples);
      big_endian16(out, 2 * values);
    };
    encoded_ok = encode_rows(row, image.width, image.height, sample_layout(image.width, image.channels, bits), metadata,
                             PngSettings{}, options.threads, encoded, &error);
  }
  if (!encoded_ok) image_write::fail_write(path, error);
  image_write::write_file_spans(path, encoded.spans(), options);
}

}  // namespace nmbake
