#include "gl_context.h"

#include <cstring>
#include <string>
#include <vector>

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <GLFW/glfw3.h>

#include "core/errors.h"

namespace nmview {
namespace {

bool has_extension(const char* list, const char* name) {
  if (!list) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)) != nullptr; p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

// Initializes `display` and makes a GL 3.3 core context current on it without a surface.
EGLContext make_context(EGLDisplay display, std::string& why) {
  EGLint major = 0, minor = 0;
  if (display == EGL_NO_DISPLAY || !eglInitialize(display, &major, &minor)) {
    why = "eglInitialize failed";
    return EGL_NO_CONTEXT;
  }
  if (!eglBindAPI(EGL_OPENGL_API)) {
    why = "EGL has no desktop OpenGL";
    return EGL_NO_CONTEXT;
  }
  const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint count = 0;
  if (!eglChooseConfig(display, config_attribs, &config, 1, &count) || count == 0) {
    // Surfaceless rendering needs no config where EGL_KHR_no_config_context is offered.
    if (!has_extension(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_no_config_context")) {
      why = "no EGL config for desktop OpenGL";
      return EGL_NO_CONTEXT;
    }
    config = EGL_NO_CONFIG_KHR;
  }
  const EGLint context_attribs[] = {
      EGL_CONTEXT_MAJOR_VERSION,           3,       EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
  if (context == EGL_NO_CONTEXT) {
    why = "no OpenGL 3.3 core context";
    return EGL_NO_CONTEXT;
  }
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    eglDestroyContext(display, context);
    why = "surfaceless eglMakeCurrent failed";
    return EGL_NO_CONTEXT;
  }
  return context;
}

}  // namespace

std::string current_renderer() {
  auto str = [](GLenum name) {
    const GLubyte* s = glGetString(name);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  return str(GL_RENDERER) + ", " + str(GL_VERSION);
}

HeadlessContext::HeadlessContext() {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  std::string tried;
  auto attempt = [&](EGLDisplay display, const char* name) {
    std::string why;
    EGLContext context = make_context(display, why);
    if (context != EGL_NO_CONTEXT) {
      display_ = display;
      context_ = context;
      description_ = std::string("EGL ") + name + ": " + current_renderer();
      return true;
    }
    if (display != EGL_NO_DISPLAY) eglTerminate(display);
    tried += std::string(tried.empty() ? "" : "; ") + name + ": " + why;
    return false;
  };

  if (has_extension(client, "EGL_MESA_platform_surfaceless") &&
      attempt(eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr), "surfaceless"))
    return;
  if (has_extension(client, "EGL_EXT_platform_device") && has_extension(client, "EGL_EXT_device_enumeration")) {
    EGLint count = 0;
    eglQueryDevicesEXT(0, nullptr, &count);
    std::vector<EGLDeviceEXT> devices(static_cast<std::size_t>(count));
    if (count > 0 && eglQueryDevicesEXT(count, devices.data(), &count))
      for (EGLDeviceEXT device : devices)
        if (attempt(eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, device, nullptr), "device")) return;
  }
  if (tried.empty())
    tried = "no EGL surfaceless or device platform (client extensions: " + std::string(client ? client : "none") + ")";
  throw nmbake::OutputError("cannot create a headless OpenGL 3.3 context (" + tried +
                            "); install Mesa's EGL and DRI drivers (libegl-mesa0, libgl1-mesa-dri)");
}

HeadlessContext::~HeadlessContext() {
  if (!display_) return;
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(display_, context_);
  eglTerminate(display_);
}

Window::Window(int width, int height, const std::string& title) {
  if (!glfwInit()) {
    const char* description = nullptr;
    glfwGetError(&description);
    throw nmbake::OutputError(std::string("cannot open a window (") + (description ? description : "GLFW init failed") +
                              "); use --screenshot FILE or --compare to render without a display");
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) {
    const char* description = nullptr;
    glfwGetError(&description);
    glfwTerminate();
    throw nmbake::OutputError(std::string("cannot create an OpenGL 3.3 core window (") + (description ? description : "unknown") +
                              ")");
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(1);
}

Window::~Window() {
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

}  // namespace nmview
