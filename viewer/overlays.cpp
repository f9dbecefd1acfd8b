#include "overlays.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <utility>

#include <epoxy/gl.h>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "gl_program.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "scene.h"
#include "texture_set.h"

namespace nmview {
namespace {

namespace fs = std::filesystem;

// The mask pass: the low-poly again, each fragment the masks' paint at its UV with alpha = how
// much of it covers the model; misses over suspects.
const char* kMaskVertex = R"(
layout(location = 0) in vec3 a_position;
layout(location = 3) in vec2 a_uv;
uniform mat4 u_view_projection;
out vec2 v_uv;
void main() {
  v_uv = a_uv;
  gl_Position = u_view_projection * vec4(a_position, 1.0);
}
)";

// The masks' paint at `uv`: rgb the colour, a how much of it covers what is under it.
const char* kMaskPaint = R"(
uniform sampler2D u_miss;
uniform sampler2D u_suspect;
uniform vec3 u_miss_colour;
uniform vec3 u_suspect_colour;
uniform float u_strength;
vec4 mask_paint(vec2 uv) {
  float m = u_strength * clamp(texture(u_miss, uv).r, 0.0, 1.0);
  float s = u_strength * clamp(texture(u_suspect, uv).r, 0.0, 1.0);
  float a = m + s * (1.0 - m);
  return a > 0.0 ? vec4((u_miss_colour * m + u_suspect_colour * s * (1.0 - m)) / a, a) : vec4(0.0);
}
)";

const char* kMaskFragment = R"(
in vec2 v_uv;
out vec4 frag_color;
void main() {
  vec4 paint = mask_paint(v_uv);
  if (paint.a < 0.5 / 255.0) discard;
  frag_color = paint;
}
)";

// The UV view: the map over the UV square [0,1]^2 drawn at u_rect (pane pixels: x, y of the lower
// left corner, side), v up, with the masks' paint over it when u_masks is 1.
const char* kUvFullscreenVertex = R"(
void main() {
  vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
)";

const char* kUvMapFragment = R"(
uniform sampler2D u_map;
uniform vec3 u_rect;
uniform int u_masks;
out vec4 frag_color;
void main() {
  vec2 uv = (gl_FragCoord.xy - u_rect.xy) / u_rect.z;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) discard;
  vec3 c = texture(u_map, uv).rgb;
  if (u_masks == 1) {
    vec4 paint = mask_paint(uv);
    c = mix(c, paint.rgb, paint.a);
  }
  frag_color = vec4(c, 1.0);
}
)";

// The low-poly's triangles at their UVs: clip = uv * scale + offset.
const char* kUvEdgeVertex = R"(
layout(location = 3) in vec2 a_uv;
uniform vec4 u_uv_to_clip;  // scale xy, offset zw
void main() { gl_Position = vec4(a_uv * u_uv_to_clip.xy + u_uv_to_clip.zw, 0.0, 1.0); }
)";

const char* kCageVertex = R"(
layout(location = 0) in vec3 a_position;
uniform mat4 u_view_projection;
void main() { gl_Position = u_view_projection * vec4(a_position, 1.0); }
)";

const char* kCageFragment = R"(
uniform vec4 u_color;
out vec4 frag_color;
void main() { frag_color = u_color; }
)";

void set_view_projection(GLuint program, const CameraMatrices& camera) {
  const glm::mat4 vp = camera.projection * camera.view;
  glUniformMatrix4fv(glGetUniformLocation(program, "u_view_projection"), 1, GL_FALSE, &vp[0][0]);
}

// A path the report names, as found (see read_report_overlays); empty for null or absent.
std::string report_path_of(const nlohmann::json& options, const char* key, const char* what, const std::string& report_path) {
  const auto it = options.find(key);
  if (it == options.end() || it->is_null()) return "";
  if (!it->is_string() || it->get<std::string>().empty())
    throw nmbake::InputError(report_path + ": options." + key + " is not a path");
  const std::string named = it->get<std::string>();
  std::error_code error;
  const fs::path path(named);
  if (fs::exists(path, error)) return named;
  if (path.is_relative()) {
    const fs::path beside = fs::path(report_path).parent_path() / path;
    if (fs::exists(beside, error)) return beside.string();
  }
  throw nmbake::InputError(report_path + " names the " + what + " '" + named + "', found " +
                           (fs::path(named).is_absolute() ? "nowhere" : "neither in the current folder nor beside the report"));
}

}  // namespace

