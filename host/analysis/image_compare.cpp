// image_compare.cpp: perceptual comparison of two renders (DESIGN.md "Perceptual metric") and the
// figures made from it: the ΔE heat map with its legend and the JND map.
#include "analysis/image_compare.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "colour/cielab.h"
#include "core/input_error.h"
#include "image/bitmap_font.h"
#include "image/display_transform.h"

namespace narval {
namespace {

size_t pixelCount(int width, int height) { return width > 0 && height > 0 ? size_t(width) * size_t(height) : 0; }

void checkBuffer(const ImageRGB& image, const char* what) {
  if (image.width < 0 || image.height < 0 || image.rgb.size() != pixelCount(image.width, image.height) * 3)
    throw std::invalid_argument(std::string(what) + ": pixel buffer size does not match the image size");
}

void checkDeltaE(const std::vector<float>& deltaE, int width, int height, const char* what) {
  if (width <= 0 || height <= 0) throw std::invalid_argument(std::string(what) + ": empty image");
  if (deltaE.size() != pixelCount(width, height))
    throw std::invalid_argument(std::string(what) + ": ΔE buffer size does not match the image size");
}

void checkFinite(const ImageRGB& image, const std::string& name) {
  size_t n = 0;
  for (float v : image.rgb)
    if (!std::isfinite(v)) ++n;
  if (n > 0)
    throw inputError(name, "", "holds " + std::to_string(n) + (n == 1 ? " non-finite value" : " non-finite values"));
}

// Mean, 95th percentile, max and JND% of per-pixel ΔE values. The 95th percentile is the value of
// rank ceil(0.95·n) (1-based) in ascending order: the smallest value that at least 95% of the pixels
// do not exceed (the "nearest-rank" definition; no interpolation). JND% = 100·count(ΔE > kJnd)/n.
// The stats use the very float values stored per pixel, so a map drawn from them agrees with them.
DeltaEStats statsOf(const std::vector<float>& d) {
  DeltaEStats s;
  const size_t n = d.size();
  if (n == 0) return s;
  double sum = 0;
  size_t over = 0;
  float mx = 0;
  for (float v : d) {
    sum += v;
    if (double(v) > kJnd) ++over;
    mx = std::max(mx, v);
  }
  std::vector<float> sorted(d);
  const size_t rank = (95 * n + 99) / 100;  // ceil(0.95 n), in integers
  std::nth_element(sorted.begin(), sorted.begin() + long(rank - 1), sorted.end());
  s.mean = sum / double(n);
  s.p95 = sorted[rank - 1];
  s.max = mx;
  s.jndPercent = 100.0 * double(over) / double(n);
  return s;
}

uint8_t to8(double v) { return displayTo8Bit(float(v)); }

// Viridis (van der Walt & Smith 2015, matplotlib's default colour map; the table is CC0): 17 of
// matplotlib's 256 `_viridis_data` entries (indices 0, 16, ..., 240, 255), sRGB-encoded, linearly
// interpolated. Perceptually ordered (lightness rises monotonically) and readable in grey and by
// colour-blind viewers. The interpolation stays within 5/255 of the full 256-entry table.
constexpr int kViridisPoints = 17;
constexpr float kViridis[kViridisPoints][3] = {
    {0.267004f, 0.004874f, 0.329415f},  // 0
    {0.282327f, 0.094955f, 0.417331f},  // 16
    {0.278826f, 0.175490f, 0.483397f},  // 32
    {0.258965f, 0.251537f, 0.524736f},  // 48
    {0.229739f, 0.322361f, 0.545706f},  // 64
    {0.199430f, 0.387607f, 0.554642f},  // 80
    {0.172719f, 0.448791f, 0.557885f},  // 96
    {0.149039f, 0.508051f, 0.557250f},  // 112
    {0.127568f, 0.566949f, 0.550556f},  // 128
    {0.120638f, 0.625828f, 0.533488f},  // 144
    {0.157851f, 0.683765f, 0.501686f},  // 160
    {0.246070f, 0.738910f, 0.452024f},  // 176
    {0.369214f, 0.788888f, 0.382914f},  // 192
    {0.515992f, 0.831158f, 0.294279f},  // 208
    {0.678489f, 0.863742f, 0.189503f},  // 224
    {0.845561f, 0.887322f, 0.099702f},  // 240
    {0.993248f, 0.906157f, 0.143936f},  // 255
};
constexpr int kViridisIndex[kViridisPoints] = {0,   16,  32,  48,  64,  80,  96,  112, 128,
                                               144, 160, 176, 192, 208, 224, 240, 255};

// t in [0, 1] (clamped; NaN counts as 1, "off the scale") -> 8-bit sRGB colour.
void viridis(float t, uint8_t* rgb) {
  if (!(t >= 0.0f)) t = std::isnan(t) ? 1.0f : 0.0f;
  t = std::min(t, 1.0f);
  const float x = t * 255.0f;
  int k = 0;
  while (k < kViridisPoints - 2 && x > float(kViridisIndex[k + 1])) ++k;
  const float f = (x - float(kViridisIndex[k])) / float(kViridisIndex[k + 1] - kViridisIndex[k]);
  for (int c = 0; c < 3; ++c) rgb[c] = to8(kViridis[k][c] + (kViridis[k + 1][c] - kViridis[k][c]) * f);
}

void fill(ImageRGB8& image, int x0, int y0, int x1, int y1, uint8_t r, uint8_t g, uint8_t b) {
  x0 = std::max(x0, 0);
  y0 = std::max(y0, 0);
  x1 = std::min(x1, image.width);
  y1 = std::min(y1, image.height);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      uint8_t* p = &image.rgb[(size_t(y) * size_t(image.width) + size_t(x)) * 3];
      p[0] = r;
      p[1] = g;
      p[2] = b;
    }
}

// A tick label: "%.3g" ("0", "5", "2.3", "12.5", "1e+03"), in the font's upper case.
std::string tickLabel(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  std::string s = buf;
  for (char& c : s) c = char(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// The legend under the heat map, in units of s = clamp(width / 200, 1, 4) pixels: 3 blank rows, the
// colour bar (8 rows), tick marks (2 rows), 1 blank row, the labels (7 rows), 2 blank rows: 23·s.
int legendScale(int width) { return std::clamp(width / 200, 1, 4); }
int legendHeight(int width) { return 23 * legendScale(width); }

// Colours used on the figures.
constexpr uint8_t kLegendBackground[3] = {0, 0, 0};
constexpr uint8_t kLegendText[3] = {255, 255, 255};
constexpr uint8_t kJndRed[3] = {255, 0, 0};
constexpr uint8_t kJndText[3] = {255, 255, 0};

}  // namespace

ImageComparison compareImages(const ImageRGB& reference, const ImageRGB& test, const DisplaySettings& display,
                              const std::string& referenceName, const std::string& testName,
                              const std::vector<uint32_t>* mask) {
  checkBuffer(reference, "compareImages: reference");
  checkBuffer(test, "compareImages: test");
  if (test.width != reference.width || test.height != reference.height)
    throw inputError(testName, "",
                     "size " + std::to_string(test.width) + "x" + std::to_string(test.height) +
                         " differs from the reference's " + std::to_string(reference.width) + "x" +
                         std::to_string(reference.height));
  // The reference is checked first; NaN and ±Inf count alike, one per channel value (not per pixel).
  checkFinite(reference, referenceName);
  checkFinite(test, testName);

  ImageComparison c;
  c.width = reference.width;
  c.height = reference.height;
  const size_t n = pixelCount(c.width, c.height);
  c.dE76.resize(n);
  c.dE2000.resize(n);
  const float scale = exposureScale(display.exposureStops);
  const ToneMapping tm = display.toneMapping;
  if (mask && mask->size() != n) throw std::invalid_argument("compareImages: the mask's size is not the images'");
  auto counted = [mask](size_t i) { return !mask || (*mask)[i] != 0; };
  double relMseSum = 0;
  for (size_t k = 0; k < n * 3; ++k) {
    if (!counted(k / 3)) continue;
    const double r = reference.rgb[k], d = double(test.rgb[k]) - r;
    relMseSum += d * d / (r * r + kRelMseEpsilon);
  }
  std::vector<float> counted76, counted2000;  // the statistics' pixels
  for (size_t i = 0; i < n; ++i) {
    const float* p = &reference.rgb[i * 3];
    const float* q = &test.rgb[i * 3];
    const Lab a =
        linearSrgbToLab(displayLinear(p[0], scale, tm), displayLinear(p[1], scale, tm), displayLinear(p[2], scale, tm));
    const Lab b =
        linearSrgbToLab(displayLinear(q[0], scale, tm), displayLinear(q[1], scale, tm), displayLinear(q[2], scale, tm));
    c.dE76[i] = float(deltaE76(a, b));
    c.dE2000[i] = float(deltaE2000(a, b));
    if (mask && counted(i)) {
      counted76.push_back(c.dE76[i]);
      counted2000.push_back(c.dE2000[i]);
    }
  }
  c.pixels = mask ? counted76.size() : n;
  c.relMse = c.pixels > 0 ? relMseSum / double(c.pixels * 3) : 0.0;
  c.stats76 = statsOf(mask ? counted76 : c.dE76);
  c.stats2000 = statsOf(mask ? counted2000 : c.dE2000);
  return c;
}

ImageRGB8 displayImage(const ImageRGB& image, const DisplaySettings& display) {
  checkBuffer(image, "displayImage");
  ImageRGB8 out;
  out.width = image.width;
  out.height = image.height;
  out.rgb.resize(image.rgb.size());
  const float scale = exposureScale(display.exposureStops);
  for (size_t i = 0; i < image.rgb.size(); ++i)
    out.rgb[i] = displayTo8Bit(displayEncoded(image.rgb[i], scale, display.toneMapping));
  return out;
}

ImageRGB8 deltaEHeatmapImage(const std::vector<float>& deltaE, int width, int height, float maxDeltaE) {
  checkDeltaE(deltaE, width, height, "deltaEHeatmapImage");
  if (!(maxDeltaE > 0.0f) || !std::isfinite(maxDeltaE))
    throw std::invalid_argument("deltaEHeatmapImage: the scale's maximum must be a positive number");
  const int s = legendScale(width);
  ImageRGB8 out;
  out.width = width;
  out.height = height + legendHeight(width);
  out.rgb.resize(size_t(out.width) * size_t(out.height) * 3);
  for (size_t i = 0; i < deltaE.size(); ++i) viridis(deltaE[i] / maxDeltaE, &out.rgb[i * 3]);

  const auto& bg = kLegendBackground;
  const auto& fg = kLegendText;
  fill(out, 0, height, width, out.height, bg[0], bg[1], bg[2]);
  // The colour bar: column x shows maxDeltaE·x/(width − 1).
  const int barTop = height + 3 * s, barBottom = barTop + 8 * s;
  for (int x = 0; x < width; ++x) {
    uint8_t c[3];
    viridis(width > 1 ? float(x) / float(width - 1) : 0.0f, c);
    fill(out, x, barTop, x + 1, barBottom, c[0], c[1], c[2]);
  }
  // Ticks at 0, max/2 and max, and their labels (left-aligned, centred, right-aligned); the middle
  // label is left out when it would run into the others.
  const int tickTop = barBottom, tickBottom = tickTop + 2 * s, textTop = tickBottom + s;
  const int xs[3] = {0, (width - s) / 2, width - s};
  const std::string labels[3] = {tickLabel(0.0), tickLabel(maxDeltaE / 2.0), tickLabel(maxDeltaE)};
  for (int x : xs) fill(out, x, tickTop, x + s, tickBottom, fg[0], fg[1], fg[2]);
  const int w0 = fontTextWidth(labels[0], s), w1 = fontTextWidth(labels[1], s), w2 = fontTextWidth(labels[2], s);
  const int x1 = (width - w1) / 2, x2 = width - w2;
  drawText(out, 0, textTop, labels[0], s, fg[0], fg[1], fg[2]);
  if (x2 >= w0 + 2 * s) drawText(out, x2, textTop, labels[2], s, fg[0], fg[1], fg[2]);
  if (x1 >= w0 + 2 * s && x1 + w1 + 2 * s <= x2) drawText(out, x1, textTop, labels[1], s, fg[0], fg[1], fg[2]);
  return out;
}

ImageRGB8 jndMapImage(const ImageRGB& image, const DisplaySettings& display, const std::vector<float>& deltaE,
                      double jndPercent) {
  checkBuffer(image, "jndMapImage");
  checkDeltaE(deltaE, image.width, image.height, "jndMapImage");
  ImageRGB8 out;
  out.width = image.width;
  out.height = image.height;
  out.rgb.resize(image.rgb.size());
  const float scale = exposureScale(display.exposureStops);
  const ToneMapping tm = display.toneMapping;
  for (size_t i = 0; i < deltaE.size(); ++i) {
    uint8_t* o = &out.rgb[i * 3];
    if (double(deltaE[i]) > kJnd) {
      o[0] = kJndRed[0];
      o[1] = kJndRed[1];
      o[2] = kJndRed[2];
      continue;
    }
    // Grey: the luminance (Rec. 709 / sRGB weights) of the display-linear colour, sRGB-encoded.
    const float* p = &image.rgb[i * 3];
    const float y = 0.2126f * displayLinear(p[0], scale, tm) + 0.7152f * displayLinear(p[1], scale, tm) +
                    0.0722f * displayLinear(p[2], scale, tm);
    o[0] = o[1] = o[2] = displayTo8Bit(srgb_encode(std::min(y, 1.0f)));
  }
  // "JND 12.34%" in yellow on a black box in the top-left corner: the box is 2s + text + 2s wide and
  // 11s high, s = clamp(min(width, height) / 150, 1, 4).
  char buf[48];
  std::snprintf(buf, sizeof buf, "JND %.2f%%", jndPercent);
  const int s = std::clamp(std::min(image.width, image.height) / 150, 1, 4);
  fill(out, 0, 0, fontTextWidth(buf, s) + 4 * s, 11 * s, 0, 0, 0);
  drawText(out, 2 * s, 2 * s, buf, s, kJndText[0], kJndText[1], kJndText[2]);
  return out;
}

void drawText(ImageRGB8& image, int x, int y, const std::string& text, int scale, uint8_t r, uint8_t g, uint8_t b) {
  scale = std::max(scale, 1);
  for (size_t i = 0; i < text.size(); ++i) {
    const uint8_t* rows = fontGlyph(text[i]);
    const int gx = x + int(i) * kFontAdvance * scale;
    for (int row = 0; row < kFontHeight; ++row)
      for (int col = 0; col < kFontWidth; ++col)
        if (rows[row] & (0x10 >> col))
          fill(image, gx + col * scale, y + row * scale, gx + (col + 1) * scale, y + (row + 1) * scale, r, g, b);
  }
}

void writeDeltaEHeatmap(const std::string& path, const std::vector<float>& deltaE, int width, int height,
                        float maxDeltaE) {
  writePng8(path, deltaEHeatmapImage(deltaE, width, height, maxDeltaE));
}

void writeJndMap(const std::string& path, const ImageRGB& image, const DisplaySettings& display,
                 const std::vector<float>& deltaE, double jndPercent) {
  writePng8(path, jndMapImage(image, display, deltaE, jndPercent));
}

void addDeltaEJson(nlohmann::ordered_json& j, const DeltaEStats& dE76, const DeltaEStats& dE2000) {
  j["mean_dE76"] = dE76.mean;
  j["jnd76_pct"] = dE76.jndPercent;
  j["mean_dE2000"] = dE2000.mean;
  j["jnd2000_pct"] = dE2000.jndPercent;
  j["p95_dE76"] = dE76.p95;
  j["max_dE76"] = dE76.max;
  j["p95_dE2000"] = dE2000.p95;
  j["max_dE2000"] = dE2000.max;
}

}  // namespace narval
