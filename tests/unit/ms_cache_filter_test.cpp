// The view cache's filter (kernels/shared/ms_cache_filter.h): neighbouring columns averaged where
// they agree within their noise, kept apart where they differ beyond it, read at the node's own
// optical depths.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "shared/ms_cache_filter.h"

namespace narval::test {
namespace {

struct FilterCase {
  node_grid_params c{};
  std::vector<float> cache;
};

// nx x ny columns of nz slices; slice s of every column spans τ ∈ [tau(s), tau(s + 1)] (the last
// slice ends at tau(nz)); node (cx, cy, s) holds grey value value(cx, cy, s) from `paths` paths whose
// grey mean has variance `variance` (the running mean of L² is then J² + paths·variance).
FilterCase filterCase(int nx, int ny, int nz, const std::function<float(int)>& tau,
                      const std::function<float(int, int, int)>& value, float variance, float paths = 100) {
  FilterCase f;
  f.c.nx = nx;
  f.c.ny = ny;
  f.c.nz = nz;
  f.cache.assign(size_t(nx * ny * nz) * MS_CACHE_STRIDE, 0.0f);
  for (int s = 0; s < nz; ++s)
    for (int cy = 0; cy < ny; ++cy)
      for (int cx = 0; cx < nx; ++cx) {
        float* v = f.cache.data() + size_t(cx + nx * (cy + ny * s)) * MS_CACHE_STRIDE;
        const float J = value(cx, cy, s);
        v[0] = v[1] = v[2] = J;
        v[3] = paths;
        v[MS_CACHE_SQUARE] = J * J + paths * variance;
        v[MS_VIEW_TAU] = tau(s);
        v[MS_VIEW_TAU_END] = tau(s + 1);
      }
  return f;
}

// The filtered cache: every column through ms_view_filter_column, as the kernel runs it.
std::vector<float> filtered(const FilterCase& f, float sigma, float tolerance) {
  std::vector<float> out(f.cache.size());
  for (int column = 0; column < f.c.nx * f.c.ny; ++column)
    ms_view_filter_column(&f.c, f.cache.data(), f.cache.data(), 0, column, sigma, tolerance,
                          out.data() + size_t(column) * MS_CACHE_STRIDE);
  return out;
}

// Twiced: the second pass over the first's output, with the running means' weights ("Twicing").
std::vector<float> twiced(const FilterCase& f, float sigma, float tolerance) {
  const std::vector<float> first = filtered(f, sigma, tolerance);
  std::vector<float> out(f.cache.size());
  for (int column = 0; column < f.c.nx * f.c.ny; ++column)
    ms_view_filter_column(&f.c, f.cache.data(), first.data(), 1, column, sigma, tolerance,
                          out.data() + size_t(column) * MS_CACHE_STRIDE);
  return out;
}

float at(const FilterCase& f, const std::vector<float>& v, int cx, int cy, int s) {
  return v[size_t(cx + f.c.nx * (cy + f.c.ny * s)) * MS_CACHE_STRIDE];
}

const std::function<float(int)> kEvenSlices = [](int s) { return 0.5f * float(s); };

// The variance of a node's mean is (mean of L² − J²)/paths ("v").
TEST(MsCacheFilter, ANodesVarianceIsThatOfItsMean) {
  const FilterCase f = filterCase(1, 1, 2, kEvenSlices, [](int, int, int) { return 3.0f; }, 0.25f, 64);
  EXPECT_NEAR(ms_view_grey_variance(f.cache.data()), 0.25f, 1e-6f);
}

// Every read of a constant field is the constant and the weights are normalised: J̃ = J exactly,
// whatever σ_s and k; the slots other than R are the column's own.
TEST(MsCacheFilter, AConstantFieldIsUnchanged) {
  const FilterCase f = filterCase(5, 4, 3, kEvenSlices, [](int, int, int) { return 2.5f; }, 0.1f);
  for (float sigma : {0.5f, 1.0f, 3.0f})
    for (float k : {0.25f, 1.0f, 8.0f}) {
      for (const std::vector<float>& out : {filtered(f, sigma, k), twiced(f, sigma, k)})
        for (size_t i = 0; i < out.size(); ++i)
          ASSERT_FLOAT_EQ(out[i], f.cache[i]) << "slot " << i % MS_CACHE_STRIDE << ", sigma " << sigma << ", k " << k;
    }
}

// Twicing cancels the blur's bias on a curved field. J = 1 + 0.01·((cx − 4)² + (cy − 4)²) on 9x9
// columns, variance 1 (every Δ² ≤ 0.32² < 2v: d² = 0, the weights are the Gaussian's). σ_s = 1 cuts
// the Gaussian at radius 2, and its weights factor over the axes, so S adds the discrete second
// moment per axis times the curvature: S(J) = J + 0.01·2·m₂, m₂ = Σ_{|d|≤2} d²e^{−d²/2} / Σ_{|d|≤2}
// e^{−d²/2} = 2(e^{−1/2} + 4e^{−2}) / (1 + 2e^{−1/2} + 2e^{−2}) = 0.92431 (a quadratic's S is the
// quadratic plus a constant). S(S(J)) = J + 2·(0.01·2·m₂), so 2·S(J) − S(S(J)) = J exactly, at every
// column whose twice-widened window (radius 4) stays inside the image: the centre.
TEST(MsCacheFilter, TwicingReproducesAQuadraticFieldWhereTheFilterIsOffByItsSecondMoment) {
  auto value = [](int cx, int cy, int) { return 1.0f + 0.01f * float((cx - 4) * (cx - 4) + (cy - 4) * (cy - 4)); };
  const FilterCase f = filterCase(9, 9, 2, kEvenSlices, value, 1.0f);
  const double m2 = 2 * (std::exp(-0.5) + 4 * std::exp(-2.0)) / (1 + 2 * std::exp(-0.5) + 2 * std::exp(-2.0));
  const std::vector<float> plain = filtered(f, 1.0f, 1.0f), twice = twiced(f, 1.0f, 1.0f);
  for (int s = 0; s < 2; ++s) {
    EXPECT_NEAR(at(f, plain, 4, 4, s), 1.0 + 0.01 * 2 * m2, 1e-5) << "slice " << s;
    EXPECT_NEAR(at(f, twice, 4, 4, s), 1.0, 1e-5) << "slice " << s;
  }
  // Off the centre the first pass is still J + 0.01·2·m₂ where its own window (radius 2) fits.
  EXPECT_NEAR(at(f, plain, 2, 5, 0), value(2, 5, 0) + 0.01 * 2 * m2, 1e-5);
}

// Twicing's kernel 2S − S² is negative beyond S's radius, so next to a dark hole it can fall below
// 0, which radiance cannot: J = 0 on the 5x5 centre of 9x9 columns and 1 around it, variance 1 (the
// Gaussian's weights, σ_s = 1, radius 2). The centre's S(J) is 0 (its window is the hole), S(S(J))
// there takes S(J) of columns such as (6, 4), which reach the 1s: 2·0 − S(S(J)) < 0, written as 0.
TEST(MsCacheFilter, TwicingIsClampedAtZero) {
  auto value = [](int cx, int cy, int) { return std::abs(cx - 4) <= 2 && std::abs(cy - 4) <= 2 ? 0.0f : 1.0f; };
  const FilterCase f = filterCase(9, 9, 1, kEvenSlices, value, 1.0f);
  const std::vector<float> plain = filtered(f, 1.0f, 1.0f), twice = twiced(f, 1.0f, 1.0f);
  EXPECT_EQ(at(f, plain, 4, 4, 0), 0.0f);
  EXPECT_GT(at(f, plain, 6, 4, 0), 0.1f);  // S(S(J)) at the centre is positive
  EXPECT_EQ(at(f, twice, 4, 4, 0), 0.0f);
  for (int cy = 0; cy < 9; ++cy)
    for (int cx = 0; cx < 9; ++cx) EXPECT_GE(at(f, twice, cx, cy, 0), 0.0f) << cx << "," << cy;
}

// Two columns, one slice each: J = 1 and 1 + Δ, each of variance v. With Δ² = (1 + k²)·2v the
// patch distance is d² = (Δ² − 2v)/(k²·2v) = 1, so each weighs the other e^{−1/(2σ²) − 1}:
//   J̃_0 = (1 + e^{−1/(2σ²) − 1}·(1 + Δ)) / (1 + e^{−1/(2σ²) − 1}).
// With σ_s = 1 the weight is e^{−1.5}; nearer (Δ² ≤ 2v) it is the Gaussian's alone, e^{−0.5}.
TEST(MsCacheFilter, ANeighbourWeighsAsItsDifferenceInStandardErrors) {
  const float v = 0.01f, k = 2.0f, delta = std::sqrt((1 + k * k) * 2 * v);
  FilterCase f = filterCase(2, 1, 1, kEvenSlices, [&](int cx, int, int) { return cx ? 1 + delta : 1.0f; }, v);
  std::vector<float> out = filtered(f, 1.0f, k);
  const double w = std::exp(-1.5);
  EXPECT_NEAR(at(f, out, 0, 0, 0), (1 + w * (1 + delta)) / (1 + w), 1e-5);
  EXPECT_NEAR(at(f, out, 1, 0, 0), (1 + delta + w) / (1 + w), 1e-5);
  f = filterCase(2, 1, 1, kEvenSlices, [&](int cx, int, int) { return cx ? 1 + 0.1f : 1.0f; }, v);  // 0.01 ≤ 2v
  out = filtered(f, 1.0f, k);
  const double near = std::exp(-0.5);
  EXPECT_NEAR(at(f, out, 0, 0, 0), (1 + near * 1.1) / (1 + near), 1e-5);
}

// A step far beyond the noise (1 against 100, standard errors 0.1) is kept: no weight crosses it
// (d² ≈ 99²/(2·0.01·k²) underflows e^{−d²} to 0), while within each side the columns, equal,
// stay equal. A plain Gaussian (k huge) would mix them.
TEST(MsCacheFilter, AStepBeyondTheNoiseIsKept) {
  const FilterCase f = filterCase(6, 3, 2, kEvenSlices, [](int cx, int, int) { return cx < 3 ? 1.0f : 100.0f; }, 0.01f);
  const std::vector<float> out = filtered(f, 1.5f, 2.0f);
  for (int s = 0; s < 2; ++s)
    for (int cy = 0; cy < 3; ++cy)
      for (int cx = 0; cx < 6; ++cx) EXPECT_FLOAT_EQ(at(f, out, cx, cy, s), cx < 3 ? 1.0f : 100.0f) << cx << "," << cy;
  const std::vector<float> plain = filtered(f, 1.5f, 1e6f);
  EXPECT_GT(at(f, plain, 2, 1, 0), 10.0f);  // column 2 takes e^{−1/(2·1.5²)}-weighted 100s from column 3
}

// Noise within the standard errors (|J − 1| ≤ 0.05, variance 0.01 each, so every Δ² ≤ 2v) is
// averaged as by the Gaussian alone: J̃ at the centre of a 5x5 field with σ_s = 1 (radius 2) is
// Σ e^{−r²/2}·J / Σ e^{−r²/2}.
TEST(MsCacheFilter, NoiseWithinTheStandardErrorsIsAveragedByTheGaussian) {
  auto value = [](int cx, int cy, int) { return 1.0f + 0.05f * std::sin(float(7 * cx + 13 * cy)); };
  const FilterCase f = filterCase(5, 5, 1, kEvenSlices, value, 0.01f);
  const std::vector<float> out = filtered(f, 1.0f, 1.0f);
  double sum = 0, weight = 0;
  for (int cy = 0; cy < 5; ++cy)
    for (int cx = 0; cx < 5; ++cx) {
      const double w = std::exp(-0.5 * ((cx - 2) * (cx - 2) + (cy - 2) * (cy - 2)));
      sum += w * value(cx, cy, 0);
      weight += w;
    }
  EXPECT_NEAR(at(f, out, 2, 2, 0), sum / weight, 1e-6);
}

// A neighbour is read over the node's own τ range, as a lookup reads it (registered by optical
// depth): column 1's slices [0, 0.25] and [0.25, ∞) hold 1 and 3, column 0's [0, 1] and [1, ∞)
// hold 2 and 2. Over [0, 1] column 1 reads (1·(1 − e^{−0.25}) + 3·(e^{−0.25} − e^{−1}))/(1 − e^{−1})
// (ms_view_lookup's step integral), not its slice 0's 1. Variances of 1 put every difference here
// within the noise (Δ² < 2), so the weights are the Gaussian's, e^{−1/2}.
TEST(MsCacheFilter, NeighboursAreReadAtTheNodesOwnOpticalDepths) {
  FilterCase f = filterCase(2, 1, 2, kEvenSlices, [](int cx, int, int s) { return cx ? (s ? 3.0f : 1.0f) : 2.0f; },
                            1.0f);
  const size_t stride1 = size_t(2) * MS_CACHE_STRIDE;  // slice 1 of a column is nx·ny nodes on
  float* c0 = f.cache.data();
  float* c1 = f.cache.data() + MS_CACHE_STRIDE;
  c0[MS_VIEW_TAU] = 0.0f, c0[MS_VIEW_TAU_END] = 1.0f;
  c0[stride1 + MS_VIEW_TAU] = 1.0f, c0[stride1 + MS_VIEW_TAU_END] = 4.6f;
  c1[MS_VIEW_TAU] = 0.0f, c1[MS_VIEW_TAU_END] = 0.25f;
  c1[stride1 + MS_VIEW_TAU] = 0.25f, c1[stride1 + MS_VIEW_TAU_END] = 4.6f;
  const std::vector<float> out = filtered(f, 1.0f, 1.0f);
  const double read = (1 * (1 - std::exp(-0.25)) + 3 * (std::exp(-0.25) - std::exp(-1.0))) / (1 - std::exp(-1.0));
  const double w = std::exp(-0.5);
  EXPECT_NEAR(at(f, out, 0, 0, 0), (2 + w * read) / (1 + w), 1e-5);
}

// Columns without medium are neither read nor written: a column of τ = −1 keeps its zeros, and its
// neighbour's J̃ is its own.
TEST(MsCacheFilter, ColumnsWithoutMediumAreSkipped) {
  FilterCase f = filterCase(2, 1, 1, kEvenSlices, [](int cx, int, int) { return cx ? 0.0f : 5.0f; }, 0.1f);
  f.cache[MS_CACHE_STRIDE + MS_VIEW_TAU] = -1.0f;
  const std::vector<float> out = filtered(f, 2.0f, 4.0f);
  EXPECT_EQ(at(f, out, 0, 0, 0), 5.0f);
  EXPECT_EQ(at(f, out, 1, 0, 0), 0.0f);
}

}  // namespace
}  // namespace narval::test

