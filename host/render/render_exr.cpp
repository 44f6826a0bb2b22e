#include "render/render_exr.h"

#include <cstdio>
#include <ctime>
#include <stdexcept>

#include "cl/cl_runtime.h"
#include "scene/input_error.h"

namespace narval {
namespace {

const char* const kChannels[6] = {"accum_sum.R", "accum_sum.G", "accum_sum.B",
                                  "accum_comp.R", "accum_comp.G", "accum_comp.B"};

// A non-negative decimal attribute, or an InputError naming it.
long long attributeNumber(const std::map<std::string, std::string>& attrs, const std::string& path,
                          const std::string& name) {
  const auto it = attrs.find(name);
  if (it == attrs.end()) throw inputError(path, name, "missing: not a resumable narval path-traced render");
  try {
    size_t used = 0;
    const long long v = std::stoll(it->second, &used);
    if (used == it->second.size() && v >= 0) return v;
  } catch (const std::exception&) {
  }
  throw inputError(path, name, "not a non-negative integer: '" + it->second + "'");
}

}  // namespace

std::string renderKey(const Scene& scene) {
  nlohmann::json doc = scene.document;
  if (doc.contains("renderer") && doc["renderer"].is_object())
    for (const char* k : {"spp", "HDR", "toneMapping", "exposure", "raymarch", "lobe"}) doc["renderer"].erase(k);
  if (doc.contains("camera") && doc["camera"].is_object()) doc["camera"].erase("speed");
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", (unsigned long long)fnv1a64(doc.dump()));
  return hex;
}

namespace {
std::string& commandLineStore() {
  static std::string text;
  return text;
}

// One argument as a POSIX shell reads it back: bare when it is safe, else in single quotes.
std::string shellQuoted(const std::string& arg) {
  const bool safe = !arg.empty() && arg.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                                          "0123456789_-+=./:,@%") == std::string::npos;
  if (safe) return arg;
  std::string out = "'";
  for (char c : arg) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}
}  // namespace

void recordCommandLine(int argc, const char* const* argv) {
  std::string text;
  for (int i = 0; i < argc; ++i) text += (i ? " " : "") + shellQuoted(argv[i]);
  commandLineStore() = text;
}

const std::string& recordedCommandLine() { return commandLineStore(); }

std::vector<ExrAttribute> renderAttributes(const RenderStats& s, const Scene& scene) {
  const std::time_t now = std::time(nullptr);
  std::tm local{}, utc{};
  localtime_r(&now, &local);
  gmtime_r(&now, &utc);
  char date[32];
  std::strftime(date, sizeof date, "%Y:%m:%d %H:%M:%S", &local);
  // UTC = local + utcOffset (OpenEXR's ImfStandardAttributes.h): mktime reads both as local time.
  const float utcOffset = float(std::difftime(std::mktime(&utc), std::mktime(&local)));
  return {{"renderTimeSeconds", float(s.seconds)},
          {"samplesPerPixel", s.spp},
          {"capDate", std::string(date)},
          {"utcOffset", utcOffset},
          {"narval:algorithm", s.algorithm},
          {"narval:spp", s.spp},
          {"narval:bounces", s.bounces},
          {"narval:seed", double(scene.renderer.seed)},  // an unsigned 32-bit seed: exact in a double
          {"narval:scene", scene.sourcePath},
          {"narval:device", s.device},
          {"narval:seconds", s.seconds},
          {"narval:status", int(s.status)},
          {"narval:render_key", renderKey(scene)},
          // The path tracer's samples also depend on these (RenderOptions): --resume keeps them.
          {"narval:majorant", s.majorant},
          {"narval:majorant_resolution", s.majorantResolution},
          {"narval:exposure", scene.renderer.exposure},
          {"narval:tone_mapping", std::string(toneMappingName(scene.renderer.toneMapping))},
          {"narval:version", std::string(NARVAL_VERSION)},
          {"narval:command_line", recordedCommandLine()},
          {"narval:overrides", scene.overrides}};
}

void writeRenderExr(const std::string& path, const RenderResult& r, const Scene& scene) {
  std::vector<ExrChannel> channels;
  const AccumulatorState& acc = r.accumulator;
  const size_t pixels = size_t(r.image.width) * size_t(r.image.height);
  if (acc.sum.size() == pixels * 4 && acc.comp.size() == pixels * 4) {
    for (int c = 0; c < 6; ++c) {
      const std::vector<float>& src = c < 3 ? acc.sum : acc.comp;
      ExrChannel ch{kChannels[c], std::vector<float>(pixels)};
      for (size_t i = 0; i < pixels; ++i) ch.values[i] = src[i * 4 + c % 3];
      channels.push_back(std::move(ch));
    }
  }
  writeExr(path, r.image, renderAttributes(r.stats, scene), channels);
}

AccumulatorState readAccumulator(const std::string& path, const Scene& scene) {
  const auto attrs = readExrAttributes(path);
  const auto algorithm = attrs.find("narval:algorithm");
  if (algorithm == attrs.end() || algorithm->second != "pathtrace")
    throw inputError(path, "narval:algorithm",
                     algorithm == attrs.end() ? "missing: not a resumable narval path-traced render"
                                              : "rendered by " + algorithm->second + "; only pathtrace renders resume");
  const auto key = attrs.find("narval:render_key");
  if (key == attrs.end()) throw inputError(path, "narval:render_key", "missing: not a resumable narval path-traced render");
  if (key->second != renderKey(scene))
    throw inputError(path, "narval:render_key",
                     "rendered from other settings than " + scene.sourcePath +
                         " with these options (only spp and display settings may change); render to another file "
                         "or leave out --resume");
  const long long spp = attributeNumber(attrs, path, "narval:spp");
  if (spp > scene.renderer.spp)
    throw inputError(path, "narval:spp",
                     "has " + std::to_string(spp) + " spp, more than the " + std::to_string(scene.renderer.spp) +
                         " requested");
  AccumulatorState acc;
  acc.samples = int(spp);
  acc.status = uint32_t(attributeNumber(attrs, path, "narval:status"));
  const std::vector<ExrChannel> channels =
      readExrChannels(path, std::vector<std::string>(std::begin(kChannels), std::end(kChannels)));
  const size_t pixels = size_t(scene.renderer.width) * size_t(scene.renderer.height);
  if (channels[0].values.size() != pixels)  // the key covers the resolution; this guards a hand-edited file
    throw inputError(path, "narval:render_key", "the image size does not match renderer.resolution");
  acc.sum.assign(pixels * 4, 0.0f);
  acc.comp.assign(pixels * 4, 0.0f);
  for (int c = 0; c < 6; ++c) {
    std::vector<float>& dst = c < 3 ? acc.sum : acc.comp;
    for (size_t i = 0; i < pixels; ++i) dst[i * 4 + c % 3] = channels[size_t(c)].values[i];
  }
  return acc;
}

}  // namespace narval
