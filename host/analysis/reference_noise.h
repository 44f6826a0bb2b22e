// reference_noise.h: what a path-traced reference's own noise costs a comparison against it. A
// method that had no error at all would still read some JND% against a reference of finitely many
// samples; where a target is a few percent (the real-time kernels against the path tracer) that
// floor must be known to read the figure. `narval compare --reference-snapshot`.
#pragma once

#include <string>

#include "image/image.h"

namespace narval {

// The reference with its own error added once more, estimated from an earlier snapshot of the same
// render (its first samples: --resume continues a render from the same stream, rng.h). A pixel of
// the reference is the mean of N_r samples and the snapshot's the mean of its first N_s, so
//   R − S = ((N_r − N_s)/N_r)·(Q − S),   Q the mean of the other N_r − N_s,
//   Var(R − S) = σ²·(1/N_s − 1/N_r),     Var(R − truth) = σ²/N_r,
// and R + k·(S − R) with k = √(N_s/(N_r − N_s)) departs from R as R departs from the truth, pixel by
// pixel with the noise's own shape (heavy tails included, one realisation of it): its ΔE against R
// estimates what a noise-free image reads against R. Throws InputError "PATH: KEY: ..." when the
// snapshot is not an earlier part of the same path-traced render (narval:render_key, narval:seed,
// its sample range inside the reference's and smaller) or the sizes differ.
struct ReferenceNoise {
  long long snapshotSamples = 0, referenceSamples = 0;
  double scale = 0.0;  // k
  ImageRGB perturbed;  // R + k·(S − R)
};
ReferenceNoise estimateReferenceNoise(const std::string& referencePath, const ImageRGB& reference,
                                      const std::string& snapshotPath);

}  // namespace narval
