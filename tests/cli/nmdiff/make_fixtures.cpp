// Writes the inputs of the nmdiff command-line tests into the folder given as argv[1].
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>

#include "hostile_fixtures.h"
#include "io/image_io.h"

namespace {

using nmbake::Image;
constexpr int kSize = 32;

void encode(float* p, double x, double y, double z) {
  const double l = std::sqrt(x * x + y * y + z * z);
  p[0] = float(x / l * 0.5 + 0.5);
  p[1] = float(y / l * 0.5 + 0.5);
  p[2] = float(z / l * 0.5 + 0.5);
}

// Rotates texel (x, y) of `img` by `deg` about the axis n x (0,0,1) (n is never +Z here).
void rotate(Image& img, int x, int y, double deg) {
  float* p = img.at(x, y);
  const double n[3] = {p[0] * 2.0 - 1, p[1] * 2.0 - 1, p[2] * 2.0 - 1};
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const double u[3] = {n[0] / len, n[1] / len, n[2] / len};
  const double al = std::sqrt(u[0] * u[0] + u[1] * u[1]);
  const double axis[3] = {u[1] / al, -u[0] / al, 0.0};
  const double k[3] = {axis[1] * u[2] - axis[2] * u[1], axis[2] * u[0] - axis[0] * u[2], axis[0] * u[1] - axis[1] * u[0]};
  const double r = deg * 3.14159265358979323846 / 180, c = std::cos(r), s = std::sin(r);
  encode(p, u[0] * c + k[0] * s, u[1] * c + k[1] * s, u[2] * c + k[2] * s);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s FOLDER\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  const auto path = [&](const char* name) { return dir + "/" + name; };

  // Random normals within 60 degrees of +Z (never exactly +Z), fixed seed.
  Image a(kSize, kSize, 3);
  std::mt19937 rng(12111);
  std::normal_distribution<double> g;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x)
      for (;;) {
        const double nx = g(rng), ny = g(rng), nz = std::abs(g(rng));
        if (nz / std::sqrt(nx * nx + ny * ny + nz * nz) <= 0.5 || (nx == 0 && ny == 0)) continue;
        encode(a.at(x, y), nx, ny, nz);
        break;
      }
  nmbake::write_image(path("a_float.exr"), a);
  nmbake::write_image(path("a.png"), a);  // its 8-bit rounding

  Image rotated = a;
  rotate(rotated, 5, 7, 10.0);
  nmbake::write_image(path("a_rot.exr"), rotated);

  // One texel that is not a number (a broken bake): a difference, never "not compared".
  Image with_nan = a;
  with_nan.at(3, 4)[0] = std::nanf("");
  nmbake::write_image(path("a_nan.exr"), with_nan);

  Image green_down = a;
  for (std::size_t i = 1; i < green_down.pixels.size(); i += 3) green_down.pixels[i] = 1.0f - green_down.pixels[i];
  nmbake::write_image(path("a_green_down.exr"), green_down);

  // The right half (texels x >= 16, u > 0.5) changed by 20 degrees.
  Image right = a;
  for (int y = 0; y < kSize; ++y)
    for (int x = kSize / 2; x < kSize; ++x) rotate(right, x, y, 20.0);
  nmbake::write_image(path("a_right_changed.exr"), right);

  // A at twice the size, each texel repeated 2x2.
  Image big(2 * kSize, 2 * kSize, 3);
  for (int y = 0; y < 2 * kSize; ++y)
    for (int x = 0; x < 2 * kSize; ++x)
      for (int k = 0; k < 3; ++k) big.at(x, y)[k] = a.at(x / 2, y / 2)[k];
  nmbake::write_image(path("a_64.exr"), big);

  nmbake::write_image(path("gray.png"), Image(kSize, kSize, 1, 0.5f));
  std::ofstream(path("not_an_image.png")) << "this is not a picture\n";

  // A low-poly quad whose UV layout covers the left half of the map (u in [0, 0.5]).
  std::ofstream(path("low_left.obj")) << "v -1 -1 0\nv 0 -1 0\nv 0 1 0\nv -1 1 0\n"
                                         "vt 0 0\nvt 0.5 0\nvt 0.5 1\nvt 0 1\nvn 0 0 1\n"
                                         "f 1/1/1 2/2/1 3/3/1 4/4/1\n";
  write_hostile_fixtures(dir);
  return 0;
}
