#include "renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include <epoxy/gl.h>

#include "core/errors.h"
#include "font.h"
#include "gl_program.h"
#include "overlays.h"
#include "shaders.h"
#include "texture_set.h"
#include "udim_textures.h"

namespace nmview {
namespace {

GLint uniform(GLuint program, const char* name) { return glGetUniformLocation(program, name); }

// Uploads vertices and indices once; `attributes` lists (location, float count) in vertex order.
template <class V>
void upload(const IndexedVertices<V>& data, std::initializer_list<std::pair<GLuint, GLint>> attributes, GLuint& vao, GLuint& vbo,
            GLuint& ebo) {
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glGenBuffers(1, &vbo);
  glBindBuffer(GL_ARRAY_BUFFER, vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.vertices.size() * sizeof(V)), data.vertices.data(), GL_STATIC_DRAW);
  glGenBuffers(1, &ebo);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(data.indices.size() * sizeof(std::uint32_t)), data.indices.data(),
               GL_STATIC_DRAW);
  std::size_t offset = 0;
  for (auto [location, count] : attributes) {
    glEnableVertexAttribArray(location);
    glVertexAttribPointer(location, count, GL_FLOAT, GL_FALSE, GLsizei(sizeof(V)), reinterpret_cast<const void*>(offset));
    offset += std::size_t(count) * sizeof(float);
  }
  glBindVertexArray(0);
}

void set_camera(GLuint program, const CameraMatrices& camera) {
  glm::mat4 vp = camera.projection * camera.view;
  glUniformMatrix4fv(uniform(program, "u_view_projection"), 1, GL_FALSE, &vp[0][0]);
  GLint light = uniform(program, "u_light_dir");
  if (light >= 0) glUniform3fv(light, 1, &camera.light_dir[0]);
  GLint eye = uniform(program, "u_eye");
  if (eye >= 0) glUniform3fv(eye, 1, &camera.eye[0]);
}

}  // namespace

