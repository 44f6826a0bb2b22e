// ms_cache_allocation.h: how many paths each column of the view cache (kernels/shared/ms_cache_view.h)
// takes, when they are spread by what their noise costs the eye instead of evenly
// (renderer.raymarch.msCache.allocation "perceptual").
//
// Why: on the back-lit Disney cloud every pixel the 8-bit judge fails lies in an opaque column, most
// on the bright rims of the cloud's dark body, where the cache's noise (one seed against another,
// over √2) is largest; in the dark interior it is small, on the white, saturated silhouettes nil
// (bench/RESULTS.md). An even share of paths spends most of them where they change no pixel.
//
// What: after a pilot of every node (kPilotShare of the mean), column c's pixel is predicted as
//   Y_c = Σ_s ΔT_s·a·J̄_s + e^{−τ_end}·L_b,
// ΔT_s the transmittance its slice s spans, a the grey albedo, J̄_s the slice's grey running mean
// and the last term the background it lets through (MS_VIEW_SEEN), and its per-path spread as
// σ_c² = Σ_s (ΔT_s·a)²·Var_s, Var_s the slice's per-path variance. An error δY shows as
// δL* = L*'(Y)·δY through the scene's display (exposure, tone curve; L* of the displayed linear
// value), so the expected (δL*)² after n_c paths is (L*'(Y_c)·σ_c)²/n_c; at a fixed total it is
// least for n_c ∝ L*'(Y_c)·σ_c (a Lagrange multiplier), kept within [kFloorShare, kCapShare] of the
// mean so that no column is left with the few paths whose skewed mean a denoiser then favours
// (a floor at the pilot darkened the rims: bench/RESULTS.md). Both Y_c and σ_c are taken from
// the column's eight neighbours, not its own pilot: its budget is then independent of its own paths
// (but for the common scale, and for a column with no neighbour in the medium), so its mean stays
// unbiased (a node that drew a dim pilot must not be starved; bench/RESULTS.md, the allocation by
// spread). The budgets average to the mean over the columns holding medium.
#pragma once

#include <vector>

#include "scene/scene.h"
#include "shared/structs.h"

namespace narval {

// The pilot every node takes before the budgets are set, and the budgets' bounds, as shares of
// the mean paths per node. The floor: kMsAllocationFloorShare of the mean read the back-lit Disney
// cloud better than a floor at the pilot (bench/RESULTS.md).
constexpr double kMsAllocationPilotShare = 0.25;
constexpr double kMsAllocationFloorShare = 0.625;
constexpr double kMsAllocationCapShare = 2.5;

// What the allocation needs to know besides the cache: whether it is on, the mean paths per node it
// spreads, and the display the eye sees the pixels through.
struct MsCacheAllocation {
  bool perceptual = false;
  int meanPaths = 0;
  ToneMapping toneMapping = ToneMapping::Aces;
  float exposure = 0.0f;
};

// The pilot's paths per node for a mean of meanPaths (at least 1, below the mean when it can be).
int msAllocationPilot(int meanPaths);

// One column's prediction from its pilot: whether it holds medium, its pixel's value Y_c and the
// per-path spread σ_c of that value (above).
struct MsColumnPilot {
  bool medium = false;
  double value = 0, spread = 0;
};

// The columns' predictions from the view cache's nodes `cache` (nodeGridCount(c) nodes of
// MS_CACHE_STRIDE floats, as ms_cache_view.h lays them out), for a medium of grey albedo `albedo`.
std::vector<MsColumnPilot> msColumnPilots(const std::vector<float>& cache, const node_grid_params& c, double albedo);

// Each column's weight L*'(Y)·σ from its eight neighbours with medium (0 without medium), for
// columns on an nx × ny image grid: a column's own pilot never enters its own weight, except for
// a column none of whose neighbours holds medium, which has only its own to go by.
std::vector<double> msPerceptualWeights(const std::vector<MsColumnPilot>& columns, int nx, int ny,
                                        const MsCacheAllocation& allocation);

// Each column's paths (0 for a column without medium): its weight times the one scale that makes the
// budgets of the columns with medium average `meanPaths` within the floor and cap (rounded; the
// average is then within ±0.5 of it). The scale depends on every column, so on a column's own pilot
// through the others' weights, by about 1/(columns with medium): a few paths' worth at most.
std::vector<int> msPerceptualBudgets(const std::vector<MsColumnPilot>& columns, int nx, int ny,
                                     const MsCacheAllocation& allocation);

// The slope dL*/dY of the displayed L* at scene-linear grey value Y (the display transform of
// DESIGN.md: 2^exposure, then the tone curve, clamped to [0, 1]); 0 where the display saturates.
double displayLightnessSlope(double Y, ToneMapping toneMapping, float exposure);

}  // namespace narval
