// The reading half of image_io.h: read_image and read_image_metadata through OpenImageIO, with the
// checks of image_read_guard.h before any pixel is allocated. Part of libnmbake-oiio.so (oiio_module.h).
#include <algorithm>
#include <cctype>
#include <cstdint>
#include <limits>
#include <map>
#include <new>
#include <string>

#include <OpenImageIO/imageio.h>

#include "core/errors.h"
#include "core/memory_budget.h"
#include "io/oiio_module.h"
#include "io/image_read_guard.h"

namespace nmbake {
namespace {

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// A reader's failure: out of memory when its message says so (OpenImageIO and OpenEXR catch
// std::bad_alloc and report it as text), otherwise unreadable input.
[[noreturn]] void fail_read(const std::string& path, const std::string& message) {
  std::string text = one_line(message);
  if (text.empty()) text = "unknown error";
  const std::string low = lower(text);
  if (low.find("bad_alloc") != std::string::npos || low.find("out of memory") != std::string::npos ||
      low.find("cannot allocate") != std::string::npos || low.find("memory allocation") != std::string::npos)
    throw ResourceError(path + ": out of memory reading the image (" + text + ")");
  throw InputError(path + ": cannot read image: " + text);
}

// The header's values read_image checks before allocating.
ImageHeader header_of(const OIIO::ImageInput& in) {
  const OIIO::ImageSpec& spec = in.spec();
  ImageHeader h;
  h.width = spec.width;
  h.height = spec.height;
  h.channels = spec.nchannels;
  h.format = in.format_name();
  h.compression = lower(spec.get_string_attribute("compression"));
  // The smallest stored channel: bits per sample when the file says (1-bit PNG), else the type's.
  std::size_t bytes = spec.format.size();
  for (const OIIO::TypeDesc& t : spec.channelformats) bytes = std::min(bytes, t.size());
  h.bits_per_sample = std::clamp(spec.get_int_attribute("oiio:BitsPerSample", int(8 * bytes)), 1, int(8 * bytes));
  // PNG and TIFF may store a palette index per pixel, shown as RGB.
  h.palette = h.format == "png" || h.format == "tiff";
  return h;
}

Image read_pixels(const std::string& path, OIIO::ImageInput& in, std::uint64_t file_size) {
  const OIIO::ImageSpec& spec = in.spec();
  auto fail = [&](const std::string& reason) { throw InputError(path + ": cannot read image: " + reason); };
  if (spec.deep) fail("deep images are not supported");
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth != 1)
    fail("unsupported size " + std::to_string(spec.width) + "x" + std::to_string(spec.height) + "x" + std::to_string(spec.depth) +
         " with " + std::to_string(spec.nchannels) + " channels");
  check_image_header(path, header_of(in), file_size, memory_budget_bytes());
  const double count = double(spec.width) * spec.height * spec.nchannels;
  if (count > double(std::numeric_limits<std::int32_t>::max()))
    throw ResourceError(path + ": image too large (" + std::to_string(spec.width) + "x" + std::to_string(spec.height) + "x" +
                        std::to_string(spec.nchannels) + ")");

  Image image(spec.width, spec.height, spec.nchannels);
  // The TIFF reader reports a truncated strip through has_error() yet returns true.
  if (!in.read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data()) || in.has_error())
    fail_read(path, in.geterror());
  in.close();
  return image;
}

}  // namespace

Image oiio_module::read(const std::string& path, std::uint64_t file_size) {
  try {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);  // alpha is coverage: do not premultiply
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) fail_read(path, OIIO::geterror());
    return read_pixels(path, *in, file_size);
  } catch (const std::bad_alloc&) {
    throw ResourceError(path + ": out of memory reading the image");
  }
}

std::map<std::string, std::string> oiio_module::read_metadata(const std::string& path) {
  try {
    auto in = OIIO::ImageInput::open(path);
    if (!in) fail_read(path, OIIO::geterror());
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
  } catch (const std::bad_alloc&) {
    throw ResourceError(path + ": out of memory reading the image's header");
  }
}

}  // namespace nmbake
