// The viewer's navigation math (view.h, issue 36 item 4), on the CPU: zooming towards a point keeps
// it under the cursor, panning moves the target in the view plane, framing fits the bounds, the
// cursor's ray and its pick against triangles, and --view's 2-, 3- and 6-number forms.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "interactive.h"
#include "vertex_data.h"
#include "view.h"

namespace {

using nmview::CameraMatrices;
using nmview::OrbitView;

// Normalized device coordinates of scene point `p` (x, y) and its depth (z), seen by `view`.
glm::vec3 nav_project(const OrbitView& view, float radius, float aspect, glm::vec3 p) {
  const CameraMatrices m = nmview::camera_matrices(view, {}, radius, aspect);
  const glm::vec4 clip = m.projection * m.view * glm::vec4(p, 1.0f);
  return glm::vec3(clip) / clip.w;
}

// A few views with the target at and away from the scene centre.
std::vector<OrbitView> nav_views() {
  return {{30.0f, 20.0f, 1.0f, glm::vec3(0.0f)},
          {-120.0f, 65.0f, 0.4f, glm::vec3(0.3f, -0.2f, 0.5f)},
          {200.0f, -35.0f, 2.5f, glm::vec3(-1.0f, 0.5f, 0.0f)}};
}

std::string nav_usage_error(const std::string& text) {
  try {
    nmview::parse_view_option(text);
  } catch (const nmbake::UsageError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ViewNavigation, ZoomTowardsAPointKeepsItUnderTheCursor) {
  const float radius = 2.0f;
  for (float aspect : {0.5f, 1.0f, 2.0f})
    for (const OrbitView& view : nav_views())
      for (glm::vec3 point : {glm::vec3(0.7f, 0.4f, -0.3f), glm::vec3(-1.2f, 0.1f, 0.9f)})
        for (float factor : {0.5f, 0.9f, 1.25f, 0.1f}) {
          const OrbitView zoomed = nmview::zoom_towards(view, point, factor);
          const glm::vec3 before = nav_project(view, radius, aspect, point), after = nav_project(zoomed, radius, aspect, point);
          EXPECT_NEAR(after.x, before.x, 1e-4f) << aspect << " " << factor;
          EXPECT_NEAR(after.y, before.y, 1e-4f) << aspect << " " << factor;
          EXPECT_LT(std::abs(after.z), 1.0f) << "the point left the depth range";
          // The eye moved towards the point by the factor; the angles are kept.
          const glm::vec3 eye0 = nmview::camera_frame(view, radius, aspect).eye,
                          eye1 = nmview::camera_frame(zoomed, radius, aspect).eye;
          EXPECT_NEAR(glm::length(eye1 - point), factor * glm::length(eye0 - point), 1e-4f * glm::length(eye0 - point));
          EXPECT_NEAR(zoomed.zoom, view.zoom * factor, 1e-6f);
          EXPECT_EQ(zoomed.azimuth, view.azimuth);
          EXPECT_EQ(zoomed.elevation, view.elevation);
        }
}

TEST(ViewNavigation, ZoomStopsAtItsLimitsAndStillKeepsThePoint) {
  const glm::vec3 point(0.5f, 0.25f, 0.0f);
  OrbitView view{10.0f, 10.0f, 0.002f, glm::vec3(0.4f, 0.2f, 0.1f)};
  const OrbitView closer = nmview::zoom_towards(view, point, 0.1f);
  EXPECT_FLOAT_EQ(closer.zoom, nmview::kMinZoom);
  const glm::vec3 before = nav_project(view, 1.0f, 1.0f, point), after = nav_project(closer, 1.0f, 1.0f, point);
  EXPECT_NEAR(after.x, before.x, 1e-3f);
  EXPECT_NEAR(after.y, before.y, 1e-3f);
  EXPECT_FLOAT_EQ(nmview::zoom_towards({0, 0, 900.0f}, point, 10.0f).zoom, nmview::kMaxZoom);
  // A factor of 0 or less (or NaN) changes nothing.
  for (float bad : {0.0f, -1.0f, NAN}) EXPECT_EQ(nmview::zoom_towards(view, point, bad).target, view.target);
}

TEST(ViewNavigation, CursorRayPassesThroughTheCursor) {
  for (float aspect : {0.5f, 2.0f})
    for (const OrbitView& view : nav_views())
      for (glm::vec2 ndc : {glm::vec2(0.0f), glm::vec2(0.3f, -0.7f), glm::vec2(-0.95f, 0.95f)}) {
        const nmview::Ray ray = nmview::cursor_ray(view, 1.5f, aspect, ndc);
        EXPECT_NEAR(glm::length(ray.direction), 1.0f, 1e-5f);
        for (float t : {0.5f, 3.0f, 8.0f}) {
          const glm::vec3 p = nav_project(view, 1.5f, aspect, ray.origin + t * ray.direction);
          EXPECT_NEAR(p.x, ndc.x, 1e-4f);
          EXPECT_NEAR(p.y, ndc.y, 1e-4f);
        }
        // Its point at the target's depth is as far along the view axis as the target.
        const nmview::CameraFrame f = nmview::camera_frame(view, 1.5f, aspect);
        const glm::vec3 q = nmview::point_at_target_depth(view, 1.5f, aspect, ray);
        EXPECT_NEAR(glm::dot(q - f.eye, f.forward), f.distance, 1e-4f * f.distance);
      }
}

TEST(ViewNavigation, PanMovesTheTargetInTheViewPlane) {
  const float radius = 3.0f;
  for (float aspect : {0.5f, 1.0f, 2.0f})
    for (const OrbitView& view : nav_views()) {
      const glm::vec2 delta(0.2f, -0.35f), cursor(-0.4f, 0.3f);
      const OrbitView panned = nmview::pan_view(view, radius, aspect, delta);
      const nmview::CameraFrame f0 = nmview::camera_frame(view, radius, aspect),
                                f1 = nmview::camera_frame(panned, radius, aspect);
      // The target moved across the view, not along it; distance and angles are kept.
      EXPECT_GT(glm::length(panned.target - view.target), 1e-3f);
      EXPECT_NEAR(glm::dot(panned.target - view.target, f0.forward), 0.0f, 1e-5f);
      EXPECT_NEAR(f1.distance, f0.distance, 1e-5f * f0.distance);
      EXPECT_NEAR(glm::length(f1.forward - f0.forward), 0.0f, 1e-6f);
      // What was under the cursor at the target's depth is under the moved cursor.
      const glm::vec3 grabbed =
          nmview::point_at_target_depth(view, radius, aspect, nmview::cursor_ray(view, radius, aspect, cursor));
      const glm::vec3 p = nav_project(panned, radius, aspect, grabbed);
      EXPECT_NEAR(p.x, cursor.x + delta.x, 1e-4f) << aspect;
      EXPECT_NEAR(p.y, cursor.y + delta.y, 1e-4f) << aspect;
    }
}

TEST(ViewNavigation, FrameFitsTheBounds) {
  const float radius = 2.0f;
  for (float aspect : {0.5f, 1.0f, 2.0f})
    for (const OrbitView& view : nav_views()) {
      // Zoomed and panned, then framed: the target is the scene centre again, at zoom 1.
      const OrbitView moved =
          nmview::pan_view(nmview::zoom_towards(view, glm::vec3(1, 1, 0), 0.2f), radius, aspect, {0.5f, 0.5f});
      const OrbitView framed = nmview::frame_view(moved);
      EXPECT_EQ(framed.target, glm::vec3(0.0f));
      EXPECT_EQ(framed.zoom, 1.0f);
      EXPECT_EQ(framed.azimuth, view.azimuth);
      // The corners of the box inscribed in the bounding sphere are all in the pane, and fill it
      // (the sphere fits the narrower side with a 5 % margin).
      float widest = 0.0f;
      const float h = radius / std::sqrt(3.0f);
      for (int c = 0; c < 8; ++c) {
        const glm::vec3 corner((c & 1) ? h : -h, (c & 2) ? h : -h, (c & 4) ? h : -h);
        const glm::vec3 p = nav_project(framed, radius, aspect, corner);
        EXPECT_LT(std::abs(p.x), 1.0f);
        EXPECT_LT(std::abs(p.y), 1.0f);
        EXPECT_LT(std::abs(p.z), 1.0f);
        widest = std::max(widest, std::max(std::abs(p.x), std::abs(p.y)));
      }
      EXPECT_GT(widest, 0.5f);
    }
}

TEST(ViewNavigation, AnOffCentreTargetIsThePaneCentreAndTheSceneStaysInDepth) {
  const OrbitView view{45.0f, 10.0f, 0.3f, glm::vec3(0.8f, 0.0f, 0.0f)};
  const glm::vec3 target = nav_project(view, 1.0f, 1.0f, view.target);
  EXPECT_NEAR(target.x, 0.0f, 1e-5f);
  EXPECT_NEAR(target.y, 0.0f, 1e-5f);
  EXPECT_LT(std::abs(target.z), 1.0f);
  // The sphere's far side is within the far plane; with the target moved right the centre is left.
  EXPECT_LT(nav_project(view, 1.0f, 1.0f, -nmview::camera_frame(view, 1.0f, 1.0f).forward * -1.0f).z, 1.0f);
  EXPECT_LT(nav_project({0.0f, 0.0f, 1.0f, glm::vec3(0.5f, 0.0f, 0.0f)}, 1.0f, 1.0f, glm::vec3(0.0f)).x, -0.1f);
}

TEST(ViewNavigation, NearAndFarHugTheBoundingSphere) {
  // At the centre or away from it, zoomed in or out: the depth range is the sphere's (with the 5 %
  // margin) wherever the sphere is in front of the camera.
  const float radius = 2.0f;
  for (const OrbitView& view : nav_views()) {
    const nmview::CameraFrame f = nmview::camera_frame(view, radius, 1.0f);
    const float centre_depth = glm::dot(-f.eye, f.forward);
    if (centre_depth - 1.05f * radius <= 0.0f) continue;
    const glm::vec3 nearest = f.eye + f.forward * (centre_depth - 1.05f * radius);
    const glm::vec3 farthest = f.eye + f.forward * (centre_depth + 1.05f * radius);
    EXPECT_NEAR(nav_project(view, radius, 1.0f, nearest).z, -1.0f, 1e-4f);
    EXPECT_NEAR(nav_project(view, radius, 1.0f, farthest).z, 1.0f, 1e-4f);
  }
  // Inside the sphere, the target is still in the depth range.
  const OrbitView inside{0.0f, 0.0f, 0.01f, glm::vec3(0.5f, 0.5f, 0.5f)};
  EXPECT_LT(std::abs(nav_project(inside, radius, 1.0f, inside.target).z), 1.0f);
}

TEST(ViewNavigation, NearestHitIsTheFirstTriangleAlongTheRay) {
  nmview::HighVertices mesh;
  // Two unit squares facing +Z, at z = 0 and z = -1, and a degenerate triangle at z = 1.
  for (float z : {0.0f, -1.0f})
    for (glm::vec2 xy : {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1), glm::vec2(0, 1)})
      mesh.vertices.push_back({glm::vec3(xy, z), glm::vec3(0, 0, 1)});
  mesh.vertices.push_back({glm::vec3(0, 0, 1), glm::vec3(0, 0, 1)});
  mesh.vertices.push_back({glm::vec3(1, 1, 1), glm::vec3(0, 0, 1)});
  mesh.indices = {4, 5, 6, 4, 6, 7, 0, 1, 2, 0, 2, 3, 8, 9, 9};
  const nmview::Ray down{glm::vec3(0.3f, 0.6f, 5.0f), glm::vec3(0, 0, -1)};
  ASSERT_TRUE(nmview::nearest_hit(down, mesh).has_value());
  EXPECT_NEAR(*nmview::nearest_hit(down, mesh), 5.0f, 1e-5f);
  // From between the squares the back one is hit from behind (either side counts).
  const nmview::Ray between{glm::vec3(0.3f, 0.6f, -0.5f), glm::vec3(0, 0, -1)};
  EXPECT_NEAR(nmview::nearest_hit(between, mesh).value_or(-1.0f), 0.5f, 1e-5f);
  // Beside the squares, pointing away, or along their plane: no hit.
  EXPECT_FALSE(nmview::nearest_hit({glm::vec3(1.5f, 0.5f, 5.0f), glm::vec3(0, 0, -1)}, mesh));
  EXPECT_FALSE(nmview::nearest_hit({glm::vec3(0.3f, 0.6f, 5.0f), glm::vec3(0, 0, 1)}, mesh));
  EXPECT_FALSE(nmview::intersect_triangle({glm::vec3(-1, 0.5f, 0), glm::vec3(1, 0, 0)}, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}));
  EXPECT_FALSE(nmview::intersect_triangle(down, {0, 0, 1}, {1, 1, 1}, {1, 1, 1}));
}

