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
    "F: FRAME BOTH MODELS   R: RESET   V: PRINT THE VIEW AS --VIEW   RIGHT DRAG OR ARROWS: LIGHT",
    "N: MAP ON/OFF   W: WIREFRAME   T: TANGENT COLOURS   D: DIFFERENCE",
    "L: ORBITING LIGHT   S: SPECULAR   P: SCREENSHOT   H: HELP   Q: QUIT",
    "A: AO ON/OFF   M: NEXT MAP OF THE SET (LIT, NORMAL, AO, ...)",
    "[ ]: DIFFERENCE SCALE DOWN/UP (DEGREES AT WHITE)",
    "K: MISS AND SUSPECT MASKS   C: CAGE   U: UV LAYOUT OVER THE MAP",
};

enum class Drag { none, orbit, pan, light };

struct State {
  const Renderer* renderer = nullptr;
  const Scene* scene = nullptr;
  InteractiveOptions initial;
  OrbitView view;
  Light light;
  Toggles toggles;
  bool orbit_light = false;
  bool help = true;
  bool dirty = true;
  bool screenshot = false;
  int dragging = -1;  // GLFW mouse button held, or -1
  Drag drag = Drag::none;
  double last_x = 0, last_y = 0;
  double pending_scroll = 0;          // wheel steps not applied yet (one pick per frame, however many events)
  double scroll_x = 0, scroll_y = 0;  // the cursor at the last wheel event, window coordinates
};

State& state_of(GLFWwindow* window) { return *static_cast<State*>(glfwGetWindowUserPointer(window)); }

// The wheel's steps since the last frame, applied once (one pick per frame, however many events).
void apply_scroll(GLFWwindow* window, State& s) {
  const float factor = std::pow(0.9f, float(s.pending_scroll));
  s.pending_scroll = 0;
  int ww = 0, wh = 0, fw = 0, fh = 0;
  glfwGetWindowSize(window, &ww, &wh);
  glfwGetFramebufferSize(window, &fw, &fh);
  const PanePoint p = pane_at(ww, wh, fw, fh, s.toggles.difference, s.scroll_x, s.scroll_y);
  s.view = zoom_towards(s.view, zoom_pivot(s.view, s.scene->low, s.scene->high, s.scene->radius, p), factor);
}

void print_view(const State& s) {
  std::cerr << "nmview: --view " << format_view_option(s.view, s.scene->bounds.centre()) << "\n";
}

void clamp_light(Light& light) {
  light.azimuth = std::remainder(light.azimuth, 360.0f);
  light.elevation = std::clamp(light.elevation, -89.0f, 89.0f);
}

void on_key(GLFWwindow* window, int key, int, int action, int) {
  if (action == GLFW_RELEASE) return;
  State& s = state_of(window);
  switch (key) {
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q: glfwSetWindowShouldClose(window, GLFW_TRUE); break;
    case GLFW_KEY_R:
      s.view = s.initial.view;
      s.light = s.initial.light;
      break;
    case GLFW_KEY_F: s.view = frame_view(s.view); break;
    case GLFW_KEY_V: print_view(s); return;
    case GLFW_KEY_N: s.toggles.map = !s.toggles.map; break;
    case GLFW_KEY_W: s.toggles.wireframe = !s.toggles.wireframe; break;
    case GLFW_KEY_T: s.toggles.tangent_colours = !s.toggles.tangent_colours; break;
    case GLFW_KEY_A:
      s.toggles.ao = !s.toggles.ao;
      if (!s.renderer->has_map(nmbake::MapKind::ao)) std::cerr << "nmview: A: the set has no ao map\n";
      break;
    case GLFW_KEY_M: cycle_display(s.toggles, s.renderer->shown_maps()); break;
    case GLFW_KEY_K:
      s.toggles.masks = !s.toggles.masks;
      if (!s.renderer->has_masks()) std::cerr << "nmview: K: no mask given (--miss-mask, --suspect-mask, or --report)\n";
      break;
    case GLFW_KEY_C:
      s.toggles.cage = !s.toggles.cage;
      if (!s.renderer->has_cage()) std::cerr << "nmview: C: no cage given (--cage, or --report of a bake with --cage)\n";
      break;
    case GLFW_KEY_U: s.toggles.uv_layout = !s.toggles.uv_layout; break;
    case GLFW_KEY_D: s.toggles.difference = !s.toggles.difference; break;
    case GLFW_KEY_LEFT_BRACKET:
    case GLFW_KEY_RIGHT_BRACKET:
      s.toggles.diff_scale = next_diff_scale(s.toggles.diff_scale, key == GLFW_KEY_RIGHT_BRACKET);
      std::cerr << "nmview: difference scale 0.." << s.toggles.diff_scale << " degrees\n";
      break;
    case GLFW_KEY_S: s.toggles.specular = s.toggles.specular > 0.0f ? 0.0f : 0.3f; break;
    case GLFW_KEY_L: s.orbit_light = !s.orbit_light; break;
    case GLFW_KEY_H: s.help = !s.help; break;
    case GLFW_KEY_P: s.screenshot = true; break;
    case GLFW_KEY_LEFT: s.light.azimuth -= 5.0f; break;
    case GLFW_KEY_RIGHT: s.light.azimuth += 5.0f; break;
    case GLFW_KEY_UP: s.light.elevation += 5.0f; break;
    case GLFW_KEY_DOWN: s.light.elevation -= 5.0f; break;
    default: return;
  }
  clamp_light(s.light);
  s.dirty = true;
}

