// The image formats nmbake writes and their bit depths, checked before a bake.
#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

#include "core/errors.h"
#include "io/image_io.h"

namespace nmbake {
namespace {

namespace fs = std::filesystem;

// Formats we write, and the bit depths each can hold (32 = float, EXR 16 = half).
struct FormatInfo {
  const char* extension;
  bool bits8, bits16, bits32;
};
constexpr FormatInfo kFormats[] = {
    {".png", true, true, false}, {".tga", true, false, false}, {".tif", true, true, true},
    {".tiff", true, true, true}, {".exr", false, true, true},
};

}  // namespace

namespace image_io_detail {
std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool is_tiff(const std::string& ext) { return ext == ".tif" || ext == ".tiff"; }
}  // namespace image_io_detail

namespace {
const FormatInfo* find_format(const std::string& ext) {
  for (const FormatInfo& f : kFormats)
    if (ext == f.extension) return &f;
  return nullptr;
}

}  // namespace

int default_bits_for(const std::string& path) {
  const std::string ext = image_io_detail::lower_extension(path);
  if (image_io_detail::is_tiff(ext)) return 16;
  if (ext == ".exr") return 32;
  return 8;
}

void check_output_format(const std::string& path, int bits) {
  const std::string ext = image_io_detail::lower_extension(path);
  const FormatInfo* f = find_format(ext);
  if (!f) throw UsageError(path + ": unsupported image format '" + ext + "' (use .png, .tga, .tif, .tiff or .exr)");
  if (bits == 0) return;
  bool ok = (bits == 8 && f->bits8) || (bits == 16 && f->bits16) || (bits == 32 && f->bits32);
  if (!ok) {
    std::string can;
    if (f->bits8) can += "8";
    if (f->bits16) can += std::string(can.empty() ? "" : ", ") + "16";
    if (f->bits32) can += std::string(can.empty() ? "" : ", ") + "32";
    throw UsageError(path + ": " + ext + " cannot hold " + std::to_string(bits) + "-bit values (supported: " + can + ")");
  }
}

}  // namespace nmbake
