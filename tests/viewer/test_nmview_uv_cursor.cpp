// The UV cursor marked on the model and the selection framed (issue 36, items 2 and 4), headless
// as in test_nmview.cpp (DISPLAY unset, LIBGL_ALWAYS_SOFTWARE=1). The low-poly is two 2 x 2 planes
// at z = 0 facing +Z: A at x in [-1, 1] with UV ((x + 1) / 2, (y + 1) / 2) (UDIM tile 1001), B at
// x in [2, 4] with the same UVs plus 1 in u (tile 1002); the high-poly is the same file. Seen from
// the front (--view 0,0), the texel at UV (u, v) is the point with a known projection, so the
// cyan cross must be at the pixel the test computes (view.h project_point), in the UV view at the
// UV's pixel, and nowhere without a cursor or for a UV in no triangle.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/image.h"
#include "io/image_io.h"
#include "overlays.h"
#include "renderer.h"
#include "scene_maker.h"
#include "test_support.h"
#include "tool_run.h"
#include "view.h"

namespace {

using nmview::test::quote;

constexpr int kCursorPane = 128;  // screenshots are 2 panes of kCursorPane x kCursorPane

struct CursorScene {
  std::string dir, mesh, map;
  std::vector<glm::vec3> vertices;  // object space, for the scene's centre and radius
};

const CursorScene& cursor_scene() {
  static const CursorScene scene = [] {
    CursorScene s;
    s.dir = nmbake::test::scratch_dir();
    s.mesh = s.dir + "/planes.obj";
    s.map = s.dir + "/flat.png";
    s.vertices = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {2, -1, 0}, {4, -1, 0}, {4, 1, 0}, {2, 1, 0}};
    nmbake::test::write_file(s.mesh,
                             "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nv 2 -1 0\nv 4 -1 0\nv 4 1 0\nv 2 1 0\n"
                             "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 1 0\nvt 2 0\nvt 2 1\nvt 1 1\nvn 0 0 1\n"
                             "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\nf 5/5/1 6/6/1 7/7/1\nf 5/5/1 7/7/1 8/8/1\n");
    nmview::test::write_flat_map(s.map, 16, 16);
    return s;
  }();
  return scene;
}

// The scene's centre (of the bounding box) and radius (farthest vertex from it), as load_scene has them.
glm::vec3 cursor_centre() { return {1.5f, 0.0f, 0.0f}; }
float cursor_radius() {
  float r = 0.0f;
  for (const glm::vec3& v : cursor_scene().vertices) r = std::max(r, glm::length(v - cursor_centre()));
  return r;
}

// The pixel (column, row from the top) of pane `pane` where object-space point `p` projects.
std::pair<int, int> cursor_pixel(const nmview::OrbitView& view, glm::vec3 p, int pane) {
  const std::optional<glm::vec2> ndc = nmview::project_point(view, cursor_radius(), 1.0f, p - cursor_centre());
  EXPECT_TRUE(ndc.has_value());
  if (!ndc) return {0, 0};
  return {pane * kCursorPane + int(std::floor((ndc->x * 0.5f + 0.5f) * kCursorPane)),
          int(std::floor((0.5f - ndc->y * 0.5f) * kCursorPane))};
}

struct CursorShot {
  int exit_code = -1;
  std::string err;
  nmbake::Image image;
  bool cyan(int x, int y) const {
    const float* p = image.at(x, y);
    return p[0] < 0.25f && p[1] > 0.8f && p[2] > 0.8f;
  }
  int cyan_count(int pane) const {
    int n = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = pane * kCursorPane; x < (pane + 1) * kCursorPane; ++x) n += cyan(x, y) ? 1 : 0;
    return n;
  }
};

CursorShot cursor_render(const std::string& name, const std::string& options, const std::string& view = "0,0") {
  const CursorScene& s = cursor_scene();
  const std::string shot = s.dir + "/" + name + ".png";
  const nmview::test::ToolRun r =
      nmview::test::nmview(s.dir, quote(s.mesh) + " " + quote(s.map) + " " + quote(s.mesh) + " --screenshot " + quote(shot) +
                                      " --size " + std::to_string(2 * kCursorPane) + "x" + std::to_string(kCursorPane) +
                                      " --view " + view + " --light 0,0 " + options);
  CursorShot out;
  out.exit_code = r.exit_code;
  out.err = r.err;
  if (r.exit_code == 0) out.image = nmbake::read_image(shot);
  return out;
}

// The cross's centre and a point on each arm, 4 pixels out.
void expect_cross_at(const CursorShot& shot, std::pair<int, int> at, const std::string& what) {
  const auto [x, y] = at;
  EXPECT_TRUE(shot.cyan(x, y)) << what << " at " << x << "," << y;
  EXPECT_TRUE(shot.cyan(x - 4, y) && shot.cyan(x + 4, y)) << what;
  EXPECT_TRUE(shot.cyan(x, y - 4) && shot.cyan(x, y + 4)) << what;
}

}  // namespace

