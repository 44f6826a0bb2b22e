// reference_noise.cpp: the reference's own noise from an earlier snapshot (reference_noise.h).
#include "analysis/reference_noise.h"

#include <cmath>

#include "core/input_error.h"
#include "render/render_exr.h"

namespace narval {

ReferenceNoise estimateReferenceNoise(const std::string& referencePath, const ImageRGB& reference,
                                      const std::string& snapshotPath) {
  const RenderPart r = readRenderPartHeader(referencePath), s = readRenderPartHeader(snapshotPath);
  if (s.attribute("narval:render_key") != r.attribute("narval:render_key"))
    throw inputError(snapshotPath, "narval:render_key", "rendered from other settings than " + referencePath);
  if (s.attribute("narval:seed") != r.attribute("narval:seed"))
    throw inputError(snapshotPath, "narval:seed",
                     "seed " + s.attribute("narval:seed") + ", the reference's " + r.attribute("narval:seed") +
                         ": not a snapshot of the same render");
  const AccumulatorState &ra = r.accumulator, &sa = s.accumulator;
  if (sa.begin < ra.begin || sa.end() > ra.end() || sa.samples >= ra.samples || sa.samples <= 0)
    throw inputError(snapshotPath, "narval:sample_end",
                     "samples [" + std::to_string(sa.begin) + ", " + std::to_string(sa.end()) +
                         ") are not a smaller part of the reference's [" + std::to_string(ra.begin) + ", " +
                         std::to_string(ra.end()) + ")");
  const ImageRGB snapshot = readExr(snapshotPath);
  if (snapshot.width != reference.width || snapshot.height != reference.height)
    throw inputError(snapshotPath, "",
                     "size " + std::to_string(snapshot.width) + "x" + std::to_string(snapshot.height) +
                         ", the reference's " + std::to_string(reference.width) + "x" +
                         std::to_string(reference.height));
  ReferenceNoise n;
  n.snapshotSamples = sa.samples;
  n.referenceSamples = ra.samples;
  n.scale = std::sqrt(double(sa.samples) / double(ra.samples - sa.samples));
  n.perturbed = reference;
  for (size_t i = 0; i < n.perturbed.rgb.size(); ++i) {
    const double r = reference.rgb[i], snap = snapshot.rgb[i];
    n.perturbed.rgb[i] = float(r + n.scale * (snap - r));
  }
  return n;
}

}  // namespace narval
