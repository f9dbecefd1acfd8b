#include "verdict.h"

namespace nmview {
namespace {

bool clearly_better(double variant, double as_decoded) {
  return variant <= kClearlyBetter * as_decoded && as_decoded - variant >= kMinAngleGain;
}

}  // namespace

double removed_share(const VariantAngles& a) { return a.no_map >= kMinAngleGain ? 1.0 - a.with_map / a.no_map : 0.0; }

Verdict judge_map(const VariantAngles& a) {
  if (clearly_better(a.green_flipped, a.with_map) && a.green_flipped <= a.swapped) return Verdict::green_flipped;
  if (clearly_better(a.swapped, a.with_map)) return Verdict::swapped_channels;
  if (a.no_map < kMinAngleGain && a.with_map < kMinAngleGain) return Verdict::good;
  if (removed_share(a) < kMinRemoved) return Verdict::barely_helps;
  return Verdict::good;
}

const char* verdict_token(Verdict v) {
  switch (v) {
    case Verdict::good: return "good";
    case Verdict::green_flipped: return "green_flipped";
    case Verdict::swapped_channels: return "swapped_channels";
    case Verdict::barely_helps: return "barely_helps";
  }
  return "good";
}

const char* verdict_text(Verdict v) {
  switch (v) {
    case Verdict::good: return "good";
    case Verdict::green_flipped: return "likely green flipped";
    case Verdict::swapped_channels: return "likely swapped channels";
    case Verdict::barely_helps: return "the map barely helps";
  }
  return "good";
}

std::string verdict_advice(Verdict v, bool green_down) {
  switch (v) {
    case Verdict::good: return "";
    case Verdict::green_flipped:
      return std::string("the map reads right with --green ") + (green_down ? "up" : "down") +
             "; bake with the other --green, or view it so if it comes from another baker";
    case Verdict::swapped_channels: return "the map's red and green look exchanged: check the exporter's channel order";
    case Verdict::barely_helps:
      return "the map adds little to the low-poly's own shading: check that it was baked for these meshes (LOW, HIGH, UV set)";
  }
  return "";
}

}  // namespace nmview
