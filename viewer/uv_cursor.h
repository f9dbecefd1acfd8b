// The UV cursor (issue 36, item 2): which of the low-poly's triangles holds a point of its UV
// layout, and where that texel lies on the model, so the UV view's cursor can be marked on the 3D
// panes and become the selection that F frames. CPU only, no GL.
//
// UVs are the low-poly's (LowVertex::uv, OBJ convention: v = 1 at the top of the image), in any
// UDIM tile (u in [1, 2) is tile 1002, v in [1, 2) tile 1011); nothing is wrapped into the unit
// square. Positions are in the re-centred scene (vertex_data.h), like everything the camera sees.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "vertex_data.h"

namespace nmview {

// The texel's place on the low-poly.
struct UvPoint {
  std::size_t triangle = 0;  // index of the triangle in the index buffer (the first holding the UV)
  glm::vec3 barycentric{0};  // weights of its three corners, each in [0, 1], summing to 1
  glm::vec3 position{0};     // the surface point, re-centred scene
  int tile = 0;              // the UDIM tile number of the triangle (udim_cell), 0 when in none
  std::size_t holders = 0;   // triangles whose UVs hold the point (> 1 where islands overlap)
};

// The first triangle of `low` (index order) whose UV triangle holds `uv` (edges included, within
// 1e-6 of the triangle's UV size), with the surface point at the same barycentric weights. Triangles
// with a degenerate UV triangle (zero area) hold nothing. Nullopt when no triangle holds it or `uv`
// is not finite. Brute force over every triangle (one query per cursor move, not per pixel).
std::optional<UvPoint> find_uv_point(const LowVertices& low, glm::vec2 uv);

// The UV of a point of a pane in the UV view: `pixel` in pane pixels (GL convention, origin at the
// lower left, y up) over the pane's UV square (overlays.h uv_square: x, y its lower-left corner,
// `side` its size); outside the square the UV leaves [0, 1] (another UDIM tile).
glm::vec2 uv_at_pane_pixel(int square_x, int square_y, int square_side, glm::vec2 pixel);

// --uv-cursor's value "U,V": two finite numbers. Throws nmbake::UsageError (one line, quoting it).
glm::vec2 parse_uv_cursor(const std::string& text);

// One line for the UV view's label and the log: "UV 0.25,0.75: TRIANGLE 12 (TILE 1001)" (plus
// "OF 2 OVERLAPPING" where islands overlap), or "UV 0.95,1.2: IN NO TRIANGLE" (upper case: the
// pane font's).
std::string describe_uv_point(glm::vec2 uv, const std::optional<UvPoint>& point);

}  // namespace nmview
