// What nmview draws over the low-poly pane to show where a bake went wrong (issue 36, item 2):
// nmbake's miss and suspect masks painted on the model, the cage as a wireframe, and the UV view
// (the map flat over the UV square with the low-poly's UV edges, the masks on it too).
//
// The masks are the images nmbake writes with --miss-mask (the share of a texel's rays that found
// nothing, 0..1) and --suspect-mask (1 for a suspect texel), in the map's UV layout; they are
// sampled at the low-poly's UVs as the map is, so any size works. The cage is a mesh with the
// low-poly's topology (nmbake --cage, or the file --save-cage wrote), loaded on the low-poly's
// origin and re-centred like the scene. The files come from nmview's options or from an nmbake
// --report, which names them ("options": miss_mask, suspect_mask, cage).
#pragma once

#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/image.h"
#include "io/output_files.h"
#include "view.h"

namespace nmview {

struct Scene;

// Paint colours (linear RGB, as written to the screenshot) and how strongly a mask value of 1
// covers the lit model (0..1; a share below 1 paints in proportion). Misses are painted over
// suspects where a texel is both.
constexpr glm::vec3 kMissColour{1.0f, 0.0f, 1.0f};      // magenta
constexpr glm::vec3 kSuspectColour{1.0f, 0.55f, 0.0f};  // orange
constexpr float kMaskStrength = 0.85f;
constexpr glm::vec4 kCageColour{0.15f, 1.0f, 0.15f, 0.9f};   // green lines, alpha
constexpr glm::vec4 kUvEdgeColour{1.0f, 1.0f, 1.0f, 0.85f};  // the UV view's edges, alpha

// The UV view's square in a pane of `width` x `height` pixels: the UV square [0,1]^2 as large as
// fits, centred; x, y its lower-left corner in pane pixels (GL convention, y up), v up.
struct UvSquare {
  int x = 0, y = 0, side = 1;
};
UvSquare uv_square(int width, int height);

// The overlay files; an empty path is none.
struct OverlayFiles {
  std::string miss_mask, suspect_mask, cage;
  std::string report;  // the report the others were found in, if any (for messages)
  bool any_mask() const { return !miss_mask.empty() || !suspect_mask.empty(); }
};

// The files an nmbake --report names: options.miss_mask, options.suspect_mask and options.cage
// (null: none). A relative path is taken from the current folder when it is there, else from the
// report's folder. Throws nmbake::InputError when the report cannot be read, is not a bake's JSON
// report, or names a file found in neither place ("r.json names the miss mask 'm.png', found
// neither in the current folder nor beside the report").
OverlayFiles read_report_overlays(const std::string& report_path);

// `explicit_files` with each empty path filled from `report` (the options win over the report).
OverlayFiles merge_overlay_files(const OverlayFiles& explicit_files, const OverlayFiles& report);

// The overlay files as inputs for nmbake::check_output_files (--screenshot may not overwrite one).
std::vector<nmbake::NamedFile> overlay_inputs(const OverlayFiles& files);

// The overlays as read: masks (first channel used, any size; empty when not given) and the cage
// as line segments (pairs of indices into positions, each edge once).
struct OverlayData {
  nmbake::Image miss_mask, suspect_mask;  // width 0: not given
  std::vector<glm::vec3> cage_positions;  // object space minus the scene centre, like the scene's
  std::vector<std::uint32_t> cage_edges;  // 2 per edge
  std::size_t cage_triangles = 0;
  bool has_miss() const { return miss_mask.width > 0; }
  bool has_suspect() const { return suspect_mask.width > 0; }
  bool has_cage() const { return !cage_edges.empty(); }
};

// Reads the files of `files` for `scene` (the cage on the low-poly's origin, minus the scene
// centre). Throws the loaders' nmbake::InputError for an unreadable file; a cage whose triangle
// count differs from the low-poly's gets a warning in `log` (it is drawn all the same).
OverlayData load_overlays(const OverlayFiles& files, const Scene& scene, std::ostream& log);

// Each edge of the triangles `indices` (3 per triangle) once, as index pairs (lower first), sorted.
std::vector<std::uint32_t> unique_edges(const std::vector<std::uint32_t>& indices);

// The low pane's legend line for the overlays shown and loaded ("MAGENTA: MISS  ORANGE: SUSPECT
// GREEN: CAGE"), empty when none is.
std::string overlay_legend(bool masks, bool cage, const OverlayData& data);

// The overlays on the GPU. Needs a current OpenGL 3.3 core context; uploads at construction.
class OverlayRenderer {
 public:
  explicit OverlayRenderer(const OverlayData& data);  // throws nmbake::OutputError when a shader fails
  ~OverlayRenderer();
  OverlayRenderer(const OverlayRenderer&) = delete;
  OverlayRenderer& operator=(const OverlayRenderer&) = delete;

  bool has_masks() const { return miss_ || suspect_; }
  bool has_cage() const { return cage_edge_count_ > 0; }

  // Paints the masks over the low-poly already drawn in the bound framebuffer: `low_vao` is the
  // low-poly's vertex array (position at location 0, UV at 3) with `index_count` indices. Depth is
  // tested (LEQUAL, pulled forward) but not written, so later lines still win.
  void draw_masks(const CameraMatrices& camera, unsigned low_vao, std::size_t index_count) const;
  // The cage's edges, depth tested against the model, blended premultiplied (coverage grows
  // where a line passes outside the model).
  void draw_cage(const CameraMatrices& camera) const;
  // The UV view into the bound framebuffer of `width` x `height` pixels (a pane): the texture
  // `map_texture` over the UV square (uv_square; outside it nothing is drawn), the masks painted on
  // it when `masks`, and the low-poly's triangles (`low_vao`, `index_count` indices) as lines at
  // their UVs.
  void draw_uv_layout(int width, int height, unsigned map_texture, unsigned low_vao, std::size_t index_count, bool masks) const;

 private:
  void bind_masks(unsigned program) const;  // the mask textures on units 1 and 2, kMaskPaint's uniforms

  unsigned mask_program_ = 0, cage_program_ = 0, uv_map_program_ = 0, uv_edge_program_ = 0;
  unsigned miss_ = 0, suspect_ = 0, fallback_ = 0;  // textures; fallback_ is 1x1 black
  unsigned cage_vao_ = 0, cage_vbo_ = 0, cage_ebo_ = 0;
  std::size_t cage_edge_count_ = 0;
};

}  // namespace nmview
