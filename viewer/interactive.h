// The interactive window: one orbit camera and one light drive both panes. Left drag orbits the
// target, middle or shift+left drag pans it, the wheel zooms towards the model under the cursor
// (view.h: zoom_towards, a ray picked against the pane's mesh), Ctrl+click selects a point (the
// model's surface, or the UV cursor's point in the UV view), F frames the selection or both models,
// R resets. What each key does is controls.h's apply_key; this file only wires GLFW's events to it.
#pragma once

#include <optional>
#include <vector>

#include "controls.h"
#include "overlays.h"
#include "scene.h"
#include "renderer.h"
#include "view.h"

namespace nmview {

struct InteractiveOptions {
  int width = 1600, height = 800;  // window size in screen units
  OrbitView view;                  // initial camera (target re-centred: resolve_view), restored by R
  Light light;                     // initial light, restored by R
  Toggles toggles;
  std::optional<glm::vec2> uv_cursor;  // --uv-cursor: its point is the initial selection
};

// Where a window point (x, y in window units, y down, as GLFW reports the cursor) falls in the
// layout the renderer draws (pane_layout over the framebuffer, which a high-DPI screen makes larger
// than the window): its pane (0 low, 1 high, 2 difference), the point in that pane's normalized
// device coordinates (view.h: -1..1, y up), the pane's aspect, and one window unit in NDC.
struct PanePoint {
  int pane = -1;  // -1: in the leftover columns between or beside the panes, or no window
  glm::vec2 ndc{0.0f}, ndc_per_unit{0.0f};
  float aspect = 1.0f;
  glm::vec2 pixel{0.0f};      // the point in the pane's framebuffer pixels, origin at its lower left
  int width = 0, height = 0;  // the pane's size in framebuffer pixels
};
PanePoint pane_at(int window_width, int window_height, int framebuffer_width, int framebuffer_height, bool difference, double x,
                  double y);

// What a Ctrl+click selects (re-centred scene): the nearest point of the pane's model under the
// cursor (the low-poly in pane 0, the high-poly in pane 1, the nearer of both in the difference
// pane); nullopt over no model or outside every pane.
std::optional<glm::vec3> pick_point(const OrbitView& view, const LowVertices& low, const HighVertices& high, float radius,
                                    const PanePoint& at);

// What the wheel zooms towards (re-centred scene): pick_point, else the cursor's point at the
// target's depth; the target itself outside every pane.
glm::vec3 zoom_pivot(const OrbitView& view, const LowVertices& low, const HighVertices& high, float radius, const PanePoint& at);

// The UV under a point of the UV view's pane (pane 0 with the UV view on), else nullopt.
std::optional<glm::vec2> uv_under(const PanePoint& at, bool uv_view);

// Opens the window and runs until it is closed (Esc or Q). Throws nmbake::Error
// (ExitCode::output) when no window can be opened (no display). `overlays` are what the K (masks)
// and C (cage) keys show.
void run_interactive(const Scene& scene, const InteractiveOptions& options, const OverlayData& overlays = {});

}  // namespace nmview
