// The window's input handling and the selection's math on the CPU (issue 36, items 2 and 4): the
// keys as controls.h's pure function over the viewer's state (no window), the UV cursor's triangle
// and surface point (uv_cursor.h) on a plane with a known UV -> 3D map, framing a selected point
// (view.h frame_point puts it at the pane's centre), and a Ctrl+click's pick.
#include <cmath>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "controls.h"
#include "core/errors.h"
#include "interactive.h"
#include "uv_cursor.h"
#include "vertex_data.h"
#include "view.h"

namespace {

using nmview::KeyAction;
using nmview::OrbitView;
using nmview::ViewerState;

// The 2 x 2 plane at height z, x, y in [-1, 1], as two triangles; UV = ((x + 1) / 2 + du, (y + 1) / 2).
// A second copy shifted by `second_dx` in x and 1 in u (UDIM tile 1002) when second_dx != 0.
nmview::LowVertices controls_plane(float z, float second_dx = 0.0f) {
  nmview::LowVertices mesh;
  const int copies = second_dx != 0.0f ? 2 : 1;
  for (int copy = 0; copy < copies; ++copy) {
    const std::uint32_t base = std::uint32_t(mesh.vertices.size());
    for (glm::vec2 c : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
      nmview::LowVertex v{};
      v.position = {c.x + float(copy) * second_dx, c.y, z};
      v.normal = {0, 0, 1};
      v.uv = {(c.x + 1.0f) / 2.0f + float(copy), (c.y + 1.0f) / 2.0f};
      mesh.vertices.push_back(v);
    }
    for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) mesh.indices.push_back(base + i);
  }
  return mesh;
}

ViewerState controls_state() {
  ViewerState s;
  s.view = {30.0f, 20.0f, 1.0f, glm::vec3(0.0f)};
  return s;
}

KeyAction press(ViewerState& s, int key, const nmview::KeyContext& c = {}) {
  std::ostringstream log;
  return nmview::apply_key(s, key, c, log);
}

}  // namespace

TEST(UvCursor, PlaneTexelIsItsKnownPoint) {
  const nmview::LowVertices plane = controls_plane(0.5f);
  // UV (u, v) is the point (2u - 1, 2v - 1, 0.5), in the triangle whose side of u = v it is on.
  for (glm::vec2 uv :
       {glm::vec2(0.25f, 0.75f), glm::vec2(0.8f, 0.1f), glm::vec2(0.5f, 0.5f), glm::vec2(0.0f, 0.0f), glm::vec2(1.0f, 1.0f)}) {
    const std::optional<nmview::UvPoint> p = nmview::find_uv_point(plane, uv);
    ASSERT_TRUE(p.has_value()) << uv.x << "," << uv.y;
    EXPECT_NEAR(p->position.x, 2.0f * uv.x - 1.0f, 1e-5f);
    EXPECT_NEAR(p->position.y, 2.0f * uv.y - 1.0f, 1e-5f);
    EXPECT_NEAR(p->position.z, 0.5f, 1e-6f);
    EXPECT_NEAR(p->barycentric.x + p->barycentric.y + p->barycentric.z, 1.0f, 1e-6f);
    EXPECT_EQ(p->tile, 1001);
  }
  EXPECT_EQ(nmview::find_uv_point(plane, {0.25f, 0.75f})->triangle, 1u);  // above the diagonal
  EXPECT_EQ(nmview::find_uv_point(plane, {0.75f, 0.25f})->triangle, 0u);
  EXPECT_EQ(nmview::find_uv_point(plane, {0.75f, 0.25f})->holders, 1u);
  // Outside the layout, or not a number: nothing.
  EXPECT_FALSE(nmview::find_uv_point(plane, {1.01f, 0.5f}));
  EXPECT_FALSE(nmview::find_uv_point(plane, {-0.2f, 0.5f}));
  EXPECT_FALSE(nmview::find_uv_point(plane, {NAN, 0.5f}));
}

