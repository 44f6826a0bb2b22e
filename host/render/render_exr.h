// render_exr.h: what a render's EXR carries besides its pixels: header attributes that name the
// render (algorithm, spp, seed, scene, device, status, a key of the settings), and for the path
// tracer its accumulator (compensated sum per channel), so that `narval render --resume` continues
// an interrupted or finished render to more samples with the bits of an uninterrupted one.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "image/image.h"
#include "render/render_types.h"
#include "scene/scene.h"

namespace narval {

// Hex FNV-1a of the scene as rendered (Scene::document), less the settings that do not change the
// path tracer's samples: renderer spp, HDR, toneMapping, exposure, raymarch.*, lobe.* and
// camera.speed. Equal keys: the same samples, sample index for sample index.
std::string renderKey(const Scene& scene);

// The command line narval was started with, shell-quoted (main records it once; "" until then):
// what a render's EXR names as the command that made it.
void recordCommandLine(int argc, const char* const* argv);
const std::string& recordedCommandLine();

// The header attributes of a render's EXR, numbers typed as numbers:
// - pbrt-v4's, which image tools read: renderTimeSeconds (float), samplesPerPixel (int);
// - OpenEXR's standard capDate ("YYYY:MM:DD hh:mm:ss", local time) and utcOffset (float seconds,
//   UTC = local time + utcOffset);
// - narval's: algorithm, spp, bounces, seed, scene, device, seconds, status, render_key, majorant,
//   majorant_resolution (what --resume checks), exposure and tone_mapping (the scene's display
//   transform, which `narval compare` applies by default), version, command_line and overrides
//   (the --set strings, a string vector).
std::vector<ExrAttribute> renderAttributes(const RenderStats& stats, const Scene& scene);

// Writes result.image to `path` (atomically) with renderAttributes and, for the path tracer, the
// accumulator as six more channels: accum_sum.{R,G,B} and accum_comp.{R,G,B}.
void writeRenderExr(const std::string& path, const RenderResult& result, const Scene& scene);

// Reads the accumulator of an earlier path-traced render of the same scene from `path` for
// --resume. InputError "PATH: ATTRIBUTE: ..." when the file is not a resumable narval render, was
// rendered from other settings (renderKey), or has more samples than `scene` asks for.
AccumulatorState readAccumulator(const std::string& path, const Scene& scene);

}  // namespace narval
