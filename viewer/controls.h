// What the window's keys and clicks do to the viewer's state, as pure functions over that state
// (no window, no GL): interactive.cpp's GLFW callbacks only translate events and call these, so
// every key is unit-tested (tests/viewer/test_controls.cpp).
//
// The selection (issue 36, item 4) is one point of the re-centred scene: picked by a Ctrl+click on
// a model (the nearest surface of the pane's model under the cursor), or the UV cursor's point
// (uv_cursor.h) by a Ctrl+click in the UV view, or --uv-cursor. F frames it (view.h frame_point)
// when there is one, else both models; Esc clears it (and closes the window when there is none).
#pragma once

#include <optional>
#include <ostream>
#include <vector>

#include <glm/glm.hpp>

#include "core/maps.h"
#include "renderer.h"
#include "uv_cursor.h"
#include "view.h"

namespace nmview {

// Key codes: printable keys are their upper-case ASCII ('D', '[', ']'), the others GLFW's numbers
// (interactive.cpp checks they match glfw3.h).
constexpr int kKeyEscape = 256, kKeyRight = 262, kKeyLeft = 263, kKeyDown = 264, kKeyUp = 265;

// Everything a key or a click may change.
struct ViewerState {
  OrbitView view;
  Light light;
  Toggles toggles;
  bool orbit_light = false;            // L: the light turns on its own
  bool help = true;                    // H: the key help at the bottom
  std::optional<glm::vec3> selection;  // re-centred scene; marked, and what F frames
  std::optional<glm::vec2> uv_cursor;  // the UV view's cursor (UV), while the mouse is over the UV pane
  std::optional<UvPoint> uv_point;     // find_uv_point of uv_cursor
};

// What the window knows that a key needs: the state R restores, the set's maps (Renderer::shown_maps)
// and which overlays were loaded (for the line that says a toggle shows nothing).
struct KeyContext {
  OrbitView initial_view;
  Light initial_light;
  std::vector<nmbake::MapKind> maps{nmbake::MapKind::normal};
  bool has_ao = false, has_masks = false, has_cage = false;
};

// What the window does after a key.
enum class KeyAction {
  ignored,     // not a key of the viewer: nothing changed
  redraw,      // the state changed
  quit,        // close the window
  print_view,  // print the view as --view (V)
  screenshot,  // write a screenshot (P)
};

// The M key: lit, then each map of `maps` (Renderer::shown_maps) shown unlit, then lit again.
void cycle_display(Toggles& toggles, const std::vector<nmbake::MapKind>& maps);

// Applies key `key` (pressed or repeated) to `state`; notes for the user (a toggle with nothing to
// show, the new difference scale) go to `log`, one line each.
KeyAction apply_key(ViewerState& state, int key, const KeyContext& context, std::ostream& log);

// The Marks (renderer.h) of `state`: the UV cursor in the UV view and its point, the selection, and
// the UV cursor's line for the label.
Marks marks_of(const ViewerState& state);

// Moves the UV cursor to `uv` (nullopt: the mouse left the UV pane), finding its point on `low`.
void set_uv_cursor(ViewerState& state, const std::optional<glm::vec2>& uv, const LowVertices& low);

// The light's azimuth wrapped to (-180, 180] degrees and its elevation kept within +-89 (what the
// keys, a right drag and the orbiting light leave it at).
void keep_light_in_range(Light& light);

}  // namespace nmview
