#include "render/lobe_directions.h"

#include "shared/phase.h"
#include "shared/rng.h"

namespace narval {

std::vector<nv_float4> lobeDirections(int n, phase_params phase, uint32_t seed) {
  std::vector<nv_float4> dirs;
  dirs.reserve(size_t(n));
  const vec3 z = vec3_make(0.0f, 0.0f, 1.0f);
  for (int i = 0; i < n; ++i) {
    // Pixel index 0xFFFFFFFF: a stream no pixel of an image uses.
    rng_state rng = rng_init(seed, 0xFFFFFFFFu, uint32_t(i));
    const float u1 = (float(i) + rng_uniform(&rng)) / float(n);
    const float u2 = rng_uniform(&rng);
    const vec3 d = sample_direction_around(z, phase_sample_mu(phase, u1), u2);
    dirs.push_back(nv_float4{d.x, d.y, d.z, 0.0f});
  }
  return dirs;
}

std::vector<nv_float4> lobeDirections(int n, const scene_params& sp, uint32_t seed) {
  return lobeDirections(n, sp.has_medium ? sp.medium.phase : phase_make(PHASE_ISOTROPIC, 0.0f), seed);
}

}  // namespace narval
