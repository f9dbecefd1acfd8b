#include "scene_maker.h"

#include <cmath>
#include <fstream>
#include <stdexcept>

#include <glm/glm.hpp>

#include "core/image.h"
#include "io/image_io.h"

namespace nmview::test {
namespace {

constexpr double kPi = 3.14159265358979323846;

glm::dvec3 sphere_direction(int i, int j, int segments, int rings) {
  const double theta = kPi * i / rings, phi = 2.0 * kPi * j / segments;
  return {std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi)};
}

// Faces of the (segments+1) x (rings+1) vertex grid with 1-based OBJ indices, skipping the pole
// triangles whose two corners are the same point.
void write_faces(std::ofstream& out, int segments, int rings, bool with_attributes) {
  auto id = [&](int i, int j) { return i * (segments + 1) + j + 1; };
  auto corner = [&](int v) {
    return with_attributes ? std::to_string(v) + "/" + std::to_string(v) + "/" + std::to_string(v) : std::to_string(v);
  };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if (i != rings - 1) out << "f " << corner(a) << " " << corner(b) << " " << corner(c) << "\n";
      if (i != 0) out << "f " << corner(a) << " " << corner(c) << " " << corner(d) << "\n";
    }
}

void write_map(const std::string& path, int width, int height, double amplitude) {
  nmbake::Image map(width, height, 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      // Texel centre (baking.md): u = (x + 0.5) / W, v = 1 - (y + 0.5) / H.
      const double u = (x + 0.5) / width, v = 1.0 - (y + 0.5) / height;
      const double dhdu = 2 * kPi * 8 * std::cos(2 * kPi * 8 * u) * std::sin(2 * kPi * 4 * v);
      const double dhdv = 2 * kPi * 4 * std::sin(2 * kPi * 8 * u) * std::cos(2 * kPi * 4 * v);
      const glm::dvec3 n = glm::normalize(glm::dvec3(-amplitude * dhdu, -amplitude * dhdv, 1.0));
      float* p = map.at(x, y);
      for (int c = 0; c < 3; ++c) p[c] = float(n[c] * 0.5 + 0.5);
    }
  nmbake::write_image(path, map);
}

}  // namespace

void write_uv_sphere(const std::string& path, int segments, int rings) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out.precision(9);
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const glm::dvec3 d = sphere_direction(i, j, segments, rings);
      out << "v " << d.x << " " << d.y << " " << d.z << "\n";
      out << "vt " << double(j) / segments << " " << 1.0 - double(i) / rings << "\n";
      out << "vn " << d.x << " " << d.y << " " << d.z << "\n";
    }
  write_faces(out, segments, rings, true);
}

void write_bumpy_sphere(const std::string& path, int segments, int rings, double frequency, double amplitude) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out.precision(9);
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const glm::dvec3 d = sphere_direction(i, j, segments, rings);
      const double r = 1.0 + amplitude * (std::sin(frequency * d.x) + std::sin(frequency * d.y) + std::sin(frequency * d.z));
      out << "v " << r * d.x << " " << r * d.y << " " << r * d.z << "\n";
    }
  write_faces(out, segments, rings, false);
}

void write_wave_map(const std::string& path, int width, int height) { write_map(path, width, height, 0.01); }

void write_flat_map(const std::string& path, int width, int height) {
  nmbake::Image map(width, height, 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      float* p = map.at(x, y);
      p[0] = p[1] = 128.0f / 255.0f;
      p[2] = 1.0f;
    }
  nmbake::write_image(path, map);
}

namespace {

// The cube's faces as corner quads, counter-clockwise seen from outside.
constexpr int kCubeFaces[6][4][3] = {
    {{1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}}, {{-1, -1, 1}, {-1, 1, 1}, {-1, 1, -1}, {-1, -1, -1}},
    {{-1, 1, -1}, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}}, {{-1, -1, 1}, {-1, -1, -1}, {1, -1, -1}, {1, -1, 1}},
    {{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}}, {{1, -1, -1}, {-1, -1, -1}, {-1, 1, -1}, {1, 1, -1}}};

glm::dvec3 cube_corner(int face, int k) {
  return {double(kCubeFaces[face][k][0]), double(kCubeFaces[face][k][1]), double(kCubeFaces[face][k][2])};
}

}  // namespace

void write_smooth_cube(const std::string& path) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  int vertex = 0;
  for (int f = 0; f < 6; ++f) {
    const double u0 = (f % 3) / 3.0 + 0.01, v0 = (f / 3) / 2.0 + 0.01, su = 1.0 / 3.0 - 0.02, sv = 0.5 - 0.02;
    const int square[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int k = 0; k < 4; ++k) {
      const glm::dvec3 p = cube_corner(f, k), n = glm::normalize(p);
      out << "v " << p.x << " " << p.y << " " << p.z << "\nvn " << n.x << " " << n.y << " " << n.z << "\nvt "
          << u0 + square[k][0] * su << " " << v0 + square[k][1] * sv << "\n";
    }
    auto c = [&](int k) {
      return std::to_string(vertex + k + 1) + "/" + std::to_string(vertex + k + 1) + "/" + std::to_string(vertex + k + 1);
    };
    out << "f " << c(0) << " " << c(1) << " " << c(2) << "\nf " << c(0) << " " << c(2) << " " << c(3) << "\n";
    vertex += 4;
  }
}

void write_normal_detail_cube(const std::string& path, int cells) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out.precision(9);
  int base = 1;
  for (int f = 0; f < 6; ++f) {
    for (int j = 0; j <= cells; ++j)
      for (int i = 0; i <= cells; ++i) {
        const double s = double(i) / cells, t = double(j) / cells;
        const glm::dvec3 p = (1 - s) * (1 - t) * cube_corner(f, 0) + s * (1 - t) * cube_corner(f, 1) + s * t * cube_corner(f, 2) +
                             (1 - s) * t * cube_corner(f, 3);
        const glm::dvec3 wave(std::sin(5 * p.y + 2 * p.z), std::sin(6 * p.z + p.x), std::sin(5 * p.x + 3 * p.y));
        const glm::dvec3 n = glm::normalize(glm::normalize(p) + 0.3 * wave);
        out << "v " << p.x << " " << p.y << " " << p.z << "\nvn " << n.x << " " << n.y << " " << n.z << "\n";
      }
    for (int j = 0; j < cells; ++j)
      for (int i = 0; i < cells; ++i) {
        const int a = base + j * (cells + 1) + i, b = a + 1, c = b + cells + 1, d = a + cells + 1;
        out << "f " << a << "//" << a << " " << b << "//" << b << " " << c << "//" << c << "\n";
        out << "f " << a << "//" << a << " " << c << "//" << c << " " << d << "//" << d << "\n";
      }
    base += (cells + 1) * (cells + 1);
  }
}

}  // namespace nmview::test