TEST(UvCursor, UdimTilesOverlapsAndDegenerateTriangles) {
  // The second copy (x + 3, u + 1): UV (1.25, 0.5) is its point (-0.5 + 3, 0, 0) in tile 1002.
  const nmview::LowVertices two = controls_plane(0.0f, 3.0f);
  const std::optional<nmview::UvPoint> p = nmview::find_uv_point(two, {1.25f, 0.5f});
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->position.x, 2.5f, 1e-5f);
  EXPECT_NEAR(p->position.y, 0.0f, 1e-5f);
  EXPECT_EQ(p->tile, 1002);
  EXPECT_GE(p->triangle, 2u);
  EXPECT_EQ(nmview::describe_uv_point({1.25f, 0.5f}, p), "UV 1.25,0.5: TRIANGLE " + std::to_string(p->triangle) + " (TILE 1002)");
  EXPECT_EQ(nmview::describe_uv_point({1.25f, 1.5f}, std::nullopt), "UV 1.25,1.5: IN NO TRIANGLE");
  // Two islands on one UV square: the first triangle in index order, the overlap counted.
  nmview::LowVertices stacked = controls_plane(0.0f);
  const nmview::LowVertices upper = controls_plane(1.0f);
  for (const nmview::LowVertex& v : upper.vertices) stacked.vertices.push_back(v);
  for (std::uint32_t i : upper.indices) stacked.indices.push_back(i + 4);
  const std::optional<nmview::UvPoint> first = nmview::find_uv_point(stacked, {0.75f, 0.25f});
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->triangle, 0u);
  EXPECT_EQ(first->holders, 2u);
  EXPECT_NEAR(first->position.z, 0.0f, 1e-6f);
  // A triangle with all its UVs on one point holds nothing (no NaN weights).
  nmview::LowVertices collapsed = controls_plane(0.0f);
  for (nmview::LowVertex& v : collapsed.vertices) v.uv = {0.5f, 0.5f};
  EXPECT_FALSE(nmview::find_uv_point(collapsed, {0.5f, 0.5f}));
}

TEST(UvCursor, PanePixelToUvAndTheOption) {
  // A 200 x 100 pane: the UV square is 100 pixels wide from column 50.
  const glm::vec2 uv = nmview::uv_at_pane_pixel(50, 0, 100, {75.0f, 80.0f});
  EXPECT_NEAR(uv.x, 0.25f, 1e-6f);
  EXPECT_NEAR(uv.y, 0.8f, 1e-6f);
  EXPECT_NEAR(nmview::uv_at_pane_pixel(50, 0, 100, {175.0f, 50.0f}).x, 1.25f, 1e-6f);  // the tile to the right
  nmview::PanePoint at;
  at.pane = 0;
  at.width = 200;
  at.height = 100;
  at.pixel = {75.0f, 80.0f};
  ASSERT_TRUE(nmview::uv_under(at, true));
  EXPECT_NEAR(nmview::uv_under(at, true)->x, 0.25f, 1e-6f);
  EXPECT_FALSE(nmview::uv_under(at, false));  // no UV view
  at.pane = 1;
  EXPECT_FALSE(nmview::uv_under(at, true));  // the high-poly's pane

  EXPECT_EQ(nmview::parse_uv_cursor("0.25,0.75"), glm::vec2(0.25f, 0.75f));
  EXPECT_EQ(nmview::parse_uv_cursor("1.5,-0.5"), glm::vec2(1.5f, -0.5f));
  for (const std::string bad : {"", "0.5", "0.5,", "a,b", "0.5,0.5,0.5", "nan,0", "1e300,0"})
    EXPECT_THROW(nmview::parse_uv_cursor(bad), nmbake::UsageError) << bad;
}

TEST(Selection, FramingPutsThePointAtThePaneCentre) {
  const float radius = 2.0f;
  for (const OrbitView& view :
       {OrbitView{30.0f, 20.0f, 1.0f, glm::vec3(0.0f)}, OrbitView{-100.0f, 60.0f, 3.0f, glm::vec3(1, 0, 0)}})
    for (glm::vec3 point : {glm::vec3(-0.5f, 0.5f, 0.0f), glm::vec3(1.5f, -1.0f, 0.7f)}) {
      const OrbitView framed = nmview::frame_point(view, point);
      EXPECT_EQ(framed.azimuth, view.azimuth);
      EXPECT_EQ(framed.elevation, view.elevation);
      EXPECT_EQ(framed.zoom, nmview::kSelectionZoom);
      const std::optional<glm::vec2> ndc = nmview::project_point(framed, radius, 1.5f, point);
      ASSERT_TRUE(ndc.has_value());
      EXPECT_NEAR(ndc->x, 0.0f, 1e-5f);
      EXPECT_NEAR(ndc->y, 0.0f, 1e-5f);
      // The neighbourhood shown: a point a tenth of the radius away across the view is in the
      // pane, one a third of the radius away is not.
      const nmview::CameraFrame f = nmview::camera_frame(framed, radius, 1.5f);
      const std::optional<glm::vec2> near = nmview::project_point(framed, radius, 1.5f, point + 0.1f * radius * f.up);
      const std::optional<glm::vec2> far = nmview::project_point(framed, radius, 1.5f, point + 0.33f * radius * f.up);
      ASSERT_TRUE(near && far);
      EXPECT_LT(std::abs(near->y), 1.0f);
      EXPECT_GT(std::abs(far->y), 1.0f);
    }
  // project_point agrees with the camera matrices, and a point behind the eye projects nowhere.
  const OrbitView view{30.0f, 20.0f, 1.0f, glm::vec3(0.2f, 0.0f, 0.0f)};
  const glm::vec3 p(0.3f, -0.4f, 0.5f);
  const nmview::CameraMatrices m = nmview::camera_matrices(view, {}, radius, 1.5f);
  const glm::vec4 clip = m.projection * m.view * glm::vec4(p, 1.0f);
  const std::optional<glm::vec2> ndc = nmview::project_point(view, radius, 1.5f, p);
  ASSERT_TRUE(ndc.has_value());
  EXPECT_NEAR(ndc->x, clip.x / clip.w, 1e-5f);
  EXPECT_NEAR(ndc->y, clip.y / clip.w, 1e-5f);
  const nmview::CameraFrame f = nmview::camera_frame(view, radius, 1.5f);
  EXPECT_FALSE(nmview::project_point(view, radius, 1.5f, f.eye - f.forward));
}

