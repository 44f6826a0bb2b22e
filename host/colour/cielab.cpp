// cielab.cpp: linear sRGB -> CIE 1976 L*a*b* (D65) and the colour differences ΔE*ab and ΔE00
// (DESIGN.md, Perceptual metric).
//
// RGB -> XYZ: the IEC 61966-2-1 matrix (Rec.709 primaries, D65), inputs linear (no transfer
// curve). The reference white is that matrix applied to (1, 1, 1):
//   Xn = 0.9504700, Yn = 1.0000001, Zn = 1.0888300,
// so linear white maps to exactly L* = 100, a* = b* = 0 (Yn differs from 1 by 1e-7 only through the
// matrix's rounding; L* of a grey of luminance Y moves by < 1e-5).
// f(t) = cbrt(t) for t > δ³, else t / (3δ²) + 4/29, δ = 6/29 (CIE 15:2004).
//
// CIEDE2000 follows Sharma, Wu & Dalal, "The CIEDE2000 color-difference formula: implementation
// notes, supplementary test data, and mathematical observations", Color Res. Appl. 30(1), 2005,
// equations (1)-(17), kL = kC = kH = 1, with their notes: h' = 0 when a' = b = 0; Δh' = 0 and
// h̄' = h'1 + h'2 when C'1·C'2 = 0; Δh' and h̄' corrected by ±360° when |h'1 − h'2| > 180°.
#include "colour/cielab.h"

#include <cmath>

namespace narval {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
constexpr double kRadToDeg = 180.0 / kPi;

// sRGB (linear) -> XYZ, D65.
constexpr double kM[3][3] = {
    {0.4124564, 0.3575761, 0.1804375},
    {0.2126729, 0.7151522, 0.0721750},
    {0.0193339, 0.1191920, 0.9503041},
};
constexpr double kXn = kM[0][0] + kM[0][1] + kM[0][2];  // 0.9504700
constexpr double kYn = kM[1][0] + kM[1][1] + kM[1][2];  // 1.0000001
constexpr double kZn = kM[2][0] + kM[2][1] + kM[2][2];  // 1.0888300

constexpr double kDelta = 6.0 / 29.0;

double labF(double t) {
  if (t > kDelta * kDelta * kDelta) return std::cbrt(t);
  return t / (3.0 * kDelta * kDelta) + 4.0 / 29.0;
}

// Hue angle in degrees, [0, 360); 0 for the achromatic axis (Sharma et al. eq. 4 note).
double hueDeg(double b, double ap) {
  if (b == 0.0 && ap == 0.0) return 0.0;
  double h = std::atan2(b, ap) * kRadToDeg;
  if (h < 0.0) h += 360.0;
  return h;
}

double pow7(double x) {
  const double x2 = x * x;
  const double x3 = x2 * x;
  return x3 * x3 * x;
}

}  // namespace

Lab linearSrgbToLab(double r, double g, double b) {
  const double x = kM[0][0] * r + kM[0][1] * g + kM[0][2] * b;
  const double y = kM[1][0] * r + kM[1][1] * g + kM[1][2] * b;
  const double z = kM[2][0] * r + kM[2][1] * g + kM[2][2] * b;
  const double fx = labF(x / kXn);
  const double fy = labF(y / kYn);
  const double fz = labF(z / kZn);
  Lab lab;
  lab.L = 116.0 * fy - 16.0;
  lab.a = 500.0 * (fx - fy);
  lab.b = 200.0 * (fy - fz);
  return lab;
}

double deltaE76(const Lab& x, const Lab& y) {
  const double dL = x.L - y.L;
  const double da = x.a - y.a;
  const double db = x.b - y.b;
  return std::sqrt(dL * dL + da * da + db * db);
}

double deltaE2000(const Lab& x, const Lab& y) {
  constexpr double k25pow7 = 6103515625.0;  // 25^7

  // Step 1: C'i, h'i.
  const double c1 = std::hypot(x.a, x.b);
  const double c2 = std::hypot(y.a, y.b);
  const double cBar = 0.5 * (c1 + c2);
  const double cBar7 = pow7(cBar);
  const double g = 0.5 * (1.0 - std::sqrt(cBar7 / (cBar7 + k25pow7)));
  const double a1p = (1.0 + g) * x.a;
  const double a2p = (1.0 + g) * y.a;
  const double c1p = std::hypot(a1p, x.b);
  const double c2p = std::hypot(a2p, y.b);
  const double h1p = hueDeg(x.b, a1p);
  const double h2p = hueDeg(y.b, a2p);

  // Step 2: ΔL', ΔC', ΔH'.
  const double dLp = y.L - x.L;
  const double dCp = c2p - c1p;
  const double cProd = c1p * c2p;
  double dhp = 0.0;
  if (cProd != 0.0) {
    dhp = h2p - h1p;
    if (dhp > 180.0) {
      dhp -= 360.0;
    } else if (dhp < -180.0) {
      dhp += 360.0;
    }
  }
  const double dHp = 2.0 * std::sqrt(cProd) * std::sin(0.5 * dhp * kDegToRad);

  // Step 3: means, weights, rotation.
  const double lBarP = 0.5 * (x.L + y.L);
  const double cBarP = 0.5 * (c1p + c2p);
  double hBarP = h1p + h2p;
  if (cProd != 0.0) {
    if (std::fabs(h1p - h2p) <= 180.0) {
      hBarP = 0.5 * (h1p + h2p);
    } else if (h1p + h2p < 360.0) {
      hBarP = 0.5 * (h1p + h2p + 360.0);
    } else {
      hBarP = 0.5 * (h1p + h2p - 360.0);
    }
  }
  const double t = 1.0 - 0.17 * std::cos((hBarP - 30.0) * kDegToRad) +
                   0.24 * std::cos(2.0 * hBarP * kDegToRad) +
                   0.32 * std::cos((3.0 * hBarP + 6.0) * kDegToRad) -
                   0.20 * std::cos((4.0 * hBarP - 63.0) * kDegToRad);
  const double dThetaArg = (hBarP - 275.0) / 25.0;
  const double dTheta = 30.0 * std::exp(-dThetaArg * dThetaArg);
  const double cBarP7 = pow7(cBarP);
  const double rC = 2.0 * std::sqrt(cBarP7 / (cBarP7 + k25pow7));
  const double l50 = (lBarP - 50.0) * (lBarP - 50.0);
  const double sL = 1.0 + 0.015 * l50 / std::sqrt(20.0 + l50);
  const double sC = 1.0 + 0.045 * cBarP;
  const double sH = 1.0 + 0.015 * cBarP * t;
  const double rT = -std::sin(2.0 * dTheta * kDegToRad) * rC;

  const double tL = dLp / sL;
  const double tC = dCp / sC;
  const double tH = dHp / sH;
  return std::sqrt(tL * tL + tC * tC + tH * tH + rT * tC * tH);
}

}  // namespace narval
