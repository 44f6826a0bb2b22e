// sweep.h: speed against perceptual error over spp or bounces (dissertation ch. 5, Tables 5.1 and 5.2, Figs.
// 5.4 and 5.8): timed renders at several values, largest first, each compared under the scene's display
// transform with a reference (the largest value's render, or a supplied image). The renderer is a parameter
// (`narval sweep` passes renderPathtrace), so the logic is tested on the host without OpenCL.
//
// All renders use the scene's seed and sample-keyed random numbers, so an n-spp render is the mean of the
// N-spp reference's first n samples: its ΔE measures σ²(1/n − 1/N), not σ²/n against an independent ground
// truth (independent seeds: σ²(1/n + 1/N)); small when N ≫ n, as in the dissertation's 10× steps.
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

// "10,100,1000" -> {10, 100, 1000}: distinct positive integers (spaces allowed). InputError "OPTION: expected
// a comma-separated list of positive integers, got 'TEXT'" or "OPTION: VALUE is listed twice".
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
  // The value timing the speed-up's numerator: the reference's, or with an external one the largest rendered.
  int speedupBaseline = 0;
  std::vector<SweepRow> rows;     // descending values
};

using SweepRenderer = std::function<RenderResult(const Scene&)>;

// Throws InputError naming `name` when an external reference cannot serve for `scene`: its size
// differs from the scene's resolution, or it holds non-finite values.
void checkSweepReference(const Scene& scene, const ImageRGB& reference, const std::string& name);

// The comparison's display transform: the scene's exposure and tone mapping.
DisplaySettings sceneDisplaySettings(const Scene& scene);

// Renders `scene` (validated) at each spec.parameter value, largest first, the other as the scene has it; `onRow`
// runs after each render and comparison (save the EXR, report progress). Bad external reference: InputError first.
SweepResult runSweep(const Scene& scene, const SweepSpec& spec, const SweepRenderer& render,
                     const std::function<void(const SweepRow&)>& onRow = {});

// The table: header "value,seconds,speedup,mean_dE76,jnd76_pct,mean_dE2000,jnd2000_pct", then the rows.
std::string sweepCsv(const SweepResult& r);
// {parameter, scene, device, fixed: {NAME: value}, width, height, seed, display, reference,
// speedup_baseline, rows: [{value, seconds, speedup, mean_dE76, jnd76_pct, mean_dE2000,
// jnd2000_pct, reference, exr (sweepFileName), ...}]}.
nlohmann::ordered_json sweepJson(const SweepResult& r);

// The figure strip (Figs. 5.4, 5.8) on white: a title, then per row (an external reference first) its label
// ("10000 spp") and speed-up, the displayed render, the ΔE76 heat map (0..10, legend) captioned with the
// mean, and the JND map with its percentage. Renders under 160 px wide are enlarged by a whole factor (pixels
// repeated, maps drawn at that size); a strip over `maxWidth` shrinks (maps box-filtered: red = share over JND).
ImageRGB8 sweepFigure(const SweepResult& r, int maxWidth = 4000);

// Box-filtered resize of an 8-bit picture (area average shrinking; whole-factor enlargement repeats pixels).
ImageRGB8 resizeImage(const ImageRGB8& src, int width, int height);

}  // namespace narval
