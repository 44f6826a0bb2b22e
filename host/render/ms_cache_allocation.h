// ms_cache_allocation.h: paths per column of the view cache (kernels/shared/ms_cache_view.h) spread by
// what their noise costs the eye (renderer.raymarch.msCache.allocation "perceptual"). Why: on the back-lit
// Disney cloud every pixel the 8-bit judge fails lies in an opaque column, mostly on the bright rims of the
// dark body, where the cache's noise (seed against seed, over √2) is largest; small inside, nil on the
// saturated silhouettes (bench/RESULTS.md). An even share spends most paths where they change no pixel.
//
// What: after a pilot of every node (kPilotShare of the mean), column c's pixel and per-path spread are
//   Y_c = Σ_s ΔT_s·a·J̄_s + e^{−τ_end}·L_b,   σ_c² = Σ_s (ΔT_s·a)²·Var_s,
// ΔT_s the transmittance slice s spans, a the grey albedo, J̄_s and Var_s the slice's grey running mean
// and per-path variance, the last term the background let through (MS_VIEW_SEEN). An error δY shows as
// δL* = L*'(Y)·δY through the display (exposure, tone curve; L* of the displayed linear value), so
// E[(δL*)²] = (L*'(Y_c)·σ_c)²/n_c, least at a fixed total for n_c ∝ L*'(Y_c)·σ_c (Lagrange multiplier), kept within
// [kFloorShare, kCapShare] of the mean: no column is left with the few paths whose skewed mean a denoiser
// favours (a floor at the pilot darkened the rims; bench/RESULTS.md). Y_c and σ_c come from the eight
// neighbours, not the column's own pilot, so its budget ignores its own paths (but for the common scale,
// and with no neighbour in the medium) and its mean stays unbiased (a dim pilot must not starve a node;
// bench/RESULTS.md, allocation by spread). The budgets average to the mean over columns with medium.
#pragma once

#include <vector>

#include "scene/scene.h"
#include "shared/structs.h"

namespace narval {

// The pilot every node takes before the budgets are set, and the budgets' bounds, as shares of the mean
// paths per node (why this floor, not one at the pilot: above).
constexpr double kMsAllocationPilotShare = 0.25;
constexpr double kMsAllocationFloorShare = 0.625;
constexpr double kMsAllocationCapShare = 2.5;

// Besides the cache: whether the allocation is on, the mean paths per node it spreads, the display.
struct MsCacheAllocation {
  bool perceptual = false;
  int meanPaths = 0;
  ToneMapping toneMapping = ToneMapping::Aces;
  float exposure = 0.0f;
};

// The pilot's paths per node for a mean of meanPaths (at least 1, below the mean when it can be).
int msAllocationPilot(int meanPaths);

// One column's prediction from its pilot (above): whether it holds medium, Y_c and σ_c.
struct MsColumnPilot {
  bool medium = false;
  double value = 0, spread = 0;
};

// Column predictions from `cache` (nodeGridCount(c) × MS_CACHE_STRIDE floats, ms_cache_view.h), grey albedo `albedo`.
std::vector<MsColumnPilot> msColumnPilots(const std::vector<float>& cache, const node_grid_params& c, double albedo);

// Each column's weight L*'(Y)·σ (0 without medium) on an nx × ny image grid, from its eight neighbours
// with medium: its own pilot enters only when none of them holds medium.
std::vector<double> msPerceptualWeights(const std::vector<MsColumnPilot>& columns, int nx, int ny,
                                        const MsCacheAllocation& allocation);

// Each column's paths (0 without medium): its weight times the one scale making the medium columns'
// budgets average `meanPaths` within floor and cap (rounded: ±0.5). Via the others' weights the scale
// depends on a column's own pilot by about 1/(columns with medium): a few paths at most.
std::vector<int> msPerceptualBudgets(const std::vector<MsColumnPilot>& columns, int nx, int ny,
                                     const MsCacheAllocation& allocation);

// The slope dL*/dY of the displayed L* at scene-linear grey value Y (the display transform of
// DESIGN.md: 2^exposure, then the tone curve, clamped to [0, 1]); 0 where the display saturates.
double displayLightnessSlope(double Y, ToneMapping toneMapping, float exposure);

}  // namespace narval
