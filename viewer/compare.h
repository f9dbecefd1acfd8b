// --compare: both models rendered from compare_views() with one light and compared (metrics.h):
// shading over the interior pixels (covered by both models, away from the silhouette), and the
// silhouette mismatch apart.
#pragma once

#include <ostream>
#include <vector>

#include "metrics.h"
#include "renderer.h"
#include "view.h"

namespace nmview {

struct ViewDifference {
  OrbitView view;
  DifferenceStats stats;
};

struct CompareResult {
  std::vector<ViewDifference> views;
  DifferenceStats total;  // all views' pixels pooled
  std::size_t worst = 0;  // index of the view with the largest interior RMSE
};

// Renders every view at `pane_width` x `pane_height` with `toggles` (map on or off; wireframe and
// colour modes should be off) and measures.
CompareResult run_compare(Renderer& renderer, int pane_width, int pane_height, const Light& light, const Toggles& toggles);

// One line per view, a blank line, then the summary; the last line is machine-readable:
// "psnr=<dB> rmse=<0..1> within2=<fraction> silhouette_mismatch=<fraction> union_psnr=<dB>
// union_rmse=<0..1> interior_share=<fraction>": the first three over the interior pixels.
void print_compare(const CompareResult& result, std::ostream& out);

}  // namespace nmview
