#include "interactive.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <optional>

#include <epoxy/gl.h>
#include <GLFW/glfw3.h>

#include "core/errors.h"
#include "gl_context.h"
#include "udim_textures.h"

namespace nmview {
namespace {

constexpr float kDegreesPerPixel = 0.4f;
constexpr float kLightOrbitDegreesPerSecond = 45.0f;

const std::vector<std::string> kHelp = {
    "LEFT DRAG: ORBIT   MIDDLE OR SHIFT+LEFT DRAG: PAN   WHEEL: ZOOM AT THE CURSOR",
    "CTRL+CLICK: SELECT A POINT   F: FRAME THE SELECTION (ELSE BOTH MODELS)   ESC: CLEAR IT",
    "R: RESET   V: PRINT THE VIEW AS --VIEW   RIGHT DRAG OR ARROWS: LIGHT",
    "N: MAP ON/OFF   W: WIREFRAME   T: TANGENT COLOURS   D: DIFFERENCE",
    "L: ORBITING LIGHT   S: SPECULAR   P: SCREENSHOT   H: HELP   Q: QUIT",
    "A: AO ON/OFF   M: NEXT MAP OF THE SET (LIT, NORMAL, AO, ...)",
    "[ ]: DIFFERENCE SCALE DOWN/UP (DEGREES AT WHITE)",
    "K: MISS AND SUSPECT MASKS   C: CAGE   U: UV LAYOUT OVER THE MAP (THE CURSOR MARKED ON THE MODEL)",
};

// GLFW's codes are the ones controls.h names.
static_assert(GLFW_KEY_ESCAPE == kKeyEscape && GLFW_KEY_RIGHT == kKeyRight && GLFW_KEY_LEFT == kKeyLeft &&
                  GLFW_KEY_DOWN == kKeyDown && GLFW_KEY_UP == kKeyUp,
              "controls.h's key codes are GLFW's");
static_assert(GLFW_KEY_D == 'D' && GLFW_KEY_LEFT_BRACKET == '[' && GLFW_KEY_RIGHT_BRACKET == ']',
              "GLFW's printable keys are their ASCII codes");

enum class Drag { none, orbit, pan, light };

struct State {
  const Scene* scene = nullptr;
  KeyContext context;
  ViewerState viewer;
  bool dirty = true;
  bool screenshot = false;
  int dragging = -1;  // GLFW mouse button held, or -1
  Drag drag = Drag::none;
  double last_x = 0, last_y = 0;
  double pending_scroll = 0;          // wheel steps not applied yet (one pick per frame, however many events)
  double scroll_x = 0, scroll_y = 0;  // the cursor at the last wheel event, window coordinates
};

State& state_of(GLFWwindow* window) { return *static_cast<State*>(glfwGetWindowUserPointer(window)); }

PanePoint window_pane_at(GLFWwindow* window, const State& s, double x, double y) {
  int ww = 0, wh = 0, fw = 0, fh = 0;
  glfwGetWindowSize(window, &ww, &wh);
  glfwGetFramebufferSize(window, &fw, &fh);
  return pane_at(ww, wh, fw, fh, s.viewer.toggles.difference, x, y);
}

// The wheel's steps since the last frame, applied once (one pick per frame, however many events).
void apply_scroll(GLFWwindow* window, State& s) {
  const float factor = std::pow(0.9f, float(s.pending_scroll));
  s.pending_scroll = 0;
  const PanePoint p = window_pane_at(window, s, s.scroll_x, s.scroll_y);
  s.viewer.view = zoom_towards(s.viewer.view, zoom_pivot(s.viewer.view, s.scene->low, s.scene->high, s.scene->radius, p), factor);
}

void print_view(const State& s) {
  std::cerr << "nmview: --view " << format_view_option(s.viewer.view, s.scene->bounds.centre()) << "\n";
}

void on_key(GLFWwindow* window, int key, int, int action, int) {
  if (action == GLFW_RELEASE) return;
  State& s = state_of(window);
  switch (apply_key(s.viewer, key, s.context, std::cerr)) {
    case KeyAction::ignored: return;
    case KeyAction::quit: glfwSetWindowShouldClose(window, GLFW_TRUE); return;
    case KeyAction::print_view: print_view(s); return;
    case KeyAction::screenshot: s.screenshot = true; break;
    case KeyAction::redraw: break;
  }
  s.dirty = true;
}

// Ctrl+click: the UV cursor's point in the UV view, else the model's surface under the cursor.
void select_at(GLFWwindow* window, State& s) {
  double x = 0, y = 0;
  glfwGetCursorPos(window, &x, &y);
  const PanePoint p = window_pane_at(window, s, x, y);
  ViewerState& v = s.viewer;
  if (const std::optional<glm::vec2> uv = uv_under(p, v.toggles.uv_layout)) {
    set_uv_cursor(v, uv, s.scene->low);
    v.selection = v.uv_point ? std::optional<glm::vec3>(v.uv_point->position) : std::nullopt;
    std::cerr << "nmview: " << describe_uv_point(*uv, v.uv_point) << (v.uv_point ? ": selected" : ": nothing selected") << "\n";
  } else {
    v.selection = pick_point(v.view, s.scene->low, s.scene->high, s.scene->radius, p);
    if (!v.selection) std::cerr << "nmview: no model under the cursor: nothing selected\n";
  }
  s.dirty = true;
}

void on_mouse_button(GLFWwindow* window, int button, int action, int mods) {
  State& s = state_of(window);
  if (action == GLFW_PRESS && s.dragging < 0 && button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_CONTROL) != 0) {
    select_at(window, s);
  } else if (action == GLFW_PRESS && s.dragging < 0) {
    s.dragging = button;
    s.drag = button == GLFW_MOUSE_BUTTON_MIDDLE                                 ? Drag::pan
             : button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_SHIFT) != 0 ? Drag::pan
             : button == GLFW_MOUSE_BUTTON_LEFT                                 ? Drag::orbit
                                                                                : Drag::light;
    glfwGetCursorPos(window, &s.last_x, &s.last_y);
  } else if (action == GLFW_RELEASE && button == s.dragging) {
    s.dragging = -1;
    s.drag = Drag::none;
  }
}