TEST(ViewOption, TwoNumbersAreTheAnglesAsBefore) {
  const nmview::ViewOption o = nmview::parse_view_option("30,20");
  EXPECT_EQ(o.view.azimuth, 30.0f);
  EXPECT_EQ(o.view.elevation, 20.0f);
  EXPECT_EQ(o.view.zoom, 1.0f);
  EXPECT_FALSE(o.target.has_value());
  EXPECT_EQ(nmview::resolve_view(o, glm::vec3(5, 6, 7)).target, glm::vec3(0.0f));
  const nmview::ViewOption spaced = nmview::parse_view_option("-45.5, 90");
  EXPECT_EQ(spaced.view.azimuth, -45.5f);
  EXPECT_EQ(spaced.view.elevation, 90.0f);
}

TEST(ViewOption, ThreeNumbersAddTheDistanceFactor) {
  const nmview::ViewOption o = nmview::parse_view_option("0,10,0.25");
  EXPECT_EQ(o.view.zoom, 0.25f);
  EXPECT_FALSE(o.target.has_value());
  EXPECT_EQ(nmview::parse_view_option("0,10,1000").view.zoom, 1000.0f);
  EXPECT_EQ(nmview::parse_view_option("0,10,0.001").view.zoom, 0.001f);
}

TEST(ViewOption, SixNumbersAddTheTargetInObjectSpace) {
  const nmview::ViewOption o = nmview::parse_view_option("30,20,0.5,10.5,-2,3");
  ASSERT_TRUE(o.target.has_value());
  EXPECT_EQ(*o.target, glm::vec3(10.5f, -2.0f, 3.0f));
  const OrbitView v = nmview::resolve_view(o, glm::vec3(10.0f, 0.0f, 1.0f));
  EXPECT_EQ(v.target, glm::vec3(0.5f, -2.0f, 2.0f));
  EXPECT_EQ(v.zoom, 0.5f);
  // The V key's text reads back as the same view.
  const OrbitView back = nmview::resolve_view(
      nmview::parse_view_option(nmview::format_view_option(v, glm::vec3(10.0f, 0.0f, 1.0f))), glm::vec3(10.0f, 0.0f, 1.0f));
  EXPECT_EQ(back.azimuth, v.azimuth);
  EXPECT_EQ(back.elevation, v.elevation);
  EXPECT_EQ(back.zoom, v.zoom);
  EXPECT_NEAR(glm::length(back.target - v.target), 0.0f, 1e-5f);
}

