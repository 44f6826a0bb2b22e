/* tonemap.h: tone mapping curves and the sRGB transfer function, one float channel at a time.
 * The display transform (DESIGN.md, Output) is: exposure, then one of these curves, then clamp to
 * [0, 1], then srgb_encode. Plain C shared by the host (PNG output, `compare`) and the device
 * (a live viewer), so both display the very same numbers. */
#ifndef NARVAL_TONEMAP_H
#define NARVAL_TONEMAP_H

#include "shared/compat.h"

/* Tone mapping kinds, in the order of narval::ToneMapping (host/scene/scene.h). */
#define TONEMAP_NONE 0
#define TONEMAP_REINHARD 1
#define TONEMAP_ACES 2

/* Reinhard et al. 2002, "Photographic Tone Reproduction for Digital Images", Eq. 3 (the simple
 * operator without a white point): L_d = L / (1 + L). Maps [0, inf) onto [0, 1). Meant for x >= 0;
 * tonemap_apply clamps negative input to 0 first (x <= -1 would divide by zero or flip sign). */
static inline float tonemap_reinhard(float x) { return x / (1.0f + x); }

/* Krzysztof Narkowicz 2015, "ACES Filmic Tone Mapping Curve" (blog post, published 2016-01-06,
 * https://knarkowicz.wordpress.com/2016/01/06/aces-filmic-tone-mapping-curve/): a rational fit of
 * the ACES RRT+ODT, f(x) = x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14), saturated to [0, 1]. Applied
 * as published, without the 0.6 pre-exposure the post mentions for matching ACES exactly: the
 * scene's `exposure` is the place for that. f(0) = 0, f(1) = 2.54 / 3.16 = 0.80380, and f reaches 1
 * at x = (0.56 + sqrt(0.56^2 + 4*0.08*0.14)) / 0.16 = 7.2417, staying clamped above.
 * Guards (they change no value in [0, 1e4]): negative x is treated as 0 (the rational function tends
 * to 2.51/2.43 > 1 as x -> -inf, so very negative input would otherwise show white), and x > 1e4 is
 * treated as 1e4 (already saturated) so that x*x cannot overflow to inf/inf = NaN. NaN stays NaN:
 * both comparisons are false for it. */
static inline float tonemap_aces(float x) {
  const float a = 2.51f;
  const float b = 0.03f;
  const float c = 2.43f;
  const float d = 0.59f;
  const float e = 0.14f;
  float y;
  x = x < 0.0f ? 0.0f : x;
  x = x > 1.0e4f ? 1.0e4f : x;
  y = (x * (a * x + b)) / (x * (c * x + d) + e);
  y = y < 0.0f ? 0.0f : y;
  y = y > 1.0f ? 1.0f : y;
  return y;
}

/* Applies tone mapping `kind` (TONEMAP_*) to one linear channel. Negative input (not a radiance,
 * but possible in a difference image) is treated as 0; NaN passes through for the caller to decide.
 * TONEMAP_NONE is the identity: clamping to [0, 1] is the caller's step. */
static inline float tonemap_apply(int kind, float x) {
  x = x < 0.0f ? 0.0f : x;
  if (kind == TONEMAP_REINHARD) return tonemap_reinhard(x);
  if (kind == TONEMAP_ACES) return tonemap_aces(x);
  return x;
}

/* sRGB transfer function, IEC 61966-2-1:1999 (also W3C/Stokes et al. 1996, "A Standard Default
 * Color Space for the Internet - sRGB"): linear -> encoded, 12.92 x for x <= 0.0031308, else
 * 1.055 x^(1/2.4) - 0.055. The pieces meet at 0.0031308 -> 0.0404500 (to 7 digits). */
static inline float srgb_encode(float x) {
  if (x <= 0.0031308f) return 12.92f * x;
  return 1.055f * nv_pow(x, 1.0f / 2.4f) - 0.055f;
}

/* Inverse of srgb_encode (same standard): x / 12.92 for x <= 0.04045, else ((x + 0.055) / 1.055)^2.4. */
static inline float srgb_decode(float x) {
  if (x <= 0.04045f) return x / 12.92f;
  return nv_pow((x + 0.055f) / 1.055f, 2.4f);
}

#endif
