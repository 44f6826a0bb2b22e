// compare_command.cpp: `narval compare REF.exr TEST.exr` (DESIGN.md, Perceptual metric): mean,
// 95th percentile and max of ΔE76 and ΔE2000 and the JND% (ΔE > 2.3) of each, as a table or as JSON;
// optionally the ΔE76 heat map and the JND map as PNGs, and the floor the reference's own noise puts
// under the JND% (--reference-snapshot, host/analysis/reference_noise.h).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <nlohmann/json.hpp>
#include <string>

#include "analysis/image_compare.h"
#include "analysis/reference_noise.h"
#include "app/cli_common.h"
#include "app/commands.h"
#include "core/input_error.h"
#include "core/number_format.h"
#include "image/image.h"
#include "render/medium_mask.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

struct CompareArgs {
  std::string reference, test, tonemap, heatmap, jndMap;  // tonemap "": the EXRs' (below)
  std::string snapshot;                                    // --reference-snapshot: "" for none
  std::optional<double> exposure;                          // double: the JSON echoes what was typed
  double heatmapMax = 10.0;
  bool json = false;
  bool mediumOnly = false;  // the statistics over the pixels that see the medium (render/medium_mask.h)
};

// The display transform both EXRs record (render_exr.h: narval:exposure and narval:tone_mapping,
// the scene's), when they record the same one: what `sweep` compared under, so `compare A B`
// reports what `sweep` reported for the pair.
struct RecordedDisplay {
  bool found = false;
  double exposure = 0.0;
  std::string toneMapping = "none";
};

RecordedDisplay recordedDisplay(const std::string& reference, const std::string& test) {
  const auto a = readExrAttributes(reference), b = readExrAttributes(test);
  RecordedDisplay d;
  for (const char* key : {"narval:exposure", "narval:tone_mapping"}) {
    const auto x = a.find(key), y = b.find(key);
    if (x == a.end() || y == b.end() || x->second != y->second) return d;
  }
  char* end = nullptr;
  d.exposure = std::strtod(a.at("narval:exposure").c_str(), &end);
  if (*end != '\0' || !std::isfinite(d.exposure)) return RecordedDisplay{};
  d.toneMapping = a.at("narval:tone_mapping");
  d.found = true;
  return d;
}


// An output picture must be a .png (its folder is created when it is written).
void checkPngOutput(const std::string& path, const std::string& option) {
  if (path.empty()) return;
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".png") throw inputError(option, "", "the output must be a .png file, got '" + path + "'");
}


// The medium mask for --medium-only: the reference's, else the test's (a path-traced sweep's renders
// carry none). Both must agree where both have one: two masks that differ are two scenes or cameras.
std::vector<uint32_t> mediumOnlyMask(const std::string& reference, const std::string& test) {
  auto maskOf = [](const std::string& path) -> std::optional<std::vector<uint32_t>> {
    const ExrHeader h = readExrHeader(path);
    if (std::find(h.channels.begin(), h.channels.end(), kMediumMaskChannel) == h.channels.end()) return std::nullopt;
    return readExrUintChannels(path, {kMediumMaskChannel})[0].values;
  };
  const auto r = maskOf(reference), t = maskOf(test);
  if (!r && !t)
    throw inputError("--medium-only", "",
                     "neither " + reference + " nor " + test + " has a " + kMediumMaskChannel +
                         " channel (narval render writes it: the pixels that see the medium)");
  if (r && t && *r != *t)
    throw inputError(test, kMediumMaskChannel,
                     "differs from " + reference + "'s: the renders are not of the same scene and camera");
  const std::vector<uint32_t>& m = r ? *r : *t;
  if (std::count(m.begin(), m.end(), 0u) == std::ptrdiff_t(m.size()))
    throw inputError(r ? reference : test, kMediumMaskChannel, "no pixel sees the medium");
  return m;
}

std::string tableRow(const char* name, const DeltaEStats& s) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%-8s %10.4f %10.4f %10.4f %9.2f%%\n", name, s.mean, s.p95, s.max, s.jndPercent);
  return buf;
}

