#include "compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "verdict.h"

namespace nmview {

CompareResult run_compare(Renderer& renderer, int pane_width, int pane_height, const Light& light, const Toggles& toggles,
                          CompareScope scope) {
  CompareResult result;
  for (const OrbitView& view : compare_views()) {
    renderer.render_panes(pane_width, pane_height, view, light, toggles);
    ViewDifference d{view, compare_images(renderer.read_pane(0), renderer.read_pane(1))};
    result.total.add(d.stats);
    if (result.views.empty() || d.stats.interior.rmse() > result.views[result.worst].stats.interior.rmse())
      result.worst = result.views.size();
    result.views.push_back(d);
    if (scope == CompareScope::shading) continue;

    // The high-poly's normals once, then the low-poly's in each variant against them.
    renderer.render_normals(pane_width, pane_height, view, MapVariant::as_decoded);
    const NormalImage high = renderer.read_normals(1);
    for (int v = 0; v < kMapVariants; ++v) {
      if (v > 0) renderer.render_normals(pane_width, pane_height, view, MapVariant(v), 1);
      result.angles[v].add(measure_angles(renderer.read_normals(0), high, kDefaultErode));
    }
  }
  return result;
}

namespace {

std::string lower_case(std::string text) {
  for (char& c : text)
    if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
  return text;
}

std::string format_psnr(double psnr) {
  if (std::isinf(psnr)) return "inf";
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f", psnr);
  return text;
}

}  // namespace

void print_compare(const CompareResult& result, const MapDecoding& decoding, std::ostream& out) {
  char line[640];
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
  // The normals: what each variant's shading normal is off from the high-poly's, and the verdict.
  const AngleStats* a = result.angles;
  const VariantAngles means{a[int(MapVariant::as_decoded)].mean(), a[int(MapVariant::no_map)].mean(),
                            a[int(MapVariant::green_flipped)].mean(), a[int(MapVariant::swapped)].mean()};
  const Verdict verdict = judge_map(means);
  const std::string as_decoded = "with the map (" + lower_case(convention_label(decoding)) + ")";
  const char* names[kMapVariants] = {as_decoded.c_str(), "no map (interpolated normal only)", "the map's green flipped",
                                     "the map's red and green swapped"};
  out << "\nnormal angle between the low-poly's shading normal and the high-poly's, interior pixels of all views (" << a[0].pixels
      << "), degrees:\n";
  for (int v = 0; v < kMapVariants; ++v) {
    std::snprintf(line, sizeof(line), "  %-56s mean %6.2f  p95 %6.2f\n", names[v], a[v].mean(), a[v].percentile(0.95));
    out << line;
  }
  std::snprintf(line, sizeof(line), "the map removes %.1f%% of the no-map angle (1 - %.2f / %.2f)\n",
                100.0 * removed_share(means), means.with_map, means.no_map);
  out << line;
  const std::string advice = verdict_advice(verdict, decoding.green_down);
  out << "verdict: " << verdict_text(verdict) << (advice.empty() ? "" : ": " + advice) << "\n";

  const DifferenceStats& t = result.total;
  std::snprintf(line, sizeof(line),
                "psnr=%s rmse=%.6f within2=%.6f silhouette_mismatch=%.6f union_psnr=%s union_rmse=%.6f "
                "interior_share=%.6f angle_mean=%.3f angle_p95=%.2f no_map_angle_mean=%.3f no_map_angle_p95=%.2f "
                "flipped_angle_mean=%.3f swapped_angle_mean=%.3f map_removes=%.4f verdict=%s\n",
                format_psnr(t.interior.psnr()).c_str(), t.interior.rmse(), t.interior.within2(), t.silhouette_mismatch(),
                format_psnr(t.object.psnr()).c_str(), t.object.rmse(),
                t.object.pixels ? double(t.interior.pixels) / double(t.object.pixels) : 0.0, means.with_map,
                a[0].percentile(0.95), means.no_map, a[int(MapVariant::no_map)].percentile(0.95), means.green_flipped,
                means.swapped, removed_share(means), verdict_token(verdict));
  out << "\n" << line;
}

}  // namespace nmview
