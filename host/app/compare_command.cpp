// compare_command.cpp: `narval compare REF.exr TEST.exr` (DESIGN.md, Perceptual metric): mean,
// 95th percentile and max of ΔE76 and ΔE2000 and the JND% (ΔE > 2.3) of each, as a table or as JSON;
// optionally the ΔE76 heat map and the JND map as PNGs.
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "app/commands.h"
#include "image/image.h"
#include "image/image_compare.h"
#include "scene/input_error.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

struct CompareArgs {
  std::string reference, test, tonemap = "none", heatmap, jndMap;
  double exposure = 0.0, heatmapMax = 10.0;  // double: the JSON echoes what was typed
  bool json = false;
};

const std::map<std::string, ToneMapping> kToneMappings = {
    {"none", ToneMapping::None}, {"reinhard", ToneMapping::Reinhard}, {"aces", ToneMapping::Aces}};

// An output picture must be a .png (its folder is created when it is written).
void checkPngOutput(const std::string& path, const std::string& option) {
  if (path.empty()) return;
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".png") throw inputError(option, "", "the output must be a .png file, got '" + path + "'");
}

void createParent(const std::string& path) {
  const fs::path p(path);
  if (p.has_parent_path()) fs::create_directories(p.parent_path());
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string tableRow(const char* name, const DeltaEStats& s) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%-8s %10.4f %10.4f %10.4f %9.2f%%\n", name, s.mean, s.p95, s.max, s.jndPercent);
  return buf;
}

int runCompare(const CompareArgs& a) {
  if (!std::isfinite(a.exposure)) throw inputError("--exposure", "", "expected a finite number of stops");
  if (!(a.heatmapMax > 0.0) || !std::isfinite(a.heatmapMax))
    throw inputError("--heatmap-max", "", "expected a positive number");
  checkPngOutput(a.heatmap, "--heatmap");
  checkPngOutput(a.jndMap, "--jnd-map");
  std::string tmName = a.tonemap;
  for (char& c : tmName) c = char(std::tolower(static_cast<unsigned char>(c)));
  const auto tm = kToneMappings.find(tmName);
  if (tm == kToneMappings.end())
    throw inputError("--tonemap", "", "expected none, reinhard or aces, got '" + a.tonemap + "'");

  DisplaySettings display;
  display.exposureStops = float(a.exposure);
  display.toneMapping = tm->second;
  const ImageRGB reference = readExr(a.reference);
  const ImageRGB test = readExr(a.test);
  const ImageComparison c = compareImages(reference, test, display, a.reference, a.test);

  if (!a.heatmap.empty()) {
    createParent(a.heatmap);
    writeDeltaEHeatmap(a.heatmap, c.dE76, c.width, c.height, float(a.heatmapMax));
  }
  if (!a.jndMap.empty()) {
    createParent(a.jndMap);
    writeJndMap(a.jndMap, test, display, c.dE76, c.stats76.jndPercent);
  }

  if (a.json) {
    const nlohmann::ordered_json j = {{"reference", a.reference},
                                      {"test", a.test},
                                      {"width", c.width},
                                      {"height", c.height},
                                      {"exposure", a.exposure},
                                      {"tonemap", tm->first},
                                      {"mean_dE76", c.stats76.mean},
                                      {"p95_dE76", c.stats76.p95},
                                      {"max_dE76", c.stats76.max},
                                      {"jnd76_pct", c.stats76.jndPercent},
                                      {"mean_dE2000", c.stats2000.mean},
                                      {"p95_dE2000", c.stats2000.p95},
                                      {"max_dE2000", c.stats2000.max},
                                      {"jnd2000_pct", c.stats2000.jndPercent}};
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "reference " << a.reference << "\n"
            << "test      " << a.test << "\n"
            << "          " << c.width << "x" << c.height << ", exposure " << fixed(a.exposure, 2)
            << " stops, tone mapping " << tm->first << "\n\n";
  char header[160];
  std::snprintf(header, sizeof header, "%-8s %10s %10s %10s %10s\n", "", "mean", "p95", "max", "JND%");
  std::cout << header << tableRow("dE76", c.stats76) << tableRow("dE2000", c.stats2000)
            << "(p95: the value of rank ceil(0.95 n); JND%: pixels with dE > 2.3)\n";
  if (!a.heatmap.empty()) std::cout << "wrote " << a.heatmap << " (dE76, 0 to " << fixed(a.heatmapMax, 2) << ")\n";
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
  sub->add_option("--exposure", a->exposure, "Exposure in stops applied to both before comparing (default 0)");
  sub->add_option("--tonemap", a->tonemap, "Tone mapping applied to both: none (default) | reinhard | aces");
  sub->add_option("--heatmap", a->heatmap, "Write the ΔE76 heat map with a legend bar as PNG");
  sub->add_option("--heatmap-max", a->heatmapMax, "ΔE at the top of the heat map's scale (default 10)");
  sub->add_option("--jnd-map", a->jndMap,
                  "Write the JND map (pixels with ΔE76 > 2.3 in red over the test image) as PNG");
  sub->add_flag("--json", a->json, "Print one JSON object instead of the table");
  return {sub, [a]() { return runCompare(*a); }};
}

}  // namespace narval
