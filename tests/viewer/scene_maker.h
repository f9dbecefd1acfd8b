// Procedural test scenes for nmview, written to files so the real binaries can read them.
#pragma once

#include <string>

namespace nmview::test {

// A UV sphere of radius 1 around the origin with `segments` x `rings` quads (pole quads are single
// triangles), analytic normals and UVs u = longitude, v = 1 at the north pole (+Y). CCW from outside.
void write_uv_sphere(const std::string& path, int segments, int rings);

// A finer sphere displaced radially by amplitude * (sin(f x) + sin(f y) + sin(f z)) at the unit
// direction (x, y, z) (the "sculpt"), no normals, no UVs.
void write_bumpy_sphere(const std::string& path, int segments, int rings, double frequency = 9.0, double amplitude = 0.01);

// A tangent-space normal map of `width` x `height` computed analytically from the height field
// h(u, v) = sin(2 pi 8 u) sin(2 pi 4 v), written as 8-bit PNG (not baked).
void write_wave_map(const std::string& path, int width, int height);

// The cube [-1,1]^3 as 12 triangles, each face its own UV island of a 3 x 2 atlas, smooth corner
// normals (the diagonals, so the tangent frame turns strongly across every triangle: per-pixel and
// per-vertex bitangents differ). CCW from outside.
void write_smooth_cube(const std::string& path);

// The same cube surface as a `cells` x `cells` grid per face (no parallax against
// write_smooth_cube), with normals that are the diagonal field of the low-poly tilted by a smooth
// wave: all of its detail is in the normals, so a correctly decoded map reproduces it exactly.
void write_normal_detail_cube(const std::string& path, int cells);

// A flat map (every texel 128,128,255).
void write_flat_map(const std::string& path, int width, int height);

}  // namespace nmview::test
