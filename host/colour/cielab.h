// cielab.h: CIE 1976 L*a*b* from linear sRGB/Rec.709 (D65 white, white Y = 1) and the colour
// differences ΔE*ab (CIE 1976, Euclidean) and ΔE00 (CIEDE2000; Sharma, Wu & Dalal 2005). The
// dissertation's ch. 5 metric: two pixels look alike when ΔE is under the JND of 2.3.
#pragma once

namespace narval {

struct Lab {
  double L = 0, a = 0, b = 0;
};

// The just-noticeable difference in ΔE*ab used throughout (dissertation ch. 5, after Sharma 2003).
constexpr double kJnd = 2.3;

// Linear sRGB (IEC 61966-2-1 primaries, D65) -> XYZ -> L*a*b* relative to the D65 white (Y = 1).
// No transfer curve: inputs are linear values (DESIGN.md, perceptual metric).
Lab linearSrgbToLab(double r, double g, double b);

double deltaE76(const Lab& x, const Lab& y);
double deltaE2000(const Lab& x, const Lab& y);

}  // namespace narval
