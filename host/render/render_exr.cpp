#include "render/render_exr.h"

#include <cstdio>
#include <filesystem>
#include <ctime>
#include <stdexcept>

#include "cl/cl_runtime.h"
#include "core/input_error.h"
#include "core/shell_quote.h"
#include "render/medium_mask.h"
#include "shared/accum.h"

namespace narval {
namespace {

// The accumulator's UINT channels: per colour four 32-bit words of its 128-bit sum (low first),
// then the count of rejected samples (accum.h). 64-bit words split into two channels each.
std::vector<std::string> accumulatorChannelNames() {
  std::vector<std::string> names;
  for (const char* c : {"R", "G", "B"})
    for (int w = 0; w < 4; ++w) names.push_back(std::string("accum.") + c + ".w" + std::to_string(w));
  names.push_back("accum.rejected");
  return names;
}

// Where channel c of accumulatorChannelNames lives: 32-bit word c % 4 of colour c / 4 (bits `shift`
// of the 64-bit word `word`), and the last channel the rejected count.
void accumulatorChannelWord(size_t c, size_t* word, int* shift) {
  *word = c < 12 ? 2 * (c / 4) + (c % 4) / 2 : size_t(ACCUM_REJECTED_WORD);
  *shift = c < 12 ? 32 * int(c % 2) : 0;
}

// A non-negative decimal attribute, or an InputError naming it.
long long attributeNumber(const std::map<std::string, std::string>& attrs, const std::string& path,
                          const std::string& name) {
  const auto it = attrs.find(name);
  if (it == attrs.end()) throw inputError(path, name, "missing: not a narval path-traced render with its samples");
  try {
    size_t used = 0;
    const long long v = std::stoll(it->second, &used);
    if (used == it->second.size() && v >= 0) return v;
  } catch (const std::exception&) {
  }
  throw inputError(path, name, "not a non-negative integer: '" + it->second + "'");
}

}  // namespace

nlohmann::json renderSettings(const Scene& scene) {
  nlohmann::json doc = scene.document;
  if (doc.contains("renderer") && doc["renderer"].is_object())
    for (const char* k : {"spp", "HDR", "toneMapping", "exposure", "raymarch", "lobe"}) doc["renderer"].erase(k);
  if (doc.contains("camera") && doc["camera"].is_object()) doc["camera"].erase("speed");
  return doc;
}

namespace {
std::string keyOfSettings(const std::string& settings) {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", (unsigned long long)fnv1a64(settings));
  return hex;
}
}  // namespace

std::string renderKey(const Scene& scene) { return keyOfSettings(renderSettings(scene).dump()); }

namespace {

// The first leaf (depth first, keys in order) where a (from `as`) and b (from `bs`) differ, at `path`.
std::string firstDifference(const nlohmann::json& a, const nlohmann::json& b, const std::string& path,
                            const std::string& as, const std::string& bs) {
  if (a.is_object() && b.is_object()) {
    for (const auto& [k, v] : a.items()) {
      const std::string p = path.empty() ? k : path + "." + k;
      if (!b.contains(k)) return p + " is " + v.dump() + " in " + as + ", absent in " + bs;
      const std::string d = firstDifference(v, b[k], p, as, bs);
      if (!d.empty()) return d;
    }
    for (const auto& [k, v] : b.items())
      if (!a.contains(k)) return (path.empty() ? k : path + "." + k) + " is absent in " + as + ", " + v.dump() + " in " + bs;
    return "";
  }
  if (a.is_array() && b.is_array() && a.size() == b.size()) {
    for (size_t i = 0; i < a.size(); ++i) {
      const std::string d = firstDifference(a[i], b[i], path + "[" + std::to_string(i) + "]", as, bs);
      if (!d.empty()) return d;
    }
    return "";
  }
  return a == b ? "" : path + " is " + a.dump() + " in " + as + ", " + b.dump() + " in " + bs;
}

}  // namespace

std::string settingsDifference(const std::string& a, const std::string& as, const std::string& b,
                               const std::string& bs) {
  const nlohmann::json x = nlohmann::json::parse(a, nullptr, false), y = nlohmann::json::parse(b, nullptr, false);
  if (x.is_discarded() || y.is_discarded()) return "";
  return firstDifference(x, y, "", as, bs);
}

namespace {
std::string& commandLineStore() {
  static std::string text;
  return text;
}

}  // namespace

void recordCommandLine(int argc, const char* const* argv) {
  commandLineStore() = shellJoined(std::vector<std::string>(argv, argv + argc));
}

const std::string& recordedCommandLine() { return commandLineStore(); }

RenderIdentity renderIdentity(const Scene& scene) {
  RenderIdentity id;
  id.seed = scene.renderer.seed;
  id.scene = scene.sourcePath;
  id.settings = renderSettings(scene).dump();
  id.renderKey = keyOfSettings(id.settings);
  id.exposure = scene.renderer.exposure;
  id.toneMapping = scene.renderer.toneMapping;
  id.overrides = scene.overrides;
  return id;
}

std::vector<ExrAttribute> renderAttributes(const RenderStats& s, const RenderIdentity& id) {
  const std::time_t now = std::time(nullptr);
  std::tm local{}, utc{};
  localtime_r(&now, &local);
  gmtime_r(&now, &utc);
  char date[32];
  std::strftime(date, sizeof date, "%Y:%m:%d %H:%M:%S", &local);
  // UTC = local + utcOffset (OpenEXR's ImfStandardAttributes.h): mktime reads both as local time.
  const float utcOffset = float(std::difftime(std::mktime(&utc), std::mktime(&local)));
  std::vector<ExrAttribute> attrs = {{"renderTimeSeconds", float(s.seconds)},
          {"samplesPerPixel", s.spp},
          {"capDate", std::string(date)},
          {"utcOffset", utcOffset},
          {"narval:algorithm", s.algorithm},
          {"narval:spp", s.spp},
          {"narval:bounces", s.bounces},
          {"narval:seed", double(id.seed)},  // an unsigned 32-bit seed: exact in a double
          {"narval:scene", id.scene},
          {"narval:device", s.device},
          {"narval:seconds", s.seconds},
          {"narval:status", int(s.status)},
          {"narval:render_key", id.renderKey},
          // The path tracer's samples also depend on these (RenderOptions): --resume keeps them.
          {"narval:majorant", s.majorant},
          {"narval:majorant_resolution", s.majorantResolution},
          {"narval:exposure", id.exposure},
          {"narval:tone_mapping", std::string(toneMappingName(id.toneMapping))},
          {"narval:version", std::string(NARVAL_VERSION)},
          {"narval:command_line", recordedCommandLine()},
          {"narval:overrides", id.overrides},
          {"narval:settings", id.settings}};
  if (s.algorithm == "pathtrace") {
    attrs.push_back({"narval:sample_begin", s.sampleBegin});
    attrs.push_back({"narval:sample_end", s.sampleBegin + s.spp});
  }
  return attrs;
}

void writeRenderExr(const std::string& path, const RenderResult& r, const RenderIdentity& identity) {
  std::vector<ExrUintChannel> channels;
  const AccumulatorState& acc = r.accumulator;
  const size_t pixels = size_t(r.image.width) * size_t(r.image.height);
  if (acc.words.size() == pixels * kAccumulatorWords) {
    const std::vector<std::string> names = accumulatorChannelNames();
    for (size_t c = 0; c < names.size(); ++c) {
      size_t word;
      int shift;
      accumulatorChannelWord(c, &word, &shift);
      ExrUintChannel ch{names[c], std::vector<uint32_t>(pixels)};
      for (size_t i = 0; i < pixels; ++i) ch.values[i] = uint32_t(acc.words[i * kAccumulatorWords + word] >> shift);
      channels.push_back(std::move(ch));
    }
  }
  if (r.mediumMask.size() == pixels) channels.push_back({kMediumMaskChannel, r.mediumMask});
  writeExr(path, r.image, renderAttributes(r.stats, identity), channels);
}

const std::string& RenderPart::attribute(const std::string& name) const {
  static const std::string none;
  const auto it = attributes.find(name);
  return it == attributes.end() ? none : it->second;
}

RenderPart readRenderPartHeader(const std::string& path) {
  RenderPart part;
  part.path = path;
  ExrHeader header = readExrHeader(path);
  part.width = header.width;
  part.height = header.height;
  part.attributes = std::move(header.attributes);
  for (const std::string& c : header.channels) part.hasMediumMask = part.hasMediumMask || c == kMediumMaskChannel;
  const auto& attrs = part.attributes;
  const auto algorithm = attrs.find("narval:algorithm");
  if (algorithm == attrs.end() || algorithm->second != "pathtrace")
    throw inputError(path, "narval:algorithm",
                     algorithm == attrs.end() ? "missing: not a narval path-traced render with its samples"
                                              : "rendered by " + algorithm->second +
                                                    "; only path-traced renders carry their samples");
  if (!attrs.count("narval:sample_begin"))
    throw inputError(path, "narval:sample_begin",
                     "missing: rendered by a narval before exact accumulation, whose float sums cannot be continued "
                     "or merged bit for bit; render it again");
  const long long begin = attributeNumber(attrs, path, "narval:sample_begin");
  const long long end = attributeNumber(attrs, path, "narval:sample_end");
  const long long spp = attributeNumber(attrs, path, "narval:spp");
  if (end - begin != spp || end > 0x7fffffffLL)
    throw inputError(path, "narval:sample_end",
                     "samples [" + std::to_string(begin) + ", " + std::to_string(end) + ") do not hold narval:spp " +
                         std::to_string(spp));
  AccumulatorState& acc = part.accumulator;
  acc.begin = int(begin);
  acc.samples = int(spp);
  acc.status = uint32_t(attributeNumber(attrs, path, "narval:status"));
  return part;
}

void loadAccumulatorWords(RenderPart& part) {
  // The pixels and the accumulator in one read.
  const ExrContents contents = readExrWithUintChannels(part.path, accumulatorChannelNames());
  if (contents.image.width != part.width || contents.image.height != part.height)  // changed since the header was read
    throw inputError(part.path, "", "the file changed while it was read");
  const std::vector<ExrUintChannel>& channels = contents.uints;
  const size_t pixels = size_t(part.width) * size_t(part.height);
  AccumulatorState& acc = part.accumulator;
  acc.words.assign(pixels * kAccumulatorWords, 0);
  for (size_t c = 0; c < channels.size(); ++c) {
    size_t word;
    int shift;
    accumulatorChannelWord(c, &word, &shift);
    for (size_t i = 0; i < pixels; ++i) acc.words[i * kAccumulatorWords + word] |= uint64_t(channels[c].values[i]) << shift;
  }
}

RenderPart readRenderPart(const std::string& path) {
  RenderPart part = readRenderPartHeader(path);
  loadAccumulatorWords(part);
  return part;
}

bool renderCovers(const std::string& path, const std::string& renderKey, int begin, int end) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return false;
  try {
    const RenderPart p = readRenderPartHeader(path);  // writes are atomic: a file there is whole
    return p.attribute("narval:render_key") == renderKey && p.accumulator.begin == begin && p.accumulator.end() == end;
  } catch (const std::exception&) {
    return false;  // unreadable, or not a path-traced render with its samples
  }
}

