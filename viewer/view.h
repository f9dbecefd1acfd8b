// The orbit camera and the light shared by both panes (CPU math only).
//
// Y is up (the sculpts are Y up). The camera orbits the centre of the union bounding box of both
// meshes: azimuth turns about +Y starting from +Z towards +X, elevation lifts towards +Y, so
// (0, 0) looks at the object from +Z and (0, 90) from straight above. Positions on the GPU are
// already re-centred, so the orbit centre is the origin there.
//
// The light is a directional light attached to the camera: its azimuth/elevation are measured
// from the viewing direction (0,0 = light from the eye; positive azimuth = from the right,
// positive elevation = from above), so every view, including --compare's, is lit from the front.
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace nmview {

struct OrbitView {
  float azimuth = 30.0f;    // degrees
  float elevation = 20.0f;  // degrees, any value (the matrices have no pole singularity)
  float zoom = 1.0f;        // distance factor; 1 frames the union bounding sphere, < 1 is closer
};

struct Light {
  float azimuth = -30.0f;   // degrees, relative to the view direction (negative = from the left)
  float elevation = 30.0f;  // degrees, relative to the view direction
};

struct CameraMatrices {
  glm::mat4 view;        // scene (re-centred) to eye
  glm::mat4 projection;  // eye to clip
  glm::vec3 eye;         // camera position in the re-centred scene
  glm::vec3 light_dir;   // unit direction towards the light, in the re-centred scene
};

// Camera matrices for a pane of `aspect` = width / height that frames a sphere of `radius`
// around the origin (vertical field of view 30 degrees; the sphere also fits horizontally).
CameraMatrices camera_matrices(const OrbitView& view, const Light& light, float radius, float aspect);

// Unit direction of (azimuth, elevation) in degrees: (sin az cos el, sin el, cos az cos el).
glm::vec3 direction_from_angles(float azimuth_deg, float elevation_deg);

// The fixed views of --compare: 8 azimuths 45 degrees apart at 20 degrees elevation, then the top
// (+90) and the bottom (-90).
std::vector<OrbitView> compare_views();

}  // namespace nmview