std::string with_thousands(std::size_t n) {
  std::string digits = std::to_string(n), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

Framebuffer::Framebuffer(int width, int height) {
  glGenFramebuffers(1, &fbo_);
  glGenRenderbuffers(1, &color_);
  glBindRenderbuffer(GL_RENDERBUFFER, color_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_);
  bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (!complete)
    throw nmbake::OutputError("cannot create a " + std::to_string(width) + "x" + std::to_string(height) + " framebuffer");
}

Framebuffer::~Framebuffer() {
  glDeleteFramebuffers(1, &fbo_);
  glDeleteRenderbuffers(1, &color_);
}

std::vector<Rect> pane_layout(int width, int height, bool difference) {
  // Equal widths (the pane textures are shared); leftover columns split between the two sides.
  const int count = difference ? 3 : 2;
  const int pane_width = std::max(width / count, 1);
  const int left = (width - pane_width * count) / 2;
  std::vector<Rect> panes;
  for (int i = 0; i < count; ++i) panes.push_back({left + i * pane_width, 0, pane_width, height});
  return panes;
}

Renderer::Renderer(const LowVertices& low, const HighVertices& high, const nmbake::Image& map, float radius,
                   const MapDecoding& decoding)
    : radius_(radius), decoding_(decoding) {
  low_program_ =
      link_program(shaders::kLowVertex, shaders::kLowFragment, "low", (shaders::kLighting + udim_shader_prelude()).c_str());
  set_udim_sampler_units(low_program_);
  high_program_ = link_program(shaders::kHighVertex, shaders::kHighFragment, "high", shaders::kLighting);
  wire_program_ = link_program(shaders::kWireVertex, shaders::kFlatFragment, "wire");
  background_program_ = link_program(shaders::kFullscreenVertex, shaders::kBackgroundFragment, "background");
  pane_program_ = link_program(shaders::kFullscreenVertex, shaders::kPaneFragment, "pane");
  difference_program_ =
      link_program(shaders::kFullscreenVertex, shaders::kDifferenceFragment, "difference", shaders::kAngleColour);
  legend_program_ = link_program(shaders::kFullscreenVertex, shaders::kLegendFragment, "legend", shaders::kAngleColour);
  text_program_ = link_program(shaders::kTextVertex, shaders::kFlatFragment, "text");

  upload(low, {{0, 3}, {1, 3}, {2, 4}, {3, 2}, {4, 3}}, low_.vao, low_.vbo, low_.ebo);
  low_.index_count = low.indices.size();
  upload(high, {{0, 3}, {1, 3}}, high_.vao, high_.vbo, high_.ebo);
  high_.index_count = high.indices.size();

  map_texture_ = upload_rgb_texture(map, "the normal map", TextureSampling::smooth);

  glGenVertexArrays(1, &empty_vao_);
  glGenVertexArrays(1, &text_vao_);
  glGenBuffers(1, &text_vbo_);
  glBindVertexArray(text_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, text_vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, sizeof(glm::vec2), nullptr);
  glBindVertexArray(0);

  GLint max_samples = 1;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  samples_ = std::clamp(max_samples, 1, 4);
  if (GLenum error = glGetError(); error == GL_OUT_OF_MEMORY)
    throw nmbake::ResourceError("out of memory uploading the meshes to OpenGL (GL_OUT_OF_MEMORY)");
  else if (error != GL_NO_ERROR)
    throw nmbake::OutputError("OpenGL error " + std::to_string(error) + " while uploading the meshes");
}

void Renderer::add_set_map(nmbake::MapKind kind, const nmbake::Image& image) {
  if (kind == nmbake::MapKind::normal) return;  // the constructor's map
  unsigned& texture = set_textures_[int(kind)];
  glDeleteTextures(1, &texture);
  texture = upload_rgb_texture(image, std::string("the ") + nmbake::map_name(kind) + " map",
                               shown_texel_exact(kind) ? TextureSampling::exact : TextureSampling::smooth);
  if (GLenum error = glGetError(); error == GL_OUT_OF_MEMORY)
    throw nmbake::ResourceError(std::string("out of memory uploading the ") + nmbake::map_name(kind) +
                                " map to OpenGL (GL_OUT_OF_MEMORY)");
  else if (error != GL_NO_ERROR)
    throw nmbake::OutputError("OpenGL error " + std::to_string(error) + " while uploading the " + nmbake::map_name(kind) +
                              " map");
}

void Renderer::set_overlays(const OverlayData& data) {
  overlays_ = std::make_unique<OverlayRenderer>(data);
  for (int i = 0; i < 4; ++i) overlay_legends_[i] = overlay_legend(i & 1, i & 2, data);
}

bool Renderer::has_masks() const { return overlays_ && overlays_->has_masks(); }
bool Renderer::has_cage() const { return overlays_ && overlays_->has_cage(); }

void Renderer::set_udim_faces(const std::vector<std::int32_t>& face_cells) { udim_ = std::make_unique<UdimTextures>(face_cells); }

void Renderer::add_udim_map(nmbake::MapKind kind, const std::vector<UdimTileImage>& tiles) {
  if (udim_) udim_->add(kind, tiles, kind != nmbake::MapKind::normal && shown_texel_exact(kind));
  if (udim_ && kind == nmbake::MapKind::normal) {
    std::vector<int> numbers;
    for (const UdimTileImage& t : tiles) numbers.push_back(t.number);
    udim_label_ = udim_range_label(numbers);
  }
}

bool Renderer::has_map(nmbake::MapKind kind) const { return kind == nmbake::MapKind::normal || set_textures_[int(kind)] != 0; }

std::vector<nmbake::MapKind> Renderer::shown_maps() const {
  std::vector<nmbake::MapKind> kinds;
  for (int k = 0; k < nmbake::kMapKinds; ++k)
    if (has_map(nmbake::MapKind(k))) kinds.push_back(nmbake::MapKind(k));
  return kinds;
}

Renderer::~Renderer() {
  for (Pane& p : panes_) {
    glDeleteFramebuffers(1, &p.msaa_fbo);
    glDeleteRenderbuffers(1, &p.msaa_color);
    glDeleteRenderbuffers(1, &p.msaa_depth);
    glDeleteFramebuffers(1, &p.fbo);
    glDeleteTextures(1, &p.texture);
    glDeleteFramebuffers(1, &p.normal_fbo);
    glDeleteTextures(1, &p.normal_texture);
    glDeleteRenderbuffers(1, &p.normal_depth);
  }
  for (Model* m : {&low_, &high_}) {
    glDeleteVertexArrays(1, &m->vao);
    glDeleteBuffers(1, &m->vbo);
    glDeleteBuffers(1, &m->ebo);
  }
  glDeleteTextures(1, &map_texture_);
  glDeleteTextures(nmbake::kMapKinds, set_textures_);
  glDeleteVertexArrays(1, &empty_vao_);
  glDeleteVertexArrays(1, &text_vao_);
  glDeleteBuffers(1, &text_vbo_);
  for (GLuint p : {low_program_, high_program_, wire_program_, background_program_, pane_program_, difference_program_,
                   text_program_, legend_program_})
    glDeleteProgram(p);
}

void Renderer::ensure_pane_size(int width, int height) {
  width = std::max(width, 1);
  height = std::max(height, 1);
  if (width == pane_width_ && height == pane_height_) return;
  pane_width_ = width;
  pane_height_ = height;
  for (Pane& p : panes_) {
    if (!p.msaa_fbo) {
      glGenFramebuffers(1, &p.msaa_fbo);
      glGenRenderbuffers(1, &p.msaa_color);
      glGenRenderbuffers(1, &p.msaa_depth);
      glGenFramebuffers(1, &p.fbo);
      glGenTextures(1, &p.texture);
      glGenFramebuffers(1, &p.normal_fbo);
      glGenTextures(1, &p.normal_texture);
      glGenRenderbuffers(1, &p.normal_depth);
    }
    glBindRenderbuffer(GL_RENDERBUFFER, p.msaa_color);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, p.msaa_depth);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, p.msaa_fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, p.msaa_color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, p.msaa_depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw nmbake::OutputError("cannot create a " + std::to_string(width) + "x" + std::to_string(height) +
                                " multisampled framebuffer");

    glBindTexture(GL_TEXTURE_2D, p.texture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, p.fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, p.texture, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw nmbake::OutputError("cannot create a " + std::to_string(width) + "x" + std::to_string(height) + " framebuffer");

    // Normals are not multisampled: a resolve would average two surfaces' normals at an edge.
    glBindTexture(GL_TEXTURE_2D, p.normal_texture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindRenderbuffer(GL_RENDERBUFFER, p.normal_depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, p.normal_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, p.normal_texture, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, p.normal_depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw nmbake::OutputError("cannot create a " + std::to_string(width) + "x" + std::to_string(height) +
                                " float framebuffer for the normals");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void Renderer::draw_model(int which, const CameraMatrices& camera, const Toggles& toggles, MapVariant variant, bool normals) {
  const Model& model = which == 0 ? low_ : high_;
  GLuint program = which == 0 ? low_program_ : high_program_;
  glUseProgram(program);
  set_camera(program, camera);
  glUniform1f(uniform(program, "u_specular"), toggles.specular);
  glUniform1i(uniform(program, "u_output"), normals ? 1 : 0);
  // A map shown texel-exact is drawn without multisampling: every sample of a pixel then takes
  // the fragment's one colour, so the resolve cannot blend two IDs.
  bool single_sample = false;
  if (which == 0) {
    const bool show = toggles.show_map && has_map(toggles.shown);
    const unsigned ao = set_textures_[int(nmbake::MapKind::ao)];
    const unsigned shown = show && toggles.shown != nmbake::MapKind::normal ? set_textures_[int(toggles.shown)] : map_texture_;
    single_sample = show && shown_texel_exact(toggles.shown);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, map_texture_);
    glUniform1i(uniform(program, "u_map"), 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, ao ? ao : map_texture_);
    glUniform1i(uniform(program, "u_ao_map"), 1);
    glUniform1i(uniform(program, "u_ao"), toggles.ao && ao ? 1 : 0);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, shown);
    glUniform1i(uniform(program, "u_shown"), 2);
    glActiveTexture(GL_TEXTURE0);
    if (udim_) udim_->bind(program, show ? toggles.shown : nmbake::MapKind::normal);
    const int lit_mode = toggles.map && variant != MapVariant::no_map ? 0 : 1;
    glUniform1i(uniform(program, "u_mode"), normals ? lit_mode : show ? 3 : toggles.tangent_colours ? 2 : lit_mode);
    glUniform1i(uniform(program, "u_object"), decoding_.object_space ? 1 : 0);
    const float green = decoding_.green_down ? -1.0f : 1.0f;
    glUniform1f(uniform(program, "u_green"), variant == MapVariant::green_flipped ? -green : green);
    glUniform1i(uniform(program, "u_swap"), variant == MapVariant::swapped ? 1 : 0);
    glUniform1i(uniform(program, "u_bitangent"), decoding_.bitangent == nmbake::BitangentMode::per_vertex ? 1 : 0);
  }
  glBindVertexArray(model.vao);
  // The filled pass is pushed back a little so the wireframe lines win the depth test. The normal
  // pass never has the wireframe: lines are not a difference between the models.
  const bool wireframe = toggles.wireframe && !normals;
  if (wireframe) {
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 1.0f);
  }
  if (single_sample) glDisable(GL_MULTISAMPLE);
  glDrawElements(GL_TRIANGLES, GLsizei(model.index_count), GL_UNSIGNED_INT, nullptr);
  glEnable(GL_MULTISAMPLE);
  glDisable(GL_POLYGON_OFFSET_FILL);
  if (which == 0 && !normals && toggles.masks && overlays_) overlays_->draw_masks(camera, model.vao, model.index_count);
  if (wireframe) {
    glUseProgram(wire_program_);
    set_camera(wire_program_, camera);
    // Half-transparent lines so a dense mesh stays readable; destination alpha (coverage) is kept.
    glUniform4f(uniform(wire_program_, "u_color"), 0.0f, 0.08f, 0.35f, 0.45f);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    glDepthFunc(GL_LEQUAL);
    glDrawElements(GL_TRIANGLES, GLsizei(model.index_count), GL_UNSIGNED_INT, nullptr);
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    glDepthFunc(GL_LESS);
    glDisable(GL_BLEND);
  }
  if (which == 0 && !normals && toggles.cage && overlays_) overlays_->draw_cage(camera);
  glBindVertexArray(0);
}

void Renderer::render_panes(int width, int height, const OrbitView& view, const Light& light, const Toggles& toggles) {
  ensure_pane_size(width, height);
  const CameraMatrices camera = camera_matrices(view, light, radius_, float(pane_width_) / float(pane_height_));
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  for (int which = 0; which < 2; ++which) {
    Pane& p = panes_[which];
    glBindFramebuffer(GL_FRAMEBUFFER, p.msaa_fbo);
    glViewport(0, 0, pane_width_, pane_height_);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    if (which == 0 && toggles.uv_layout && overlays_) {
      const bool set_map = toggles.show_map && toggles.shown != nmbake::MapKind::normal && has_map(toggles.shown);
      overlays_->draw_uv_layout(pane_width_, pane_height_, set_map ? set_textures_[int(toggles.shown)] : map_texture_, low_.vao,
                                low_.index_count, toggles.masks);
    } else {
      draw_model(which, camera, toggles);
    }
    glBindFramebuffer(GL_READ_FRAMEBUFFER, p.msaa_fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, p.fbo);
    glBlitFramebuffer(0, 0, pane_width_, pane_height_, 0, 0, pane_width_, pane_height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDisable(GL_DEPTH_TEST);
}

Rgba8Image Renderer::read_pane(int which) const { return read_framebuffer(panes_[which].fbo, pane_width_, pane_height_); }

void Renderer::render_normals(int width, int height, const OrbitView& view, MapVariant variant, int which_models) {
  ensure_pane_size(width, height);
  const CameraMatrices camera = camera_matrices(view, Light{}, radius_, float(pane_width_) / float(pane_height_));
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  Toggles plain;  // lit with the map, no wireframe, no AO: only the normal matters
  for (int which = 0; which < 2; ++which) {
    if (!(which_models & (1 << which))) continue;
    glBindFramebuffer(GL_FRAMEBUFFER, panes_[which].normal_fbo);
    glViewport(0, 0, pane_width_, pane_height_);
    glClearColor(0, 0, 0, 0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    draw_model(which, camera, plain, variant, true);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDisable(GL_DEPTH_TEST);
}

NormalImage Renderer::read_normals(int which) const {
  NormalImage image{pane_width_, pane_height_, std::vector<glm::vec4>(std::size_t(pane_width_) * std::size_t(pane_height_))};
  std::vector<glm::vec4> rows(image.pixels.size());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, panes_[which].normal_fbo);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, pane_width_, pane_height_, GL_RGBA, GL_FLOAT, rows.data());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  const std::size_t stride = std::size_t(pane_width_);
  for (int y = 0; y < pane_height_; ++y)
    std::copy_n(&rows[std::size_t(pane_height_ - 1 - y) * stride], stride, &image.pixels[std::size_t(y) * stride]);
  return image;
}

Rgba8Image Renderer::read_framebuffer(unsigned target, int width, int height) {
  Rgba8Image image{width, height, std::vector<std::uint8_t>(std::size_t(width) * std::size_t(height) * 4)};
  std::vector<std::uint8_t> rows(image.pixels.size());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, target);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rows.data());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  const std::size_t stride = std::size_t(width) * 4;
  for (int y = 0; y < height; ++y)
    std::copy_n(&rows[std::size_t(height - 1 - y) * stride], stride, &image.pixels[std::size_t(y) * stride]);
  return image;
}

void Renderer::draw_text(const std::string& text, float x, float y, float scale, int target_width, int target_height) {
  std::vector<glm::vec2> triangles;
  append_text_triangles(text, {x, y}, scale, triangles);
  if (triangles.empty()) return;
  glUseProgram(text_program_);
  glUniform2f(uniform(text_program_, "u_target_size"), float(target_width), float(target_height));
  glBindVertexArray(text_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, text_vbo_);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(triangles.size() * sizeof(glm::vec2)), triangles.data(), GL_STREAM_DRAW);
  // A dark shadow one font pixel down-right, then the text.
  glUniform2f(uniform(text_program_, "u_offset"), scale, scale);
  glUniform4f(uniform(text_program_, "u_color"), 0.0f, 0.0f, 0.0f, 1.0f);
  glDrawArrays(GL_TRIANGLES, 0, GLsizei(triangles.size()));
  glUniform2f(uniform(text_program_, "u_offset"), 0.0f, 0.0f);
  glUniform4f(uniform(text_program_, "u_color"), 0.95f, 0.95f, 0.95f, 1.0f);
  glDrawArrays(GL_TRIANGLES, 0, GLsizei(triangles.size()));
  glBindVertexArray(0);
}

void Renderer::draw_flat(const std::vector<glm::vec2>& triangles, glm::vec4 colour, int target_width, int target_height) {
  if (triangles.empty()) return;
  glUseProgram(text_program_);
  glUniform2f(uniform(text_program_, "u_target_size"), float(target_width), float(target_height));
  glUniform2f(uniform(text_program_, "u_offset"), 0.0f, 0.0f);
  glUniform4fv(uniform(text_program_, "u_color"), 1, &colour[0]);
  glBindVertexArray(text_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, text_vbo_);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(triangles.size() * sizeof(glm::vec2)), triangles.data(), GL_STREAM_DRAW);
  glDrawArrays(GL_TRIANGLES, 0, GLsizei(triangles.size()));
  glBindVertexArray(0);
}

