// nmview's --view with a distance and a target (issue 36 item 4), headless as in test_nmview.cpp
// (DISPLAY unset, LIBGL_ALWAYS_SOFTWARE=1): a zoomed --view renders the model larger, a target off
// the centre moves it, and the target is read in the meshes' own coordinates. The scene is a unit
// UV sphere moved to x = 10, shown in the left pane in tangent-space colours with a flat map (blue,
// 128,128,255), so its pixels are told from the grey background by colour alone.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "core/image.h"
#include "io/image_io.h"
#include "scene_maker.h"
#include "test_support.h"
#include "tool_run.h"
#include "view.h"

namespace {

constexpr int kZoomPane = 160;  // screenshots are 2 panes of kZoomPane x kZoomPane
constexpr float kSphereX = 10.0f;

// The unit sphere of scene_maker.h moved by kSphereX along x: the target's object space is not the
// renderer's re-centred one.
std::string write_moved_sphere(const std::string& dir) {
  const std::string unit = dir + "/unit.obj", moved = dir + "/moved.obj";
  nmview::test::write_uv_sphere(unit, 32, 16);
  std::ifstream in(unit);
  std::ofstream out(moved);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("v ", 0) == 0) {
      std::istringstream v(line.substr(2));
      double x = 0, y = 0, z = 0;
      v >> x >> y >> z;
      std::ostringstream shifted;
      shifted.precision(9);
      shifted << "v " << x + double(kSphereX) << " " << y << " " << z;
      line = shifted.str();
    }
    out << line << "\n";
  }
  return moved;
}

// The sphere's pixels in the left pane: how many, and their centroid (column, row from the top).
struct Coverage {
  long pixels = 0;
  double x = 0, y = 0;
};

Coverage zoom_shot(const std::string& dir, const std::string& mesh, const std::string& map, const std::string& view) {
  const std::string shot = dir + "/view_" + std::to_string(std::hash<std::string>{}(view)) + ".png";
  const nmview::test::ToolRun r =
      nmview::test::nmview(dir, nmview::test::quote(mesh) + " " + nmview::test::quote(map) + " " + nmview::test::quote(mesh) +
                                    " --screenshot " + nmview::test::quote(shot) + " --size " + std::to_string(2 * kZoomPane) +
                                    "x" + std::to_string(kZoomPane) + " --show tangent,nolabels --view " + view);
  Coverage c;
  EXPECT_EQ(r.exit_code, 0) << "--view " << view << "\n" << r.err;
  if (r.exit_code != 0) return c;
  const nmbake::Image image = nmbake::read_image(shot);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < kZoomPane; ++x) {
      const float* p = image.at(x, y);
      // The map's blue against the grey background (r = g = b).
      if (p[2] - p[0] < 60.0f / 255.0f) continue;
      ++c.pixels;
      c.x += x + 0.5;
      c.y += y + 0.5;
    }
  if (c.pixels > 0) {
    c.x /= double(c.pixels);
    c.y /= double(c.pixels);
  }
  return c;
}

// Where the viewer's camera puts the re-centred point `p` in the pane (column from the left).
double pane_column(const nmview::OrbitView& view, glm::vec3 p) {
  const nmview::CameraMatrices m = nmview::camera_matrices(view, {}, 1.0f, 1.0f);
  const glm::vec4 clip = m.projection * m.view * glm::vec4(p, 1.0f);
  return (clip.x / clip.w * 0.5 + 0.5) * kZoomPane;
}

}  // namespace

TEST(NmviewView, DistanceAndTargetMoveTheScreenshot) {
  const std::string dir = nmbake::test::scratch_dir();
  const std::string mesh = write_moved_sphere(dir), map = dir + "/flat.png";
  nmview::test::write_flat_map(map, 16, 16);

  // Twice the framing distance: the sphere small in the middle of the pane.
  const Coverage far = zoom_shot(dir, mesh, map, "0,0,2");
  ASSERT_GT(far.pixels, 1000);
  EXPECT_NEAR(far.x, 0.5 * kZoomPane, 1.0);
  EXPECT_NEAR(far.y, 0.5 * kZoomPane, 1.0);

  // The 2-number form, today's view, is the framing distance: half as far, about four times the
  // pixels, the same centre.
  const Coverage framed = zoom_shot(dir, mesh, map, "0,0");
  EXPECT_GT(double(framed.pixels), 3.5 * double(far.pixels));
  EXPECT_LT(double(framed.pixels), 4.5 * double(far.pixels));
  EXPECT_NEAR(framed.x, 0.5 * kZoomPane, 1.0);
  EXPECT_NEAR(framed.y, 0.5 * kZoomPane, 1.0);

  // Half the framing distance: the sphere covers the whole pane.
  const Coverage closer = zoom_shot(dir, mesh, map, "0,0,0.5");
  EXPECT_EQ(closer.pixels, long(kZoomPane) * kZoomPane);

  // The target half a unit right of the sphere's centre, in object space (x = 10.5): the sphere
  // moves left, to where the viewer's camera projects its centre (about 18 pixels); it stays level.
  // Read in the renderer's re-centred space instead, 10.5 would put it out of the pane.
  const Coverage moved = zoom_shot(dir, mesh, map, "0,0,2,10.5,0,0");
  const double expected = pane_column({0.0f, 0.0f, 2.0f, glm::vec3(0.5f, 0.0f, 0.0f)}, glm::vec3(0.0f));
  EXPECT_LT(expected, 0.5 * kZoomPane - 10.0);
  EXPECT_NEAR(moved.x, expected, 1.5);
  EXPECT_NEAR(moved.y, 0.5 * kZoomPane, 1.0);
  EXPECT_NEAR(double(moved.pixels), double(far.pixels), 0.05 * double(far.pixels));
}

TEST(NmviewView, BadViewIsOneUsageLine) {
  const std::string dir = nmbake::test::scratch_dir();
  const std::string mesh = write_moved_sphere(dir), map = dir + "/flat.png";
  nmview::test::write_flat_map(map, 16, 16);
  for (const std::string bad : {"30,20,1,2"}) {
    const nmview::test::ToolRun r =
        nmview::test::nmview(dir, nmview::test::quote(mesh) + " " + nmview::test::quote(map) + " " + nmview::test::quote(mesh) +
                                      " --screenshot " + nmview::test::quote(dir + "/bad.png") + " --view " + bad);
    EXPECT_EQ(r.exit_code, 1) << bad << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("error: --view: ", 0), 0u) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}
