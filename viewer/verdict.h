// --compare's verdict on a normal map (CPU only): from the mean angle between the low-poly's
// shading normal and the high-poly's normal (angle_metrics.h) with the map as decoded, with no map,
// with the map's green flipped and with its red and green swapped, is the bake right, decoded with
// the wrong convention, or of little use?
//
// Rules, in this order (the thresholds below):
// 1. "likely green flipped": the green-flipped variant is clearly better than the map as decoded
//    (its mean angle at most kClearlyBetter times as-decoded's, and at least kMinAngleGain degrees
//    less) and no worse than the swapped variant;
// 2. "likely swapped channels": the same for the red/green-swapped variant;
// 3. "good" when the low-poly alone is already within kMinAngleGain degrees of the high-poly and
//    so is it with the map (a low-poly baked from itself: nothing to remove, the map keeps it so);
// 4. "the map barely helps": the map removes less than kMinRemoved of the no-map angle
//    (removed = 1 - with_map / no_map; negative when the map makes it worse);
// 5. "good" otherwise.
#pragma once

#include <string>

namespace nmview {

// A variant is clearly better than the map as decoded at <= 0.8 times its mean angle...
constexpr double kClearlyBetter = 0.8;
// ...and at least this many degrees below it (so that near-zero angles, as of a map baked from the
// low-poly itself, never flag a convention on noise).
constexpr double kMinAngleGain = 0.5;
// The map helps when it removes at least this share of the no-map mean angle. Measured on right
// maps (llvmpipe, 256^2, --size 300x150): the sample torus 0.33, suz_L3 0.39, suz_L4 0.33, torus_s3
// 0.25 (0.22 at --size 200x100: its finest detail stays in the angle whatever the map's size); a
// flat map removes 0, a green-flipped one -0.2. 0.1 sits between the flat map and the lowest right
// one (it was 0.2, within 0.02 of torus_s3's right map).
constexpr double kMinRemoved = 0.1;

enum class Verdict { good, green_flipped, swapped_channels, barely_helps };

// Mean angles in degrees (>= 0) over the same pixels.
struct VariantAngles {
  double with_map = 0.0;       // the map as decoded (metadata, overrides)
  double no_map = 0.0;         // the low-poly's interpolated normal only
  double green_flipped = 0.0;  // the map's green negated after decoding
  double swapped = 0.0;        // the map's red and green exchanged before decoding
};

// 1 - with_map / no_map: the share of the no-map angle the map removes (1 = all, 0 = none,
// negative = the map adds to it). 0 when no_map is below kMinAngleGain (nothing to remove: the
// share of a near-zero angle would only measure noise).
double removed_share(const VariantAngles& a);

Verdict judge_map(const VariantAngles& a);

// "good", "green_flipped", "swapped_channels", "barely_helps": the machine-readable token.
const char* verdict_token(Verdict v);
// The sentence --compare prints: "good", "likely green flipped", "likely swapped channels",
// "the map barely helps".
const char* verdict_text(Verdict v);
// What to do about it, one short sentence ("" for good).
std::string verdict_advice(Verdict v, bool green_down);

}  // namespace nmview
