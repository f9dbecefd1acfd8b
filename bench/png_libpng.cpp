// libpng's one-stream encoder (png_libpng.h).
#include "png_libpng.h"

#include <png.h>

#include <cstdio>
#include <cstring>

#include "io/image_write.h"

namespace nmbake::bench {
namespace {

// Where the encoder's bytes go, and libpng's first error message.
struct Sink {
  std::vector<unsigned char>* bytes;
  char message[256];
};

extern "C" void on_png_error(png_structp png, png_const_charp message) {
  Sink* sink = static_cast<Sink*>(png_get_error_ptr(png));
  std::snprintf(sink->message, sizeof sink->message, "%s", message ? message : "unknown libpng error");
  png_longjmp(png, 1);
}

extern "C" void on_png_warning(png_structp, png_const_charp) {}  // nothing libpng warns of here is ours to show

extern "C" void on_png_write(png_structp png, png_bytep data, png_size_t size) {
  Sink* sink = static_cast<Sink*>(png_get_io_ptr(png));
  bool ok = true;
  try {
    sink->bytes->insert(sink->bytes->end(), data, data + size);
  } catch (...) {
    ok = false;
  }
  if (!ok) png_error(png, "insufficient memory");
}

extern "C" void on_png_flush(png_structp) {}

// What one encode writes, prepared before libpng runs.
struct Encode {
  const unsigned char* rows;
  std::size_t row_bytes;
  int width, height, bits, color_type;
  png_text* text;
  int text_count;
  bool has_time;
  png_time time;
  PngSettings settings;
};

// libpng reports errors by longjmp back to the setjmp here: no object with a destructor lives in
// this frame, and nothing it sets after setjmp is read after the jump.
bool run_encoder(png_structp png, png_infop info, Sink* sink, const Encode& e) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_write_fn(png, sink, on_png_write, on_png_flush);
  png_set_IHDR(png, info, png_uint_32(e.width), png_uint_32(e.height), e.bits, e.color_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, e.settings.level);
  png_set_compression_strategy(png, e.settings.strategy);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, e.settings.filters);
  png_set_compression_buffer_size(png, 1u << 18);  // IDAT chunks of 256 KiB, not 8 KiB
  if (e.text_count) png_set_text(png, info, e.text, e.text_count);
  if (e.has_time) png_set_tIME(png, info, &e.time);
  png_write_info(png, info);
  if (e.bits == 16) png_set_swap(png);  // the rows are native (little-endian) uint16
  for (int y = 0; y < e.height; ++y) png_write_row(png, e.rows + std::size_t(y) * e.row_bytes);
  png_write_end(png, info);
  return true;
}

// "YYYY:MM:DD HH:MM:SS" as a tIME; false when it is not that.
bool parse_date_time(const std::string& text, png_time* t) {
  int f[6];
  if (!image_write::date_time_fields(text, f)) return false;
  *t = {png_uint_16(f[0]), png_byte(f[1]), png_byte(f[2]), png_byte(f[3]), png_byte(f[4]), png_byte(f[5])};
  return true;
}

}  // namespace

std::vector<unsigned char> encode_png_libpng(const void* rows, int width, int height, int channels, int bits,
                                             const std::vector<std::pair<std::string, std::string>>& metadata,
                                             const PngSettings& settings, std::string* error) {
  static constexpr int kColorTypes[] = {PNG_COLOR_TYPE_GRAY, PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB,
                                        PNG_COLOR_TYPE_RGB_ALPHA};
  std::vector<unsigned char> bytes;
  Encode e{};
  e.rows = static_cast<const unsigned char*>(rows);
  e.row_bytes = std::size_t(width) * std::size_t(channels) * std::size_t(bits / 8);
  e.width = width;
  e.height = height;
  e.bits = bits;
  e.color_type = kColorTypes[channels - 1];
  e.settings = settings;
  std::vector<std::string> keys;  // png_text points into these
  std::vector<png_text> text;
  keys.reserve(metadata.size());
  for (const auto& [key, value] : metadata) {
    if (key == "DateTime") {
      e.has_time = parse_date_time(value, &e.time);
      continue;
    }
    keys.push_back(key == "ImageDescription" ? "Description" : key);
    png_text t{};
    t.compression = PNG_TEXT_COMPRESSION_NONE;
    t.key = const_cast<char*>(keys.back().c_str());
    t.text = const_cast<char*>(value.c_str());
    t.text_length = value.size();
    text.push_back(t);
  }
  e.text = text.data();
  e.text_count = int(text.size());
  Sink sink{&bytes, {}};
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &sink, on_png_error, on_png_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  const bool created = info != nullptr;
  const bool ok = created && run_encoder(png, info, &sink, e);
  png_destroy_write_struct(png ? &png : nullptr, info ? &info : nullptr);  // sets both to null
  if (!ok) {
    *error = created ? sink.message : "insufficient memory";
    return {};
  }
  return bytes;
}

}  // namespace nmbake::bench