TEST(Selection, CtrlClickPicksThePanesModel) {
  // Looking down -Z at the low-poly plane at z = 0 (left pane) and the high-poly at z = 0.5.
  const nmview::LowVertices low = controls_plane(0.0f);
  nmview::HighVertices high;
  for (const nmview::LowVertex& v : controls_plane(0.5f).vertices) high.vertices.push_back({v.position, v.normal});
  high.indices = low.indices;
  const OrbitView view{0.0f, 0.0f, 1.0f, glm::vec3(0.0f)};
  const nmview::PanePoint left = nmview::pane_at(800, 400, 800, 400, false, 150.0, 180.0);
  const std::optional<glm::vec3> on_low = nmview::pick_point(view, low, high, std::sqrt(2.0f), left);
  ASSERT_TRUE(on_low.has_value());
  EXPECT_NEAR(on_low->z, 0.0f, 1e-5f);
  const nmview::PanePoint right = nmview::pane_at(800, 400, 800, 400, false, 550.0, 180.0);
  const std::optional<glm::vec3> on_high = nmview::pick_point(view, low, high, std::sqrt(2.0f), right);
  ASSERT_TRUE(on_high.has_value());
  EXPECT_NEAR(on_high->z, 0.5f, 1e-5f);
  // The corner of the pane shows the background: nothing to select.
  EXPECT_FALSE(nmview::pick_point(view, low, high, std::sqrt(2.0f), nmview::pane_at(800, 400, 800, 400, false, 2.0, 2.0)));
}

TEST(Keys, DifferenceAndItsScaleWithinBounds) {
  ViewerState s = controls_state();
  EXPECT_EQ(press(s, 'D'), KeyAction::redraw);
  EXPECT_TRUE(s.toggles.difference);
  press(s, 'D');
  EXPECT_FALSE(s.toggles.difference);
  // ] steps up to the top of the scale and stays there; [ down to the bottom and stays.
  float last = s.toggles.diff_scale;
  for (int i = 0; i < 30; ++i) {
    press(s, ']');
    EXPECT_GE(s.toggles.diff_scale, last);
    last = s.toggles.diff_scale;
  }
  EXPECT_EQ(s.toggles.diff_scale, nmview::kMaxDiffScale);
  for (int i = 0; i < 30; ++i) {
    press(s, '[');
    EXPECT_LE(s.toggles.diff_scale, last);
    last = s.toggles.diff_scale;
  }
  EXPECT_EQ(s.toggles.diff_scale, 1.0f);  // the lowest step: never 0
  std::ostringstream log;
  nmview::apply_key(s, ']', {}, log);
  EXPECT_EQ(log.str().rfind("nmview: difference scale 0..", 0), 0u) << log.str();
}

TEST(Keys, FramesTheSelectionElseBothModels) {
  ViewerState s = controls_state();
  s.view = {30.0f, 20.0f, 0.3f, glm::vec3(0.5f, 0.0f, 0.0f)};
  EXPECT_EQ(press(s, 'F'), KeyAction::redraw);  // no selection: both models
  EXPECT_EQ(s.view.target, glm::vec3(0.0f));
  EXPECT_EQ(s.view.zoom, 1.0f);
  s.selection = glm::vec3(-0.5f, 0.5f, 0.0f);
  press(s, 'F');
  EXPECT_EQ(s.view.target, glm::vec3(-0.5f, 0.5f, 0.0f));
  EXPECT_EQ(s.view.zoom, nmview::kSelectionZoom);
  EXPECT_EQ(s.view.azimuth, 30.0f);
  // Esc clears the selection first, then closes; F frames both models again.
  EXPECT_EQ(press(s, nmview::kKeyEscape), KeyAction::redraw);
  EXPECT_FALSE(s.selection);
  press(s, 'F');
  EXPECT_EQ(s.view.zoom, 1.0f);
  EXPECT_EQ(press(s, nmview::kKeyEscape), KeyAction::quit);
  EXPECT_EQ(press(s, 'Q'), KeyAction::quit);
}