void on_cursor(GLFWwindow* window, double x, double y) {
  State& s = state_of(window);
  if (s.drag == Drag::none) {
    // The UV view's cursor follows the mouse over its pane; its point is marked on the model.
    if (!s.viewer.toggles.uv_layout && !s.viewer.uv_cursor) return;
    const std::optional<glm::vec2> uv = uv_under(window_pane_at(window, s, x, y), s.viewer.toggles.uv_layout);
    if (!uv && !s.viewer.uv_cursor) return;
    set_uv_cursor(s.viewer, uv, s.scene->low);
    s.dirty = true;
    return;
  }
  const double move_x = x - s.last_x, move_y = y - s.last_y;
  const float dx = float(move_x) * kDegreesPerPixel, dy = float(move_y) * kDegreesPerPixel;
  s.last_x = x;
  s.last_y = y;
  if (s.drag == Drag::pan) {
    // The point under the cursor at the target's depth follows it (window y is down, NDC y up).
    const PanePoint p = window_pane_at(window, s, x, y);
    const glm::vec2 delta{float(move_x) * p.ndc_per_unit.x, -float(move_y) * p.ndc_per_unit.y};
    s.viewer.view = pan_view(s.viewer.view, s.scene->radius, p.aspect, delta);
  } else if (s.drag == Drag::orbit) {
    // Dragging right turns the object right, i.e. the camera left.
    OrbitView& view = s.viewer.view;
    view.azimuth = std::remainder(view.azimuth - dx, 360.0f);
    view.elevation = std::clamp(view.elevation + dy, -90.0f, 90.0f);
  } else {
    Light& light = s.viewer.light;
    light.azimuth += dx;
    light.elevation -= dy;
    keep_light_in_range(light);
  }
  s.dirty = true;
}

void on_scroll(GLFWwindow* window, double, double y) {
  State& s = state_of(window);
  s.pending_scroll += y;
  glfwGetCursorPos(window, &s.scroll_x, &s.scroll_y);
  s.dirty = true;
}

void on_resize(GLFWwindow* window, int, int) { state_of(window).dirty = true; }

std::string title(const Scene& scene) {
  return "nmview - " + scene.low_name + " (" + with_thousands(scene.low_triangles) + " tris) + " + scene.map_name + " | " +
         scene.high_name + " (" + with_thousands(scene.high_triangles) + " tris)";
}

}  // namespace

PanePoint pane_at(int window_width, int window_height, int framebuffer_width, int framebuffer_height, bool difference, double x,
                  double y) {
  PanePoint p;
  if (window_width <= 0 || window_height <= 0 || framebuffer_width <= 0 || framebuffer_height <= 0) return p;
  // Framebuffer pixels (more than window units on a high-DPI screen), origin at the lower left.
  const float sx = float(framebuffer_width) / float(window_width), sy = float(framebuffer_height) / float(window_height);
  const float px = float(x) * sx, py = float(framebuffer_height) - float(y) * sy;
  const std::vector<Rect> layout = pane_layout(framebuffer_width, framebuffer_height, difference);
  const Rect& first = layout.front();
  p.aspect = float(first.width) / float(first.height);
  p.ndc_per_unit = {2.0f * sx / float(first.width), 2.0f * sy / float(first.height)};
  for (std::size_t i = 0; i < layout.size(); ++i) {
    const Rect& r = layout[i];
    if (px < float(r.x) || px >= float(r.x + r.width)) continue;
    p.pane = int(i);
    p.ndc = {2.0f * (px - float(r.x)) / float(r.width) - 1.0f, 2.0f * (py - float(r.y)) / float(r.height) - 1.0f};
    p.pixel = {px - float(r.x), py - float(r.y)};
    p.width = r.width;
    p.height = r.height;
  }
  return p;
}