void append_cross_triangles(glm::vec2 centre, float arm, float thickness, std::vector<glm::vec2>& out) {
  const auto box = [&](glm::vec2 lo, glm::vec2 hi) { out.insert(out.end(), {lo, {hi.x, lo.y}, hi, lo, hi, {lo.x, hi.y}}); };
  const float t = 0.5f * thickness;
  box({centre.x - arm, centre.y - t}, {centre.x + arm, centre.y + t});
  box({centre.x - t, centre.y - arm}, {centre.x + t, centre.y + arm});
}

void Renderer::draw_marks(const std::vector<Rect>& layout, const OrbitView& view, const Toggles& toggles, float scale,
                          int target_width, int target_height) {
  const bool uv_view = toggles.uv_layout && overlays_;
  // Each mark's centre in target pixels (y down) with its pane, clipped to that pane.
  std::vector<std::pair<std::size_t, glm::vec2>> centres;
  for (std::size_t i = 0; i < layout.size(); ++i) {
    const Rect& r = layout[i];
    if (i == 0 && uv_view) {
      if (!marks_.uv) continue;
      const UvSquare square = uv_square(r.width, r.height);
      const float x = float(r.x + square.x) + marks_.uv->x * float(square.side);
      const float y = float(r.y + square.y) + marks_.uv->y * float(square.side);
      centres.push_back({i, {x, float(target_height) - y}});
      continue;
    }
    for (const glm::vec3& p : marks_.points) {
      const std::optional<glm::vec2> ndc = project_point(view, radius_, float(r.width) / float(r.height), p);
      if (!ndc || std::abs(ndc->x) > 1.0f || std::abs(ndc->y) > 1.0f) continue;
      const float x = float(r.x) + (0.5f * ndc->x + 0.5f) * float(r.width);
      const float y = float(r.y) + (0.5f * ndc->y + 0.5f) * float(r.height);
      centres.push_back({i, {x, float(target_height) - y}});
    }
  }
  if (centres.empty()) return;
  // A dark outline one font pixel wider all round, then the bright cross.
  const float arm = 6.0f * scale, thickness = 2.0f * scale;
  glEnable(GL_SCISSOR_TEST);
  for (const auto& [pane, centre] : centres) {
    const Rect& r = layout[pane];
    glScissor(r.x, r.y, r.width, r.height);
    std::vector<glm::vec2> outline, cross;
    append_cross_triangles(centre, arm + scale, thickness + 2.0f * scale, outline);
    append_cross_triangles(centre, arm, thickness, cross);
    draw_flat(outline, {0.0f, 0.0f, 0.0f, 1.0f}, target_width, target_height);
    draw_flat(cross, glm::vec4(kMarkColour, 1.0f), target_width, target_height);
  }
  glDisable(GL_SCISSOR_TEST);
}

