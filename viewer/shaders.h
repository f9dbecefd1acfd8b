// GLSL 3.30 core sources of nmview. Both panes share one lighting function, so the only
// difference between them is the normal fed to it.
#pragma once

namespace nmview::shaders {

// Lambert with a little ambient on a grey albedo, optional Blinn specular (0 by default so
// software rendering stays stable). Linear values, written to the framebuffer as they are (no
// sRGB encoding), with alpha 1 as the coverage mask. One-sided: a normal facing away from the
// light gets the ambient term only, on both panes alike. `occlusion` (the ao map, 1 = open)
// multiplies the Lambert term, ambient and diffuse alike, and not the specular highlight.
inline const char* kLighting = R"(
uniform vec3 u_light_dir;   // unit, towards the light, scene space
uniform vec3 u_eye;         // camera position, scene space
uniform float u_specular;   // Blinn specular weight, 0 = off
const float kAlbedo = 0.8;
const float kAmbient = 0.1;
vec3 shade(vec3 n, vec3 position, float occlusion) {
  float diffuse = max(dot(n, u_light_dir), 0.0);
  float value = occlusion * kAlbedo * (kAmbient + (1.0 - kAmbient) * diffuse);
  if (u_specular > 0.0 && diffuse > 0.0) {
    vec3 h = normalize(normalize(u_eye - position) + u_light_dir);
    value += u_specular * pow(max(dot(n, h), 0.0), 64.0);
  }
  return vec3(value);
}
)";

inline const char* kLowVertex = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_tangent;
layout(location = 3) in vec2 a_uv;
layout(location = 4) in vec3 a_bitangent;
uniform mat4 u_view_projection;
out vec3 v_position;
out vec3 v_normal;
out vec4 v_tangent;
out vec2 v_uv;
out vec3 v_bitangent;
void main() {
  v_position = a_position;
  v_normal = a_normal;
  v_tangent = a_tangent;
  v_uv = a_uv;
  v_bitangent = a_bitangent;
  gl_Position = u_view_projection * vec4(a_position, 1.0);
}
)";

// The renderer side of tangent_frames.h, verbatim: N and T interpolated and not normalized,
// B = sign * cross(N, T) per pixel, n = normalize(t.x*T + t.y*B + t.z*N) with t = texel*2-1.
// The sign is tangent.w interpolated like N and T, as nmbake::interpolate_frame does (it is +1 or
// -1 on every triangle whose corners agree, i.e. all but some UV-degenerate ones). Perspective-
// correct interpolation gives the same barycentrics the baker uses on the triangle.
// Maps baked otherwise (decoding.h): green down negates t.y, as the baker negated it; a per-vertex
// bitangent map takes B interpolated from the corners' B (computed by interpolate_frame); an
// object-space map is the normal itself (re-centring the scene does not turn directions).
// The map texture's rows are uploaded bottom-up, so texture coordinates are the mesh UVs as they
// are (v = 1 is the image's top row); so are the texture set's other maps (texture_set.h).
// Mode 3 shows one of them (u_shown) unlit, as its texels are; u_ao multiplies the lit modes by the
// ao map's value.
// u_output 1 writes the shading normal itself (xyz, alpha 1 = covered) instead of the shaded colour,
// for the angle difference (angle_metrics.h); u_swap exchanges the texel's red and green before the
// decoding, and --compare's green-flipped variant passes the opposite u_green. With UDIM tiles
// every map is read through map_texel (udim_textures.h) from the face's tile. A zero-length
// perturbed normal (a grey 0.5 texel) falls back to the interpolated normal, so no NaN is shaded.
inline const char* kLowFragment = R"(
in vec3 v_position;
in vec3 v_normal;
in vec4 v_tangent;
in vec2 v_uv;
in vec3 v_bitangent;
uniform sampler2D u_map;
uniform sampler2D u_ao_map;
uniform sampler2D u_shown;
uniform int u_mode;       // 0 = lit with the map, 1 = lit with the bare interpolated normal, 2 = map colours,
                          // 3 = u_shown's colours
uniform int u_ao;         // 1 = the lit modes times u_ao_map's red (grey) value
uniform int u_object;     // 1 = object-space map
uniform float u_green;    // +1 green up (OpenGL), -1 green down (DirectX)
uniform int u_bitangent;  // 0 = per pixel, 1 = per vertex
uniform int u_output;     // 0 = colour, 1 = the shading normal (modes 0 and 1)
uniform int u_swap;       // 1 = the texel's red and green exchanged before decoding
out vec4 frag_color;
vec3 unit_or(vec3 v, vec3 fallback) {
  float l = length(v);
  return l > 1e-12 ? v / l : fallback;
}
void main() {
  vec3 N = v_normal;
  vec3 T = v_tangent.xyz;
  bool found = true;  // with UDIM tiles (udim_textures.h): the face's tile has a file of that map
  if (u_mode == 3) {
    vec3 shown = map_texel(u_shown, u_shown_tiles, 2, v_uv, found).rgb;
    frag_color = vec4(found ? shown : kMissingTile, 1.0);
    return;
  }
  vec3 texel = map_texel(u_map, u_map_tiles, 0, v_uv, found).rgb;
  if (!found && u_mode != 1) {
    // No normal map on this face: the missing-tile colour; as a normal, the bare one marked w = 2.
    frag_color = u_output == 1 ? vec4(unit_or(N, vec3(0.0, 0.0, 1.0)), 2.0) : vec4(kMissingTile, 1.0);
    return;
  }
  if (u_mode == 2) {
    frag_color = vec4(texel, 1.0);
    return;
  }
  vec3 bare = unit_or(N, vec3(0.0, 0.0, 1.0));
  vec3 n;
  vec3 t = texel * 2.0 - 1.0;
  if (u_swap == 1) t.xy = t.yx;
  if (u_mode == 0 && u_object == 1) {
    t.y *= u_green;
    n = unit_or(t, bare);
  } else if (u_mode == 0) {
    vec3 B = u_bitangent == 1 ? v_bitangent : v_tangent.w * cross(N, T);
    t.y *= u_green;
    n = unit_or(t.x * T + t.y * B + t.z * N, bare);
  } else {
    n = bare;
  }
  if (u_output == 1) {
    frag_color = vec4(n, 1.0);
    return;
  }
  float ao = map_texel(u_ao_map, u_ao_tiles, 1, v_uv, found).r;
  float occlusion = u_ao == 1 && found ? ao : 1.0;
  frag_color = vec4(shade(n, v_position, occlusion), 1.0);
}
)";

