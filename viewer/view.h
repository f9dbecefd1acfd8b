// The orbit camera and the light shared by both panes (CPU math only).
//
// Y is up (the sculpts are Y up). The camera orbits a target point, by default the centre of the
// union bounding box of both meshes: azimuth turns about +Y starting from +Z towards +X, elevation
// lifts towards +Y, so (0, 0) looks at the target from +Z and (0, 90) from straight above. Positions
// on the GPU are already re-centred on that centre (vertex_data.h), so every point here (target,
// eye, rays) is in the re-centred scene: object space minus Scene::bounds.centre().
//
// The distance from the target is a factor of the framing distance (zoom): at 1 the sphere of
// `radius` around the scene centre just fits the pane, with a 5 % margin, whatever the mesh's
// units; 0.5 is half as far (the model twice as large). Zooming towards a point scales the camera
// and the target about that point, so the point stays under the cursor; panning moves the target
// in the view plane, so the point at the target's depth follows the cursor.
//
// The light is a directional light attached to the camera: its azimuth/elevation are measured
// from the viewing direction (0,0 = light from the eye; positive azimuth = from the right,
// positive elevation = from above), so every view, including --compare's, is lit from the front.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "vertex_data.h"

namespace nmview {

constexpr float kMinZoom = 1e-3f;  // closest: a thousandth of the framing distance
constexpr float kMaxZoom = 1e3f;   // farthest: a thousand framing distances

struct OrbitView {
  float azimuth = 30.0f;    // degrees
  float elevation = 20.0f;  // degrees, any value (the matrices have no pole singularity)
  float zoom = 1.0f;        // distance from the target as a factor of the framing distance, 1 frames
                            // both models, < 1 is closer; used clamped to [kMinZoom, kMaxZoom]
  glm::vec3 target{0.0f};   // the point looked at and orbited, re-centred scene (0 = the scene centre)
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

// The camera's position and unit axes in the re-centred scene (right, up, forward = towards the
// target), its distance from the target in scene units, and the tangents of half its fields of view.
struct CameraFrame {
  glm::vec3 eye, right, up, forward;
  float distance = 1.0f;
  float tan_half_fovy = 0.0f, tan_half_fovx = 0.0f;
};

// Distance at which a sphere of `radius` fits a pane of `aspect` = width / height (vertical field of
// view 30 degrees; the sphere also fits horizontally), with a 5 % margin: zoom 1's distance.
float framing_distance(float radius, float aspect);

CameraFrame camera_frame(const OrbitView& view, float radius, float aspect);

// Camera matrices for a pane of `aspect` = width / height; `radius` is the scene's bounding radius
// around the origin (the framing distance, and near and far planes that hug that sphere).
CameraMatrices camera_matrices(const OrbitView& view, const Light& light, float radius, float aspect);

// Unit direction of (azimuth, elevation) in degrees: (sin az cos el, sin el, cos az cos el).
glm::vec3 direction_from_angles(float azimuth_deg, float elevation_deg);

// The fixed views of --compare: 8 azimuths 45 degrees apart at 20 degrees elevation, then the top
// (+90) and the bottom (-90), each framing both models around the scene centre.
std::vector<OrbitView> compare_views();

// A ray in the re-centred scene; `direction` is unit length.
struct Ray {
  glm::vec3 origin, direction;
};

// The ray from the eye through `ndc`, the pane point in normalized device coordinates (-1..1,
// x to the right, y up; (0,0) is the pane's centre, where the target is).
Ray cursor_ray(const OrbitView& view, float radius, float aspect, glm::vec2 ndc);

// The point of `ray` at the target's depth (in the plane through the target facing the camera):
// what the wheel zooms towards where the cursor is over no model.
glm::vec3 point_at_target_depth(const OrbitView& view, float radius, float aspect, const Ray& ray);

// The view moved towards `point` (re-centred scene) by `factor` of its distance (0.5: half as far),
// camera and target scaled about `point`, so `point` projects where it did. The factor is reduced
// so the zoom stays within [kMinZoom, kMaxZoom]; factor <= 0 changes nothing.
OrbitView zoom_towards(const OrbitView& view, glm::vec3 point, float factor);

// The view whose target moved in the view plane so that what was at `ndc` at the target's depth is
// at `ndc + ndc_delta` (the cursor's move in normalized device coordinates, y up).
OrbitView pan_view(const OrbitView& view, float radius, float aspect, glm::vec2 ndc_delta);

// The view framing both models: the target back at the scene centre and zoom 1, the angles kept.
OrbitView frame_view(const OrbitView& view);

// How close F frames a selection: the zoom that fits a sphere of this share of the scene's radius
// around the selected point (a tenth: the point's neighbourhood, whatever the mesh's units).
constexpr float kSelectionZoom = 0.1f;

// The view framing a selected `point` (re-centred scene): the target at it, so it is the pane's
// centre, and zoom kSelectionZoom; the angles kept.
OrbitView frame_point(const OrbitView& view, glm::vec3 point);

// Where `point` (re-centred scene) projects in a pane of `aspect`: normalized device coordinates
// (view.h's -1..1, y up; outside that range off the pane), or nullopt when it is not in front of the
// camera (at or behind the eye's plane).
std::optional<glm::vec2> project_point(const OrbitView& view, float radius, float aspect, glm::vec3 point);

// Distance along `ray` to triangle (a, b, c), either side facing, if the ray crosses it at t > 0
// (Moller and Trumbore 1997). Degenerate triangles are never hit.
std::optional<float> intersect_triangle(const Ray& ray, glm::vec3 a, glm::vec3 b, glm::vec3 c);

// Distance along `ray` to the nearest triangle of `mesh` it crosses, if any. Brute force over every
// triangle (measured: about 55 ms per million on one core of the build machine): for one pick per
// frame, not per pixel.
template <class V>
std::optional<float> nearest_hit(const Ray& ray, const IndexedVertices<V>& mesh) {
  std::optional<float> nearest;
  for (std::size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
    const std::optional<float> t =
        intersect_triangle(ray, mesh.vertices[mesh.indices[i]].position, mesh.vertices[mesh.indices[i + 1]].position,
                           mesh.vertices[mesh.indices[i + 2]].position);
    if (t && (!nearest || *t < *nearest)) nearest = t;
  }
  return nearest;
}

// --view's value, "AZ,EL[,DIST[,TX,TY,TZ]]": angles in degrees, DIST the zoom (a factor of the
// framing distance, 1 when absent), TX,TY,TZ the target in the meshes' own object space (the scene
// centre when absent).
struct ViewOption {
  OrbitView view;                   // target left at 0 (re-centred) until resolve_view
  std::optional<glm::vec3> target;  // object space, when given
};

// Throws nmbake::UsageError (one line, quoting the value) for anything but 2, 3 or 6 finite numbers
// separated by commas, or a DIST outside [kMinZoom, kMaxZoom].
ViewOption parse_view_option(const std::string& text);

// The option's view with its target re-centred on `scene_centre` (Scene::bounds.centre()).
OrbitView resolve_view(const ViewOption& option, glm::vec3 scene_centre);

// `view` as the --view value that reproduces it ("AZ,EL,DIST,TX,TY,TZ", target in object space).
std::string format_view_option(const OrbitView& view, glm::vec3 scene_centre);

}  // namespace nmview