namespace narval::test {
namespace {

// A slice of no width (levels a column's march did not reach collapse onto its end) in noiseless
// nodes, one with a path and the next with none yet (a budgeted build mid-sweep): reading the column
// over that slice's τ range gives the next slice's value, so the column differs from itself beyond
// a noise of 0. Its own weight stays 1 all the same, and every filtered value is finite (the
// distance once put the column's own weight, and every neighbour's, at 0: 0/0).
TEST(MsCacheFilter, ASliceOfNoWidthBesideANodeOfNoPathsStaysFinite) {
  const std::function<float(int)> collapsed = [](int s) { return s <= 2 ? 0.5f * float(s) : 1.0f; };
  FilterCase f = filterCase(3, 3, 4, collapsed, [](int, int, int s) { return s == 2 ? 1.0f : 0.0f; }, 0.0f, 1);
  for (size_t n = 0; n < f.cache.size(); n += MS_CACHE_STRIDE)
    if (f.cache[n + MS_VIEW_TAU] == 1.0f && f.cache[n] == 0.0f) f.cache[n + 3] = 0.0f;  // slice 3: no paths yet
  ASSERT_EQ(collapsed(2), collapsed(3));  // slice 2 spans [1, 1]
  for (const std::vector<float>& out : {filtered(f, 1.5f, 2.0f), twiced(f, 1.5f, 2.0f)})
    for (size_t i = 0; i < out.size(); i += MS_CACHE_STRIDE)
      for (int ch = 0; ch < 3; ++ch) ASSERT_TRUE(std::isfinite(out[i + size_t(ch)])) << "node " << i / MS_CACHE_STRIDE;
}

}  // namespace
}  // namespace narval::test
