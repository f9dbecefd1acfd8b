#include "view.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace nmview {

glm::vec3 direction_from_angles(float azimuth_deg, float elevation_deg) {
  float az = glm::radians(azimuth_deg), el = glm::radians(elevation_deg);
  return {std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)};
}

CameraMatrices camera_matrices(const OrbitView& view, const Light& light, float radius, float aspect) {
  radius = std::max(radius, 1e-20f);
  aspect = std::max(aspect, 1e-3f);
  const float fovy = glm::radians(30.0f);
  const float fovx = 2.0f * std::atan(std::tan(0.5f * fovy) * aspect);
  // Distance at which the bounding sphere just fits the narrower field of view, with a margin.
  const float fit = radius / std::sin(0.5f * std::min(fovy, fovx));
  const float distance = 1.05f * fit * std::max(view.zoom, 1e-3f);

  // Camera to scene: rotate about Y by azimuth, about X by -elevation, step back along +Z.
  glm::mat4 orbit = glm::rotate(glm::mat4(1.0f), glm::radians(view.azimuth), glm::vec3(0, 1, 0));
  orbit = glm::rotate(orbit, glm::radians(-view.elevation), glm::vec3(1, 0, 0));

  CameraMatrices m;
  m.view = glm::translate(glm::mat4(1.0f), glm::vec3(0, 0, -distance)) * glm::transpose(orbit);
  m.eye = glm::vec3(orbit * glm::vec4(0, 0, distance, 1));
  m.light_dir = glm::normalize(glm::vec3(orbit * glm::vec4(direction_from_angles(light.azimuth, light.elevation), 0)));

  // Near and far hug the bounding sphere; a zoom inside the sphere keeps a small positive near.
  float near_plane = std::max(distance - 1.05f * radius, 1e-3f * radius);
  float far_plane = distance + 1.05f * radius;
  m.projection = glm::perspective(fovy, aspect, near_plane, far_plane);
  return m;
}

std::vector<OrbitView> compare_views() {
  std::vector<OrbitView> views;
  for (int i = 0; i < 8; ++i) views.push_back({45.0f * float(i), 20.0f, 1.0f});
  views.push_back({0.0f, 90.0f, 1.0f});
  views.push_back({0.0f, -90.0f, 1.0f});
  return views;
}

}  // namespace nmview
