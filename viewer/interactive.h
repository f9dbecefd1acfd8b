// The interactive window: one orbit camera and one light drive both panes. Left drag orbits the
// target, middle or shift+left drag pans it, the wheel zooms towards the model under the cursor
// (view.h: zoom_towards, a ray picked against the pane's mesh), F frames both models, R resets.
#pragma once

#include <vector>

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
};

// Where a window point (x, y in window units, y down, as GLFW reports the cursor) falls in the
// layout the renderer draws (pane_layout over the framebuffer, which a high-DPI screen makes larger
// than the window): its pane (0 low, 1 high, 2 difference), the point in that pane's normalized
// device coordinates (view.h: -1..1, y up), the pane's aspect, and one window unit in NDC.
struct PanePoint {
  int pane = -1;  // -1: in the leftover columns between or beside the panes, or no window
  glm::vec2 ndc{0.0f}, ndc_per_unit{0.0f};
  float aspect = 1.0f;
};
PanePoint pane_at(int window_width, int window_height, int framebuffer_width, int framebuffer_height, bool difference, double x,
                  double y);

// What the wheel zooms towards (re-centred scene): the nearest point of the pane's model under the
// cursor (the low-poly in pane 0, the high-poly in pane 1, the nearer of both in the difference
// pane), else the cursor's point at the target's depth; the target itself outside every pane.
glm::vec3 zoom_pivot(const OrbitView& view, const LowVertices& low, const HighVertices& high, float radius, const PanePoint& at);

// The M key: lit, then each map of `maps` (Renderer::shown_maps) shown unlit, then lit again.
void cycle_display(Toggles& toggles, const std::vector<nmbake::MapKind>& maps);

// Opens the window and runs until it is closed (Esc or Q). Throws nmbake::Error
// (ExitCode::output) when no window can be opened (no display). `overlays` are what the K (masks)
// and C (cage) keys show.
void run_interactive(const Scene& scene, const InteractiveOptions& options, const OverlayData& overlays = {});

}  // namespace nmview
