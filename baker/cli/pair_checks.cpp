#include "cli/pair_checks.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cli/format_line.h"
#include "core/bounds.h"
#include "pipeline/bake.h"

namespace nmbake {

namespace {

Box box_of(const Mesh& m, int threads) {
  const double inf = std::numeric_limits<double>::infinity();
  glm::dvec3 lo(inf), hi(-inf);
  grow_box(lo, hi, m.positions, m.position_index, threads);
  if (!(lo.x <= hi.x)) lo = hi = glm::dvec3(0.0);  // no face (the loaders refuse it; defined anyway)
  return {lo + m.origin, hi + m.origin};
}

std::string box_text(const Box& b) {
  return format_line("(%.4g, %.4g, %.4g) to (%.4g, %.4g, %.4g)", b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z);
}

// The unit mix-up a size ratio looks like, or "" when none is within 10%.
std::string unit_hint(double ratio) {
  static const struct {
    double factor;
    const char* units;
  } known[] = {{10, "millimetres against centimetres"}, {12, "inches against feet"},         {25.4, "millimetres against inches"},
               {30.48, "centimetres against feet"},     {39.37, "inches against metres"},    {100, "centimetres against metres"},
               {304.8, "millimetres against feet"},     {1000, "millimetres against metres"}};
  for (const auto& k : known)
    if (std::abs(ratio / k.factor - 1.0) < 0.1) return format_line("different units (%s)?", k.units);
  return "different units, or a scale applied to one on export?";
}

// 46080 as "46,080".
std::string grouped(std::size_t n) {
  std::string s = std::to_string(n);
  for (int i = int(s.size()) - 3; i > 0; i -= 3) s.insert(std::size_t(i), ",");
  return s;
}

}  // namespace

PairBoxes compare_boxes(const Mesh& low, const Mesh& high, int threads) {
  PairBoxes b;
  b.low = box_of(low, threads);
  b.high = box_of(high, threads);
  const double dl = b.low.diagonal(), dh = b.high.diagonal();
  const double small = std::min(dl, dh), large = std::max(dl, dh);
  b.size_ratio = small > 0.0 ? large / small : (large > 0.0 ? std::numeric_limits<double>::infinity() : 1.0);
  const double pad = 0.01 * large;
  for (int k = 0; k < 3; ++k) {
    const double l0 = b.low.lo[k] - pad, l1 = b.low.hi[k] + pad, h0 = b.high.lo[k] - pad, h1 = b.high.hi[k] + pad;
    const double shared = std::max(0.0, std::min(l1, h1) - std::max(l0, h0));
    const double length = std::min(l1 - l0, h1 - h0);
    b.overlap = std::min(b.overlap, length > 0.0 ? shared / length : 1.0);
  }
  // Coordinates beyond the ray tracer's reach are the bake's to refuse, with its own line.
  const double largest = std::max({glm::length(b.low.lo), glm::length(b.low.hi), glm::length(b.high.lo), glm::length(b.high.hi)});
  if (!(largest <= kMaxCoordinate)) return b;
  b.mismatch = b.overlap < kApartOverlap      ? PairBoxes::Mismatch::apart
               : !(b.size_ratio < kSizeRatio) ? PairBoxes::Mismatch::size
                                              : PairBoxes::Mismatch::none;
  return b;
}

std::string mismatch_text(const PairBoxes& b, const std::string& low_path, const std::string& high_path, bool allowed) {
  if (!b.mismatched()) return "";
  const std::string low = low_path + " (LOW)", high = high_path + " (HIGH)";
  const bool high_larger = b.high.diagonal() >= b.low.diagonal();
  const std::string sizes = format_line("%s is %.3g times the size of %s", (high_larger ? high : low).c_str(), b.size_ratio,
                                        (high_larger ? low : high).c_str());
  const std::string boxes = "LOW's box is " + box_text(b.low) + ", HIGH's " + box_text(b.high);
  const std::string tail = allowed ? " (baked anyway: --allow-mismatch)" : " (--allow-mismatch bakes anyway)";
  if (b.mismatch == PairBoxes::Mismatch::apart)
    return format_line(
        "%s and %s do not lie in one place (they share %.0f%% of the smaller extent along one axis): %s%s; most "
        "rays would miss. Was one moved, or exported with another transform or up axis?%s",
        low.c_str(), high.c_str(), 100.0 * b.overlap, boxes.c_str(), b.size_ratio < kSizeRatio ? "" : (", and " + sizes).c_str(),
        tail.c_str());
  return format_line("%s: %s; %s Scale one to match the other%s", sizes.c_str(), boxes.c_str(), unit_hint(b.size_ratio).c_str(),
                     tail.c_str());
}

std::optional<std::string> swap_warning(std::size_t low_triangles, std::size_t high_triangles, bool high_has_uvs,
                                        const std::string& low_path, const std::string& high_path) {
  if (!high_has_uvs || !(double(low_triangles) > kSwapRatio * double(high_triangles))) return std::nullopt;
  return format_line(
      "warning: %s (LOW) has %s triangles and %s (HIGH) %s: the low-poly has %.3g times as many. Were LOW and HIGH "
      "given the wrong way round? (nmbake LOW HIGH -o MAP: the low-poly with UVs first)",
      low_path.c_str(), grouped(low_triangles).c_str(), high_path.c_str(), grouped(high_triangles).c_str(),
      high_triangles ? double(low_triangles) / double(high_triangles) : double(low_triangles));
}

UvOverlap measure_map_overlap(const Mesh& low, int width, int height, bool udim, int threads) {
  const double scale = std::min(1.0, double(kOverlapGridSide) / double(std::max(width, height)));
  const int w = std::max(1, int(std::lround(width * scale))), h = std::max(1, int(std::lround(height * scale)));
  return measure_uv_overlap(low, w, h, udim, threads);
}

bool overlap_refused(const UvOverlap& o) { return o.stacked_share() > kStackedShareRefuse; }

std::string overlap_text(const UvOverlap& o, std::uint64_t samples, const std::string& low_path, bool allowed) {
  if (!o.overlapped) return "";
  if (!overlap_refused(o))
    return format_line(
        "%s: UV islands overlap (%llu samples covered twice; the lower face number wins): %.1f%% of the covered "
        "texels lie under more than one triangle (%.2f layers on average)",
        low_path.c_str(), (unsigned long long)samples, 100.0 * o.overlapped_share(), o.mean_layers());
  return format_line(
      "%s (LOW): its UVs lie %.3g layers deep on average: %.1f%% of the covered texels lie under three or more "
      "triangles (UVs for a tiling texture, or every face mapped onto the whole square?), and the map would be "
      "pieces of all of them%s",
      low_path.c_str(), o.mean_layers(), 100.0 * o.stacked_share(),
      allowed ? " (baked anyway, the lower face number winning: --allow-overlap)"
              : ". Lay the UVs out without overlap; --allow-overlap bakes anyway (the lower face number wins)");
}

nlohmann::json pair_report(const PairBoxes& b) {
  auto box = [](const Box& x) { return nlohmann::json{{"min", {x.lo.x, x.lo.y, x.lo.z}}, {"max", {x.hi.x, x.hi.y, x.hi.z}}}; };
  return {{"low_box", box(b.low)},
          {"high_box", box(b.high)},
          {"size_ratio", std::isfinite(b.size_ratio) ? nlohmann::json(b.size_ratio) : nlohmann::json(nullptr)},
          {"overlap", b.overlap},
          {"mismatch", b.mismatch == PairBoxes::Mismatch::apart  ? "apart"
                       : b.mismatch == PairBoxes::Mismatch::size ? "size"
                                                                 : "none"}};
}

nlohmann::json overlap_report(const UvOverlap& o) {
  return {{"share", o.overlapped_share()},
          {"stacked_share", o.stacked_share()},
          {"mean_layers", o.mean_layers()},
          {"grid", {o.width, o.height}}};
}

}  // namespace nmbake