std::optional<glm::vec3> pick_point(const OrbitView& view, const LowVertices& low, const HighVertices& high, float radius,
                                    const PanePoint& at) {
  if (at.pane < 0) return std::nullopt;
  const Ray ray = cursor_ray(view, radius, at.aspect, at.ndc);
  std::optional<float> t;
  if (at.pane != 1) t = nearest_hit(ray, low);
  if (at.pane != 0) {
    const std::optional<float> t_high = nearest_hit(ray, high);
    if (t_high && (!t || *t_high < *t)) t = t_high;
  }
  if (!t) return std::nullopt;
  return ray.origin + *t * ray.direction;
}

glm::vec3 zoom_pivot(const OrbitView& view, const LowVertices& low, const HighVertices& high, float radius, const PanePoint& at) {
  if (at.pane < 0) return view.target;
  if (const std::optional<glm::vec3> p = pick_point(view, low, high, radius, at)) return *p;
  return point_at_target_depth(view, radius, at.aspect, cursor_ray(view, radius, at.aspect, at.ndc));
}

std::optional<glm::vec2> uv_under(const PanePoint& at, bool uv_view) {
  if (!uv_view || at.pane != 0) return std::nullopt;
  const UvSquare square = uv_square(at.width, at.height);
  return uv_at_pane_pixel(square.x, square.y, square.side, at.pixel);
}

void run_interactive(const Scene& scene, const InteractiveOptions& options, const OverlayData& overlays) {
  Window window(options.width, options.height, title(scene));
  std::cerr << "nmview: " << current_renderer() << "\n";
  Renderer renderer(scene.low, scene.high, scene.map, scene.radius, scene.decoding);
  for (const SetMap& m : scene.set_maps) renderer.add_set_map(m.kind, m.image);
  renderer.set_overlays(overlays);
  upload_udim_tiles(renderer, scene);

  State s;
  s.scene = &scene;
  s.context.initial_view = options.view;
  s.context.initial_light = options.light;
  s.context.maps = renderer.shown_maps();
  s.context.has_ao = renderer.has_map(nmbake::MapKind::ao);
  s.context.has_masks = renderer.has_masks();
  s.context.has_cage = renderer.has_cage();
  s.viewer.view = options.view;
  s.viewer.light = options.light;
  s.viewer.toggles = options.toggles;
  if (options.uv_cursor) {
    set_uv_cursor(s.viewer, options.uv_cursor, scene.low);
    if (s.viewer.uv_point) s.viewer.selection = s.viewer.uv_point->position;
  }
  GLFWwindow* w = window.handle();
  glfwSetWindowUserPointer(w, &s);
  glfwSetKeyCallback(w, on_key);
  glfwSetMouseButtonCallback(w, on_mouse_button);
  glfwSetCursorPosCallback(w, on_cursor);
  glfwSetScrollCallback(w, on_scroll);
  glfwSetFramebufferSizeCallback(w, on_resize);
  glfwSetWindowRefreshCallback(w, [](GLFWwindow* win) { state_of(win).dirty = true; });

  double last_time = glfwGetTime();
  int screenshots = 0;
  while (!glfwWindowShouldClose(w)) {
    // Sleep until input arrives unless the light is orbiting on its own.
    if (s.viewer.orbit_light) glfwPollEvents();
    else glfwWaitEvents();
    const double now = glfwGetTime();
    if (s.viewer.orbit_light) {
      s.viewer.light.azimuth += float(now - last_time) * kLightOrbitDegreesPerSecond;
      keep_light_in_range(s.viewer.light);
      s.dirty = true;
    }
    last_time = now;
    if (!s.dirty) continue;
    s.dirty = false;
    if (s.pending_scroll != 0) apply_scroll(w, s);

    int width = 0, height = 0;
    glfwGetFramebufferSize(w, &width, &height);
    if (width <= 0 || height <= 0) continue;  // minimized
    renderer.set_marks(marks_of(s.viewer));
    renderer.render(0, width, height, s.viewer.view, s.viewer.light, s.viewer.toggles,
                    s.viewer.help ? kHelp : std::vector<std::string>{});
    if (s.screenshot) {
      s.screenshot = false;
      std::string path = "nmview-" + std::to_string(++screenshots) + ".png";
      try {
        write_screenshot(path, Renderer::read_framebuffer(0, width, height), scene);
        std::cerr << "nmview: wrote " << path << " (--view " << format_view_option(s.viewer.view, scene.bounds.centre()) << ")\n";
      } catch (const nmbake::Error& e) {
        std::cerr << "nmview: " << e.what() << "\n";
      }
    }
    glfwSwapBuffers(w);
  }
}

}  // namespace nmview
