// display_transform.h: linear radiance -> display values (DESIGN.md, Output): multiply by
// 2^exposure, tone map, clamp to [0, 1], sRGB transfer function. PNG output uses it; `compare`
// applies the same steps (without the sRGB curve, since CIELAB wants linear RGB) to both images.
#pragma once

#include <cmath>
#include <cstdint>

#include <string>

#include "core/enum_names.h"
#include "shared/tonemap.h"

namespace narval {

enum class ToneMapping { None, Reinhard, Aces };
inline const EnumNames<ToneMapping> kToneMappingNames = {
    {"none", ToneMapping::None}, {"reinhard", ToneMapping::Reinhard}, {"aces", ToneMapping::Aces}};
inline const char* toneMappingName(ToneMapping t) { return enumName(kToneMappingNames, t); }
inline bool toneMappingFromName(const std::string& name, ToneMapping* out) {
  return enumFromName(kToneMappingNames, name, out);
}

inline int toneMappingKind(ToneMapping tm) {
  switch (tm) {
    case ToneMapping::Reinhard: return TONEMAP_REINHARD;
    case ToneMapping::Aces: return TONEMAP_ACES;
    case ToneMapping::None: break;
  }
  return TONEMAP_NONE;
}

// One exposure value for a whole image: 2^stops.
inline float exposureScale(float exposureStops) { return std::exp2(exposureStops); }

// Linear channel -> tone-mapped linear value in [0, 1] (before the sRGB curve). Non-finite values
// after exposure are defined, not left to the curves: NaN shows as 0 (black), +inf as 1 (full
// white, as any large finite value would), -inf and negatives as 0.
inline float displayLinear(float linear, float scale, ToneMapping tm) {
  const float v = linear * scale;
  if (std::isnan(v)) return 0.0f;
  if (std::isinf(v)) return v > 0.0f ? 1.0f : 0.0f;
  const float t = tonemap_apply(toneMappingKind(tm), v);
  return std::fmin(std::fmax(t, 0.0f), 1.0f);
}

// Linear channel -> sRGB-encoded display value in [0, 1]: what a PNG stores, before quantising.
inline float displayEncoded(float linear, float scale, ToneMapping tm) {
  return srgb_encode(displayLinear(linear, scale, tm));
}

// Display value in [0, 1] -> 8 bit, rounding to nearest (v*255 + 0.5, truncated).
inline uint8_t displayTo8Bit(float encoded) {
  const float v = std::fmin(std::fmax(encoded, 0.0f), 1.0f);
  return static_cast<uint8_t>(v * 255.0f + 0.5f);
}

}  // namespace narval