inline const char* kHighVertex = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_view_projection;
out vec3 v_position;
out vec3 v_normal;
void main() {
  v_position = a_position;
  v_normal = a_normal;
  gl_Position = u_view_projection * vec4(a_position, 1.0);
}
)";

inline const char* kHighFragment = R"(
in vec3 v_position;
in vec3 v_normal;
uniform int u_output;  // 0 = colour, 1 = the unit normal (alpha 1 = covered)
out vec4 frag_color;
void main() {
  float l = length(v_normal);
  vec3 n = l > 1e-12 ? v_normal / l : vec3(0.0, 0.0, 1.0);
  frag_color = u_output == 1 ? vec4(n, 1.0) : vec4(shade(n, v_position, 1.0), 1.0);
}
)";

// Wireframe overlay: the triangles again as lines, in one flat colour.
inline const char* kWireVertex = R"(
layout(location = 0) in vec3 a_position;
uniform mat4 u_view_projection;
void main() { gl_Position = u_view_projection * vec4(a_position, 1.0); }
)";

inline const char* kFlatFragment = R"(
uniform vec4 u_color;
out vec4 frag_color;
void main() { frag_color = u_color; }
)";

// A triangle covering the viewport; the fragment shaders read gl_FragCoord.
inline const char* kFullscreenVertex = R"(
void main() {
  vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
)";

inline const char* kBackgroundFragment = R"(
uniform float u_height;
out vec4 frag_color;
void main() {
  float s = gl_FragCoord.y / max(u_height, 1.0);
  frag_color = vec4(vec3(mix(0.13, 0.30, s)), 1.0);
}
)";

// A pane texture (premultiplied over black, alpha = coverage) copied texel for texel.
inline const char* kPaneFragment = R"(
uniform sampler2D u_pane;
uniform ivec2 u_origin;  // the pane's lower-left corner in the target, pixels
out vec4 frag_color;
void main() { frag_color = texelFetch(u_pane, ivec2(gl_FragCoord.xy) - u_origin, 0); }
)";

// The angle colour scale of angle_metrics.h (angle_colour): v = angle / scale clamped to 0..1,
// black -> red -> yellow -> white, r + g + b = 3v.
inline const char* kAngleColour = R"(
vec3 angle_colour(float v) {
  v = clamp(v, 0.0, 1.0);
  return clamp(vec3(3.0 * v, 3.0 * v - 1.0, 3.0 * v - 2.0), 0.0, 1.0);
}
)";

// The difference pane: per pixel the angle between the two models' normals (Renderer's normal
// targets, single-sample float, alpha = coverage) on the angle colour scale up to u_scale degrees.
// Pixels only one model covers (the silhouette mismatch, which no map can fix) are kOneModelColour
// (angle_metrics.h), so they are not read as shading error. atan2(|a x b|, a.b) as
// angle_between_degrees, well conditioned near 0.
inline const char* kDifferenceFragment = R"(
uniform sampler2D u_low_normals;
uniform sampler2D u_high_normals;
uniform ivec2 u_origin;
uniform float u_scale;  // degrees at the top of the scale
out vec4 frag_color;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy) - u_origin;
  vec4 a = texelFetch(u_low_normals, p, 0);
  vec4 b = texelFetch(u_high_normals, p, 0);
  bool in_a = a.a > 0.5, in_b = b.a > 0.5;
  if (!in_a && !in_b) discard;
  if (!in_a || !in_b) {
    frag_color = vec4(0.15, 0.35, 0.85, 1.0);
    return;
  }
  if (a.a > 1.5) {  // a face of a UDIM tile without a normal map (kMissingTileColour)
    frag_color = vec4(1.0, 0.0, 1.0, 1.0);
    return;
  }
  float angle = degrees(atan(length(cross(a.xyz, b.xyz)), dot(a.xyz, b.xyz)));
  frag_color = vec4(angle_colour(angle / max(u_scale, 1e-6)), 1.0);
}
)";

// The colour scale's legend: a bar from 0 on the left to u_scale at the right of the viewport.
inline const char* kLegendFragment = R"(
uniform ivec2 u_origin;
uniform float u_width;  // pixels
out vec4 frag_color;
void main() { frag_color = vec4(angle_colour((gl_FragCoord.x - float(u_origin.x)) / max(u_width - 1.0, 1.0)), 1.0); }
)";

// Text squares in window pixels, y down.
inline const char* kTextVertex = R"(
layout(location = 0) in vec2 a_pixel;
uniform vec2 u_target_size;
uniform vec2 u_offset;
void main() {
  vec2 p = (a_pixel + u_offset) / u_target_size;
  gl_Position = vec4(p.x * 2.0 - 1.0, 1.0 - p.y * 2.0, 0.0, 1.0);
}
)";

}  // namespace nmview::shaders
