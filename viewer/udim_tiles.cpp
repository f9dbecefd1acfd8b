#include "udim_tiles.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <system_error>

#include "core/errors.h"

namespace nmview {

bool has_udim_token(const std::string& pattern) { return pattern.find(kUdimPatternToken) != std::string::npos; }

std::string udim_tile_path(const std::string& pattern, int number) {
  std::string out = pattern;
  const std::string token = kUdimPatternToken, digits = std::to_string(number);
  for (std::size_t at = out.find(token); at != std::string::npos; at = out.find(token, at + digits.size()))
    out.replace(at, token.size(), digits);
  return out;
}

std::vector<UdimTileFile> find_udim_files(const std::string& pattern) {
  std::vector<UdimTileFile> files;
  if (!has_udim_token(pattern)) return files;
  // A thousand status calls (about a millisecond): the folder may hold other files that look like
  // tiles of another pattern, so listing it would need the same test per name anyway.
  for (int cell = 0; cell < kUdimCells; ++cell) {
    const std::string path = udim_tile_path(pattern, udim_tile_number(cell));
    std::error_code error;
    const std::filesystem::file_status status = std::filesystem::status(path, error);
    if (status.type() != std::filesystem::file_type::not_found) files.push_back({udim_tile_number(cell), path});
  }
  return files;
}

int udim_cell(glm::vec2 a, glm::vec2 b, glm::vec2 c) {
  // In double, as the baker sums the corners (pipeline/udim.cpp centroid_cell), so that a centroid
  // on a tile's edge lands in the same tile; NaN fails every comparison and lands in none.
  const glm::dvec2 centroid = (glm::dvec2(a) + glm::dvec2(b) + glm::dvec2(c)) / 3.0;
  const double u = std::floor(centroid.x), v = std::floor(centroid.y);
  if (!(u >= 0.0 && u < kUdimTileColumns && v >= 0.0 && v < kUdimTileRows)) return -1;
  return int(u) + kUdimTileColumns * int(v);
}

std::vector<std::int32_t> face_udim_cells(const LowVertices& low) {
  std::vector<std::int32_t> cells(low.triangle_count());
  for (std::size_t t = 0; t < cells.size(); ++t)
    cells[t] = udim_cell(low.vertices[low.indices[3 * t]].uv, low.vertices[low.indices[3 * t + 1]].uv,
                         low.vertices[low.indices[3 * t + 2]].uv);
  return cells;
}

void check_tile_sizes(const std::vector<UdimTileImage>& tiles) {
  for (const UdimTileImage& t : tiles) {
    const nmbake::Image& first = tiles.front().image;
    if (t.image.width != first.width || t.image.height != first.height)
      throw nmbake::InputError(t.path + " is " + std::to_string(t.image.width) + "x" + std::to_string(t.image.height) + " but " +
                               tiles.front().path + " is " + std::to_string(first.width) + "x" + std::to_string(first.height) +
                               "; every UDIM tile of a map must have one size (bake them with one --size)");
  }
}

UdimUse count_udim_use(const std::vector<std::int32_t>& face_cells) {
  UdimUse use;
  for (std::int32_t cell : face_cells) {
    if (cell < 0) ++use.outside;
    else ++use.triangles[std::size_t(cell)];
  }
  return use;
}

std::vector<int> missing_udim_tiles(const UdimUse& use, const std::vector<int>& found) {
  std::vector<bool> has(kUdimCells, false);
  for (int number : found)
    if (number >= kUdimFirstTile && number < kUdimFirstTile + kUdimCells) has[std::size_t(number - kUdimFirstTile)] = true;
  std::vector<int> missing;
  for (int cell = 0; cell < kUdimCells; ++cell)
    if (use.triangles[std::size_t(cell)] > 0 && !has[std::size_t(cell)]) missing.push_back(udim_tile_number(cell));
  return missing;
}

std::string describe_missing_tiles(const UdimUse& use, const std::vector<int>& missing) {
  std::string text;
  for (int number : missing) {
    const std::size_t n = use.triangles[std::size_t(number - kUdimFirstTile)];
    text +=
        (text.empty() ? "" : ", ") + std::to_string(number) + " (" + std::to_string(n) + (n == 1 ? " triangle)" : " triangles)");
  }
  return text;
}

std::string tile_number_list(const std::vector<int>& numbers) {
  std::string text;
  for (int number : numbers) text += (text.empty() ? "" : ", ") + std::to_string(number);
  return text;
}

std::string udim_range_label(const std::vector<int>& numbers) {
  if (numbers.empty()) return "";
  const auto [low, high] = std::minmax_element(numbers.begin(), numbers.end());
  if (*low == *high) return "MAP " + std::to_string(*low);
  std::string label = "MAP " + std::to_string(*low) + "-" + std::to_string(*high);
  if (std::size_t(*high - *low + 1) != numbers.size()) label += ", " + std::to_string(numbers.size()) + " TILES";
  return label;
}

}  // namespace nmview
