// image_compare.h: perceptual comparison of two renders (DESIGN.md "Perceptual metric"). Both go
// through the same display transform (exposure, tone mapping, clip to [0, 1]; no sRGB curve: the
// values stay linear), then linear sRGB -> CIELAB, and each pixel gets ΔE76 and ΔE2000.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "image/image.h"
#include "image/display_transform.h"

namespace narval {

struct DeltaEStats {
  double mean = 0, p95 = 0, max = 0;
  double jndPercent = 0;  // % of pixels with ΔE > kJnd
};

struct ImageComparison {
  int width = 0, height = 0;
  std::vector<float> dE76, dE2000;  // per pixel, row 0 at the top
  size_t pixels = 0;                // those the statistics are over: all, or the mask's
  DeltaEStats stats76, stats2000;
  // Relative mean squared error of the linear values (before the display transform), the error
  // Monte Carlo renderers are raced by (pbrt-v4, Mitsuba 3): the mean over pixels and channels of
  // (test − ref)² / (ref² + kRelMseEpsilon). It falls as 1/spp for an unbiased renderer, so time ×
  // relMSE is a renderer's cost at equal error.
  double relMse = 0;
};

// The statistics' keys in narval's JSON (compare --json, sweep.json), sweep.csv's columns first:
// mean_dE76, jnd76_pct, mean_dE2000, jnd2000_pct, then p95_ and max_ of each.
void addDeltaEJson(nlohmann::ordered_json& j, const DeltaEStats& dE76, const DeltaEStats& dE2000);

// The ε that keeps relMSE finite where the reference is black.
constexpr double kRelMseEpsilon = 1e-2;

struct DisplaySettings {
  float exposureStops = 0.0f;
  ToneMapping toneMapping = ToneMapping::None;
};

// Throws InputError naming `testName` when the sizes differ ("size 10x8 differs from the
// reference's 12x8") or either image holds NaN/Inf ("… holds 3 non-finite values"), naming the
// image with the problem. With `mask` (one value per pixel, e.g. render/medium_mask.h's), the
// statistics and relMSE are over the pixels where it is not 0; dE76 and dE2000 still hold every pixel.
ImageComparison compareImages(const ImageRGB& reference, const ImageRGB& test, const DisplaySettings& display,
                              const std::string& referenceName = "reference", const std::string& testName = "test",
                              const std::vector<uint32_t>* mask = nullptr);

// The image as displayed: display transform, then the sRGB curve, 8 bit (as writePng does).
ImageRGB8 displayImage(const ImageRGB& image, const DisplaySettings& display);
// The ΔE map and the JND map as pictures (what the two writers below save).
ImageRGB8 deltaEHeatmapImage(const std::vector<float>& deltaE, int width, int height, float maxDeltaE = 10.0f);
ImageRGB8 jndMapImage(const ImageRGB& image, const DisplaySettings& display, const std::vector<float>& deltaE,
                      double jndPercent);
// Text in a small built-in bitmap font (digits, letters, '%', '.', '-', ' '), `scale` pixels per
// font pixel, at (x, y) = top-left.
void drawText(ImageRGB8& image, int x, int y, const std::string& text, int scale, uint8_t r, uint8_t g, uint8_t b);

// ΔE colour map (a perceptually ordered ramp from 0 to `maxDeltaE`, values above it saturate) with
// a legend bar and tick labels along the bottom, as PNG.
void writeDeltaEHeatmap(const std::string& path, const std::vector<float>& deltaE, int width, int height,
                        float maxDeltaE = 10.0f);

// The test image (display-transformed, sRGB-encoded, greyed) with the pixels over kJnd in red and
// the percentage printed on it, as PNG (dissertation Figs. 5.4, 5.8).
void writeJndMap(const std::string& path, const ImageRGB& image, const DisplaySettings& display,
                 const std::vector<float>& deltaE, double jndPercent);

}  // namespace narval
