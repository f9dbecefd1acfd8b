// Hostile inputs of the nmdiff command-line tests: files that are not regular files, headers that
// state more pixels than their file can hold, and maps carrying nmbake's convention metadata.
#include "hostile_fixtures.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/image_io.h"

namespace {

using Bytes = std::vector<unsigned char>;

std::uint32_t crc32(const Bytes& data, std::size_t begin) {
  std::uint32_t crc = 0xffffffffu;
  for (std::size_t i = begin; i < data.size(); ++i) {
    crc ^= data[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void put32(Bytes& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back((unsigned char)(v >> shift));
}

void chunk(Bytes& png, const char* type, const Bytes& data) {
  put32(png, std::uint32_t(data.size()));
  const std::size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data.begin(), data.end());
  put32(png, crc32(png, start));
}

}  // namespace

void write_png_header(const std::string& path, std::uint32_t width, std::uint32_t height, std::size_t idat_bytes) {
  Bytes png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  Bytes ihdr;
  put32(ihdr, width);
  put32(ihdr, height);
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // 8 bits, RGB, deflate, adaptive filters, not interlaced
  chunk(png, "IHDR", ihdr);
  chunk(png, "IDAT", Bytes(idat_bytes, 0));
  chunk(png, "IEND", {});
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(png.data()), std::streamsize(png.size()));
}

namespace {

// `small` (an uncompressed EXR) with its data and display windows widened to width x height.
void widen_exr(const std::string& small, const std::string& path, int width, int height) {
  std::ifstream in(small, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const std::string name : {"dataWindow", "displayWindow"}) {
    const std::string key = name + std::string("\0box2i\0", 7);
    const std::size_t at = bytes.find(key);
    if (at == std::string::npos) throw std::runtime_error(small + ": no " + name);
    const std::int32_t box[4] = {0, 0, width - 1, height - 1};  // little-endian, as the file
    bytes.replace(at + key.size() + 4, 16, reinterpret_cast<const char*>(box), 16);
  }
  std::ofstream(path, std::ios::binary) << bytes;
}

}  // namespace

void write_hostile_fixtures(const std::string& dir) {
  const auto path = [&](const char* name) { return dir + "/" + name; };

  // Not regular files: a FIFO (opening it for reading would block) and a link to it.
  ::unlink(path("fifo.png").c_str());
  if (::mkfifo(path("fifo.png").c_str(), 0600) != 0) throw std::runtime_error("cannot make " + path("fifo.png"));
  ::unlink(path("fifo_link.png").c_str());
  if (::symlink("fifo.png", path("fifo_link.png").c_str()) != 0) throw std::runtime_error("cannot link to the FIFO");

  // 20000 x 20000 RGB in 100 bytes of pixel data: deflate cannot pack 1.2 GB that tight.
  write_png_header(path("header_20000.png"), 20000, 20000, 100);
  // The same size in 4 MB: possible (300:1), but its 4.8 GB of floats exceed a 2 GB ulimit -v.
  write_png_header(path("plausible_20000.png"), 20000, 20000, 4u << 20);

  // An uncompressed 32 x 32 EXR whose header says 20000 x 20000.
  nmbake::write_image(path("exr_small.exr"), nmbake::Image(32, 32, 3, 0.5f));
  widen_exr(path("exr_small.exr"), path("header_20000.exr"), 20000, 20000);

  // nmbake's convention metadata: the same normals baked green up (PNG) and green down (EXR), an
  // object-space map, and per-pixel against per-vertex bitangents.
  nmbake::Image up(16, 16, 3), down(16, 16, 3);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const float g = 0.3f + 0.025f * float(y), r = 0.4f + 0.0125f * float(x);
      float* u = up.at(x, y);
      u[0] = r, u[1] = g, u[2] = 0.9f;
      float* d = down.at(x, y);
      d[0] = r, d[1] = 1.0f - g, d[2] = 0.9f;
    }
  nmbake::WriteOptions o;
  o.metadata = {{"nmbake:space", "tangent"}, {"nmbake:green", "up"}};
  nmbake::write_image(path("meta_green_up.png"), up, o);
  o.metadata = {{"nmbake:space", "tangent"}, {"nmbake:green", "down"}};
  nmbake::write_image(path("meta_green_down.exr"), down, o);
  o.metadata = {{"nmbake:space", "object"}, {"nmbake:green", "up"}};
  nmbake::write_image(path("meta_object.exr"), up, o);
  nmbake::write_image(path("untagged_green_down.exr"), down);
  // The same normals said to be baked with per-pixel and with per-vertex bitangents.
  o.metadata = {{"nmbake:space", "tangent"}, {"nmbake:green", "up"}, {"nmbake:bitangent", "pixel"}};
  nmbake::write_image(path("meta_pixel.png"), up, o);
  o.metadata = {{"nmbake:space", "tangent"}, {"nmbake:green", "up"}, {"nmbake:bitangent", "vertex"}};
  nmbake::write_image(path("meta_vertex.png"), up, o);

  // A 2048^2 map (smooth, so the PNG stays small) for the runs under ulimit -v.
  nmbake::Image medium(2048, 2048, 3);
  for (int y = 0; y < 2048; ++y)
    for (int x = 0; x < 2048; ++x) {
      float* p = medium.at(x, y);
      p[0] = 0.5f + 0.2f * float(x % 64) / 64.0f, p[1] = 0.5f + 0.2f * float(y % 32) / 32.0f, p[2] = 0.9f;
    }
  nmbake::write_image(path("medium_2048.png"), medium);
}
