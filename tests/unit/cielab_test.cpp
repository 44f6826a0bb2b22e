// cielab_test.cpp: linear sRGB -> L*a*b* (D65) against the white point, the published Lab of the
// sRGB primaries and the CIE lightness formula; ΔE*ab; ΔE00 against the 34 test pairs of Sharma,
// Wu & Dalal (2005), Table 1, plus symmetry.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "colour/cielab.h"

namespace {

using narval::deltaE2000;
using narval::deltaE76;
using narval::Lab;
using narval::linearSrgbToLab;

void expectLab(const Lab& got, double L, double a, double b, double tol) {
  EXPECT_NEAR(got.L, L, tol);
  EXPECT_NEAR(got.a, a, tol);
  EXPECT_NEAR(got.b, b, tol);
}

TEST(Cielab, WhiteIsL100Neutral) {
  expectLab(linearSrgbToLab(1, 1, 1), 100, 0, 0, 1e-9);
}

TEST(Cielab, BlackIsZero) {
  expectLab(linearSrgbToLab(0, 0, 0), 0, 0, 0, 1e-12);
}

// Published Lab of the sRGB primaries and secondaries relative to D65 (e.g. Bruce Lindbloom's
// calculator, sRGB, reference white D65, linear input).
TEST(Cielab, PrimariesMatchPublishedValues) {
  expectLab(linearSrgbToLab(1, 0, 0), 53.2408, 80.0925, 67.2032, 1e-3);
  expectLab(linearSrgbToLab(0, 1, 0), 87.7347, -86.1827, 83.1793, 1e-3);
  expectLab(linearSrgbToLab(0, 0, 1), 32.2970, 79.1875, -107.8602, 1e-3);
  expectLab(linearSrgbToLab(0, 1, 1), 91.1132, -48.0875, -14.1312, 1e-3);  // cyan
  expectLab(linearSrgbToLab(1, 0, 1), 60.3242, 98.2343, -60.8249, 1e-3);   // magenta
  expectLab(linearSrgbToLab(1, 1, 0), 97.1393, -21.5537, 94.4780, 1e-3);   // yellow
}

// Greys are neutral; L* follows 116·Y^(1/3) − 16 above (6/29)³ and (29/3)³·Y below it.
TEST(Cielab, GreyLightness) {
  const Lab mid = linearSrgbToLab(0.18, 0.18, 0.18);
  EXPECT_NEAR(mid.L, 116.0 * std::cbrt(0.18) - 16.0, 1e-4);
  EXPECT_NEAR(mid.L, 49.4961, 1e-4);
  EXPECT_NEAR(mid.a, 0.0, 1e-9);
  EXPECT_NEAR(mid.b, 0.0, 1e-9);

  const double kappa = std::pow(29.0 / 3.0, 3.0);  // 903.296...
  const Lab dark = linearSrgbToLab(0.001, 0.001, 0.001);
  EXPECT_NEAR(dark.L, kappa * 0.001, 1e-5);
  EXPECT_NEAR(dark.a, 0.0, 1e-9);
  EXPECT_NEAR(dark.b, 0.0, 1e-9);

  // Continuous across the knee at Y = (6/29)³ ≈ 0.008856 (L* = 8).
  const double knee = std::pow(6.0 / 29.0, 3.0);
  EXPECT_NEAR(linearSrgbToLab(knee, knee, knee).L, 8.0, 1e-5);
  EXPECT_NEAR(linearSrgbToLab(knee * (1 + 1e-9), knee * (1 + 1e-9), knee * (1 + 1e-9)).L, 8.0, 1e-5);
}

TEST(Cielab, LightnessIsMonotoneInGrey) {
  double prev = -1.0;
  for (int i = 0; i <= 1000; ++i) {
    const double v = i / 1000.0;
    const double L = linearSrgbToLab(v, v, v).L;
    EXPECT_GT(L, prev) << v;
    prev = L;
  }
}

TEST(CielabDeltaE76, KnownDifferences) {
  EXPECT_DOUBLE_EQ(deltaE76({50, 0, 0}, {53, 4, 0}), 5.0);
  EXPECT_DOUBLE_EQ(deltaE76({50, 0, 0}, {50, 0, 0}), 0.0);
  EXPECT_DOUBLE_EQ(deltaE76({10, -3, 20}, {10, 9, 25}), 13.0);
  EXPECT_DOUBLE_EQ(deltaE76({0, 0, 0}, {2, 3, 6}), 7.0);
  EXPECT_DOUBLE_EQ(deltaE76({53, 4, 0}, {50, 0, 0}), deltaE76({50, 0, 0}, {53, 4, 0}));
}

struct SharmaPair {
  double L1, a1, b1, L2, a2, b2, dE;
};

// Sharma, Wu & Dalal (2005), Table 1: CIEDE2000 test data, pairs 1-34.
constexpr SharmaPair kSharma[34] = {
    {50.0000, 2.6772, -79.7751, 50.0000, 0.0000, -82.7485, 2.0425},
    {50.0000, 3.1571, -77.2803, 50.0000, 0.0000, -82.7485, 2.8615},
    {50.0000, 2.8361, -74.0200, 50.0000, 0.0000, -82.7485, 3.4412},
    {50.0000, -1.3802, -84.2814, 50.0000, 0.0000, -82.7485, 1.0000},
    {50.0000, -1.1848, -84.8006, 50.0000, 0.0000, -82.7485, 1.0000},
    {50.0000, -0.9009, -85.5211, 50.0000, 0.0000, -82.7485, 1.0000},
    {50.0000, 0.0000, 0.0000, 50.0000, -1.0000, 2.0000, 2.3669},
    {50.0000, -1.0000, 2.0000, 50.0000, 0.0000, 0.0000, 2.3669},
    {50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0009, 7.1792},
    {50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0010, 7.1792},
    {50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0011, 7.2195},
    {50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0012, 7.2195},
    {50.0000, -0.0010, 2.4900, 50.0000, 0.0009, -2.4900, 4.8045},
    {50.0000, -0.0010, 2.4900, 50.0000, 0.0010, -2.4900, 4.8045},
    {50.0000, -0.0010, 2.4900, 50.0000, 0.0011, -2.4900, 4.7461},
    {50.0000, 2.5000, 0.0000, 50.0000, 0.0000, -2.5000, 4.3065},
    {50.0000, 2.5000, 0.0000, 73.0000, 25.0000, -18.0000, 27.1492},
    {50.0000, 2.5000, 0.0000, 61.0000, -5.0000, 29.0000, 22.8977},
    {50.0000, 2.5000, 0.0000, 56.0000, -27.0000, -3.0000, 31.9030},
    {50.0000, 2.5000, 0.0000, 58.0000, 24.0000, 15.0000, 19.4535},
    {50.0000, 2.5000, 0.0000, 50.0000, 3.1736, 0.5854, 1.0000},
    {50.0000, 2.5000, 0.0000, 50.0000, 3.2972, 0.0000, 1.0000},
    {50.0000, 2.5000, 0.0000, 50.0000, 1.8634, 0.5757, 1.0000},
    {50.0000, 2.5000, 0.0000, 50.0000, 3.2592, 0.3350, 1.0000},
    {60.2574, -34.0099, 36.2677, 60.4626, -34.1751, 39.4387, 1.2644},
    {63.0109, -31.0961, -5.8663, 62.8187, -29.7946, -4.0864, 1.2630},
    {61.2901, 3.7196, -5.3901, 61.4292, 2.2480, -4.9620, 1.8731},
    {35.0831, -44.1164, 3.7933, 35.0232, -40.0716, 1.5901, 1.8645},
    {22.7233, 20.0904, -46.6940, 23.0331, 14.9730, -42.5619, 2.0373},
    {36.4612, 47.8580, 18.3852, 36.2715, 50.5065, 21.2231, 1.4146},
    {90.8027, -2.0831, 1.4410, 91.1528, -1.6435, 0.0447, 1.4441},
    {90.9257, -0.5406, -0.9208, 88.6381, -0.8985, -0.7239, 1.5381},
    {6.7747, -0.2908, -2.4247, 5.8714, -0.0985, -2.2286, 0.6377},
    {2.0776, 0.0795, -1.1350, 0.9033, -0.0636, -0.5514, 0.9082},
};

TEST(DeltaE2000, SharmaWuDalalTable1) {
  double maxDev = 0.0;
  for (int i = 0; i < 34; ++i) {
    const SharmaPair& p = kSharma[i];
    const double got = deltaE2000({p.L1, p.a1, p.b1}, {p.L2, p.a2, p.b2});
    // The table gives four decimals: a correct implementation is within 5e-5.
    EXPECT_NEAR(got, p.dE, 1e-4) << "pair " << (i + 1);
    maxDev = std::max(maxDev, std::fabs(got - p.dE));
  }
  std::printf("max |dE00 - published| over the 34 Sharma pairs: %.3g\n", maxDev);
  EXPECT_LE(maxDev, 5.0001e-5);
}

TEST(DeltaE2000, Symmetric) {
  for (int i = 0; i < 34; ++i) {
    const SharmaPair& p = kSharma[i];
    const Lab x{p.L1, p.a1, p.b1};
    const Lab y{p.L2, p.a2, p.b2};
    EXPECT_NEAR(deltaE2000(x, y), deltaE2000(y, x), 1e-12) << "pair " << (i + 1);
  }
  // Converted colours, hue wrap-around included.
  const Lab colours[] = {linearSrgbToLab(1, 0, 0), linearSrgbToLab(0, 1, 0),
                         linearSrgbToLab(0, 0, 1), linearSrgbToLab(0.5, 0.2, 0.9),
                         linearSrgbToLab(0.3, 0.3, 0.3), {40, 10, -0.1}, {45, 10, 0.1}};
  for (const Lab& x : colours) {
    for (const Lab& y : colours) {
      EXPECT_NEAR(deltaE2000(x, y), deltaE2000(y, x), 1e-12);
    }
  }
}

TEST(DeltaE2000, IdenticalIsZeroAndNeutralLightness) {
  EXPECT_EQ(deltaE2000({50, 2.5, 0}, {50, 2.5, 0}), 0.0);
  EXPECT_EQ(deltaE2000({0, 0, 0}, {0, 0, 0}), 0.0);
  // Pure lightness difference between neutrals at L̄ = 50: S_L = 1, so ΔE00 = ΔL.
  EXPECT_NEAR(deltaE2000({49, 0, 0}, {51, 0, 0}), 2.0, 1e-12);
  // Finite and non-negative on achromatic vs chromatic (h' = 0 branch).
  const double d = deltaE2000({50, 0, 0}, {50, 0, 5});
  EXPECT_TRUE(std::isfinite(d));
  EXPECT_GT(d, 0.0);
}

}  // namespace
