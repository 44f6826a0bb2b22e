// render_exr.h: a render's EXR beyond pixels: attributes naming it (algorithm, spp, seed, scene, device,
// status, settings key) and, for the path tracer, its sample range and exact accumulator (render/accumulator.h),
// so `narval render --resume` and `narval merge` (disjoint ranges) give the bits of one uninterrupted render.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "image/image.h"
#include "render/render_types.h"
#include "scene/scene.h"

namespace narval {

// Hex FNV-1a of the scene as rendered (Scene::document) less what leaves the path tracer's samples alone
// (renderer spp, HDR, toneMapping, exposure, raymarch.*, lobe.*, camera.speed): equal keys, equal samples.
std::string renderKey(const Scene& scene);

// The shell-quoted command line (main records it once; "" until then), named in a render's EXR.
void recordCommandLine(int argc, const char* const* argv);
const std::string& recordedCommandLine();

// What names a render besides its statistics: from the scene, or a part's header when merging (render_merge.h).
struct RenderIdentity {
  uint32_t seed = 0;
  std::string scene, renderKey;  // Scene::sourcePath; renderKey(scene)
  std::string settings;           // renderSettings(scene).dump(): what the key hashes ("" unknown)
  float exposure = 0.0f;
  ToneMapping toneMapping = ToneMapping::Aces;
  std::vector<std::string> overrides;
};
RenderIdentity renderIdentity(const Scene& scene);

// The settings a path-traced render's samples depend on (Scene::document less the display and
// real-time keys): what renderKey hashes and narval:settings records.
nlohmann::json renderSettings(const Scene& scene);
// The first setting that differs between two renderSettings documents (as text), from `as` and `bs`:
// "KEY is A in AS, B in BS" ("" when they agree or one is not JSON, e.g. a file from before the
// attribute): what a refused --resume or merge names.
std::string settingsDifference(const std::string& a, const std::string& as, const std::string& b,
                               const std::string& bs);

// The header attributes of a render's EXR, numbers typed as numbers: pbrt-v4's renderTimeSeconds (float)
// and samplesPerPixel (int), which image tools read; OpenEXR's capDate ("YYYY:MM:DD hh:mm:ss", local) and
// utcOffset (float s; UTC = local + utcOffset); narval's algorithm, spp, bounces, seed, scene, device,
// seconds, status, render_key, majorant, majorant_resolution (what --resume checks), sample_begin and
// sample_end (samples [begin, end), what `narval merge` tiles), exposure and tone_mapping (the display
// transform `narval compare` applies by default), version, command_line, overrides (--set strings, a vector),
// settings (renderSettings as JSON: what a refused --resume or merge names the difference from).
std::vector<ExrAttribute> renderAttributes(const RenderStats& stats, const RenderIdentity& identity);

// Writes result.image to `path` (atomically) with renderAttributes and, for the path tracer, the
// accumulator as 13 UINT channels: accum.{R,G,B}.w0–w3 (each channel's 128-bit sum, low 32-bit word
// first) and accum.rejected (samples not added; accum.h).
void writeRenderExr(const std::string& path, const RenderResult& result, const RenderIdentity& identity);

// A path-traced render as read back from its EXR: header attributes (as text), size, accumulator.
struct RenderPart {
  std::string path;
  std::map<std::string, std::string> attributes;
  int width = 0, height = 0;
  AccumulatorState accumulator;
  bool hasMediumMask = false;  // the render/medium_mask.h channel is there (renders before it lack it)
  const std::string& attribute(const std::string& name) const;  // "" when absent
};

// Reads a path-traced narval render with its accumulator. InputError "PATH: ATTRIBUTE: ..." when
// it is not one (another algorithm, no sample range: a render older than exact accumulation).
RenderPart readRenderPart(const std::string& path);
// The same from the header alone: accumulator.words stays empty (`narval merge` checks every part
// this way, then loads their sums one at a time with loadAccumulatorWords).
RenderPart readRenderPartHeader(const std::string& path);
void loadAccumulatorWords(RenderPart& part);

// Whether `path` is a path-traced render with this render key and samples [begin, end), by its
// header: what a farm task must have left (a part, or one of a sweep's renders).
bool renderCovers(const std::string& path, const std::string& renderKey, int begin, int end);

// The accumulator of an earlier path-traced render of the scene at `path`, to --resume samples
// [sampleBegin, sampleBegin + scene.renderer.spp). InputError "PATH: ATTRIBUTE: ..." when it is not a
// resumable narval render, has another renderKey, starts at another sample or holds more than asked for.
AccumulatorState readAccumulator(const std::string& path, const Scene& scene, int sampleBegin);

}  // namespace narval