TEST(NmviewUvCursor, TexelMarkedOnTheModelAndInTheUvView) {
  const CursorShot plain = cursor_render("plain", "--show nolabels,uv");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(plain.cyan_count(0) + plain.cyan_count(1), 0);  // no cursor, no mark

  const CursorShot shot = cursor_render("cursor", "--show nolabels,uv --uv-cursor 0.25,0.75");
  ASSERT_EQ(shot.exit_code, 0) << shot.err;
  EXPECT_TRUE(nmbake::test::contains(shot.err, "--uv-cursor 0.25,0.75: triangle 1 (tile 1001) of the low-poly, at -0.5,0.5,0"))
      << shot.err;
  // UV (0.25, 0.75) is plane A's point (-0.5, 0.5, 0), marked on the model in the right pane.
  const nmview::OrbitView front{0.0f, 0.0f, 1.0f, glm::vec3(0.0f)};
  expect_cross_at(shot, cursor_pixel(front, {-0.5f, 0.5f, 0.0f}, 1), "the texel's point");
  // The UV view's cursor at the UV's pixel (the UV square fills the square pane, v up).
  const nmview::UvSquare square = nmview::uv_square(kCursorPane, kCursorPane);
  expect_cross_at(shot, {square.x + int(0.25 * square.side), kCursorPane - 1 - (square.y + int(0.75 * square.side))},
                  "the UV cursor");
  // One cross per pane, nothing else cyan: the crosses' areas (2 x 13 + 2 x 11 pixels at most).
  EXPECT_LE(shot.cyan_count(1), 60);
  EXPECT_GE(shot.cyan_count(1), 30);
}

TEST(NmviewUvCursor, UdimTileAndNoTriangle) {
  // UV (1.25, 0.75) is in tile 1002: plane B's point (2.5, 0.5, 0).
  const CursorShot shot = cursor_render("udim", "--show nolabels,uv --uv-cursor 1.25,0.75");
  ASSERT_EQ(shot.exit_code, 0) << shot.err;
  EXPECT_TRUE(nmbake::test::contains(shot.err, "triangle 3 (tile 1002) of the low-poly, at 2.5,0.5,0")) << shot.err;
  const nmview::OrbitView front{0.0f, 0.0f, 1.0f, glm::vec3(0.0f)};
  expect_cross_at(shot, cursor_pixel(front, {2.5f, 0.5f, 0.0f}, 1), "the tile 1002 texel's point");

  // Between the tiles' islands nothing holds the UV: no mark on the model, one line saying so.
  const CursorShot none = cursor_render("none", "--show nolabels,uv --uv-cursor 0.5,1.5");
  ASSERT_EQ(none.exit_code, 0) << none.err;
  EXPECT_TRUE(nmbake::test::contains(none.err, "--uv-cursor 0.5,1.5: in no triangle of the low-poly's UV layout: no marker"))
      << none.err;
  EXPECT_EQ(none.cyan_count(1), 0);
}

TEST(NmviewUvCursor, FrameSelectionCentresTheTexelsPoint) {
  // Without the UV view the point is marked in both model panes; framed, at both panes' centres.
  const nmview::OrbitView view{20.0f, 10.0f, 1.0f, glm::vec3(0.0f)};
  const CursorShot marked = cursor_render("marked", "--show nolabels --uv-cursor 0.25,0.75", "20,10");
  ASSERT_EQ(marked.exit_code, 0) << marked.err;
  for (int pane : {0, 1}) expect_cross_at(marked, cursor_pixel(view, {-0.5f, 0.5f, 0.0f}, pane), "unframed");
  const std::pair<int, int> unframed = cursor_pixel(view, {-0.5f, 0.5f, 0.0f}, 1);
  ASSERT_GT(std::abs(unframed.first - (kCursorPane + kCursorPane / 2)), 8);  // not already at the centre

  const CursorShot framed = cursor_render("framed", "--show nolabels --uv-cursor 0.25,0.75 --frame-selection", "20,10");
  ASSERT_EQ(framed.exit_code, 0) << framed.err;
  for (int pane : {0, 1}) {
    expect_cross_at(framed, {pane * kCursorPane + kCursorPane / 2, kCursorPane / 2}, "framed");
    EXPECT_LE(framed.cyan_count(pane), 60);  // one cross
  }
  // A tenth of the scene's radius around the point fills the pane: the plane covers every corner
  // (lit grey, not the background's gradient at the corners of the unframed shot).
  const float* corner = framed.image.at(kCursorPane + 2, 2);
  const float* centre_lit = framed.image.at(kCursorPane + kCursorPane / 2 + 12, kCursorPane / 2 + 12);
  EXPECT_NEAR(corner[0], centre_lit[0], 0.02f);
}

TEST(NmviewUvCursor, OptionErrorsAreOneUsageLine) {
  struct Case {
    std::string options, error;
  };
  for (const Case& c :
       {Case{"--uv-cursor 0.5", "error: --uv-cursor: expected U,V"}, Case{"--uv-cursor a,b", "error: --uv-cursor: expected U,V"},
        Case{"--frame-selection", "error: --frame-selection: nothing selected"},
        Case{"--uv-cursor 0.5,0.5 --compare", "error: --uv-cursor: --compare keeps its fixed views"}}) {
    const CursorShot r = cursor_render("bad", c.options);
    EXPECT_EQ(r.exit_code, 1) << c.options << "\n" << r.err;
    EXPECT_TRUE(nmbake::test::contains(r.err, c.error)) << r.err;
  }
}
