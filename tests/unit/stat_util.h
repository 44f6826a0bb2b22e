// stat_util.h: statistics helpers shared by the statistical tests (unit and render), all in double
// precision: χ² tail probabilities, Pearson's χ² with pooling of small cells, the Šidák correction,
// the correlation coefficient, and the mean with its standard error.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace narval::test {

// Regularized upper incomplete gamma Q(a, x) = Γ(a, x)/Γ(a) = 1 − P(a, x), the standard two-branch
// evaluation (as in Numerical Recipes §6.2, written here from the formulas): for x < a + 1 the series
// P(a, x) = e^{−x} x^a / Γ(a) · Σ_{n≥0} x^n / (a (a+1) ... (a+n)), which converges fast there; else
// Legendre's continued fraction
//   Q(a, x) = e^{−x} x^a / Γ(a) · 1/(x+1−a − 1·(1−a)/(x+3−a − 2·(2−a)/(x+5−a − ...))),
// evaluated by the modified Lentz method. Both stop at 1e-15 relative: far below any test's need.
// The prefactor is formed in logs (lgamma), so large a (χ² with ~1000 dof) does not overflow.
inline double gammaQ(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double lnPre = -x + a * std::log(x) - std::lgamma(a);
  if (x < a + 1.0) {
    double ap = a, sum = 1.0 / a, del = sum;
    for (int n = 0; n < 100000; ++n) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::fabs(del) < std::fabs(sum) * 1e-15) break;
    }
    return 1.0 - sum * std::exp(lnPre);
  }
  const double tiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::fabs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::fabs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::fabs(del - 1.0) < 1e-15) break;
  }
  return std::exp(lnPre) * h;
}

// Upper-tail p-value of a χ² statistic with `dof` degrees of freedom: P(χ²_dof > chi2) = Q(dof/2, chi2/2).
inline double chiSquarePValue(double chi2, int dof) { return gammaQ(0.5 * dof, 0.5 * chi2); }

// Šidák: per-test significance so that `tests` independent tests reject a true null with total
// probability `alpha`: 1 − (1 − alpha)^{1/tests}.
inline double sidak(double alpha, int tests) { return 1.0 - std::pow(1.0 - alpha, 1.0 / tests); }

struct ChiSquareResult {
  double chi2 = 0.0;
  int dof = 0;
  double pValue = 1.0;
  int64_t samplesInZeroCells = 0;
};

// Pearson's χ² with Mitsuba 3's pooling (its chi2 test helper, re-implemented): cells are visited by
// increasing expected count; cells with an expected count below `minExpected` are pooled until the
// pool reaches it. Cells with zero expected count are not tested but their observed samples are
// counted in samplesInZeroCells (a correct sampler leaves them empty). dof = tested cells − 1 (the
// counts are constrained to sum to N).
inline ChiSquareResult chiSquare(const std::vector<double>& observed, const std::vector<double>& expected,
                                 double minExpected = 5.0) {
  std::vector<size_t> order(observed.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expected[a] < expected[b]; });
  ChiSquareResult r;
  double pooledObs = 0.0, pooledExp = 0.0;
  for (size_t i : order) {
    if (expected[i] == 0.0) {
      r.samplesInZeroCells += static_cast<int64_t>(observed[i]);
    } else if (expected[i] < minExpected || (pooledExp > 0.0 && pooledExp < minExpected)) {
      pooledObs += observed[i];
      pooledExp += expected[i];
      if (pooledExp >= minExpected) {
        r.chi2 += (pooledObs - pooledExp) * (pooledObs - pooledExp) / pooledExp;
        ++r.dof;
        pooledObs = pooledExp = 0.0;
      }
    } else {
      r.chi2 += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
      ++r.dof;
    }
  }
  if (pooledExp > 0.0) {
    r.chi2 += (pooledObs - pooledExp) * (pooledObs - pooledExp) / pooledExp;
    ++r.dof;
  }
  r.dof -= 1;
  r.pValue = chiSquarePValue(r.chi2, r.dof);
  return r;
}

// χ² of counts against equal expected counts (cells of equal probability, e.g. a uniform variate
// in equal bins): returns the p-value with dof = cells − 1 and, if asked, the statistic.
inline double equalCellsChiSquarePValue(const std::vector<double>& counts, double* chi2Out = nullptr) {
  double n = 0.0;
  for (double c : counts) n += c;
  const double e = n / counts.size();
  double chi2 = 0.0;
  for (double c : counts) chi2 += (c - e) * (c - e) / e;
  if (chi2Out) *chi2Out = chi2;
  return chiSquarePValue(chi2, static_cast<int>(counts.size()) - 1);
}

// Pearson correlation coefficient of paired samples (two-pass: means first).
inline double correlation(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = x.size();
  double mx = 0.0, my = 0.0;
  for (size_t i = 0; i < n; ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= n;
  my /= n;
  double sxy = 0.0, sxx = 0.0, syy = 0.0;
  for (size_t i = 0; i < n; ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
  }
  return sxy / std::sqrt(sxx * syy);
}

// Mean of a sample and the standard error of that mean, √(s²/n) with the unbiased sample variance
// s² = (Σx² − n·mean²)/(n − 1) (clamped at 0 against rounding).
struct MeanSe {
  double mean = 0.0, se = 0.0;
};
struct MeanAccumulator {
  double n = 0.0, sum = 0.0, sum2 = 0.0;
  void add(double x) {
    n += 1.0;
    sum += x;
    sum2 += x * x;
  }
  MeanSe result() const {
    MeanSe r;
    r.mean = sum / n;
    const double var = std::max(0.0, (sum2 - n * r.mean * r.mean) / (n - 1.0));
    r.se = std::sqrt(var / n);
    return r;
  }
};

}  // namespace narval::test