OverlayFiles read_report_overlays(const std::string& report_path) {
  std::ifstream in(report_path, std::ios::binary);
  if (!in) throw nmbake::InputError(report_path + ": cannot read the report");
  nlohmann::json report;
  try {
    in >> report;
  } catch (const nlohmann::json::exception&) {
    throw nmbake::InputError(report_path + ": not JSON; expected the report nmbake --report wrote");
  }
  if (!report.is_object() || !report.contains("options") || !report["options"].is_object())
    throw nmbake::InputError(report_path +
                             ": not a bake's report (no \"options\"); expected the report nmbake --report "
                             "wrote for one bake");
  const nlohmann::json& options = report["options"];
  OverlayFiles files;
  files.report = report_path;
  files.miss_mask = report_path_of(options, "miss_mask", "miss mask", report_path);
  files.suspect_mask = report_path_of(options, "suspect_mask", "suspect mask", report_path);
  files.cage = report_path_of(options, "cage", "cage", report_path);
  // A bake with the automatic cage that saved it (--save-cage): that file is the cage it used.
  if (files.cage.empty()) files.cage = report_path_of(options, "save_cage", "saved cage", report_path);
  return files;
}

OverlayFiles merge_overlay_files(const OverlayFiles& explicit_files, const OverlayFiles& report) {
  OverlayFiles merged = explicit_files;
  if (merged.miss_mask.empty()) merged.miss_mask = report.miss_mask;
  if (merged.suspect_mask.empty()) merged.suspect_mask = report.suspect_mask;
  if (merged.cage.empty()) merged.cage = report.cage;
  merged.report = report.report;
  return merged;
}

std::vector<nmbake::NamedFile> overlay_inputs(const OverlayFiles& files) {
  std::vector<nmbake::NamedFile> inputs;
  if (!files.report.empty()) inputs.push_back({"", files.report, "the report"});
  if (!files.miss_mask.empty()) inputs.push_back({"", files.miss_mask, "the miss mask"});
  if (!files.suspect_mask.empty()) inputs.push_back({"", files.suspect_mask, "the suspect mask"});
  if (!files.cage.empty()) inputs.push_back({"", files.cage, "the cage"});
  return inputs;
}

std::vector<std::uint32_t> unique_edges(const std::vector<std::uint32_t>& indices) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  edges.reserve(indices.size());
  for (std::size_t t = 0; t + 2 < indices.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = indices[t + std::size_t(k)], b = indices[t + std::size_t((k + 1) % 3)];
      if (a != b) edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<std::uint32_t> out;
  out.reserve(2 * edges.size());
  for (const auto& [a, b] : edges) {
    out.push_back(a);
    out.push_back(b);
  }
  return out;
}

OverlayData load_overlays(const OverlayFiles& files, const Scene& scene, std::ostream& log) {
  OverlayData data;
  if (!files.miss_mask.empty()) data.miss_mask = nmbake::read_image(files.miss_mask);
  if (!files.suspect_mask.empty()) data.suspect_mask = nmbake::read_image(files.suspect_mask);
  for (const auto& [image, path] : {std::pair{&data.miss_mask, &files.miss_mask}, {&data.suspect_mask, &files.suspect_mask}})
    if (!path->empty() && (image->width <= 0 || image->height <= 0 || image->channels < 1))
      throw nmbake::InputError(*path + ": empty image");
  if (!files.cage.empty()) {
    nmbake::LoadOptions options;  // on the low-poly's origin, as nmbake loads a cage
    options.origin = scene.origin;
    const nmbake::Mesh cage = nmbake::load_mesh(files.cage, options);
    const glm::vec3 centre = scene.bounds.centre();
    data.cage_positions.reserve(cage.positions.size());
    for (const glm::vec3& p : cage.positions) data.cage_positions.push_back(p - centre);
    data.cage_edges = unique_edges(cage.position_index);
    data.cage_triangles = cage.triangle_count();
    if (data.cage_triangles != scene.low_triangles)
      log << "nmview: warning: " << files.cage << ": " << data.cage_triangles << " triangles, the low-poly "
          << scene.low_triangles << "; a cage has the low-poly's topology (drawn all the same)\n";
    else log << "nmview: cage " << files.cage << ": " << data.cage_triangles << " triangles\n";
  }
  return data;
}

