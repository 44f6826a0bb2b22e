// Blackbody emission (host/colour/blackbody.h) against values computed here, independently of its code:
// Planck's law written out again and the CIE 1931 2° table at 5 nm (tests/data/cie1931_2deg_5nm.csv;
// the implementation integrates its own 1 nm table).
#include "colour/blackbody.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace narval {
namespace {

struct CmfRow {
  double nm, x, y, z;
};

std::vector<CmfRow> cieTable() {
  std::ifstream in(std::string(NARVAL_SOURCE_DIR) + "/tests/data/cie1931_2deg_5nm.csv");
  std::vector<CmfRow> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    CmfRow r{};
    char comma;
    std::istringstream s(line);
    s >> r.nm >> comma >> r.x >> comma >> r.y >> comma >> r.z;
    rows.push_back(r);
  }
  return rows;
}

// Planck's law written out again (h, c, k as CODATA 2010), peak-normalised with Wien's law, then
// XYZ by trapezoids over the 5 nm table divided by the table's own ȳ integral, then linear sRGB.
std::array<double, 3> expectedSrgb(double T) {
  auto planck = [T](double nm) {
    const double h = 6.62606957e-34, c = 299792458.0, k = 1.3806488e-23, l = nm * 1e-9;
    return 2 * h * c * c / (std::pow(l, 5) * (std::exp(h * c / (l * k * T)) - 1));
  };
  const double peak = planck(2.8977721e-3 / T * 1e9);
  const std::vector<CmfRow> t = cieTable();
  double X = 0, Y = 0, Z = 0, yInt = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    const double w = (i == 0 || i + 1 == t.size()) ? 2.5 : 5.0;  // trapezoids of 5 nm
    const double b = planck(t[i].nm) / peak;
    X += w * b * t[i].x;
    Y += w * b * t[i].y;
    Z += w * b * t[i].z;
    yInt += w * t[i].y;
  }
  X /= yInt;
  Y /= yInt;
  Z /= yInt;
  return {3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z, -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z,
          0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z};
}

TEST(Blackbody, TheTableIsTheCie1931Observer) {
  const std::vector<CmfRow> t = cieTable();
  ASSERT_EQ(t.size(), 95u);  // 360, 365, ..., 830 nm
  EXPECT_EQ(t.front().nm, 360.0);
  EXPECT_EQ(t.back().nm, 830.0);
  // ȳ is the photopic luminosity function: 1 at 555 nm; ∫ȳ dλ = 106.857 nm (pbrt-v4's CIE_Y_integral).
  double yInt = 0;
  for (size_t i = 0; i < t.size(); ++i) yInt += (i == 0 || i + 1 == t.size() ? 2.5 : 5.0) * t[i].y;
  EXPECT_NEAR(t[39].nm, 555.0, 0.0);
  EXPECT_NEAR(t[39].y, 1.0, 1e-4);
  EXPECT_NEAR(yInt, 106.857, 0.05);
}

TEST(Blackbody, NormalisedPeakIsOneAtWiensWavelength) {
  for (double T : {1000.0, 3000.0, 6500.0}) {
    const double peakNm = 2.8977721e-3 / T * 1e9;
    EXPECT_NEAR(blackbodyNormalized(peakNm, T), 1.0, 1e-12) << T;
    EXPECT_LT(blackbodyNormalized(peakNm * 0.9, T), 1.0);
    EXPECT_LT(blackbodyNormalized(peakNm * 1.1, T), 1.0);
  }
  EXPECT_EQ(blackbodyNormalized(500.0, 100.0), 0.0);  // nothing at or below 100 K
  EXPECT_EQ(blackbodyNormalized(500.0, 50.0), 0.0);
}

// Trapezoids of 5 nm against 1 nm over the same smooth integrands differ by O(h²) of the integrand's
// curvature; measured at most 3e-5 of the largest channel (1000 K, the steepest: the deep-red tail),
// so 1e-4 of it bounds the comparison. An error in the pipeline (a wrong constant, the wrong
// normalisation, a swapped matrix row) moves the colours by far more.
TEST(Blackbody, ColoursMatchTheCieTablesAt1000And3000And6500K) {
  for (double T : {1000.0, 3000.0, 6500.0}) {
    const std::array<double, 3> want = expectedSrgb(T);
    const std::array<float, 3> got = blackbodyLinearSrgb(T);
    const double top = std::max({std::fabs(want[0]), std::fabs(want[1]), std::fabs(want[2])});
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(got[c], want[c], 1e-4 * top) << T << " K, channel " << c;
      std::printf("[ blackbody ] %5.0f K channel %d: here %.6e, narval %.6e\n", T, c, want[c], double(got[c]));
    }
  }
  // Hotter is bluer: the blue/red ratio grows with temperature.
  const auto a = blackbodyLinearSrgb(1000), b = blackbodyLinearSrgb(3000), c = blackbodyLinearSrgb(6500);
  EXPECT_LT(a[2] / a[0], b[2] / b[0]);
  EXPECT_LT(b[2] / b[0], c[2] / c[0]);
  // 6500 K is close to D65, sRGB's white: the channels within 10% of each other.
  EXPECT_NEAR(c[2] / c[0], 1.0, 0.1);
  EXPECT_NEAR(c[1] / c[0], 1.0, 0.1);
}

TEST(Blackbody, NothingAtOrBelow100K) {
  for (double T : {-5.0, 0.0, 50.0, 100.0}) {
    const std::array<float, 3> v = blackbodyLinearSrgb(T);
    EXPECT_EQ(v[0], 0.0f) << T;
    EXPECT_EQ(v[1], 0.0f) << T;
    EXPECT_EQ(v[2], 0.0f) << T;
  }
  // Just above, a real but tiny emission: at 500 K the visible tail is about 1e-9 of the peak.
  EXPECT_GT(blackbodyLinearSrgb(500.0)[0], 0.0f);
}

}  // namespace
}  // namespace narval
