#include "compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace nmview {

CompareResult run_compare(Renderer& renderer, int pane_width, int pane_height, const Light& light,
                          const Toggles& toggles) {
  CompareResult result;
  for (const OrbitView& view : compare_views()) {
    renderer.render_panes(pane_width, pane_height, view, light, toggles);
    ViewDifference d{view, compare_images(renderer.read_pane(0), renderer.read_pane(1))};
    result.total.add(d.stats);
    if (result.views.empty() || d.stats.rmse() > result.views[result.worst].stats.rmse())
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
  char line[256];
  for (std::size_t i = 0; i < result.views.size(); ++i) {
    const ViewDifference& v = result.views[i];
    std::snprintf(line, sizeof(line),
                  "view az=%4.0f el=%4.0f  pixels=%8zu  rmse=%.5f  psnr=%6s dB  within2=%.4f  "
                  "both-covered=%5.1f%% rmse=%.5f%s\n",
                  double(v.view.azimuth), double(v.view.elevation), v.stats.object_pixels, v.stats.rmse(),
                  format_psnr(v.stats.psnr()).c_str(), v.stats.within2(),
                  100.0 * double(v.stats.shared_pixels) / double(std::max<std::size_t>(v.stats.object_pixels, 1)),
                  v.stats.shared_rmse(), i == result.worst ? "  (worst)" : "");
    out << line;
  }
  std::snprintf(line, sizeof(line), "psnr=%s rmse=%.6f within2=%.6f\n", format_psnr(result.total.psnr()).c_str(),
                result.total.rmse(), result.total.within2());
  out << "\n" << line;
}

}  // namespace nmview
