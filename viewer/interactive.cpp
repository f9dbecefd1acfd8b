#include "interactive.h"

#include <algorithm>
#include <cmath>
#include <iostream>

#include <epoxy/gl.h>
#include <GLFW/glfw3.h>

#include "core/errors.h"
#include "gl_context.h"

namespace nmview {
namespace {

constexpr float kDegreesPerPixel = 0.4f;
constexpr float kLightOrbitDegreesPerSecond = 45.0f;

const std::vector<std::string> kHelp = {
    "LEFT DRAG: ORBIT   RIGHT DRAG OR ARROWS: LIGHT   WHEEL: ZOOM   R: RESET",
    "N: MAP ON/OFF   W: WIREFRAME   T: TANGENT COLOURS   D: DIFFERENCE",
    "L: ORBITING LIGHT   S: SPECULAR   P: SCREENSHOT   H: HELP   Q: QUIT",
    "A: AO ON/OFF   M: NEXT MAP OF THE SET (LIT, NORMAL, AO, ...)",
    "[ ]: DIFFERENCE SCALE DOWN/UP (DEGREES AT WHITE)",
};

struct State {
  const Renderer* renderer = nullptr;
  InteractiveOptions initial;
  OrbitView view;
  Light light;
  Toggles toggles;
  bool orbit_light = false;
  bool help = true;
  bool dirty = true;
  bool screenshot = false;
  int dragging = -1;  // GLFW mouse button held, or -1
  double last_x = 0, last_y = 0;
};

State& state_of(GLFWwindow* window) { return *static_cast<State*>(glfwGetWindowUserPointer(window)); }

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
    case GLFW_KEY_N: s.toggles.map = !s.toggles.map; break;
    case GLFW_KEY_W: s.toggles.wireframe = !s.toggles.wireframe; break;
    case GLFW_KEY_T: s.toggles.tangent_colours = !s.toggles.tangent_colours; break;
    case GLFW_KEY_A:
      s.toggles.ao = !s.toggles.ao;
      if (!s.renderer->has_map(nmbake::MapKind::ao)) std::cerr << "nmview: A: the set has no ao map\n";
      break;
    case GLFW_KEY_M: cycle_display(s.toggles, s.renderer->shown_maps()); break;
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

void on_mouse_button(GLFWwindow* window, int button, int action, int) {
  State& s = state_of(window);
  if (action == GLFW_PRESS && s.dragging < 0) {
    s.dragging = button;
    glfwGetCursorPos(window, &s.last_x, &s.last_y);
  } else if (action == GLFW_RELEASE && button == s.dragging) {
    s.dragging = -1;
  }
}

void on_cursor(GLFWwindow* window, double x, double y) {
  State& s = state_of(window);
  if (s.dragging < 0) return;
  const float dx = float(x - s.last_x) * kDegreesPerPixel, dy = float(y - s.last_y) * kDegreesPerPixel;
  s.last_x = x;
  s.last_y = y;
  if (s.dragging == GLFW_MOUSE_BUTTON_LEFT) {
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
  s.view.zoom = std::clamp(s.view.zoom * std::pow(0.9f, float(y)), 0.05f, 20.0f);
  s.dirty = true;
}

void on_resize(GLFWwindow* window, int, int) { state_of(window).dirty = true; }

std::string title(const Scene& scene) {
  return "nmview - " + scene.low_name + " (" + with_thousands(scene.low_triangles) + " tris) + " + scene.map_name + " | " +
         scene.high_name + " (" + with_thousands(scene.high_triangles) + " tris)";
}

}  // namespace

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

void run_interactive(const Scene& scene, const InteractiveOptions& options) {
  Window window(options.width, options.height, title(scene));
  std::cerr << "nmview: " << current_renderer() << "\n";
  Renderer renderer(scene.low, scene.high, scene.map, scene.radius, scene.decoding);
  for (const SetMap& m : scene.set_maps) renderer.add_set_map(m.kind, m.image);

  State s;
  s.renderer = &renderer;
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

    int width = 0, height = 0;
    glfwGetFramebufferSize(w, &width, &height);
    if (width <= 0 || height <= 0) continue;  // minimized
    renderer.render(0, width, height, s.view, s.light, s.toggles, s.help ? kHelp : std::vector<std::string>{});
    if (s.screenshot) {
      s.screenshot = false;
      std::string path = "nmview-" + std::to_string(++screenshots) + ".png";
      try {
        write_screenshot(path, Renderer::read_framebuffer(0, width, height), scene);
        std::cerr << "nmview: wrote " << path << "\n";
      } catch (const nmbake::Error& e) {
        std::cerr << "nmview: " << e.what() << "\n";
      }
    }
    glfwSwapBuffers(w);
  }
}

}  // namespace nmview
