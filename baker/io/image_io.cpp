#include "io/image_io.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <system_error>

#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include "core/errors.h"

namespace nmbake {
namespace {

namespace fs = std::filesystem;

// OpenImageIO messages may span lines; our errors are printed as one line.
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s.empty() ? std::string("unknown error") : s;
}

// value * scale rounded half away from zero, clamped to [0, scale]; NaN becomes 0.
// For v = value * scale >= 0, round(v) == trunc(v + 0.5) exactly: v is a float times at most
// 65535, so v + 0.5 is exact in double wherever it can reach 1. Negative and NaN values clamp to 0
// either way.
template <typename T, typename Floats>
std::vector<T> quantize(const Floats& values, double scale) {
  std::vector<T> out(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    double v = static_cast<double>(values[i]) * scale + 0.5;
    if (!(v > 0.0)) v = 0.0;
    if (v > scale) v = scale;
    out[i] = static_cast<T>(v);  // truncation of a value in [0, scale]
  }
  return out;
}

std::string temp_path_for(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  std::string name = "." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) +
                     target.extension().string();
  return (target.parent_path() / name).string();
}

// The EXR and TIFF writers stamp the current time into "DateTime", so two identical bakes differ
// in a few bytes. With SOURCE_DATE_EPOCH set (seconds since 1970, the reproducible-builds
// convention) that time is used instead and identical bakes give identical files.
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
  throw OutputError(path + ": cannot write: " + reason);
}

}  // namespace

void write_image(const std::string& path, const Image& image, const WriteOptions& options) {
  const int bits = options.bits ? options.bits : default_bits_for(path);
  check_output_format(path, bits);
  assert(image.pixels.size() == static_cast<std::size_t>(image.width) * image.height * image.channels);
  if (image.width <= 0 || image.height <= 0 || image.channels <= 0)
    fail_write(path, "empty image (" + std::to_string(image.width) + "x" + std::to_string(image.height) + "x" +
                         std::to_string(image.channels) + ")");

  // Check the folder first: OpenImageIO would only name the temporary file.
  const fs::path target(path);
  const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) fail_write(path, "folder '" + folder.string() + "' does not exist");
  if (::access(folder.c_str(), W_OK) != 0)
    fail_write(path, "folder '" + folder.string() + "' is not writable (" + std::strerror(errno) + ")");

  // Pixels in the stored type: integer formats are quantized here, float goes through as is
  // (OpenImageIO converts float to half for EXR 16).
  const std::string ext = image_io_detail::lower_extension(path);
  OIIO::TypeDesc stored = OIIO::TypeDesc::FLOAT;
  OIIO::TypeDesc given = OIIO::TypeDesc::FLOAT;
  std::vector<std::uint8_t> data8;
  std::vector<std::uint16_t> data16;
  const void* data = image.pixels.data();
  if (bits == 8) {
    data8 = quantize<std::uint8_t>(image.pixels, 255.0);
    stored = given = OIIO::TypeDesc::UINT8;
    data = data8.data();
  } else if (bits == 16 && ext != ".exr") {
    data16 = quantize<std::uint16_t>(image.pixels, 65535.0);
    stored = given = OIIO::TypeDesc::UINT16;
    data = data16.data();
  } else if (bits == 16) {
    stored = OIIO::TypeDesc::HALF;
  }

  OIIO::ImageSpec spec(image.width, image.height, image.channels, stored);
  // Alpha is coverage, not premultiplication: keep colour values exactly as given.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  for (const auto& [key, value] : options.metadata) spec.attribute(key, value);
  if (const std::string date = reproducible_date_time(); !date.empty() && spec.get_string_attribute("DateTime").empty())
    spec.attribute("DateTime", date);
  // Measured on a 2048^2 map: PNG at zlib level 6 took 3.3 s, level 1 0.6 s (file ~10% larger);
  // EXR zip shrank float normals by 1% in 2.3 s, uncompressed takes 0.1 s. With level 1, libpng's
  // adaptive filter choice costs about a third of the write: the "up" filter alone (0x20) wrote
  // the torus_s3 map in 0.18-0.27 s instead of 0.31-0.37 s, and 2% smaller (4.97 MB, not 5.08).
  if (ext == ".png") {
    spec.attribute("png:compressionLevel", 1);
    spec.attribute("png:filter", 0x20);
  }
  if (ext == ".exr") spec.attribute("compression", "none");
  // The TIFF writer drops attributes it does not know; keep them readable (and parsable by
  // read_image_metadata) as "key=value" items after any given description in the description tag.
  if (ext == ".tif" || ext == ".tiff") {
    std::string description = spec.get_string_attribute("ImageDescription");
    for (const auto& [key, value] : options.metadata)
      if (key != "ImageDescription") description += (description.empty() ? "" : "; ") + key + "=" + value;
    if (!description.empty()) spec.attribute("ImageDescription", description);
  }

  // Create with the real path so the writer is chosen by its extension.
  auto out = OIIO::ImageOutput::create(path);
  if (!out) fail_write(path, one_line(OIIO::geterror()));

  const std::string temp = temp_path_for(target);
  auto discard = [&](const std::string& reason) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    fail_write(path, reason);
  };
  if (!out->open(temp, spec)) {
    std::string reason = one_line(out->geterror());
    out.reset();
    discard(reason);
  }
  if (!out->write_image(given, data) || out->has_error()) {
    std::string reason = one_line(out->geterror());
    out->close();
    out.reset();
    discard(reason);
  }
  // Only close()'s result counts: with Debian 12's libtiff every TIFF close records a harmless
  // "failed TIFFWriteCustomDirectory() of the Exif data" and still writes a good file.
  if (!out->close()) {
    std::string reason = one_line(out->geterror());
    out.reset();
    discard(reason);
  }
  out->geterror();  // drop that message
  out.reset();
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    std::string reason = std::strerror(errno);
    if (fs::is_directory(target, ec)) reason = "a folder of that name exists";
    discard(reason);
  }
}

