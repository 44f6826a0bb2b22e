// light_selection.h: the probabilities with which the path tracer's next-event estimation picks one
// light per scattering event (kernels/shared/light_select.h; renderer.pathtrace.lightSampling).
#pragma once

#include <vector>

#include "render/scene_upload.h"
#include "scene/scene.h"

namespace narval {

// The share of the probability spread evenly over the lights by `fluence` selection, so that a light
// the estimate misses (one lighting the medium only where the sample points are not, or behind the
// box's corners) is still picked: its variance is bounded by 1/(kFluenceUniformShare/N) times the
// all-lights estimate's. Power selection has none: a light's power is exact, and a light of no
// power contributes nothing.
constexpr double kFluenceUniformShare = 0.1;

// Each light's unnormalised selection weight.
// - Power: emitted power, π·A·mean(Le) for a rectangle (one-sided), 4π·mean(I) for a point light
//   (pbrt-v4's PowerLightSampler).
// - Fluence: the unshadowed fluence the light gives the medium, averaged over points of the medium
//   weighted by their density: ∫ Le dω over the rectangle (4×4 patches, cos θ_l·ΔA/d²) or I/d².
//   Shadows and the phase function are left out: the estimate only has to be roughly proportional
//   to each light's share for the one-light estimator's variance to be low; unbiasedness does not
//   depend on it.
std::vector<double> lightSelectionWeights(const DeviceScene& ds, LightSampling mode);

// Sets ds.params.light_sampling and every light's select_prob for `mode` (lightSelectionWeights,
// normalised; fluence mixed with the uniform share above). All: every light gets a shadow ray,
// probabilities 1.
void assignLightSelection(DeviceScene& ds, LightSampling mode);

}  // namespace narval