std::string overlay_legend(bool masks, bool cage, const OverlayData& data) {
  std::string line;
  auto add = [&](const std::string& item) { line += (line.empty() ? "" : "  ") + item; };
  if (masks && data.has_miss()) add("MAGENTA: MISS");
  if (masks && data.has_suspect()) add("ORANGE: SUSPECT");
  if (cage && data.has_cage()) add("GREEN: CAGE");
  return line;
}

OverlayRenderer::OverlayRenderer(const OverlayData& data) {
  mask_program_ = link_program(kMaskVertex, kMaskFragment, "masks", kMaskPaint);
  cage_program_ = link_program(kCageVertex, kCageFragment, "cage");
  uv_map_program_ = link_program(kUvFullscreenVertex, kUvMapFragment, "uv map", kMaskPaint);
  uv_edge_program_ = link_program(kUvEdgeVertex, kCageFragment, "uv edges");
  if (data.has_miss()) miss_ = upload_rgb_texture(data.miss_mask, "the miss mask", TextureSampling::texels_magnified);
  if (data.has_suspect()) suspect_ = upload_rgb_texture(data.suspect_mask, "the suspect mask", TextureSampling::texels_magnified);
  const float black[3] = {0.0f, 0.0f, 0.0f};
  glGenTextures(1, &fallback_);
  glBindTexture(GL_TEXTURE_2D, fallback_);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB16, 1, 1, 0, GL_RGB, GL_FLOAT, black);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);

  if (data.has_cage()) {
    glGenVertexArrays(1, &cage_vao_);
    glBindVertexArray(cage_vao_);
    glGenBuffers(1, &cage_vbo_);
    glBindBuffer(GL_ARRAY_BUFFER, cage_vbo_);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.cage_positions.size() * sizeof(glm::vec3)), data.cage_positions.data(),
                 GL_STATIC_DRAW);
    glGenBuffers(1, &cage_ebo_);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, cage_ebo_);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(data.cage_edges.size() * sizeof(std::uint32_t)), data.cage_edges.data(),
                 GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, GLsizei(sizeof(glm::vec3)), nullptr);
    glBindVertexArray(0);
    cage_edge_count_ = data.cage_edges.size() / 2;
  }
  if (GLenum error = glGetError(); error == GL_OUT_OF_MEMORY)
    throw nmbake::ResourceError("out of memory uploading the overlays to OpenGL (GL_OUT_OF_MEMORY)");
  else if (error != GL_NO_ERROR)
    throw nmbake::OutputError("OpenGL error " + std::to_string(error) + " while uploading the overlays");
}

OverlayRenderer::~OverlayRenderer() {
  glDeleteProgram(mask_program_);
  glDeleteProgram(cage_program_);
  glDeleteProgram(uv_map_program_);
  glDeleteProgram(uv_edge_program_);
  for (GLuint* t : {&miss_, &suspect_, &fallback_}) glDeleteTextures(1, t);
  glDeleteVertexArrays(1, &cage_vao_);
  glDeleteBuffers(1, &cage_vbo_);
  glDeleteBuffers(1, &cage_ebo_);
}

