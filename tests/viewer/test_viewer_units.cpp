// Known answers for the viewer: vertex merging, camera, metrics, font, layout (CPU), and the
// decoding of a constant tilted map on a plane rendered headless (GPU or llvmpipe).
#include <cmath>
#include <set>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "decoding.h"
#include "core/errors.h"
#include "font.h"
#include "gl_context.h"
#include "metrics.h"
#include "renderer.h"
#include "core/tangent_frames.h"
#include "test_support.h"
#include "vertex_data.h"
#include "view.h"

namespace {

using namespace nmview;

TEST(VertexData, LowVerticesKeepEveryCornerExactly) {
  nmbake::Mesh grid = nmbake::test::make_grid(3, 2);
  const nmbake::TangentFrames frames = nmbake::compute_tangent_frames(grid);
  const glm::vec3 centre(0.5f, -0.25f, 0.0f);
  const LowVertices v = build_low_vertices(grid, frames, centre);
  ASSERT_EQ(v.indices.size(), grid.position_index.size());
  // A flat grid has one frame per position: corners merge to the 4 x 3 grid points.
  EXPECT_EQ(v.vertices.size(), 12u);
  for (std::size_t c = 0; c < v.indices.size(); ++c) {
    const LowVertex& x = v.vertices[v.indices[c]];
    EXPECT_EQ(x.position, grid.positions[grid.position_index[c]] - centre) << c;
    EXPECT_EQ(x.normal, frames.normal[c]) << c;
    EXPECT_EQ(x.tangent, frames.tangent[c]) << c;
    EXPECT_EQ(x.uv, grid.uvs[grid.uv_index[c]]) << c;
  }
}

TEST(VertexData, HighVerticesFastPathAndMergedPath) {
  nmbake::Mesh grid = nmbake::test::make_grid(2, 2);  // one shared normal: normal_index != position_index
  const HighVertices merged = build_high_vertices(grid, glm::vec3(0.0f));
  EXPECT_EQ(merged.vertices.size(), 9u);
  grid.normals.assign(grid.positions.size(), glm::vec3(0, 0, 1));
  grid.normal_index = grid.position_index;
  const HighVertices direct = build_high_vertices(grid, glm::vec3(0.0f));
  EXPECT_EQ(direct.vertices.size(), grid.positions.size());
  EXPECT_EQ(direct.indices, grid.position_index);
  for (std::size_t c = 0; c < merged.indices.size(); ++c)
    EXPECT_EQ(merged.vertices[merged.indices[c]].position, direct.vertices[direct.indices[c]].position);
}

TEST(VertexData, BoundsAreTheUnionOfUsedPositions) {
  nmbake::Mesh grid = nmbake::test::make_grid(1, 1, -2, 4, -1, 1);
  grid.positions.push_back({100, 100, 100});  // unused
  const Bounds b = mesh_bounds(grid);
  EXPECT_EQ(b.min, glm::vec3(-2, -1, 0));
  EXPECT_EQ(b.max, glm::vec3(4, 1, 0));
  EXPECT_EQ(b.centre(), glm::vec3(1, 0, 0));
  EXPECT_FLOAT_EQ(b.radius(), 0.5f * std::sqrt(40.0f));
}

TEST(View, CameraLooksAtTheCentreFromTheOrbitDirection) {
  for (float az : {0.0f, 30.0f, -135.0f})
    for (float el : {-90.0f, -20.0f, 0.0f, 45.0f, 90.0f}) {
      const CameraMatrices m = camera_matrices({az, el, 1.0f}, {0.0f, 0.0f}, 2.0f, 1.5f);
      const glm::vec3 dir = direction_from_angles(az, el);
      EXPECT_NEAR(glm::length(glm::normalize(m.eye) - dir), 0.0f, 1e-5f) << az << "," << el;
      // A light at (0, 0) shines from the eye.
      EXPECT_NEAR(glm::length(m.light_dir - dir), 0.0f, 1e-5f) << az << "," << el;
      // The centre projects to the middle of the pane, inside the depth range.
      const glm::vec4 clip = m.projection * m.view * glm::vec4(0, 0, 0, 1);
      EXPECT_NEAR(clip.x / clip.w, 0.0f, 1e-5f);
      EXPECT_NEAR(clip.y / clip.w, 0.0f, 1e-5f);
      EXPECT_LT(std::abs(clip.z / clip.w), 1.0f);
    }
}

TEST(View, BoundingSphereFitsThePane) {
  for (float aspect : {0.5f, 1.0f, 2.0f}) {
    const CameraMatrices m = camera_matrices({10.0f, 20.0f, 1.0f}, {}, 3.0f, aspect);
    // Points on the sphere along the eye's right and up axes stay inside the clip square.
    const glm::mat3 r = glm::transpose(glm::mat3(m.view));
    for (glm::vec3 axis : {r[0], -r[0], r[1], -r[1]}) {
      const glm::vec4 clip = m.projection * m.view * glm::vec4(3.0f * axis, 1.0f);
      EXPECT_LT(std::abs(clip.x / clip.w), 1.0f) << aspect;
      EXPECT_LT(std::abs(clip.y / clip.w), 1.0f) << aspect;
    }
  }
}

TEST(View, LightAzimuthIsRelativeToTheView) {
  // Positive light azimuth comes from the viewer's right.
  const CameraMatrices m = camera_matrices({0.0f, 0.0f, 1.0f}, {90.0f, 0.0f}, 1.0f, 1.0f);
  const glm::vec3 right = glm::transpose(glm::mat3(m.view))[0];
  EXPECT_NEAR(glm::dot(m.light_dir, right), 1.0f, 1e-5f);
}

TEST(View, CompareViewsAreEightAroundPlusTopAndBottom) {
  const std::vector<OrbitView> views = compare_views();
  ASSERT_EQ(views.size(), 10u);
  std::set<int> azimuths;
  for (int i = 0; i < 8; ++i) azimuths.insert(int(views[std::size_t(i)].azimuth));
  EXPECT_EQ(azimuths.size(), 8u);
  EXPECT_EQ(views[8].elevation, 90.0f);
  EXPECT_EQ(views[9].elevation, -90.0f);
}

Rgba8Image solid(int w, int h, std::uint8_t value, std::uint8_t alpha) {
  Rgba8Image im{w, h, std::vector<std::uint8_t>(std::size_t(w) * h * 4, value)};
  for (std::size_t i = 3; i < im.pixels.size(); i += 4) im.pixels[i] = alpha;
  return im;
}

TEST(Metrics, IdenticalImagesHaveZeroError) {
  const Rgba8Image a = solid(4, 3, 100, 255);
  const DifferenceStats s = compare_images(a, a, 0);
  EXPECT_EQ(s.object.pixels, 12u);
  EXPECT_EQ(s.interior.pixels, 12u);
  EXPECT_EQ(s.interior.rmse(), 0.0);
  EXPECT_TRUE(std::isinf(s.interior.psnr()));
  EXPECT_EQ(s.interior.within2(), 1.0);
  EXPECT_EQ(s.silhouette_mismatch(), 0.0);
}

TEST(Metrics, UnionCountsObjectPixelsOnly) {
  Rgba8Image a = solid(2, 2, 0, 0), b = solid(2, 2, 0, 0);
  // Pixel 0 covered by a only (white vs black background), pixel 1 by both with a difference of
  // 2 in one channel, pixels 2 and 3 background in both (differences there are ignored).
  a.pixels[0] = a.pixels[1] = a.pixels[2] = 255, a.pixels[3] = 255;
  a.pixels[4] = 10, a.pixels[7] = 255;
  b.pixels[4] = 12, b.pixels[7] = 255;
  a.pixels[8] = 200;
  const DifferenceStats s = compare_images(a, b, 0);
  EXPECT_EQ(s.object.pixels, 2u);
  EXPECT_EQ(s.object.within2_pixels, 1u);
  const double expected = std::sqrt((3.0 * 255 * 255 + 2.0 * 2) / (255.0 * 255) / 6.0);
  EXPECT_NEAR(s.object.rmse(), expected, 1e-12);
  EXPECT_NEAR(s.object.psnr(), 20.0 * std::log10(1.0 / expected), 1e-9);
  // Without erosion the interior is pixel 1 alone; the mismatch is pixel 0 of the two.
  EXPECT_EQ(s.interior.pixels, 1u);
  EXPECT_NEAR(s.interior.rmse(), std::sqrt(4.0 / (255.0 * 255) / 3.0), 1e-12);
  EXPECT_EQ(s.mismatch_pixels, 1u);
  EXPECT_EQ(s.silhouette_mismatch(), 0.5);
}

TEST(Metrics, InteriorLeavesOutEdgesAndTheirNeighbours) {
  // 7 x 5, both fully covered except a's column 0 (only a half-covered pixel at row 2, an
  // anti-aliased edge) and b's column 6 (not covered). Interior with erosion 1: columns 2..4 of
  // rows 1..3 (9 pixels): column 1 touches a's edge column, column 5 touches b's missing column,
  // rows 0 and 4 touch the image border.
  Rgba8Image a = solid(7, 5, 100, 255), b = solid(7, 5, 100, 255);
  for (int y = 0; y < 5; ++y) {
    a.pixels[4 * std::size_t(y * 7) + 3] = y == 2 ? 128 : 0;
    b.pixels[4 * std::size_t(y * 7 + 6) + 3] = 0;
  }
  b.pixels[4 * std::size_t(2 * 7 + 3)] = 110;  // a difference of 10 inside the interior
  b.pixels[4 * std::size_t(0 * 7 + 3)] = 200;  // and one outside it (row 0)
  const DifferenceStats s = compare_images(a, b, 1);
  EXPECT_EQ(s.interior.pixels, 9u);
  EXPECT_EQ(s.interior.within2_pixels, 8u);
  EXPECT_NEAR(s.interior.rmse(), std::sqrt(100.0 / (255.0 * 255) / 27.0), 1e-12);
  // Union: every pixel is covered by one model at least; a-only column 6 (5 pixels) and b-only
  // column 0 rows 0, 1, 3, 4 (4 pixels) mismatch.
  EXPECT_EQ(s.object.pixels, 35u);
  EXPECT_EQ(s.mismatch_pixels, 9u);
  // Erosion 0 keeps every pixel fully covered by both: columns 1..5, 25 pixels.
  EXPECT_EQ(compare_images(a, b, 0).interior.pixels, 25u);
}

TEST(Metrics, PooledStatsAddUp) {
  DifferenceStats a, b;
  a.interior.pixels = 10, a.interior.within2_pixels = 5, a.interior.sum_squared = 0.3;
  b.interior.pixels = 30, b.interior.within2_pixels = 30, b.interior.sum_squared = 0.0;
  a.object.pixels = 20, a.mismatch_pixels = 4;
  b.object.pixels = 60, b.mismatch_pixels = 0;
  a.add(b);
  EXPECT_EQ(a.interior.within2(), 35.0 / 40.0);
  EXPECT_NEAR(a.interior.rmse(), std::sqrt(0.3 / 120.0), 1e-12);
  EXPECT_EQ(a.silhouette_mismatch(), 4.0 / 80.0);
  EXPECT_EQ(DifferenceStats{}.interior.rmse(), 0.0);
  EXPECT_EQ(DifferenceStats{}.silhouette_mismatch(), 0.0);
}

TEST(Decoding, MetadataThenOverridesThenDefaults) {
  std::string note;
  MapDecoding d = resolve_decoding({}, {}, "m.png", &note);
  EXPECT_FALSE(d.object_space);
  EXPECT_FALSE(d.green_down);
  EXPECT_EQ(d.bitangent, nmbake::BitangentMode::per_pixel);
  EXPECT_EQ(note, "space tangent (default), green up (default), bitangent pixel (default)");

  const std::map<std::string, std::string> baked = {
      {"nmbake:space", "tangent"}, {"nmbake:green", "down"}, {"nmbake:bitangent", "vertex"}};
  d = resolve_decoding(baked, {}, "m.png", &note);
  EXPECT_TRUE(d.green_down);
  EXPECT_EQ(d.bitangent, nmbake::BitangentMode::per_vertex);
  EXPECT_EQ(note, "space tangent (metadata), green down (metadata), bitangent vertex (metadata)");

  DecodingOverrides o;
  o.green = "up";
  d = resolve_decoding(baked, o, "m.png", &note);
  EXPECT_FALSE(d.green_down);
  EXPECT_EQ(d.bitangent, nmbake::BitangentMode::per_vertex);
  EXPECT_EQ(note, "space tangent (metadata), green up (--green), bitangent vertex (metadata)");

  d = resolve_decoding({{"nmbake:space", "object"}, {"nmbake:green", "up"}}, {}, "m.png", &note);
  EXPECT_TRUE(d.object_space);
  EXPECT_EQ(note, "space object (metadata)");
}

TEST(Decoding, UnknownValuesAreErrors) {
  EXPECT_THROW(resolve_decoding({{"nmbake:green", "sideways"}}, {}, "m.png"), nmbake::InputError);
  DecodingOverrides o;
  o.space = "world";
  EXPECT_THROW(resolve_decoding({}, o, "m.png"), nmbake::UsageError);
  o = {};
  o.space = "object";
  o.green = "down";
  EXPECT_THROW(resolve_decoding({}, o, "m.png"), nmbake::UsageError);
}

TEST(Font, EveryPrintedCharacterHasAGlyph) {
  const std::string all = "ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789,.+-:=/()%?";
  for (char c : all) {
    int set = 0;
    for (int y = 0; y < kGlyphHeight; ++y)
      for (int x = 0; x < kGlyphWidth; ++x) set += glyph_pixel(c, x, y);
    EXPECT_GT(set, 0) << c;
  }
  for (int y = 0; y < kGlyphHeight; ++y)
    for (int x = 0; x < kGlyphWidth; ++x) {
      EXPECT_FALSE(glyph_pixel(' ', x, y));
      EXPECT_EQ(glyph_pixel('a', x, y), glyph_pixel('A', x, y));
      EXPECT_EQ(glyph_pixel('~', x, y), glyph_pixel('?', x, y));
    }
}

TEST(Font, TextBecomesSquaresInsideItsBox) {
  std::vector<glm::vec2> tris;
  append_text_triangles("1,0", {10, 20}, 2.0f, tris);
  EXPECT_EQ(tris.size() % 6, 0u);
  EXPECT_FALSE(tris.empty());
  const float width = text_width("1,0", 2.0f);
  EXPECT_EQ(width, (3 * kCellWidth - 1) * 2.0f);
  for (glm::vec2 p : tris) {
    EXPECT_GE(p.x, 10.0f);
    EXPECT_LE(p.x, 10.0f + width);
    EXPECT_GE(p.y, 20.0f);
    EXPECT_LE(p.y, 20.0f + kGlyphHeight * 2.0f);
  }
}

TEST(Layout, PanesHaveEqualWidthsSideBySide) {
  for (bool difference : {false, true}) {
    const std::vector<Rect> panes = pane_layout(1601, 800, difference);
    ASSERT_EQ(panes.size(), difference ? 3u : 2u);
    for (std::size_t i = 0; i < panes.size(); ++i) {
      EXPECT_EQ(panes[i].width, panes[0].width);
      EXPECT_EQ(panes[i].height, 800);
      if (i > 0) {
        EXPECT_EQ(panes[i].x, panes[i - 1].x + panes[i - 1].width);
      }
    }
    EXPECT_LE(panes.back().x + panes.back().width, 1601);
  }
  EXPECT_EQ(with_thousands(98304), "98,304");
  EXPECT_EQ(with_thousands(1234567), "1,234,567");
  EXPECT_EQ(with_thousands(12), "12");
}

// --- rendering known answers --------------------------------------------------------------------

// Lambert of the shaders: albedo 0.8, ambient 0.1, one-sided.
double lit(glm::dvec3 n, glm::dvec3 light) {
  return 0.8 * (0.1 + 0.9 * std::max(0.0, glm::dot(glm::normalize(n), glm::normalize(light))));
}

// The centre pixel of each pane for a 2 x 2 plane at z = 0 facing +Z seen from +Z, its map
// constant = the encoding of `t` (tangent space unless `decoding` says otherwise); `mirror_v` flips
// the UVs' v (handedness -1).
std::pair<double, double> render_plane(glm::dvec3 t, Light light, bool mirror_v, bool use_map = true,
                                       const MapDecoding& decoding = {}) {
  nmbake::Mesh plane = nmbake::test::make_grid(4, 4);
  if (mirror_v)
    for (glm::vec2& uv : plane.uvs) uv.y = 1.0f - uv.y;
  const nmbake::TangentFrames frames = nmbake::compute_tangent_frames(plane);
  nmbake::Image map(8, 8, 3);
  const glm::dvec3 n = glm::normalize(t);
  for (std::size_t i = 0; i < map.pixels.size(); ++i) map.pixels[i] = float(n[int(i % 3)] * 0.5 + 0.5);

  HeadlessContext context;
  Renderer renderer(build_low_vertices(plane, frames, glm::vec3(0.0f)), build_high_vertices(plane, glm::vec3(0.0f)), map,
                    std::sqrt(2.0f), decoding);
  Toggles toggles;
  toggles.map = use_map;
  renderer.render_panes(64, 64, {0.0f, 0.0f, 1.0f}, light, toggles);
  const Rgba8Image low = renderer.read_pane(0), high = renderer.read_pane(1);
  const std::size_t centre = (32 * 64 + 32) * 4;
  EXPECT_EQ(low.pixels[centre + 3], 255);
  EXPECT_EQ(high.pixels[centre + 3], 255);
  return {low.pixels[centre] / 255.0, high.pixels[centre] / 255.0};
}

TEST(RenderKnownAnswer, RedTiltsTowardsTangentAndGreenTowardsBitangent) {
  // Light 60 degrees to the viewer's right (+X): a normal tilted towards +X (red) is bright,
  // towards -X dark. Light 60 degrees above (+Y): the same for green.
  const double tol = 1.5 / 255.0;  // 8-bit quantization plus float rounding
  const glm::dvec3 right(std::sin(glm::radians(60.0)), 0, 0.5), up(0, std::sin(glm::radians(60.0)), 0.5);
  auto [plus_x, flat_a] = render_plane({0.5, 0, 1}, {60.0f, 0.0f}, false);
  EXPECT_NEAR(plus_x, lit({0.5, 0, 1}, right), tol);
  EXPECT_NEAR(flat_a, lit({0, 0, 1}, right), tol);
  EXPECT_NEAR(render_plane({-0.5, 0, 1}, {60.0f, 0.0f}, false).first, lit({-0.5, 0, 1}, right), tol);
  EXPECT_NEAR(render_plane({0, 0.5, 1}, {0.0f, 60.0f}, false).first, lit({0, 0.5, 1}, up), tol);
  EXPECT_NEAR(render_plane({0, -0.5, 1}, {0.0f, 60.0f}, false).first, lit({0, -0.5, 1}, up), tol);
}

TEST(RenderKnownAnswer, MirroredUvsFlipTheBitangent) {
  const double tol = 1.5 / 255.0;
  const glm::dvec3 up(0, std::sin(glm::radians(60.0)), 0.5);
  // With v running down the plane the handedness is -1 and +green points to -Y.
  EXPECT_NEAR(render_plane({0, 0.5, 1}, {0.0f, 60.0f}, true).first, lit({0, -0.5, 1}, up), tol);
  // Red is unaffected by the mirror.
  const glm::dvec3 right(std::sin(glm::radians(60.0)), 0, 0.5);
  EXPECT_NEAR(render_plane({0.5, 0, 1}, {60.0f, 0.0f}, true).first, lit({0.5, 0, 1}, right), tol);
}

TEST(RenderKnownAnswer, GreenDownAndObjectSpaceMaps) {
  const double tol = 1.5 / 255.0;
  const glm::dvec3 up(0, std::sin(glm::radians(60.0)), 0.5);
  MapDecoding green_down;
  green_down.green_down = true;
  // A DirectX map stores -green: (0, -0.5, 1) is the normal tilted towards +bitangent (+Y).
  EXPECT_NEAR(render_plane({0, -0.5, 1}, {0.0f, 60.0f}, false, true, green_down).first, lit({0, 0.5, 1}, up), tol);
  // An object-space map is the normal itself, whatever the tangent frame (here mirrored).
  MapDecoding object;
  object.object_space = true;
  EXPECT_NEAR(render_plane({0, 0.5, 1}, {0.0f, 60.0f}, true, true, object).first, lit({0, 0.5, 1}, up), tol);
  EXPECT_NEAR(render_plane({0, -0.5, 1}, {0.0f, 60.0f}, true, true, object).first, lit({0, -0.5, 1}, up), tol);
}

TEST(RenderKnownAnswer, MapOffShowsTheBareNormal) {
  const glm::dvec3 right(std::sin(glm::radians(60.0)), 0, 0.5);
  auto [low, high] = render_plane({0.5, 0, 1}, {60.0f, 0.0f}, false, false);
  EXPECT_NEAR(low, lit({0, 0, 1}, right), 1.5 / 255.0);
  EXPECT_EQ(low, high);
}

}  // namespace