TEST(ViewOption, OtherFormsAreClearErrors) {
  for (const std::string bad : {"30", "30,20,1,2", "30,20,1,2,3", "1,2,3,4,5,6,7", ""}) {
    const std::string message = nav_usage_error(bad);
    EXPECT_NE(message.find("--view: expected AZ,EL[,DIST[,TX,TY,TZ]]: 2, 3 or 6 numbers"), std::string::npos)
        << bad << ": " << message;
  }
  EXPECT_NE(nav_usage_error("30,20,1,2").find("(4 numbers)"), std::string::npos);
  for (const std::string bad : {"30,x", "30,,20", "30,20,", "30,20,nan", "30,inf", "0x10,5", "30;20", "1e40,0"}) {
    const std::string message = nav_usage_error(bad);
    EXPECT_NE(message.find("is not a finite number"), std::string::npos) << bad << ": " << message;
  }
  for (const std::string bad : {"30,20,0", "30,20,-1", "30,20,1e-4", "30,20,2000", "30,20,0,1,2,3"}) {
    const std::string message = nav_usage_error(bad);
    EXPECT_NE(message.find("--view: DIST"), std::string::npos) << bad << ": " << message;
    EXPECT_NE(message.find("0.001..1000"), std::string::npos) << bad << ": " << message;
  }
}