void OverlayRenderer::bind_masks(unsigned program) const {
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, miss_ ? miss_ : fallback_);
  glActiveTexture(GL_TEXTURE2);
  glBindTexture(GL_TEXTURE_2D, suspect_ ? suspect_ : fallback_);
  glActiveTexture(GL_TEXTURE0);
  glUniform1i(glGetUniformLocation(program, "u_miss"), 1);
  glUniform1i(glGetUniformLocation(program, "u_suspect"), 2);
  glUniform3fv(glGetUniformLocation(program, "u_miss_colour"), 1, &kMissColour[0]);
  glUniform3fv(glGetUniformLocation(program, "u_suspect_colour"), 1, &kSuspectColour[0]);
  glUniform1f(glGetUniformLocation(program, "u_strength"), kMaskStrength);
}

void OverlayRenderer::draw_masks(const CameraMatrices& camera, unsigned low_vao, std::size_t index_count) const {
  if (!has_masks()) return;
  glUseProgram(mask_program_);
  set_view_projection(mask_program_, camera);
  bind_masks(mask_program_);
  // The same triangles as the fill: pulled forward so they pass LEQUAL whatever the fill's offset,
  // depth not written so the wireframe after them is tested against the fill as before.
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(-1.0f, -1.0f);
  glDepthFunc(GL_LEQUAL);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
  glBindVertexArray(low_vao);
  glDrawElements(GL_TRIANGLES, GLsizei(index_count), GL_UNSIGNED_INT, nullptr);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glDisable(GL_POLYGON_OFFSET_FILL);
}

void OverlayRenderer::draw_cage(const CameraMatrices& camera) const {
  if (!has_cage()) return;
  glUseProgram(cage_program_);
  set_view_projection(cage_program_, camera);
  glUniform4fv(glGetUniformLocation(cage_program_, "u_color"), 1, &kCageColour[0]);
  // Premultiplied over: colour by alpha, coverage grows where a line passes outside the model.
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  glDepthFunc(GL_LEQUAL);
  glBindVertexArray(cage_vao_);
  glDrawElements(GL_LINES, GLsizei(2 * cage_edge_count_), GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
  glDepthFunc(GL_LESS);
  glDisable(GL_BLEND);
}

void OverlayRenderer::draw_uv_layout(int width, int height, unsigned map_texture, unsigned low_vao, std::size_t index_count,
                                     bool masks) const {
  const UvSquare square = uv_square(width, height);
  glDisable(GL_DEPTH_TEST);
  glBindVertexArray(low_vao);  // the fullscreen triangle reads no attribute; any vertex array does
  glUseProgram(uv_map_program_);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, map_texture);
  glUniform1i(glGetUniformLocation(uv_map_program_, "u_map"), 0);
  glUniform3f(glGetUniformLocation(uv_map_program_, "u_rect"), float(square.x), float(square.y), float(square.side));
  glUniform1i(glGetUniformLocation(uv_map_program_, "u_masks"), masks && has_masks() ? 1 : 0);
  bind_masks(uv_map_program_);
  glDrawArrays(GL_TRIANGLES, 0, 3);

  // The UV edges, premultiplied over (coverage grows where a UV lies outside the square).
  glUseProgram(uv_edge_program_);
  const float sx = 2.0f * float(square.side) / float(width), sy = 2.0f * float(square.side) / float(height);
  glUniform4f(glGetUniformLocation(uv_edge_program_, "u_uv_to_clip"), sx, sy, 2.0f * float(square.x) / float(width) - 1.0f,
              2.0f * float(square.y) / float(height) - 1.0f);
  glUniform4fv(glGetUniformLocation(uv_edge_program_, "u_color"), 1, &kUvEdgeColour[0]);
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
  glDrawElements(GL_TRIANGLES, GLsizei(index_count), GL_UNSIGNED_INT, nullptr);
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glDisable(GL_BLEND);
  glBindVertexArray(0);
  glEnable(GL_DEPTH_TEST);
}

UvSquare uv_square(int width, int height) {
  const int side = std::max(std::min(width, height), 1);
  return {(width - side) / 2, (height - side) / 2, side};
}

}  // namespace nmview
