#include "inputs.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <string>

#include "core/errors.h"
#include "io/image_io.h"

namespace nmview {

namespace {

constexpr std::size_t kProbeBytes = 4096;

bool starts_with(const std::string& s, const char* prefix, std::size_t length) {
  return s.size() >= length && std::memcmp(s.data(), prefix, length) == 0;
}
bool starts_with(const std::string& s, const char* prefix) { return starts_with(s, prefix, std::strlen(prefix)); }

std::uint32_t little_u32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(s[at + std::size_t(i)]);
  return v;
}

// Formats whose first bytes are a signature of their own.
bool image_signature(const std::string& head) {
  static const char* const kSignatures[] = {
      "\x89PNG\r\n\x1a\n",  // PNG
      "\x76\x2f\x31\x01",   // OpenEXR
      "II*\0",              // TIFF, little-endian
      "MM\0*",              // TIFF, big-endian
      "II+\0",              // BigTIFF
      "\xff\xd8\xff",       // JPEG
      "#?RADIANCE",         // Radiance HDR
      "#?RGBE",
      "DDS ",            // DirectDraw surface
      "8BPS",            // Photoshop
      "GIF8",            // GIF
      "\0\0\0\x0cjP  ",  // JPEG 2000 (the first 8 of its 12 bytes)
  };
  static const std::size_t kLengths[] = {8, 4, 4, 4, 4, 3, 10, 6, 4, 4, 4, 8};
  for (std::size_t i = 0; i < std::size(kSignatures); ++i)
    if (starts_with(head, kSignatures[i], kLengths[i])) return true;
  return head.size() >= 12 && starts_with(head, "RIFF") && head.compare(8, 4, "WEBP") == 0;
}

// The first word of the first line that is neither blank nor a comment ('#', ';' or "//").
std::string first_statement(const std::string& head) {
  std::size_t at = 0;
  while (at < head.size()) {
    std::size_t end = head.find('\n', at);
    if (end == std::string::npos) end = head.size();
    std::string line = head.substr(at, end - at);
    at = end + 1;
    const std::size_t begin = line.find_first_not_of(" \t\r\xef\xbb\xbf");
    if (begin == std::string::npos || line[begin] == '#') continue;
    line.erase(0, begin);
    const std::size_t word_end = line.find_first_of(" \t\r");
    return line.substr(0, word_end);
  }
  return "";
}

bool is_text(const std::string& head) { return head.find('\0') == std::string::npos; }

// Formats of the meshes nmbake reads, by content: our readers' (OBJ, PLY, OFF, STL) and Assimp's
// commonest (glTF, GLB, FBX, DAE, 3DS, X, Blender, LightWave).
bool mesh_signature(const std::string& head, std::uintmax_t size, const std::string& extension) {
  if (starts_with(head, "ply\n") || starts_with(head, "ply\r\n")) return true;
  if (starts_with(head, "glTF") || starts_with(head, "Kaydara FBX Binary") || starts_with(head, "; FBX") ||
      starts_with(head, "xof ") || starts_with(head, "BLENDER") || (starts_with(head, "FORM") && head.find("LWO") == 8))
    return true;
  // Binary STL: an 80-byte header, a triangle count, 50 bytes per triangle.
  if (head.size() >= 84 && size == 84 + 50 * std::uintmax_t(little_u32(head, 80))) return true;
  // 3DS: its main chunk 0x4D4D, whose length is the file's.
  if (head.size() >= 6 && starts_with(head, "MM") && little_u32(head, 2) == size) return true;
  if (!is_text(head)) return false;
  const std::string word = first_statement(head);
  // OFF and its variants (COFF, NOFF, STOFF, 4OFF, ...), ASCII STL.
  if (word.size() >= 3 && word.size() <= 6 && word.compare(word.size() - 3, 3, "OFF") == 0) return true;
  if (word == "solid") return true;
  // OBJ: its first statement is one of its keywords.
  static const char* const kObj[] = {"v", "vt", "vn", "vp", "f", "l", "p", "o", "g", "s", "mtllib", "usemtl", "cstype", "curv"};
  for (const char* k : kObj)
    if (word == k) return true;
  // glTF (JSON with an "asset"), COLLADA (XML).
  if (starts_with(word, "{") && (head.find("\"asset\"") != std::string::npos || extension == ".gltf")) return true;
  if (starts_with(word, "<") && head.find("COLLADA") != std::string::npos) return true;
  return false;
}

// Extensions that decide only where the content said nothing: the loader then reports what is
// wrong with the file.
bool mesh_extension(const std::string& e) {
  static const char* const kMesh[] = {".obj", ".ply", ".off", ".stl", ".gltf", ".glb", ".fbx", ".dae", ".3ds", ".blend",
                                      ".lwo", ".x",   ".ase", ".ifc", ".ms3d", ".md2", ".md3", ".ac",  ".b3d", ".smd"};
  return std::find(std::begin(kMesh), std::end(kMesh), e) != std::end(kMesh);
}
bool image_extension(const std::string& e) {
  static const char* const kImage[] = {".png", ".tga", ".tif", ".tiff", ".exr", ".jpg", ".jpeg", ".hdr", ".dds", ".bmp", ".psd"};
  return std::find(std::begin(kImage), std::end(kImage), e) != std::end(kImage);
}

// OpenImageIO opens the file's header (formats without a signature: TGA, BMP, PNM, ...).
bool image_header_reads(const std::string& path) {
  try {
    nmbake::read_image_metadata(path);
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

const char* kReads =
    "nmview reads meshes as nmbake does (OBJ, PLY, OFF, STL, glTF, FBX, DAE, ...) and maps as images (PNG, TGA, TIFF, "
    "EXR, ...)";

}  // namespace

FileKind classify_file(const std::string& path) {
  if (path.find("<MAP>") != std::string::npos) return FileKind::image;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return FileKind::unknown;
  std::ifstream in(path, std::ios::binary);
  if (!in) return FileKind::unknown;
  std::string head(kProbeBytes, '\0');
  in.read(&head[0], std::streamsize(head.size()));
  head.resize(std::size_t(std::max<std::streamsize>(in.gcount(), 0)));
  const std::string extension = nmbake::image_io_detail::lower_extension(path);
  if (image_signature(head)) return FileKind::image;
  if (mesh_signature(head, std::uintmax_t(st.st_size), extension)) return FileKind::mesh;
  if (!head.empty() && image_header_reads(path)) return FileKind::image;
  if (mesh_extension(extension)) return FileKind::mesh;
  if (image_extension(extension)) return FileKind::image;
  return FileKind::neither;
}

InputFiles resolve_inputs(const std::vector<std::string>& files, const std::string& map_option) {
  std::vector<FileKind> kinds;
  for (const std::string& f : files) {
    kinds.push_back(classify_file(f));
    if (kinds.back() == FileKind::neither) throw nmbake::InputError(f + ": neither a mesh nor an image: " + kReads);
  }
  const std::string forms = "give nmview LOW HIGH -m MAP or nmview LOW MAP HIGH";
  if (!map_option.empty()) {
    if (files.size() != 2) throw nmbake::UsageError("-m " + map_option + " and three files: " + forms);
    switch (classify_file(map_option)) {
      case FileKind::neither: throw nmbake::InputError(map_option + ": neither a mesh nor an image: " + kReads);
      case FileKind::mesh: throw nmbake::UsageError("-m " + map_option + ": a mesh where the map was expected: " + forms);
      default: break;
    }
    for (std::size_t i = 0; i < 2; ++i)
      if (kinds[i] == FileKind::image)
        throw nmbake::UsageError(files[i] + ": an image where the " + (i == 0 ? "low" : "high") +
                                 "-poly mesh was expected (the map is -m " + map_option + "): " + forms);
    return {files[0], map_option, files[1]};
  }
  if (files.size() != 3) {
    const bool has_image = std::find(kinds.begin(), kinds.end(), FileKind::image) != kinds.end();
    throw nmbake::UsageError(std::string(has_image ? "no high-poly mesh given: " : "no map given: ") + forms);
  }

  std::vector<std::size_t> images, undecided;
  for (std::size_t i = 0; i < 3; ++i) {
    if (kinds[i] == FileKind::image) images.push_back(i);
    if (kinds[i] == FileKind::unknown) undecided.push_back(i);
  }
  if (images.size() > 1)
    throw nmbake::UsageError(files[images[0]] + " and " + files[images[1]] + " are both images: nmview shows one map; " + forms);
  std::size_t map = 1;  // LOW MAP HIGH where the content does not decide
  if (images.size() == 1) map = images[0];
  else if (undecided.size() == 1) map = undecided[0];
  else if (undecided.empty())
    throw nmbake::UsageError(files[0] + ", " + files[1] + " and " + files[2] + " are all meshes and no map is given: " + forms);
  std::vector<std::string> meshes;
  for (std::size_t i = 0; i < 3; ++i)
    if (i != map) meshes.push_back(files[i]);
  return {meshes[0], files[map], meshes[1]};
}

}  // namespace nmview