int runCompare(const CompareArgs& a) {
  if (a.exposure && !std::isfinite(*a.exposure)) throw inputError("--exposure", "", "expected a finite number of stops");
  if (!(a.heatmapMax > 0.0) || !std::isfinite(a.heatmapMax))
    throw inputError("--heatmap-max", "", "expected a positive number");
  checkPngOutput(a.heatmap, "--heatmap");
  checkPngOutput(a.jndMap, "--jnd-map");
  checkOutputWritable(a.heatmap, "--heatmap");
  checkOutputWritable(a.jndMap, "--jnd-map");
  std::string tmName = a.tonemap;
  for (char& c : tmName) c = char(std::tolower(static_cast<unsigned char>(c)));
  ToneMapping toneMapping = ToneMapping::None;
  if (!tmName.empty() && !toneMappingFromName(tmName, &toneMapping))
    throw inputError("--tonemap", "", "expected none, reinhard or aces, got '" + a.tonemap + "'");

  const ImageRGB reference = readExr(a.reference);
  const ImageRGB test = readExr(a.test);
  std::optional<std::vector<uint32_t>> mask;
  if (a.mediumOnly) mask = mediumOnlyMask(a.reference, a.test);
  std::optional<ReferenceNoise> noise;
  if (!a.snapshot.empty()) noise = estimateReferenceNoise(a.reference, reference, a.snapshot);
  // Flags win; what they leave open comes from the EXRs when both record the same transform.
  const RecordedDisplay recorded = recordedDisplay(a.reference, a.test);
  const bool anyFlag = a.exposure || !tmName.empty(), allFlags = a.exposure && !tmName.empty();
  if (tmName.empty()) tmName = recorded.found ? recorded.toneMapping : "none";
  if (!toneMappingFromName(tmName, &toneMapping))  // a recorded name this build does not know
    throw inputError(a.reference, "narval:tone_mapping", "unknown tone mapping '" + tmName + "'");
  const double exposure = a.exposure ? *a.exposure : recorded.found ? recorded.exposure : 0.0;
  const std::string source = allFlags         ? "given"
                             : recorded.found ? (anyFlag ? "given, the rest as both EXRs record it" : "as both EXRs record it")
                             : anyFlag        ? "given, the rest the default"
                                              : "the default: the EXRs record no common display transform";
  DisplaySettings display;
  display.exposureStops = float(exposure);
  display.toneMapping = toneMapping;
  const std::vector<uint32_t>* maskPtr = mask ? &*mask : nullptr;
  const ImageComparison c = compareImages(reference, test, display, a.reference, a.test, maskPtr);
  std::optional<ImageComparison> floor;  // a noise-free image against the reference, estimated
  if (noise) floor = compareImages(reference, noise->perturbed, display, a.reference, a.snapshot, maskPtr);

  if (!a.heatmap.empty()) {
    writeDeltaEHeatmap(a.heatmap, c.dE76, c.width, c.height, float(a.heatmapMax));
  }
  if (!a.jndMap.empty()) {
    writeJndMap(a.jndMap, test, display, c.dE76, c.stats76.jndPercent);
  }

  if (a.json) {
    nlohmann::ordered_json j = {{"reference", a.reference}, {"test", a.test},      {"width", c.width},
                                {"height", c.height},       {"exposure", exposure}, {"tonemap", toneMappingName(toneMapping)},
                                {"display_transform", source}};
    j["pixels"] = c.pixels;
    j["mask"] = mask ? kMediumMaskChannel : "none";
    addDeltaEJson(j, c.stats76, c.stats2000);
    j["rel_mse"] = c.relMse;
    if (floor) {
      nlohmann::ordered_json n = {{"snapshot", a.snapshot},
                                  {"snapshot_spp", noise->snapshotSamples},
                                  {"reference_spp", noise->referenceSamples}};
      addDeltaEJson(n, floor->stats76, floor->stats2000);
      j["reference_noise"] = n;
    }
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "reference " << a.reference << "\n"
            << "test      " << a.test << "\n"
            << "          " << c.width << "x" << c.height << ", exposure " << formatFixed(exposure, 2)
            << " stops, tone mapping " << toneMappingName(toneMapping) << " (" << source << ")\n";
  if (mask) std::cout << "          over the " << c.pixels << " pixels that see the medium\n";
  std::cout << "\n";
  char header[160];
  std::snprintf(header, sizeof header, "%-8s %10s %10s %10s %10s\n", "", "mean", "p95", "max", "JND%");
  std::cout << header << tableRow("dE76", c.stats76) << tableRow("dE2000", c.stats2000)
            << "(p95: the value of rank ceil(0.95 n); JND%: pixels with dE > 2.3)\n"
            << "relMSE (linear, before the display transform) " << c.relMse << "\n";
  if (floor)
    std::cout << "reference noise (from " << a.snapshot << ", " << noise->snapshotSamples << " of its "
              << noise->referenceSamples << " samples): a noise-free image would read about JND "
              << formatFixed(floor->stats76.jndPercent, 2) << "% (dE76 mean " << formatFixed(floor->stats76.mean, 4) << "), "
              << formatFixed(floor->stats2000.jndPercent, 2) << "% in dE2000\n";
  if (!a.heatmap.empty()) std::cout << "wrote " << a.heatmap << " (dE76, 0 to " << formatFixed(a.heatmapMax, 2) << ")\n";
  if (!a.jndMap.empty()) std::cout << "wrote " << a.jndMap << " (dE76 > 2.3 in red)\n";
  return 0;
}

}  // namespace

Command addCompareCommand(CLI::App& app) {
  CLI::App* sub = app.add_subcommand(
      "compare", "Perceptual difference of TEST.exr from REF.exr: ΔE76 and ΔE2000 mean, p95, max and JND% (ΔE > 2.3)");
  auto a = std::make_shared<CompareArgs>();
  sub->add_option("REF.exr", a->reference, "Reference image (linear EXR)")->required();
  sub->add_option("TEST.exr", a->test, "Image to compare with it (same size)")->required();
  sub->add_option("--exposure", a->exposure,
                  "Exposure in stops applied to both before comparing (default: the EXRs' narval:exposure when "
                  "both record the same, else 0)");
  sub->add_option("--tonemap", a->tonemap,
                  "Tone mapping applied to both: none | reinhard | aces (default: the EXRs' narval:tone_mapping "
                  "when both record the same, else none)");
  sub->add_option("--heatmap", a->heatmap, "Write the ΔE76 heat map with a legend bar as PNG");
  sub->add_option("--heatmap-max", a->heatmapMax, "ΔE at the top of the heat map's scale (default 10)");
  sub->add_option("--jnd-map", a->jndMap,
                  "Write the JND map (pixels with ΔE76 > 2.3 in red over the test image) as PNG");
  sub->add_option("--reference-snapshot", a->snapshot,
                  "An earlier snapshot of REF's path-traced render (its first samples, before --resume "
                  "continued it): also report the JND% that REF's own noise alone would give");
  sub->add_flag("--medium-only", a->mediumOnly,
                "Judge only the pixels whose ray meets the medium (the renders' medium channel), so an empty "
                "background does not dilute the statistics");
  sub->add_flag("--json", a->json, "Print one JSON object instead of the table");
  return {sub, [a]() { return runCompare(*a); }};
}

}  // namespace narval