AccumulatorState readAccumulator(const std::string& path, const Scene& scene, int sampleBegin) {
  const auto attrs = readExrAttributes(path);
  const auto algorithm = attrs.find("narval:algorithm");
  if (algorithm == attrs.end() || algorithm->second != "pathtrace")
    throw inputError(path, "narval:algorithm",
                     algorithm == attrs.end() ? "missing: not a resumable narval path-traced render"
                                              : "rendered by " + algorithm->second + "; only pathtrace renders resume");
  const auto key = attrs.find("narval:render_key");
  if (key == attrs.end()) throw inputError(path, "narval:render_key", "missing: not a resumable narval path-traced render");
  if (key->second != renderKey(scene)) {
    const auto settings = attrs.find("narval:settings");
    const std::string difference =
        settings == attrs.end() ? ""
                                : settingsDifference(settings->second, path, renderSettings(scene).dump(), "the scene");
    throw inputError(path, "narval:render_key",
                     "rendered from other settings than " + scene.sourcePath + " with these options" +
                         (difference.empty() ? "" : " (" + difference + ")") +
                         "; only spp and display settings may change: render to another file or leave out --resume");
  }
  RenderPart part = readRenderPart(path);
  AccumulatorState& acc = part.accumulator;
  if (acc.begin != sampleBegin)
    throw inputError(path, "narval:sample_begin",
                     "holds samples from " + std::to_string(acc.begin) + " on, not from " + std::to_string(sampleBegin) +
                         "; resume it with --samples " + std::to_string(acc.begin) + ":END");
  if (acc.samples > scene.renderer.spp)
    throw inputError(path, "narval:spp",
                     "has " + std::to_string(acc.samples) + " spp, more than the " + std::to_string(scene.renderer.spp) +
                         " requested");
  if (part.width != scene.renderer.width || part.height != scene.renderer.height)  // the key covers the size; this guards a hand-edited file
    throw inputError(path, "narval:render_key", "the image size does not match renderer.resolution");
  return std::move(part.accumulator);
}

}  // namespace narval
