// image.h: linear RGB float images, EXR and PNG output, display transform.
#pragma once

#include <string>
#include <vector>

#include "scene/scene.h"

namespace narval {

struct ImageRGB {
  int width = 0, height = 0;
  std::vector<float> rgb;  // width*height*3, row 0 at the top
  float* pixel(int x, int y) { return &rgb[(size_t(y) * width + x) * 3]; }
  const float* pixel(int x, int y) const { return &rgb[(size_t(y) * width + x) * 3]; }
};

// 32-bit float linear RGB EXR; `attributes` become string attributes in the header (spp, seed...).
// Written to a temporary file beside `path` and renamed, so a failure never leaves a broken file.
void writeExr(const std::string& path, const ImageRGB& image,
              const std::vector<std::pair<std::string, std::string>>& attributes = {});
ImageRGB readExr(const std::string& path);  // throws InputError

// Display transform: multiply by 2^exposure, tone map, sRGB transfer, 8-bit.
void writePng(const std::string& path, const ImageRGB& image, float exposureStops, ToneMapping tm);

}  // namespace narval