namespace {

// A 2 x 2 square facing +Z at height z, as a mesh of either kind (only positions matter here).
template <class V>
nmview::IndexedVertices<V> nav_square(float z) {
  nmview::IndexedVertices<V> mesh;
  for (glm::vec2 xy : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
    V v{};
    v.position = glm::vec3(xy, z);
    mesh.vertices.push_back(v);
  }
  mesh.indices = {0, 1, 2, 0, 2, 3};
  return mesh;
}

}  // namespace

TEST(WindowNavigation, CursorFallsInItsPaneOnAHighDpiScreen) {
  // A window of 800 x 400 units drawn into 1600 x 800 pixels: two panes of 800 x 800 pixels.
  const nmview::PanePoint left = nmview::pane_at(800, 400, 1600, 800, false, 100.0, 150.0);
  EXPECT_EQ(left.pane, 0);
  EXPECT_NEAR(left.ndc.x, -0.5f, 1e-6f);  // pixel 200 of 800
  EXPECT_NEAR(left.ndc.y, 0.25f, 1e-6f);  // pixel row 500 of 800 from the bottom
  EXPECT_FLOAT_EQ(left.aspect, 1.0f);
  EXPECT_NEAR(left.ndc_per_unit.x, 2.0f * 2.0f / 800.0f, 1e-7f);
  EXPECT_EQ(nmview::pane_at(800, 400, 1600, 800, false, 500.0, 150.0).pane, 1);
  // With the difference pane: three panes of 533 pixels and one leftover column on each side.
  EXPECT_EQ(nmview::pane_at(1601, 800, 1601, 800, true, 0.0, 10.0).pane, -1);
  EXPECT_EQ(nmview::pane_at(1601, 800, 1601, 800, true, 1.0, 10.0).pane, 0);
  EXPECT_EQ(nmview::pane_at(1601, 800, 1601, 800, true, 1200.0, 10.0).pane, 2);
  EXPECT_EQ(nmview::pane_at(0, 0, 0, 0, false, 1.0, 1.0).pane, -1);  // minimized
}

