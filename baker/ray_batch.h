// The bake's rays for many samples at once, for the default policy (cage-first without a cage):
// from P + front * N towards -N, where P is the sample's point on the low-poly and N its unit ray
// normal.
//
// Lane by lane it computes exactly the operations of the bake's one-sample-at-a-time ray setup
// (low_point, low_ray_normal, sample_rays in bake.cpp) in the same order, so every ray is
// bit-identical; only the instruction count changes (4 samples per vector operation). Samples
// whose interpolated ray normal is too short to normalize are flagged for the caller's
// one-at-a-time path, which has the face-normal fallback.
#pragma once

#include <cstddef>
#include <cstdint>

#include "shade_batch.h"

namespace nmbake {

// Rays as arrays (raycast::RayBatch's layout), written by the bake.
struct RayArrays {
  float *org_x, *org_y, *org_z, *dir_x, *dir_y, *dir_z, *tnear, *tfar;
};

// For i < count: ray i of sample i, and fallback[i] = 0; or fallback[i] = 1 (ray i unspecified)
// when the sample's interpolated ray normal has squared length <= 1e-24.
void surface_rays(const LowTriangle* low, const SampleArrays& samples, std::size_t count, float front, float rear,
                  const RayArrays& rays, std::uint8_t* fallback);

}  // namespace nmbake
