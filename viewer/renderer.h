// Draws the comparison: the low-poly with its normal map and the high-poly, side by side, from
// one camera and one light. Needs a current OpenGL 3.3 core context (gl_context.h).
//
// The meshes and the map are uploaded once at construction (vertex and index buffers, a mip-mapped
// texture); a frame only sets uniforms and issues a fixed number of draw calls. Each model is
// drawn into its own offscreen pane (4x multisampled, resolved to an RGBA8 texture cleared to
// transparent black, so alpha is the coverage mask), then the panes are composited side by side
// over a background, with an optional difference pane and text labels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "angle_metrics.h"
#include "decoding.h"
#include "core/image.h"
#include "core/maps.h"
#include "metrics.h"
#include "udim_tiles.h"
#include "vertex_data.h"
#include "view.h"

namespace nmview {

struct Toggles {
  bool map = true;                       // left pane decodes the normal map; off: the low-poly's bare shading
  bool ao = false;                       // lit left pane (ambient + diffuse, not specular) times the ao map, if added
  bool show_map = false;                 // left pane shows `shown` unlit in its own colours, if added (wins over the rest)
  bool wireframe = false;                // triangle edges over both models
  bool tangent_colours = false;          // left pane shows the map's RGB (tangent-space colours) unlit
  bool difference = false;               // a third pane: the angle between the models' normals (angle_metrics.h)
  bool labels = true;                    // pane titles with triangle counts
  bool masks = false;                    // the miss and suspect masks painted on the low-poly, if set (overlays.h)
  bool cage = false;                     // the cage's edges over the low-poly pane, if set (overlays.h)
  bool uv_layout = false;                // left pane: the shown map flat over the UV square with the UV edges (overlays.h)
  float specular = 0.0f;                 // Blinn specular weight, 0 = off
  float diff_scale = kDefaultDiffScale;  // degrees at the top of the difference pane's colour scale, > 0
  // With show_map: normal, or a map given to Renderer::add_set_map.
  nmbake::MapKind shown = nmbake::MapKind::normal;
};

// How the low-poly's normal pass decodes the map: as decoded (the lit pane's normal with the map),
// the bare interpolated normal, or --compare's wrong-convention variants: green negated after the
// decoding, red and green exchanged before it.
enum class MapVariant { as_decoded, no_map, green_flipped, swapped };

class OverlayRenderer;
struct OverlayData;

// What the UV cursor and the selection mark (issue 36, items 2 and 4): crosses of kMarkColour with a
// dark outline, drawn over the composed panes without a depth test, so a point on the far side of
// a model is marked all the same (where it projects).
struct Marks {
  std::optional<glm::vec2> uv;    // the UV view's cursor (uv_cursor.h): a cross at this UV in the UV view
  std::vector<glm::vec3> points;  // re-centred scene points: a cross where each projects in every 3D pane
  std::string label;              // a line under the low pane's titles ("" none), with the labels on
};
constexpr glm::vec3 kMarkColour{0.0f, 1.0f, 1.0f};  // cyan: no other overlay, map or scale uses it

// Pixel rectangle, origin at the lower left (GL convention).
class UdimTextures;

struct Rect {
  int x = 0, y = 0, width = 0, height = 0;
};

// Side-by-side layout of a `width` x `height` target: 2 panes, or 3 with the difference pane.
std::vector<Rect> pane_layout(int width, int height, bool difference);

class Renderer {
 public:
  // `map` has at least 3 channels (RGB encoded normals). Throws nmbake::Error (ExitCode::output)
  // when a shader does not compile or the map is larger than the GL texture limit.
  // `decoding` is the convention the map was baked with.
  Renderer(const LowVertices& low, const HighVertices& high, const nmbake::Image& map, float radius,
           const MapDecoding& decoding = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Uploads a texture-set member other than the normal map (texture_set.h; any size, 1 to 4
  // channels: grey is shown as grey), replacing one of the same kind. ID maps (shown_texel_exact)
  // get nearest filtering and are drawn without multisampling, so every covered pixel is exactly one
  // texel's colour. Throws like the constructor for a map over the GL texture limit.
  void add_set_map(nmbake::MapKind kind, const nmbake::Image& image);
  // UDIM tiles (udim_tiles.h, udim_textures.h): each triangle's cell (face_udim_cells of the
  // constructor's `low`), then each map's tiles (its add_set_map image or the constructor's map
  // stays for has_map and the labels). From then on every map is sampled from the face's tile, and
  // a face whose tile has no normal map is drawn kMissingTileColour (its normal marked w = 2 in
  // render_normals, the difference pane in that colour). Throws like add_set_map.
  void set_udim_faces(const std::vector<std::int32_t>& face_cells);
  void add_udim_map(nmbake::MapKind kind, const std::vector<UdimTileImage>& tiles);
  // Whether `kind` can be shown: normal always, the others once added.
  bool has_map(nmbake::MapKind kind) const;
  // normal, then every added map, in MapKind order (the order the display cycles through).
  std::vector<nmbake::MapKind> shown_maps() const;

  // Uploads the overlays (overlays.h) that Toggles::masks and Toggles::cage draw, replacing any
  // earlier ones. Throws like the constructor.
  void set_overlays(const OverlayData& data);
  bool has_masks() const;
  bool has_cage() const;

  // The marks every later frame draws (none by default).
  void set_marks(const Marks& marks) { marks_ = marks; }

  // A whole frame into framebuffer `target` (0 = the window) of `width` x `height` pixels.
  // `help` lines are printed at the bottom left.
  void render(unsigned target, int width, int height, const OrbitView& view, const Light& light, const Toggles& toggles,
              const std::vector<std::string>& help = {});

  // Just the two panes at `width` x `height` each, for measuring; then read_pane(0 = low, 1 = high).
  void render_panes(int width, int height, const OrbitView& view, const Light& light, const Toggles& toggles);
  Rgba8Image read_pane(int which) const;

  // Each model's shading normal (angle_metrics.h: unit, scene space, w = coverage) into a
  // single-sample float target of `width` x `height`, no wireframe, the low-poly's decoded as
  // `variant`; then read_normals(0 = low, 1 = high). `which_models`: 1 = low only, 2 = high only,
  // 3 = both (the high-poly's does not depend on the variant).
  void render_normals(int width, int height, const OrbitView& view, MapVariant variant, int which_models = 3);
  NormalImage read_normals(int which) const;

  // Reads framebuffer `target` (row 0 at the top).
  static Rgba8Image read_framebuffer(unsigned target, int width, int height);

  std::size_t low_triangles() const { return low_.index_count / 3; }
  std::size_t high_triangles() const { return high_.index_count / 3; }

 private:
  struct Model {
    unsigned vao = 0, vbo = 0, ebo = 0;
    std::size_t index_count = 0;
  };
  struct Pane {
    unsigned msaa_fbo = 0, msaa_color = 0, msaa_depth = 0;
    unsigned fbo = 0, texture = 0;                                  // resolved RGBA8
    unsigned normal_fbo = 0, normal_texture = 0, normal_depth = 0;  // single-sample RGBA32F normals
  };

  void ensure_pane_size(int width, int height);
  void draw_model(int which, const CameraMatrices& camera, const Toggles& toggles, MapVariant variant = MapVariant::as_decoded,
                  bool normals = false);
  void draw_legend(const Rect& pane, float scale, float margin, float top, float diff_scale, int target_width, int target_height);
  void draw_text(const std::string& text, float x, float y, float scale, int target_width, int target_height);
  // Triangles in target pixels (y down) of one flat colour, through the text program.
  void draw_flat(const std::vector<glm::vec2>& triangles, glm::vec4 colour, int target_width, int target_height);
  void draw_marks(const std::vector<Rect>& layout, const OrbitView& view, const Toggles& toggles, float scale, int target_width,
                  int target_height);

  Model low_, high_;
  unsigned map_texture_ = 0;
  unsigned set_textures_[nmbake::kMapKinds] = {};  // by MapKind; 0 = not loaded (normal uses map_texture_)
  unsigned low_program_ = 0, high_program_ = 0, wire_program_ = 0;
  unsigned background_program_ = 0, pane_program_ = 0, difference_program_ = 0, text_program_ = 0, legend_program_ = 0;
  unsigned empty_vao_ = 0, text_vao_ = 0, text_vbo_ = 0;
  Pane panes_[2];
  int pane_width_ = 0, pane_height_ = 0, samples_ = 1;
  float radius_ = 1.0f;
  MapDecoding decoding_;
  std::unique_ptr<OverlayRenderer> overlays_;
  std::string overlay_legends_[4];      // overlay_legend() by toggles: [masks + 2 * cage]
  std::unique_ptr<UdimTextures> udim_;  // null without UDIM tiles
  std::string udim_label_;              // udim_range_label of the normal map's tiles ("" without)
  Marks marks_;
};

// A cross centred on `centre` (target pixels, y down): a horizontal and a vertical bar of
// `thickness`, each reaching `arm` from the centre; 4 triangles appended to `out`.
void append_cross_triangles(glm::vec2 centre, float arm, float thickness, std::vector<glm::vec2>& out);

// An offscreen RGBA8 framebuffer for headless frames.
class Framebuffer {
 public:
  Framebuffer(int width, int height);  // throws nmbake::Error (ExitCode::output) when incomplete
  ~Framebuffer();
  Framebuffer(const Framebuffer&) = delete;
  Framebuffer& operator=(const Framebuffer&) = delete;
  unsigned id() const { return fbo_; }

 private:
  unsigned fbo_ = 0, color_ = 0;
};

// "98,304"
std::string with_thousands(std::size_t n);

}  // namespace nmview