TEST(Keys, UvViewMasksCageAndTheirNotes) {
  ViewerState s = controls_state();
  std::ostringstream log;
  nmview::KeyContext c;
  EXPECT_EQ(nmview::apply_key(s, 'U', c, log), KeyAction::redraw);
  EXPECT_TRUE(s.toggles.uv_layout);
  // The UV cursor's point is marked while the UV view is on, and dropped with it.
  const nmview::LowVertices plane = controls_plane(0.0f);
  nmview::set_uv_cursor(s, glm::vec2(0.25f, 0.75f), plane);
  nmview::Marks m = nmview::marks_of(s);
  ASSERT_TRUE(m.uv.has_value());
  ASSERT_EQ(m.points.size(), 1u);
  EXPECT_NEAR(m.points[0].x, -0.5f, 1e-5f);
  EXPECT_EQ(m.label, "UV 0.25,0.75: TRIANGLE 1 (TILE 1001)");
  nmview::apply_key(s, 'U', c, log);
  EXPECT_FALSE(s.toggles.uv_layout);
  EXPECT_FALSE(s.uv_cursor);
  EXPECT_TRUE(nmview::marks_of(s).points.empty());
  // K and C toggle, with one line each when nothing was loaded; none when it was.
  nmview::apply_key(s, 'K', c, log);
  nmview::apply_key(s, 'C', c, log);
  EXPECT_TRUE(s.toggles.masks && s.toggles.cage);
  EXPECT_NE(log.str().find("K: no mask given"), std::string::npos) << log.str();
  EXPECT_NE(log.str().find("C: no cage given"), std::string::npos) << log.str();
  c.has_masks = c.has_cage = true;
  std::ostringstream quiet;
  nmview::apply_key(s, 'K', c, quiet);
  nmview::apply_key(s, 'C', c, quiet);
  EXPECT_FALSE(s.toggles.masks || s.toggles.cage);
  EXPECT_EQ(quiet.str(), "");
}

TEST(Keys, MCyclesTheSetsMapsThenLit) {
  ViewerState s = controls_state();
  nmview::KeyContext c;
  c.maps = {nmbake::MapKind::normal, nmbake::MapKind::ao, nmbake::MapKind::curvature};
  press(s, 'M', c);
  EXPECT_TRUE(s.toggles.show_map);
  EXPECT_EQ(s.toggles.shown, nmbake::MapKind::normal);
  press(s, 'M', c);
  EXPECT_EQ(s.toggles.shown, nmbake::MapKind::ao);
  press(s, 'M', c);
  EXPECT_EQ(s.toggles.shown, nmbake::MapKind::curvature);
  press(s, 'M', c);
  EXPECT_FALSE(s.toggles.show_map);  // lit again
}

TEST(Keys, ResetLightAndOtherKeys) {
  ViewerState s = controls_state();
  nmview::KeyContext c;
  c.initial_view = {10.0f, 5.0f, 1.0f, glm::vec3(0.0f)};
  s.light.elevation = 85.0f;
  press(s, nmview::kKeyUp, c);
  press(s, nmview::kKeyUp, c);
  EXPECT_EQ(s.light.elevation, 89.0f);  // kept below the pole
  press(s, nmview::kKeyLeft, c);
  EXPECT_EQ(s.light.azimuth, -35.0f);
  EXPECT_EQ(press(s, 'R', c), KeyAction::redraw);
  EXPECT_EQ(s.view.azimuth, 10.0f);
  EXPECT_EQ(s.light.elevation, c.initial_light.elevation);
  EXPECT_EQ(press(s, 'V', c), KeyAction::print_view);
  EXPECT_EQ(press(s, 'P', c), KeyAction::screenshot);
  EXPECT_EQ(press(s, 'Z', c), KeyAction::ignored);
  press(s, 'N', c);
  EXPECT_FALSE(s.toggles.map);
  press(s, 'W', c);
  EXPECT_TRUE(s.toggles.wireframe);
  press(s, 'S', c);
  EXPECT_GT(s.toggles.specular, 0.0f);
}
