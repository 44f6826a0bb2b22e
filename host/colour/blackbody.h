// blackbody.h: emission of a temperature as pbrt-v4 defines it, for emissive media. Planck's law
// B(λ, T) = 2hc² / (λ⁵ (e^{hc/(λ k T)} − 1)), normalised by its peak B(λ_max, T) with Wien's
// λ_max = 2.8977721e-3 m·K / T (pbrt-v4's BlackbodySpectrum: the peak is 1 at every temperature),
// seen as a colour: XYZ = ∫ B̂(λ) (x̄, ȳ, z̄)(λ) dλ / ∫ ȳ(λ) dλ over 360–830 nm (pbrt-v4's
// SpectrumToXYZ divides by the CIE ȳ integral), then linear sRGB (IEC 61966-2-1, D65), with the
// CIE 1931 2° table every nanometre (cie1931_table.h). Why the table and not an analytic fit
// (Wyman, Sloan and Shirley 2013): flames are 1000–1500 K, whose visible light is the deep-red
// tail where the CMFs are small; there the fit's green was 3x the table's at 1000 K.
#pragma once

#include <array>

namespace narval {

// Nothing is emitted at or below this temperature (K), as the emission keys require.
constexpr double kBlackbodyMinKelvin = 100.0;

// Planck's spectral radiance (W·sr⁻¹·m⁻³) at `lambdaNm` nanometres; 0 for T <= 0.
double blackbodyPlanck(double lambdaNm, double kelvin);
// B(λ, T) / B(λ_max, T): 1 at the peak; 0 at or below kBlackbodyMinKelvin.
double blackbodyNormalized(double lambdaNm, double kelvin);
// The normalised blackbody's colour in linear sRGB (may have negative components outside the
// gamut, e.g. blue at 1000 K); {0, 0, 0} at or below kBlackbodyMinKelvin.
std::array<float, 3> blackbodyLinearSrgb(double kelvin);

}  // namespace narval