namespace {

// "30", "2.5": a scale value in the labels' words.
std::string degrees_label(float degrees) {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", double(degrees));
  return text;
}

}  // namespace

// The difference pane's colour scale: a bar of the scale from 0 to `diff_scale` degrees with its
// top `top` window pixels (y down) below the target's top, 0, the middle and the maximum written under it.
void Renderer::draw_legend(const Rect& pane, float scale, float margin, float top, float diff_scale, int target_width,
                           int target_height) {
  const float bar_height = kCellHeight * scale;
  const int bar_width = int(std::min(float(pane.width) - 2.0f * margin, 150.0f * scale));
  if (bar_width < 8) return;
  const int x = pane.x + int(margin), y = int(float(target_height) - top - bar_height);
  glViewport(x, y, bar_width, int(bar_height));
  glUseProgram(legend_program_);
  glUniform2i(uniform(legend_program_, "u_origin"), x, y);
  glUniform1f(uniform(legend_program_, "u_width"), float(bar_width));
  glBindVertexArray(empty_vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glViewport(0, 0, target_width, target_height);
  const float text_y = top + bar_height + 2.0f * scale;
  const std::string low = "0", middle = degrees_label(0.5f * diff_scale), high = degrees_label(diff_scale) + " DEG";
  draw_text(low, float(x), text_y, scale, target_width, target_height);
  draw_text(middle, float(x) + 0.5f * float(bar_width) - 0.5f * text_width(middle, scale), text_y, scale, target_width,
            target_height);
  draw_text(high, float(x + bar_width) - text_width(high, scale), text_y, scale, target_width, target_height);
}

void Renderer::render(unsigned target, int width, int height, const OrbitView& view, const Light& light, const Toggles& toggles,
                      const std::vector<std::string>& help) {
  const std::vector<Rect> layout = pane_layout(width, height, toggles.difference);
  render_panes(layout[0].width, layout[0].height, view, light, toggles);
  if (toggles.difference)
    render_normals(layout[0].width, layout[0].height, view, toggles.map ? MapVariant::as_decoded : MapVariant::no_map);

  glBindFramebuffer(GL_FRAMEBUFFER, target);
  glViewport(0, 0, width, height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glBindVertexArray(empty_vao_);
  glUseProgram(background_program_);
  glUniform1f(uniform(background_program_, "u_height"), float(height));
  glDrawArrays(GL_TRIANGLES, 0, 3);

  // Panes are premultiplied over black with alpha = coverage: blend them over the background.
  glEnable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  for (std::size_t i = 0; i < layout.size(); ++i) {
    const Rect& r = layout[i];
    glViewport(r.x, r.y, r.width, r.height);
    glActiveTexture(GL_TEXTURE0);
    GLuint program = i < 2 ? pane_program_ : difference_program_;
    glUseProgram(program);
    glUniform2i(uniform(program, "u_origin"), r.x, r.y);
    if (i < 2) {
      glBindTexture(GL_TEXTURE_2D, panes_[i].texture);
      glUniform1i(uniform(program, "u_pane"), 0);
    } else {
      glBindTexture(GL_TEXTURE_2D, panes_[0].normal_texture);
      glActiveTexture(GL_TEXTURE1);
      glBindTexture(GL_TEXTURE_2D, panes_[1].normal_texture);
      glUniform1i(uniform(program, "u_low_normals"), 0);
      glUniform1i(uniform(program, "u_high_normals"), 1);
      glUniform1f(uniform(program, "u_scale"), std::max(toggles.diff_scale, 1e-3f));
    }
    glBindVertexArray(empty_vao_);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  glActiveTexture(GL_TEXTURE0);
  glDisable(GL_BLEND);

  glViewport(0, 0, width, height);
  const float scale = std::max(1.0f, std::floor(float(height) / 400.0f));
  const float margin = 4.0f * scale;
  draw_marks(layout, view, toggles, scale, width, height);
  if (toggles.labels) {
    // Up to three lines per pane, clipped to the pane: what it is with its triangle count, its mode,
    // and the convention the map is decoded with wherever it is (decoding.h, with where it came from).
    const bool ao = toggles.ao && set_textures_[int(nmbake::MapKind::ao)] != 0;
    const bool uv = toggles.uv_layout && overlays_;
    const std::string shown_name = toggles.show_map && has_map(toggles.shown) ? nmbake::map_name(toggles.shown) : "normal";
    const std::string mode = uv ? "UV LAYOUT OVER THE " + shown_name + " MAP"
                             : toggles.show_map && has_map(toggles.shown)
                                 ? std::string(nmbake::map_name(toggles.shown)) + " MAP, UNLIT"
                             : toggles.tangent_colours ? "MAP IN TANGENT-SPACE COLOURS"
                             : toggles.map             ? std::string(ao ? "WITH NORMAL MAP X AO" : "WITH NORMAL MAP")
                                                       : std::string(ao ? "NO MAP (BARE SHADING) X AO" : "NO MAP (BARE SHADING)");
    const bool lit_with_map = toggles.map && !(toggles.show_map && has_map(toggles.shown)) && !toggles.tangent_colours && !uv;
    // With UDIM tiles the normal map's tile range first: "MAP 1001-1004, GREEN UP (OPENGL) ...".
    const std::string convention = (udim_label_.empty() ? "" : udim_label_ + ", ") + convention_label(decoding_);
    const std::vector<std::vector<std::string>> titles = {
        {"LOW  " + with_thousands(low_triangles()) + " TRIS", mode, lit_with_map ? convention : "",
         overlay_legends_[(toggles.masks ? 1 : 0) + (toggles.cage && !uv ? 2 : 0)], marks_.label},
        {"HIGH  " + with_thousands(high_triangles()) + " TRIS", "OWN NORMALS, NO MAP"},
        {"ANGLE LOW TO HIGH NORMAL", "BLUE: ONE MODEL ONLY", toggles.map ? "LOW: " + convention : "LOW: NO MAP"}};
    glEnable(GL_SCISSOR_TEST);
    for (std::size_t i = 0; i < layout.size(); ++i) {
      const Rect& r = layout[i];
      glScissor(r.x, r.y, r.width, r.height);
      for (std::size_t line = 0; line < titles[i].size(); ++line)
        draw_text(titles[i][line], float(r.x) + margin, margin + float(line) * kCellHeight * scale, scale, width, height);
    }
    if (toggles.difference)
      draw_legend(layout[2], scale, margin, margin + 3.5f * kCellHeight * scale, toggles.diff_scale, width, height);
    glDisable(GL_SCISSOR_TEST);
  }
  for (std::size_t i = 0; i < help.size(); ++i) {
    float y = float(height) - margin - float(help.size() - i) * kCellHeight * scale;
    draw_text(help[i], margin, y, scale, width, height);
  }
  glBindVertexArray(0);
  glUseProgram(0);
}

}  // namespace nmview
