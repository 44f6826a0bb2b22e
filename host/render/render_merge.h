// render_merge.h: `narval merge`: path-traced renders of disjoint sample ranges of one scene,
// added into the render of their union. The accumulator is exact (render/accumulator.h), so the
// result has the bits of one uninterrupted render of [0, N), whatever the split and the order of
// the parts; a merged file is itself a part (merged again, or continued with --resume).
#pragma once

#include <string>
#include <vector>

#include "render/render_exr.h"
#include "render/render_types.h"

namespace narval {

// The attributes parts must agree on to hold samples of one render: the scene and settings (the
// render key, which covers the seed and the resolution), the seed named apart for a clear message,
// the device (another device or driver rounds differently, so its samples differ), the majorant and
// its grid, the bounces and the narval version.
extern const std::vector<std::string> kPartIdentityAttributes;

struct MergedRender {
  RenderResult result;  // image, accumulator and stats of samples [0, N)
  RenderIdentity identity;
};

// Reads and checks every part, then adds them. InputError (exit 2), naming the part and the
// attribute, when a file is not a narval path-traced render with its samples, when a part differs
// from the first in kPartIdentityAttributes or in size, and when the ranges do not tile [0, N)
// exactly: the first missing samples, or the first two parts that overlap.
MergedRender mergeRenderParts(const std::vector<std::string>& paths);

}  // namespace narval
