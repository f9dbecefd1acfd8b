#include "view.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <glm/gtc/matrix_transform.hpp>

#include "cli/numbers.h"
#include "core/errors.h"

namespace nmview {

namespace {

constexpr float kFovyDegrees = 30.0f;
constexpr float kMargin = 1.05f;  // the framed sphere's radius is enlarged by this much

// Camera to scene: rotate about Y by azimuth, then about X by -elevation.
glm::mat4 orbit_rotation(const OrbitView& view) {
  glm::mat4 orbit = glm::rotate(glm::mat4(1.0f), glm::radians(view.azimuth), glm::vec3(0, 1, 0));
  return glm::rotate(orbit, glm::radians(-view.elevation), glm::vec3(1, 0, 0));
}

float clamped_zoom(float zoom) { return std::clamp(zoom, kMinZoom, kMaxZoom); }

const char* kViewForms = "expected AZ,EL[,DIST[,TX,TY,TZ]]: 2, 3 or 6 numbers (e.g. 30,20 or 30,20,0.5 or 30,20,0.5,0,1,0)";

}  // namespace

glm::vec3 direction_from_angles(float azimuth_deg, float elevation_deg) {
  float az = glm::radians(azimuth_deg), el = glm::radians(elevation_deg);
  return {std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)};
}

float framing_distance(float radius, float aspect) {
  radius = std::max(radius, 1e-20f);
  aspect = std::max(aspect, 1e-3f);
  const float fovy = glm::radians(kFovyDegrees);
  const float fovx = 2.0f * std::atan(std::tan(0.5f * fovy) * aspect);
  // In this order (the fit, then the margin) for the same rounding as before the target existed:
  // the golden images' wireframes sit on depth ties.
  const float fit = radius / std::sin(0.5f * std::min(fovy, fovx));
  return kMargin * fit;
}

CameraFrame camera_frame(const OrbitView& view, float radius, float aspect) {
  aspect = std::max(aspect, 1e-3f);
  const glm::mat4 orbit = orbit_rotation(view);
  CameraFrame f;
  f.right = glm::vec3(orbit[0]);
  f.up = glm::vec3(orbit[1]);
  f.forward = -glm::vec3(orbit[2]);
  f.distance = framing_distance(radius, aspect) * clamped_zoom(view.zoom);
  f.eye = view.target + glm::vec3(orbit * glm::vec4(0.0f, 0.0f, f.distance, 0.0f));
  f.tan_half_fovy = std::tan(0.5f * glm::radians(kFovyDegrees));
  f.tan_half_fovx = f.tan_half_fovy * aspect;
  return f;
}

CameraMatrices camera_matrices(const OrbitView& view, const Light& light, float radius, float aspect) {
  radius = std::max(radius, 1e-20f);
  aspect = std::max(aspect, 1e-3f);
  const CameraFrame f = camera_frame(view, radius, aspect);
  const glm::mat4 orbit = orbit_rotation(view);

  CameraMatrices m;
  m.view = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -f.distance)) * glm::transpose(orbit) *
           glm::translate(glm::mat4(1.0f), -view.target);
  m.eye = f.eye;
  m.light_dir = glm::normalize(glm::vec3(orbit * glm::vec4(direction_from_angles(light.azimuth, light.elevation), 0)));

  // Near and far hug the bounding sphere around the scene centre at its depth; a camera inside the
  // sphere keeps a small positive near, below the target's distance so the target is never clipped.
  // (Written so that a target at the centre gives exactly the distance: golden images keep their depths.)
  const float centre_depth = f.distance - glm::dot(view.target, f.forward);
  const float near_plane = std::max(centre_depth - kMargin * radius, std::min(1e-3f * radius, 0.05f * f.distance));
  // (A sphere wholly behind the near plane draws nothing; far only has to stay beyond near.)
  const float far_plane = std::max(centre_depth + kMargin * radius, near_plane + kMargin * radius);
  m.projection = glm::perspective(glm::radians(kFovyDegrees), aspect, near_plane, far_plane);
  return m;
}

std::vector<OrbitView> compare_views() {
  std::vector<OrbitView> views;
  for (int i = 0; i < 8; ++i) views.push_back({45.0f * float(i), 20.0f, 1.0f});
  views.push_back({0.0f, 90.0f, 1.0f});
  views.push_back({0.0f, -90.0f, 1.0f});
  return views;
}

Ray cursor_ray(const OrbitView& view, float radius, float aspect, glm::vec2 ndc) {
  const CameraFrame f = camera_frame(view, radius, aspect);
  const glm::vec3 d = f.forward + f.right * (ndc.x * f.tan_half_fovx) + f.up * (ndc.y * f.tan_half_fovy);
  return {f.eye, glm::normalize(d)};
}

glm::vec3 point_at_target_depth(const OrbitView& view, float radius, float aspect, const Ray& ray) {
  const CameraFrame f = camera_frame(view, radius, aspect);
  // A ray of the pane is within 45 degrees of forward, so the cosine is well away from 0.
  const float cosine = std::max(glm::dot(ray.direction, f.forward), 1e-3f);
  return ray.origin + ray.direction * (f.distance / cosine);
}

