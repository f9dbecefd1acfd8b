// OpenGL 3.3 core contexts: headless through EGL, or a GLFW window. Function pointers come from
// libepoxy in both cases.
#pragma once

#include <string>

struct GLFWwindow;

namespace nmview {

// A context with no window and no display server: EGL's Mesa surfaceless platform first, then
// the EGL device platform (EGL_EXT_platform_device, e.g. Mesa's software device or a GPU's).
// Rendering goes to framebuffer objects. Under Mesa without a GPU this is llvmpipe; setting
// LIBGL_ALWAYS_SOFTWARE=1 forces llvmpipe even where a GPU exists (the tests do, for stable
// golden images). Throws nmbake::Error (ExitCode::output) when no context can be made.
class HeadlessContext {
 public:
  HeadlessContext();
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;

  // "EGL surfaceless: llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile) Mesa 22.3.6"
  const std::string& description() const { return description_; }

 private:
  void* display_ = nullptr;
  void* context_ = nullptr;
  std::string description_;
};

// A window of `width` x `height` screen units with a current GL 3.3 core context and vsync.
// Throws nmbake::Error (ExitCode::output) when there is no display or no suitable context.
class Window {
 public:
  Window(int width, int height, const std::string& title);
  ~Window();
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  GLFWwindow* handle() const { return window_; }

 private:
  GLFWwindow* window_ = nullptr;
};

// "llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile) Mesa 22.3.6" for the current context.
std::string current_renderer();

}  // namespace nmview
