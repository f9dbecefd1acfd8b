// A tiny 5x7 bitmap font of our own for pane labels (triangle counts, mode names, key help).
//
// Covers A-Z (lower case is drawn as upper case), 0-9, space and , . + - : = / ( ) [ ] % ?; any other
// character is drawn as '?'. Glyph cells are 6 x 9 font pixels (one column and two rows of gap).
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace nmview {

constexpr int kGlyphWidth = 5, kGlyphHeight = 7, kCellWidth = 6, kCellHeight = 9;

// True when font pixel (x, y) of `c` is set; y = 0 is the top row.
bool glyph_pixel(char c, int x, int y);

// Axis-aligned squares (one per set font pixel) covering `text` drawn with its top-left corner at
// `origin` in window pixels (y down), each font pixel `scale` window pixels wide. Two triangles per
// square, 6 vertices, appended to `out` as (x, y) pairs.
void append_text_triangles(const std::string& text, glm::vec2 origin, float scale, std::vector<glm::vec2>& out);

// Width in window pixels of `text` at `scale`.
float text_width(const std::string& text, float scale);

}  // namespace nmview
