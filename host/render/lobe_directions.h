// lobe_directions.h: the Lobe Estimator's n directions (dissertation ch. 6: "pre-computing the
// sampling process"), importance-sampled from the phase function about +Z in a canonical frame
// and rotated per pixel onto the view ray by the kernel.
#pragma once

#include <cstdint>
#include <vector>

#include "shared/structs.h"

namespace narval {

// n unit directions (w = 0) drawn from the phase function about +Z, stratified in the cosine (one
// uniform per stratum [i/n, (i+1)/n)) with an independent uniform azimuth, from the counter-based
// RNG keyed by `seed`: the same set for the same (n, phase, seed) on every machine.
std::vector<nv_float4> lobeDirections(int n, phase_params phase, uint32_t seed);

// The directions for the medium of `sp` (scene as uploaded), isotropic without a medium.
std::vector<nv_float4> lobeDirections(int n, const scene_params& sp, uint32_t seed);

}  // namespace narval
