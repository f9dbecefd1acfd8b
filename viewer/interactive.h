// The interactive window: one orbit camera and one light drive both panes. Left drag orbits the
// target, middle or shift+left drag pans it, the wheel zooms towards the model under the cursor
// (view.h: zoom_towards, a ray picked against the pane's mesh), F frames both models, R resets.
#pragma once

#include <vector>

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

// The M key: lit, then each map of `maps` (Renderer::shown_maps) shown unlit, then lit again.
void cycle_display(Toggles& toggles, const std::vector<nmbake::MapKind>& maps);

// Opens the window and runs until it is closed (Esc or Q). Throws nmbake::Error
// (ExitCode::output) when no window can be opened (no display).
void run_interactive(const Scene& scene, const InteractiveOptions& options);

}  // namespace nmview
