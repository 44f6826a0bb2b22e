#include "render/render_stats.h"

#include <sstream>

#include <nlohmann/json.hpp>

#include "shared/structs.h"

namespace narval {

nlohmann::json framesJson(const FrameTimings& f) {
  return {{"frames", f.count},
          {"first_frame_ms", {{"kernel", f.firstKernelMs}, {"wall", f.firstWallMs}}},
          {"median", f.medianKernelMs},
          {"min", f.minKernelMs},
          {"max", f.maxKernelMs},
          {"wall", {{"median", f.medianWallMs}, {"min", f.minWallMs}, {"max", f.maxWallMs}}}};
}

void addJson(nlohmann::json& j, const CollisionCounts& c) {
  if (!c.on) return;
  j["collisions_tentative"] = c.tentative;
  j["collisions_real"] = c.real;
  j["density_lookups"] = c.densityLookups;
}

void addJson(nlohmann::json& j, const LightCacheStats& c) {
  j["light_cache_cells"] = {c.cells[0], c.cells[1], c.cells[2]};
  j["light_cache_bytes"] = c.bytes;
  j["light_cache_builds"] = c.builds;
  j["light_cache_ms"] = c.ms;
}

void addJson(nlohmann::json& j, const MsCacheStats& c) {
  j["ms_cache_cells"] = {c.cells[0], c.cells[1], c.cells[2]};
  j["ms_cache_layout"] = c.view ? "view" : "grid";
  j["ms_cache_paths"] = c.paths;
  j["ms_cache_progress"] = c.progress;
  j["ms_cache_builds"] = c.builds;
  j["ms_cache_ms"] = c.ms;
  j["ms_cache_filter"] = c.filter;
  j["ms_cache_filter_twicing"] = c.filterTwicing;
}

nlohmann::json statsJson(const RenderStats& s, uint32_t seed, const std::string& scenePath) {
  nlohmann::json j = {{"algorithm", s.algorithm},
                      {"device", s.device},
                      {"storage", s.storage},
                      {"grid_bytes", s.gridBytes},
                      {"bricks", {{"total", s.bricks}, {"occupied", s.bricksOccupied}}},
                      {"width", s.width},
                      {"height", s.height},
                      {"spp", s.spp},
                      {"sample_begin", s.sampleBegin},
                      {"spp_requested", s.sppRequested},
                      {"resumed_from_spp", s.resumedFromSpp},
                      {"interrupted", s.interrupted},
                      {"bounces", s.bounces},
                      {"seed", seed},
                      {"seconds", s.seconds},
                      {"kernel_seconds", s.kernelSeconds},
                      {"build_seconds", s.buildSeconds},
                      {"samples_per_second", s.samplesPerSecond},
                      {"passes", s.passes},
                      {"nan_pixels", s.nanPixels},
                      {"program_from_cache", s.programFromCache},
                      {"majorant", s.majorant},
                      {"majorant_cells", {s.majorantCells[0], s.majorantCells[1], s.majorantCells[2]}},
                      {"status",
                       {{"nan", (s.status & STATUS_NAN) != 0},
                        {"negative_pdf", (s.status & STATUS_NEGATIVE_PDF) != 0},
                        {"iteration_cap", (s.status & STATUS_ITERATION_CAP) != 0},
                        {"unknown_kind", (s.status & STATUS_UNKNOWN_KIND) != 0}}},
                      {"scene", scenePath}};
  addJson(j, s.counters);
  addJson(j, s.lightCache);
  addJson(j, s.msCache);
  return j;
}

std::string describe(const LightCacheStats& c) {
  if (c.builds == 0) return "";
  std::ostringstream line;
  line << "light cache: " << c.cells[0] << "x" << c.cells[1] << "x" << c.cells[2] << " cells, " << c.builds
       << (c.builds == 1 ? " light" : " lights") << " built in " << c.ms << " ms (not in the frame times)\n";
  return line.str();
}

std::string describe(const MsCacheStats& c) {
  if (c.builds == 0) return "";
  std::ostringstream line;
  line << "multiple-scattering cache: " << c.cells[0] << "x" << c.cells[1] << "x" << c.cells[2]
       << (c.view ? " columns x rows x slices, " : " cells, ") << c.paths << " paths per node";
  if (c.progress < 1) line << " (" << int(c.progress * 100) << "% of the paths asked for)";
  if (c.filter > 0)
    line << ", filtered (sigma " << c.filter << " columns"
         << (c.filterTwicing ? ", twiced" : "") << ")";
  line << " in " << c.ms << " ms (not in the frame times)\n";
  return line.str();
}

}  // namespace narval
