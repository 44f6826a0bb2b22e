#include "render/ms_cache_allocation.h"

#include <algorithm>
#include <cmath>

#include "colour/cielab.h"
#include "image/display_transform.h"
#include "shared/ms_cache.h"
#include "shared/ms_cache_view.h"

namespace narval {

int msAllocationPilot(int meanPaths) {
  return std::max(1, std::min(meanPaths - 1, int(std::lround(kMsAllocationPilotShare * meanPaths))));
}

std::vector<MsColumnPilot> msColumnPilots(const std::vector<float>& cache, const node_grid_params& c, double albedo) {
  const size_t columns = size_t(c.nx) * size_t(c.ny), sliceStride = columns * MS_CACHE_STRIDE;
  std::vector<MsColumnPilot> out(columns);
  for (size_t col = 0; col < columns; ++col) {
    const float* first = &cache[col * MS_CACHE_STRIDE];
    if (!(first[MS_VIEW_TAU] >= 0.0f)) continue;
    MsColumnPilot& p = out[col];
    p.medium = true;
    p.value = first[MS_VIEW_SEEN];
    double variance = 0;
    for (int s = 0; s < c.nz; ++s) {
      const float* v = first + size_t(s) * sliceStride;
      // ΔT: the transmittance between the slice's ends (the last one's end is the column's level
      // of MS_VIEW_T_MIN, or its own end, where the lookup reads it on).
      const double dT = (std::exp(-double(v[MS_VIEW_TAU])) - std::exp(-double(v[MS_VIEW_TAU_END]))) * albedo;
      const double J = (double(v[0]) + double(v[1]) + double(v[2])) / 3.0;
      p.value += dT * J;
      variance += dT * dT * std::max(0.0, double(v[MS_CACHE_SQUARE]) - J * J);
    }
    p.spread = std::sqrt(variance);
  }
  return out;
}

double displayLightnessSlope(double Y, ToneMapping toneMapping, float exposure) {
  const float scale = exposureScale(exposure);
  auto lightness = [&](double y) {
    const double d = displayLinear(float(std::max(0.0, y)), scale, toneMapping);
    return linearSrgbToLab(d, d, d).L;
  };
  // A central difference over ±5% (and a floor, for Y = 0): the slope over the spread of a few
  // paths' means, not at a point.
  const double h = 0.05 * Y + 1e-6;
  return std::fabs(lightness(Y + h) - lightness(Y - h)) / (2 * h);
}

std::vector<double> msPerceptualWeights(const std::vector<MsColumnPilot>& columns, int nx, int ny,
                                        const MsCacheAllocation& allocation) {
  std::vector<double> weight(columns.size(), 0.0);
  for (int cy = 0; cy < ny; ++cy)
    for (int cx = 0; cx < nx; ++cx) {
      const size_t col = size_t(cx) + size_t(nx) * size_t(cy);
      if (!columns[col].medium) continue;
      double value = 0, variance = 0;
      int n = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = cx + dx, y = cy + dy;
          if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= nx || y >= ny) continue;
          const MsColumnPilot& p = columns[size_t(x) + size_t(nx) * size_t(y)];
          if (!p.medium) continue;
          value += p.value;
          variance += p.spread * p.spread;
          ++n;
        }
      if (n == 0) {
        value = columns[col].value;
        variance = columns[col].spread * columns[col].spread;
        n = 1;
      }
      weight[col] = displayLightnessSlope(value / n, allocation.toneMapping, allocation.exposure) *
                    std::sqrt(variance / n);
    }
  return weight;
}

std::vector<int> msPerceptualBudgets(const std::vector<MsColumnPilot>& columns, int nx, int ny,
                                     const MsCacheAllocation& allocation) {
  const std::vector<double> weight = msPerceptualWeights(columns, nx, ny, allocation);
  size_t withMedium = 0;
  for (const MsColumnPilot& p : columns) withMedium += p.medium ? 1 : 0;
  std::vector<int> budgets(columns.size(), 0);
  if (withMedium == 0) return budgets;
  const double mean = allocation.meanPaths, lo = kMsAllocationFloorShare * mean, hi = kMsAllocationCapShare * mean;
  auto total = [&](double k) {
    double sum = 0;
    for (size_t col = 0; col < columns.size(); ++col)
      if (columns[col].medium) sum += std::clamp(k * weight[col], lo, hi);
    return sum;
  };
  // total(k) rises from lo·n to hi·n: bisect (in log k) for the k whose budgets sum to mean·n. All
  // weights 0 (noiseless pilots) leave every column at the floor: then the even share instead.
  const double target = mean * double(withMedium);
  double kLo = 1e-30, kHi = 1e30;
  if (total(kHi) < target) {
    for (size_t col = 0; col < columns.size(); ++col) budgets[col] = columns[col].medium ? allocation.meanPaths : 0;
    return budgets;
  }
  for (int i = 0; i < 200; ++i) {
    const double k = std::sqrt(kLo * kHi);
    (total(k) > target ? kHi : kLo) = k;
  }
  for (size_t col = 0; col < columns.size(); ++col)
    if (columns[col].medium) budgets[col] = int(std::lround(std::clamp(kLo * weight[col], lo, hi)));
  return budgets;
}

}  // namespace narval
