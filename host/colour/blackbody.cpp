#include "colour/blackbody.h"

#include <cmath>

#include "colour/cie1931_table.h"

namespace narval {
namespace {

// CODATA 2010 values, as pbrt-v4 uses them.
constexpr double kPlanck = 6.62606957e-34, kLight = 299792458.0, kBoltzmann = 1.3806488e-23;
constexpr double kWien = 2.8977721e-3;  // m·K

}  // namespace

double blackbodyPlanck(double lambdaNm, double kelvin) {
  if (!(kelvin > 0.0)) return 0.0;
  const double l = lambdaNm * 1e-9;
  return 2.0 * kPlanck * kLight * kLight / (std::pow(l, 5) * std::expm1(kPlanck * kLight / (l * kBoltzmann * kelvin)));
}

double blackbodyNormalized(double lambdaNm, double kelvin) {
  if (!(kelvin > kBlackbodyMinKelvin)) return 0.0;
  return blackbodyPlanck(lambdaNm, kelvin) / blackbodyPlanck(kWien / kelvin * 1e9, kelvin);
}

std::array<float, 3> blackbodyLinearSrgb(double kelvin) {
  if (!(kelvin > kBlackbodyMinKelvin)) return {0.0f, 0.0f, 0.0f};
  // Trapezoids of 1 nm over the table (360–830 nm); the ȳ integral over the same grid.
  double xyz[3] = {0, 0, 0}, yIntegral = 0;
  for (int i = 0; i < kCie1931Count; ++i) {
    const double w = (i == 0 || i == kCie1931Count - 1) ? 0.5 : 1.0;
    const double b = blackbodyNormalized(kCie1931FirstNm + i, kelvin);
    for (int c = 0; c < 3; ++c) xyz[c] += w * b * kCie1931[i][c];
    yIntegral += w * kCie1931[i][1];
  }
  for (double& v : xyz) v /= yIntegral;
  // XYZ -> linear sRGB (IEC 61966-2-1).
  return {float(3.2404542 * xyz[0] - 1.5371385 * xyz[1] - 0.4985314 * xyz[2]),
          float(-0.9692660 * xyz[0] + 1.8760108 * xyz[1] + 0.0415560 * xyz[2]),
          float(0.0556434 * xyz[0] - 0.2040259 * xyz[1] + 1.0572252 * xyz[2])};
}

}  // namespace narval
