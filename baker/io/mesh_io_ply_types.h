// The PLY reader's parsed header and scalar loading, shared by its general reader
// (mesh_io_ply.cpp) and its fast path for binary triangle meshes (mesh_io_ply_fast.cpp). Internal
// to io/.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "io/mesh_io_detail.h"

namespace nmbake::mesh_io_detail::ply {

enum class Scalar { int8, uint8, int16, uint16, int32, uint32, float32, float64 };
enum class Encoding { ascii, binary_little_endian, binary_big_endian };

// What a property is for us; kNone is read past.
enum Role { kNone, kX, kY, kZ, kNx, kNy, kNz, kU, kV, kRed, kGreen, kBlue, kAlpha, kIndices, kTexcoords };

struct Property {
  std::string name;
  bool is_list = false;
  Scalar count_type = Scalar::uint8;  // lists only
  Scalar type = Scalar::float32;      // the scalar, or the list's items
  Role role = kNone;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

struct Header {
  Encoding encoding = Encoding::ascii;
  std::vector<Element> elements;
  std::size_t data_offset = 0;
};

inline unsigned scalar_size(Scalar t) {
  switch (t) {
    case Scalar::int8:
    case Scalar::uint8: return 1;
    case Scalar::int16:
    case Scalar::uint16: return 2;
    case Scalar::int32:
    case Scalar::uint32:
    case Scalar::float32: return 4;
    case Scalar::float64: return 8;
  }
  return 0;
}

// What a colour value of type t is divided by to bring it to [0, 1] (Mesh::colors): the type's
// largest value for integers (uchar 255, ushort 65535), 1 for floats.
inline double color_scale(Scalar t) {
  switch (t) {
    case Scalar::int8: return 127.0;
    case Scalar::uint8: return 255.0;
    case Scalar::int16: return 32767.0;
    case Scalar::uint16: return 65535.0;
    case Scalar::int32: return 2147483647.0;
    case Scalar::uint32: return 4294967295.0;
    case Scalar::float32:
    case Scalar::float64: return 1.0;
  }
  return 1.0;
}

constexpr bool kHostLittleEndian = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

template <typename T>
T load(const char* p, bool swap) {
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, p, sizeof(T));
  if (swap)
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
  T value;
  std::memcpy(&value, raw, sizeof(T));
  return value;
}

inline double load_scalar(const char* p, Scalar t, bool swap) {
  switch (t) {
    case Scalar::int8: return load<std::int8_t>(p, swap);
    case Scalar::uint8: return load<std::uint8_t>(p, swap);
    case Scalar::int16: return load<std::int16_t>(p, swap);
    case Scalar::uint16: return load<std::uint16_t>(p, swap);
    case Scalar::int32: return load<std::int32_t>(p, swap);
    case Scalar::uint32: return load<std::uint32_t>(p, swap);
    case Scalar::float32: return static_cast<double>(load<float>(p, swap));
    case Scalar::float64: return load<double>(p, swap);
  }
  return 0.0;
}

struct Layout {
  const Element* vertex = nullptr;
  const Element* face = nullptr;
  bool normals = false;
  bool vertex_uvs = false;
  bool colors = false;          // red, green and blue (alpha optional) on the vertices
  bool face_texcoords = false;  // per-corner UVs on the faces; they win over vertex_uvs
};

// The fast path: a binary little-endian file (on a little-endian host) whose first elements with
// properties are the vertices (scalars only) and then the faces (the index list alone, every face a
// triangle, int32 or uint32 indices), read on every core. True: `out` holds exactly what the
// general reader makes of the file. False: the file is not of that kind, or something in it is
// wrong (a non-finite value, an index out of range, a face that is not a triangle): the general
// reader then reads it and names the problem.
bool parse_fast(const Header& header, const Layout& layout, std::string_view data, ParsedMesh& out);

}  // namespace nmbake::mesh_io_detail::ply
