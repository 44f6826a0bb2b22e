// sweep.h: speed against perceptual error over one path-tracing parameter (dissertation ch. 5,
// Tables 5.1 and 5.2, Figs. 5.4 and 5.8). A sweep renders a scene at several values of spp or
// bounces, largest first, times each render, and compares each with a reference (the largest
// value's render, or an image the caller supplies) under the scene's display transform.
//
// Every render uses the scene's seed. The path tracer's random numbers are keyed by sample index, so
// an n-spp render is exactly the mean of the first n samples of the N-spp reference: its ΔE measures
// a variance of σ²(1/n − 1/N) rather than the σ²/n of an independent ground truth (independent seeds
// would give σ²(1/n + 1/N)); the difference is small when N ≫ n, as in the dissertation's 10× steps.
//
// The renderer is passed in as a function, so the sweep logic (order, reference row, speed-up,
// tables, figure) is tested on the host without OpenCL; `narval sweep` passes renderPathtrace.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "analysis/image_compare.h"
#include "image/image.h"
#include "render/render_types.h"
#include "scene/scene.h"

namespace narval {

enum class SweepParameter { Spp, Bounces };

// "spp" / "bounces": the parameter's name in files, tables and labels.
const char* sweepParameterName(SweepParameter p);

// "10,100,1000" -> {10, 100, 1000}. Values must be positive integers (spaces around them are
// allowed) and distinct. Throws InputError "OPTION: expected a comma-separated list of positive
// integers, got 'TEXT'" (or "OPTION: VALUE is listed twice").
std::vector<int> parseSweepList(const std::string& text, const std::string& option);

// The EXR name of one value: spp_00010.exr, bounces_0035.exr (wider values keep all digits).
std::string sweepFileName(SweepParameter p, int value);
// The figure's column label: "10000 spp", "35 bounces", "1 bounce".
std::string sweepLabel(SweepParameter p, int value);

struct SweepSpec {
  SweepParameter parameter = SweepParameter::Spp;
  std::vector<int> values;              // any order; rendered in descending order
  const ImageRGB* reference = nullptr;  // external reference; null: the largest value's render
  std::string referenceName;            // the external reference's name (its file), for messages
  bool warmUp = true;                   // one untimed 1-spp render first (kernel compile, caches)
};

struct SweepRow {
  int value = 0;
  bool isReference = false;  // this render is the reference (never with an external reference)
  double seconds = 0;        // RenderStats::seconds: the sample loop, after build and upload
  double speedup = 0;        // reference seconds / seconds (see SweepResult::speedupBaseline)
  DeltaEStats dE76, dE2000;  // against the reference; exactly 0 on the reference's own row
  RenderStats stats;
  ImageRGB image;
  std::vector<float> dE76Map;  // per pixel, for the figure
};

struct SweepResult {
  SweepParameter parameter = SweepParameter::Spp;
  int fixedValue = 0;      // the other parameter (bounces for an spp sweep, spp for a bounces sweep)
  std::string scene, device;
  int width = 0, height = 0;
  uint32_t seed = 0;
  DisplaySettings display;
  std::string referenceFile;      // the external reference, or "" (the first row is the reference)
  ImageRGB referenceImage;        // what every row was compared with
  // The value whose render time is the speed-up's numerator: the reference's value, or with an
  // external reference (whose render time is unknown) the largest value rendered.
  int speedupBaseline = 0;
  std::vector<SweepRow> rows;     // descending values
};

using SweepRenderer = std::function<RenderResult(const Scene&)>;

// Throws InputError naming `name` when an external reference cannot serve for `scene`: its size
// differs from the scene's resolution, or it holds non-finite values.
void checkSweepReference(const Scene& scene, const ImageRGB& reference, const std::string& name);

// The comparison's display transform: the scene's exposure and tone mapping.
DisplaySettings sceneDisplaySettings(const Scene& scene);

// Renders `scene` (validated) with spec.parameter set to each value, largest first, the other
// parameter as the scene has it. `onRow` is called after each render and its comparison (to save
// the EXR at once, report progress). An external reference must be the scene's size (InputError
// otherwise, before anything is rendered).
SweepResult runSweep(const Scene& scene, const SweepSpec& spec, const SweepRenderer& render,
                     const std::function<void(const SweepRow&)>& onRow = {});

// The table: header "value,seconds,speedup,mean_dE76,jnd76_pct,mean_dE2000,jnd2000_pct", one line
// per row in the rows' order.
std::string sweepCsv(const SweepResult& r);
// {parameter, scene, device, fixed: {NAME: value}, width, height, seed, display, reference,
// speedup_baseline, rows: [{value, seconds, speedup, mean_dE76, jnd76_pct, mean_dE2000,
// jnd2000_pct, reference, exr (sweepFileName), ...}]}.
nlohmann::ordered_json sweepJson(const SweepResult& r);

// The figure strip (Figs. 5.4, 5.8) on a white page: a title, then one column per row (an external
// reference gets a column of its own first) with its label ("10000 spp") and speed-up above, the
// displayed render, the ΔE76 heat map (0..10, with legend) captioned with the mean ΔE76, and the JND
// map captioned with its percentage. Renders narrower than 160 px are enlarged by a whole factor
// (pixels repeated; maps drawn at that size); a strip wider than `maxWidth` is shrunk (maps drawn at
// full size, then box-filtered, so a JND map's red shows the share of pixels over the JND).
ImageRGB8 sweepFigure(const SweepResult& r, int maxWidth = 4000);

// Box-filtered resize of an 8-bit picture (area average when shrinking; whole-factor enlargements
// repeat pixels exactly).
ImageRGB8 resizeImage(const ImageRGB8& src, int width, int height);

}  // namespace narval