void on_mouse_button(GLFWwindow* window, int button, int action, int mods) {
  State& s = state_of(window);
  if (action == GLFW_PRESS && s.dragging < 0) {
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
  if (s.drag == Drag::none) return;
  const double move_x = x - s.last_x, move_y = y - s.last_y;
  const float dx = float(move_x) * kDegreesPerPixel, dy = float(move_y) * kDegreesPerPixel;
  s.last_x = x;
  s.last_y = y;
  if (s.drag == Drag::pan) {
    // The point under the cursor at the target's depth follows it (window y is down, NDC y up).
    int ww = 0, wh = 0, fw = 0, fh = 0;
    glfwGetWindowSize(window, &ww, &wh);
    glfwGetFramebufferSize(window, &fw, &fh);
    const PanePoint p = pane_at(ww, wh, fw, fh, s.toggles.difference, x, y);
    const glm::vec2 delta{float(move_x) * p.ndc_per_unit.x, -float(move_y) * p.ndc_per_unit.y};
    s.view = pan_view(s.view, s.scene->radius, p.aspect, delta);
  } else if (s.drag == Drag::orbit) {
    // Dragging right turns the object right, i.e. the camera left.
    s.view.azimuth = std::remainder(s.view.azimuth - dx, 360.0f);
    s.view.elevation = std::clamp(s.view.elevation + dy, -90.0f, 90.0f);
  } else {
    s.light.azimuth += dx;
    s.light.elevation -= dy;
    clamp_light(s.light);
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
  }
  return p;
}

glm::vec3 zoom_pivot(const OrbitView& view, const LowVertices& low, const HighVertices& high, float radius, const PanePoint& at) {
  if (at.pane < 0) return view.target;
  const Ray ray = cursor_ray(view, radius, at.aspect, at.ndc);
  std::optional<float> t;
  if (at.pane != 1) t = nearest_hit(ray, low);
  if (at.pane != 0) {
    const std::optional<float> t_high = nearest_hit(ray, high);
    if (t_high && (!t || *t_high < *t)) t = t_high;
  }
  return t ? ray.origin + *t * ray.direction : point_at_target_depth(view, radius, at.aspect, ray);
}

void cycle_display(Toggles& toggles, const std::vector<nmbake::MapKind>& maps) {
  if (!toggles.show_map) {
    toggles.show_map = !maps.empty();
    if (toggles.show_map) toggles.shown = maps.front();
    return;
  }
  const auto at = std::find(maps.begin(), maps.end(), toggles.shown);
  if (at == maps.end() || at + 1 == maps.end()) toggles.show_map = false;
  else toggles.shown = *(at + 1);
}

void run_interactive(const Scene& scene, const InteractiveOptions& options, const OverlayData& overlays) {
  Window window(options.width, options.height, title(scene));
  std::cerr << "nmview: " << current_renderer() << "\n";
  Renderer renderer(scene.low, scene.high, scene.map, scene.radius, scene.decoding);
  for (const SetMap& m : scene.set_maps) renderer.add_set_map(m.kind, m.image);
  renderer.set_overlays(overlays);
  upload_udim_tiles(renderer, scene);

  State s;
  s.renderer = &renderer;
  s.scene = &scene;
  s.initial = options;
  s.view = options.view;
  s.light = options.light;
  s.toggles = options.toggles;
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
    if (s.orbit_light) glfwPollEvents();
    else glfwWaitEvents();
    const double now = glfwGetTime();
    if (s.orbit_light) {
      s.light.azimuth += float(now - last_time) * kLightOrbitDegreesPerSecond;
      clamp_light(s.light);
      s.dirty = true;
    }
    last_time = now;
    if (!s.dirty) continue;
    s.dirty = false;
    if (s.pending_scroll != 0) apply_scroll(w, s);

    int width = 0, height = 0;
    glfwGetFramebufferSize(w, &width, &height);
    if (width <= 0 || height <= 0) continue;  // minimized
    renderer.render(0, width, height, s.view, s.light, s.toggles, s.help ? kHelp : std::vector<std::string>{});
    if (s.screenshot) {
      s.screenshot = false;
      std::string path = "nmview-" + std::to_string(++screenshots) + ".png";
      try {
        write_screenshot(path, Renderer::read_framebuffer(0, width, height), scene);
        std::cerr << "nmview: wrote " << path << " (--view " << format_view_option(s.view, scene.bounds.centre()) << ")\n";
      } catch (const nmbake::Error& e) {
        std::cerr << "nmview: " << e.what() << "\n";
      }
    }
    glfwSwapBuffers(w);
  }
}

}  // namespace nmview
