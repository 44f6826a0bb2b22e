#include "render/render_merge.h"

#include <algorithm>
#include <cstdlib>

#include "core/input_error.h"
#include "render/medium_mask.h"

namespace narval {

const std::vector<std::string> kPartIdentityAttributes = {
    "narval:render_key", "narval:seed",     "narval:device",  "narval:majorant",
    "narval:majorant_resolution", "narval:bounces", "narval:version"};

namespace {

std::string range(const AccumulatorState& a) {
  return "[" + std::to_string(a.begin) + ", " + std::to_string(a.end()) + ")";
}

// The identity the merged file records: the first part's, with the spp of the whole render in
// place of the part's (--samples A:B records renderer.spp=B-A).
RenderIdentity mergedIdentity(const RenderPart& first, int spp) {
  RenderIdentity id;
  id.seed = uint32_t(std::strtoull(first.attribute("narval:seed").c_str(), nullptr, 10));
  id.scene = first.attribute("narval:scene");
  id.renderKey = first.attribute("narval:render_key");
  id.settings = first.attribute("narval:settings");
  id.exposure = std::strtof(first.attribute("narval:exposure").c_str(), nullptr);
  if (!toneMappingFromName(first.attribute("narval:tone_mapping"), &id.toneMapping))
    throw inputError(first.path, "narval:tone_mapping",
                     "unknown tone mapping '" + first.attribute("narval:tone_mapping") + "'");
  const std::string& overrides = first.attribute("narval:overrides");
  size_t at = 0;
  while (!overrides.empty() && at <= overrides.size()) {
    const size_t end = std::min(overrides.find('\n', at), overrides.size());
    const std::string line = overrides.substr(at, end - at);
    if (line.rfind("renderer.spp=", 0) != 0) id.overrides.push_back(line);
    at = end + 1;
  }
  id.overrides.push_back("renderer.spp=" + std::to_string(spp));
  return id;
}

}  // namespace

MergedRender mergeRenderParts(const std::vector<std::string>& paths) {
  if (paths.empty()) throw inputError("merge", "", "no parts given");
  // Every header is checked before any pixel is read; then the sums are added one part at a time,
  // so a merge of K parts holds two accumulators, not K.
  std::vector<RenderPart> parts;
  for (const std::string& p : paths) parts.push_back(readRenderPartHeader(p));
  const RenderPart& first = parts.front();
  for (const RenderPart& p : parts) {
    for (const std::string& key : kPartIdentityAttributes) {
      if (p.attribute(key) == first.attribute(key)) continue;
      // Another render key: the setting that differs, where both parts record their settings.
      const std::string difference = key == "narval:render_key"
                                         ? settingsDifference(first.attribute("narval:settings"), first.path,
                                                              p.attribute("narval:settings"), "this part")
                                         : "";
      throw inputError(p.path, key,
                       "'" + p.attribute(key) + "' where " + first.path + " has '" + first.attribute(key) + "'" +
                           (difference.empty() ? "" : " (" + difference + ")") +
                           ": parts must come from one scene, settings, seed, device and narval version");
    }
    if (p.width != first.width || p.height != first.height)
      throw inputError(p.path, "narval:render_key",
                       std::to_string(p.width) + "x" + std::to_string(p.height) + " where " + first.path + " is " +
                           std::to_string(first.width) + "x" + std::to_string(first.height));
  }
  std::vector<const RenderPart*> order;
  for (const RenderPart& p : parts) order.push_back(&p);
  std::stable_sort(order.begin(), order.end(), [](const RenderPart* a, const RenderPart* b) {
    return a->accumulator.begin < b->accumulator.begin;
  });
  if (order.front()->accumulator.begin != 0)
    throw inputError(order.front()->path, "narval:sample_begin",
                     "the parts start at sample " + std::to_string(order.front()->accumulator.begin) + ": samples [0, " +
                         std::to_string(order.front()->accumulator.begin) + ") are missing");
  for (size_t i = 1; i < order.size(); ++i) {
    const RenderPart& a = *order[i - 1];
    const RenderPart& b = *order[i];
    if (b.accumulator.begin < a.accumulator.end())
      throw inputError(b.path, "narval:sample_begin",
                       "samples " + range(b.accumulator) + " overlap " + a.path + "'s " + range(a.accumulator));
    if (b.accumulator.begin > a.accumulator.end())
      throw inputError(b.path, "narval:sample_begin",
                       "samples [" + std::to_string(a.accumulator.end()) + ", " + std::to_string(b.accumulator.begin) +
                           ") are missing between " + a.path + " " + range(a.accumulator) + " and this part " +
                           range(b.accumulator));
  }

  MergedRender merged;
  RenderResult& r = merged.result;
  RenderStats& st = r.stats;
  for (size_t i = 0; i < order.size(); ++i) {
    RenderPart part = *order[i];
    loadAccumulatorWords(part);
    if (i == 0) r.accumulator = std::move(part.accumulator);
    else addAccumulator(r.accumulator, part.accumulator);
    st.seconds += std::strtod(part.attribute("narval:seconds").c_str(), nullptr);
  }
  st.algorithm = "pathtrace";
  st.device = first.attribute("narval:device");
  st.width = first.width;
  st.height = first.height;
  st.bounces = std::atoi(first.attribute("narval:bounces").c_str());
  st.spp = st.sppRequested = r.accumulator.samples;
  st.sampleBegin = 0;
  st.status = r.accumulator.status;
  st.majorant = first.attribute("narval:majorant");
  st.majorantResolution = std::atoi(first.attribute("narval:majorant_resolution").c_str());
  r.image = accumulatorImage(r.accumulator, first.width, first.height, &st.nanPixels);
  // Every part renders the same scene and camera (the render key), so the first's mask is theirs.
  if (first.hasMediumMask) r.mediumMask = readExrUintChannels(first.path, {kMediumMaskChannel})[0].values;
  merged.identity = mergedIdentity(first, st.spp);
  return merged;
}

}  // namespace narval
