#include "compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace nmview {

CompareResult run_compare(Renderer& renderer, int pane_width, int pane_height, const Light& light, const Toggles& toggles) {
  CompareResult result;
  for (const OrbitView& view : compare_views()) {
    renderer.render_panes(pane_width, pane_height, view, light, toggles);
    ViewDifference d{view, compare_images(renderer.read_pane(0), renderer.read_pane(1))};
    result.total.add(d.stats);
    if (result.views.empty() || d.stats.interior.rmse() > result.views[result.worst].stats.interior.rmse())
      result.worst = result.views.size();
    result.views.push_back(d);
  }
  return result;
}

namespace {

std::string format_psnr(double psnr) {
  if (std::isinf(psnr)) return "inf";
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f", psnr);
  return text;
}

}  // namespace

void print_compare(const CompareResult& result, std::ostream& out) {
  char line[320];
  for (std::size_t i = 0; i < result.views.size(); ++i) {
    const ViewDifference& v = result.views[i];
    const ErrorSums& in = v.stats.interior;
    std::snprintf(line, sizeof(line),
                  "view az=%4.0f el=%4.0f  interior: pixels=%7zu rmse=%.5f psnr=%6s dB within2=%.4f  "
                  "silhouette mismatch=%5.2f%%  union: rmse=%.5f psnr=%6s dB%s\n",
                  double(v.view.azimuth), double(v.view.elevation), in.pixels, in.rmse(), format_psnr(in.psnr()).c_str(),
                  in.within2(), 100.0 * v.stats.silhouette_mismatch(), v.stats.object.rmse(),
                  format_psnr(v.stats.object.psnr()).c_str(), i == result.worst ? "  (worst)" : "");
    out << line;
  }
  const DifferenceStats& t = result.total;
  std::snprintf(line, sizeof(line),
                "psnr=%s rmse=%.6f within2=%.6f silhouette_mismatch=%.6f union_psnr=%s union_rmse=%.6f "
                "interior_share=%.6f\n",
                format_psnr(t.interior.psnr()).c_str(), t.interior.rmse(), t.interior.within2(), t.silhouette_mismatch(),
                format_psnr(t.object.psnr()).c_str(), t.object.rmse(),
                t.object.pixels ? double(t.interior.pixels) / double(t.object.pixels) : 0.0);
  out << "\n" << line;
}

}  // namespace nmview
