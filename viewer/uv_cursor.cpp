#include "uv_cursor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "cli/numbers.h"
#include "core/errors.h"
#include "udim_tiles.h"

namespace nmview {
namespace {

float cross_2d(glm::vec2 a, glm::vec2 b) { return a.x * b.y - a.y * b.x; }

// "0.25", "1.2": a UV coordinate as the label shows it.
std::string uv_coordinate(float x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", double(x));
  return text;
}

}  // namespace

std::optional<UvPoint> find_uv_point(const LowVertices& low, glm::vec2 uv) {
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return std::nullopt;
  std::optional<UvPoint> found;
  for (std::size_t i = 0; i + 2 < low.indices.size(); i += 3) {
    const LowVertex& a = low.vertices[low.indices[i]];
    const LowVertex& b = low.vertices[low.indices[i + 1]];
    const LowVertex& c = low.vertices[low.indices[i + 2]];
    const glm::vec2 ab = b.uv - a.uv, ac = c.uv - a.uv, ap = uv - a.uv;
    const float area = cross_2d(ab, ac);  // twice the signed area: mirrored islands are negative
    // A degenerate UV triangle (relative to its edges) holds nothing: weights would be 0 / 0.
    const float scale = glm::dot(ab, ab) + glm::dot(ac, ac);
    if (!(std::abs(area) > 1e-7f * scale)) continue;
    const float wb = cross_2d(ap, ac) / area, wc = cross_2d(ab, ap) / area, wa = 1.0f - wb - wc;
    // Within 1e-6 of an edge counts, so a UV on a shared edge is held by one of its triangles.
    constexpr float kEdge = -1e-6f;
    if (wa < kEdge || wb < kEdge || wc < kEdge) continue;
    if (!found) {
      UvPoint p;
      p.triangle = i / 3;
      p.barycentric = glm::clamp(glm::vec3(wa, wb, wc), 0.0f, 1.0f);
      p.barycentric /= p.barycentric.x + p.barycentric.y + p.barycentric.z;
      p.position = p.barycentric.x * a.position + p.barycentric.y * b.position + p.barycentric.z * c.position;
      const int cell = udim_cell(a.uv, b.uv, c.uv);
      p.tile = cell < 0 ? 0 : udim_tile_number(cell);
      found = p;
    }
    ++found->holders;
  }
  return found;
}

glm::vec2 uv_at_pane_pixel(int square_x, int square_y, int square_side, glm::vec2 pixel) {
  const float side = float(std::max(square_side, 1));
  return {(pixel.x - float(square_x)) / side, (pixel.y - float(square_y)) / side};
}

glm::vec2 parse_uv_cursor(const std::string& text) {
  const std::size_t comma = text.find(',');
  const std::string u = comma == std::string::npos ? text : text.substr(0, comma);
  const std::string v = comma == std::string::npos ? "" : text.substr(comma + 1);
  const auto number = [](const std::string& item) {
    return nmbake::is_number(item, false) ? std::strtod(item.c_str(), nullptr) : NAN;
  };
  const double x = number(u), y = number(v);
  if (!std::isfinite(x) || !std::isfinite(y) || std::abs(x) > 1e6 || std::abs(y) > 1e6)
    throw nmbake::UsageError(
        "--uv-cursor: expected U,V: two numbers, the low-poly's UV (e.g. 0.25,0.75; 1.5,0.5 is in UDIM tile "
        "1002), got '" +
        nmbake::printable(text) + "'");
  return {float(x), float(y)};
}

std::string describe_uv_point(glm::vec2 uv, const std::optional<UvPoint>& point) {
  const std::string where = "UV " + uv_coordinate(uv.x) + "," + uv_coordinate(uv.y) + ": ";
  if (!point) return where + "IN NO TRIANGLE";
  std::string line = where + "TRIANGLE " + std::to_string(point->triangle);
  if (point->holders > 1) line += " OF " + std::to_string(point->holders) + " OVERLAPPING";
  if (point->tile > 0) line += " (TILE " + std::to_string(point->tile) + ")";
  return line;
}

}  // namespace nmview