TEST(WindowNavigation, WheelZoomsTowardsTheModelUnderTheCursor) {
  // Looking down -Z at the low-poly square at z = 0 and the high-poly one at z = 0.5.
  const nmview::LowVertices low = nav_square<nmview::LowVertex>(0.0f);
  const nmview::HighVertices high = nav_square<nmview::HighVertex>(0.5f);
  const float radius = std::sqrt(2.0f);
  const OrbitView view{0.0f, 0.0f, 1.0f, glm::vec3(0.0f)};
  struct Case {
    bool difference;
    double x;
    float z;  // the pivot's height: the pane's model, the nearer in the difference pane
  };
  for (const Case& c : {Case{false, 150.0, 0.0f}, Case{false, 550.0, 0.5f}, Case{true, 650.0, 0.5f}}) {
    const nmview::PanePoint at = nmview::pane_at(800, 400, 800, 400, c.difference, c.x, 180.0);
    const glm::vec3 pivot = nmview::zoom_pivot(view, low, high, radius, at);
    EXPECT_NEAR(pivot.z, c.z, 1e-5f) << c.x;
    const glm::vec3 before = nav_project(view, radius, at.aspect, pivot);
    EXPECT_NEAR(before.x, at.ndc.x, 1e-4f);
    EXPECT_NEAR(before.y, at.ndc.y, 1e-4f);
    // Three wheel steps in: the point under the cursor stays under it.
    const OrbitView zoomed = nmview::zoom_towards(view, pivot, std::pow(0.9f, 3.0f));
    const glm::vec3 after = nav_project(zoomed, radius, at.aspect, pivot);
    EXPECT_NEAR(after.x, at.ndc.x, 1e-4f);
    EXPECT_NEAR(after.y, at.ndc.y, 1e-4f);
  }
  // Over the background: the cursor's point at the target's depth (z = 0 here, the target's plane).
  const nmview::PanePoint corner = nmview::pane_at(800, 400, 800, 400, false, 2.0, 2.0);
  const glm::vec3 beside = nmview::zoom_pivot(view, low, high, radius, corner);
  EXPECT_NEAR(beside.z, 0.0f, 1e-4f);
  EXPECT_GT(std::abs(beside.x), 1.0f);  // off the square
  // Between panes: the target.
  EXPECT_EQ(nmview::zoom_pivot(view, low, high, radius, nmview::PanePoint{}), view.target);
}
