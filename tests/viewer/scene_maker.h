// Procedural test scenes for nmview, written to files so the real binaries can read them.
#pragma once

#include <string>

namespace nmview::test {

// A UV sphere of radius 1 around the origin with `segments` x `rings` quads (pole quads are single
// triangles), analytic normals and UVs u = longitude, v = 1 at the north pole (+Y). CCW from outside.
void write_uv_sphere(const std::string& path, int segments, int rings);

// A finer sphere displaced radially by amplitude * (sin(f x) + sin(f y) + sin(f z)) at the unit
// direction (x, y, z) (the "sculpt"), no normals, no UVs.
void write_bumpy_sphere(const std::string& path, int segments, int rings, double frequency = 9.0,
                        double amplitude = 0.01);

// A tangent-space normal map of `width` x `height` computed analytically from the height field
// h(u, v) = sin(2 pi 8 u) sin(2 pi 4 v), written as 8-bit PNG (not baked).
void write_wave_map(const std::string& path, int width, int height);

// A flat map (every texel 128,128,255).
void write_flat_map(const std::string& path, int width, int height);

}  // namespace nmview::test