OrbitView zoom_towards(const OrbitView& view, glm::vec3 point, float factor) {
  if (!(factor > 0.0f)) return view;
  const float from = clamped_zoom(view.zoom), to = clamped_zoom(from * factor);
  const float s = to / from;
  // Eye and target scaled about `point` by s: the direction from the eye to `point` is unchanged.
  OrbitView v = view;
  v.target = point + s * (view.target - point);
  v.zoom = to;
  return v;
}

OrbitView pan_view(const OrbitView& view, float radius, float aspect, glm::vec2 ndc_delta) {
  const CameraFrame f = camera_frame(view, radius, aspect);
  // Half the pane's width and height at the target's depth, in scene units per NDC unit.
  const float sx = f.distance * f.tan_half_fovx, sy = f.distance * f.tan_half_fovy;
  OrbitView v = view;
  // The scene follows the cursor, so the camera and its target move the other way.
  v.target -= f.right * (ndc_delta.x * sx) + f.up * (ndc_delta.y * sy);
  return v;
}

OrbitView frame_view(const OrbitView& view) {
  OrbitView v = view;
  v.target = glm::vec3(0.0f);
  v.zoom = 1.0f;
  return v;
}

OrbitView frame_point(const OrbitView& view, glm::vec3 point) {
  OrbitView v = view;
  v.target = point;
  v.zoom = kSelectionZoom;
  return v;
}

std::optional<glm::vec2> project_point(const OrbitView& view, float radius, float aspect, glm::vec3 point) {
  const CameraFrame f = camera_frame(view, radius, aspect);
  const glm::vec3 d = point - f.eye;
  const float depth = glm::dot(d, f.forward);
  if (!(depth > 0.0f)) return std::nullopt;
  return glm::vec2(glm::dot(d, f.right) / (depth * f.tan_half_fovx), glm::dot(d, f.up) / (depth * f.tan_half_fovy));
}

std::optional<float> intersect_triangle(const Ray& ray, glm::vec3 a, glm::vec3 b, glm::vec3 c) {
  const glm::vec3 e1 = b - a, e2 = c - a;
  const glm::vec3 p = glm::cross(ray.direction, e2);
  const float det = glm::dot(e1, p);
  // Parallel to the plane, or a degenerate triangle (relative to the edges' lengths).
  if (!(std::abs(det) > 1e-7f * glm::length(e1) * glm::length(e2))) return std::nullopt;
  const float inv = 1.0f / det;
  const glm::vec3 s = ray.origin - a;
  const float u = glm::dot(s, p) * inv;
  if (u < 0.0f || u > 1.0f) return std::nullopt;
  const glm::vec3 q = glm::cross(s, e1);
  const float v = glm::dot(ray.direction, q) * inv;
  if (v < 0.0f || u + v > 1.0f) return std::nullopt;
  const float t = glm::dot(e2, q) * inv;
  if (!(t > 0.0f) || !std::isfinite(t)) return std::nullopt;
  return t;
}

ViewOption parse_view_option(const std::string& text) {
  const std::string got = ", got '" + nmbake::printable(text) + "'";
  std::vector<std::string> items;
  std::size_t at = 0;
  while (true) {
    const std::size_t end = std::min(text.find(',', at), text.size());
    std::string item = text.substr(at, end - at);
    // Blanks around a number are allowed, as "30, 20" always was.
    item.erase(0, std::min(item.find_first_not_of(" \t"), item.size()));
    item.erase(item.find_last_not_of(" \t") + 1);
    items.push_back(item);
    if (end == text.size()) break;
    at = end + 1;
  }
  std::vector<float> numbers;
  for (const std::string& item : items) {
    const double x = nmbake::is_number(item, false) ? std::strtod(item.c_str(), nullptr) : NAN;
    if (!std::isfinite(x) || std::abs(x) > 1e30)
      throw nmbake::UsageError("--view: " + std::string(kViewForms) + got + " ('" + nmbake::printable(item) +
                               "' is not a finite number)");
    numbers.push_back(float(x));
  }
  if (numbers.size() != 2 && numbers.size() != 3 && numbers.size() != 6)
    throw nmbake::UsageError("--view: " + std::string(kViewForms) + got + " (" + std::to_string(numbers.size()) + " numbers)");
  ViewOption o;
  o.view.azimuth = numbers[0];
  o.view.elevation = numbers[1];
  if (numbers.size() >= 3) {
    if (!(numbers[2] >= kMinZoom && numbers[2] <= kMaxZoom))
      throw nmbake::UsageError("--view: DIST " + nmbake::printable(items[2]) +
                               " is not within 0.001..1000 (a factor of the distance that frames both models: 1 frames "
                               "them, 0.5 is twice as close)");
    o.view.zoom = numbers[2];
  }
  if (numbers.size() == 6) o.target = glm::vec3(numbers[3], numbers[4], numbers[5]);
  return o;
}

OrbitView resolve_view(const ViewOption& option, glm::vec3 scene_centre) {
  OrbitView v = option.view;
  v.target = option.target ? *option.target - scene_centre : glm::vec3(0.0f);
  return v;
}

std::string format_view_option(const OrbitView& view, glm::vec3 scene_centre) {
  const glm::vec3 t = view.target + scene_centre;
  char text[160];
  std::snprintf(text, sizeof text, "%.6g,%.6g,%.6g,%.7g,%.7g,%.7g", double(view.azimuth), double(view.elevation),
                double(clamped_zoom(view.zoom)), double(t.x), double(t.y), double(t.z));
  return text;
}

}  // namespace nmview