Image read_image(const std::string& path) {
  auto fail = [&](const std::string& reason) -> Image { throw InputError(path + ": cannot read image: " + reason); };
  std::error_code ec;
  if (!fs::exists(path, ec)) return fail("no such file");
  if (fs::is_directory(path, ec)) return fail("it is a folder");

  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // alpha is coverage: do not premultiply
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) return fail(one_line(OIIO::geterror()));

  const OIIO::ImageSpec& spec = in->spec();
  if (spec.deep) return fail("deep images are not supported");
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth != 1)
    return fail("unsupported size " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + "x" +
                std::to_string(spec.depth) + " with " + std::to_string(spec.nchannels) + " channels");
  const double count = double(spec.width) * spec.height * spec.nchannels;
  if (count > double(std::numeric_limits<std::int32_t>::max()))
    throw ResourceError(path + ": image too large (" + std::to_string(spec.width) + "x" + std::to_string(spec.height) + "x" +
                        std::to_string(spec.nchannels) + ")");

  Image image;
  try {
    image = Image(spec.width, spec.height, spec.nchannels);
  } catch (const std::bad_alloc&) {
    throw ResourceError(path + ": out of memory reading a " + std::to_string(spec.width) + "x" + std::to_string(spec.height) +
                        " image");
  }
  // The TIFF reader reports a truncated strip through has_error() yet returns true.
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data()) || in->has_error())
    return fail(one_line(in->geterror()));
  in->close();
  return image;
}

std::map<std::string, std::string> read_image_metadata(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec) || fs::is_directory(path, ec))
    throw InputError(path + ": cannot read image: " + (fs::is_directory(path, ec) ? "it is a folder" : "no such file"));
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw InputError(path + ": cannot read image: " + one_line(OIIO::geterror()));
  std::map<std::string, std::string> metadata;
  for (const OIIO::ParamValue& p : in->spec().extra_attribs)
    if (p.type() == OIIO::TypeDesc::STRING) metadata[p.name().string()] = p.get_string();
  // "key=value" items of the description tag (how write_image keeps them in TIFF).
  const std::string description = in->spec().get_string_attribute("ImageDescription");
  std::size_t begin = 0;
  while (begin < description.size()) {
    std::size_t end = description.find(';', begin);
    if (end == std::string::npos) end = description.size();
    std::string item = description.substr(begin, end - begin);
    item.erase(0, item.find_first_not_of(' '));
    const std::size_t equals = item.find('=');
    if (item.rfind("nmbake:", 0) == 0 && equals != std::string::npos)
      metadata.emplace(item.substr(0, equals), item.substr(equals + 1));
    begin = end + 1;
  }
  in->close();
  return metadata;
}

void preload_image_io() {}  // linked directly: nothing to load
void wait_for_image_io() {}
std::string image_io_problem() { return {}; }

}  // namespace nmbake
