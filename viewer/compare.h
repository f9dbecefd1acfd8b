// --compare: both models rendered from compare_views() with one light and compared (metrics.h):
// shading over the interior pixels (covered by both models, away from the silhouette), and the
// silhouette mismatch apart. Then the normals themselves (angle_metrics.h): the angle between the
// low-poly's shading normal and the high-poly's over the same interior, with the map as decoded,
// with no map, with its green flipped and with red and green swapped, and the verdict (verdict.h).
#pragma once

#include <ostream>
#include <vector>

#include "angle_metrics.h"
#include "decoding.h"
#include "metrics.h"
#include "renderer.h"
#include "view.h"

namespace nmview {

struct ViewDifference {
  OrbitView view;
  DifferenceStats stats;
};

constexpr int kMapVariants = 4;  // MapVariant values, as_decoded first

struct CompareResult {
  std::vector<ViewDifference> views;
  DifferenceStats total;  // all views' pixels pooled
  std::size_t worst = 0;  // index of the view with the largest interior RMSE
  // The normal angle of each MapVariant (by its value), all views pooled, interior pixels
  // (kDefaultErode), whatever `toggles.map` was.
  AngleStats angles[kMapVariants];
};

// What run_compare measures: the lit panes only, or the normals of every MapVariant too (what
// --compare prints). The angle passes draw the high-poly once more and the low-poly four times a
// view, about half of the work on a dense high-poly.
enum class CompareScope { shading, shading_and_angles };

// Renders every view at `pane_width` x `pane_height` with `toggles` (map on or off; wireframe and
// colour modes should be off) and measures; then, with CompareScope::shading_and_angles, the
// normals of every MapVariant (with CompareScope::shading, `angles` stay empty).
CompareResult run_compare(Renderer& renderer, int pane_width, int pane_height, const Light& light, const Toggles& toggles,
                          CompareScope scope = CompareScope::shading_and_angles);

// One line per view, a blank line, the angle block (each variant's mean and 95th percentile, the
// share the map removes, the verdict with `decoding` named), then the summary. The last line is
// machine-readable: "psnr=<dB> rmse=<0..1> within2=<fraction> silhouette_mismatch=<fraction>
// union_psnr=<dB> union_rmse=<0..1> interior_share=<fraction>" (the first three over the interior
// pixels), then "angle_mean=<deg> angle_p95=<deg> no_map_angle_mean=<deg> no_map_angle_p95=<deg>
// flipped_angle_mean=<deg> swapped_angle_mean=<deg> map_removes=<share> verdict=<token>"
// (verdict.h's tokens; the angle figures as the block's).
void print_compare(const CompareResult& result, const MapDecoding& decoding, std::ostream& out);

}  // namespace nmview
