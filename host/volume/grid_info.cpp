#include "volume/grid_info.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/input_error.h"
#include "volume/dense_grid.h"

namespace narval {
namespace {

using nlohmann::json;

// A number as people write it: %g (6 significant digits).
std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

template <typename T>
std::string triple(const std::array<T, 3>& v, const char* sep = ", ") {
  return num(double(v[0])) + sep + num(double(v[1])) + sep + num(double(v[2]));
}

std::string bytes(uint64_t n) {
  if (n < 1024) return std::to_string(n) + " B";
  const char* units[] = {"KiB", "MiB", "GiB", "TiB"};
  double v = double(n) / 1024;
  int u = 0;
  while (v >= 1024 && u < 3) {
    v /= 1024;
    ++u;
  }
  char b[32];
  std::snprintf(b, sizeof b, "%.1f %s", v, units[u]);
  return b;
}

}  // namespace

std::vector<GridInfo> inspectGridFile(const std::string& path) {
  const std::string ext = gridFileExtension(path);
  if (ext == ".vdb") return inspectVdb(path);
  if (ext != ".vol")
    throw inputError(path, "", "unknown volume file type '" +
                                   (ext.empty() ? std::string("(none)") : std::filesystem::path(path).extension().string()) +
                                   "' (narval reads .vdb and .vol)");
  // The dissertation's text format: one unnamed grid of floats, identity transform.
  const DenseGrid g = loadVol(path);
  GridInfo info;
  info.valueType = "float";
  info.gridClass = "fog volume";
  info.indexMax = {g.nx - 1, g.ny - 1, g.nz - 1};
  info.voxelSize = {1, 1, 1};
  info.worldMin = {0, 0, 0};  // voxel i covers [i, i + 1]: the index box [0, dims]
  info.worldMax = {double(g.nx), double(g.ny), double(g.nz)};
  info.denseBytes = info.memoryBytes = g.voxelCount() * sizeof(float);
  info.hasRange = !g.data.empty();
  if (info.hasRange) {
    const auto [lo, hi] = std::minmax_element(g.data.begin(), g.data.end());
    info.valueMin = *lo;
    info.valueMax = *hi;
  }
  // Every voxel of a .vol file is stored: active means non-zero here.
  info.activeVoxels = uint64_t(std::count_if(g.data.begin(), g.data.end(), [](float v) { return v != 0.0f; }));
  return {info};
}

std::string gridInfoText(const std::string& path, const std::vector<GridInfo>& grids) {
  std::string out = path + ": " + std::to_string(grids.size()) + (grids.size() == 1 ? " grid\n" : " grids\n");
  for (const GridInfo& g : grids) {
    out += "  " + (g.name.empty() ? std::string("(unnamed)") : g.name) + ": " + g.valueType + ", " + g.gridClass +
           ", " + std::to_string(g.activeVoxels) + " active voxels\n";
    if (g.activeVoxels == 0) continue;
    std::array<int64_t, 3> dims{};
    for (size_t a = 0; a < 3; ++a) dims[a] = g.indexMax[a] - g.indexMin[a] + 1;
    out += "    index box   [" + triple(g.indexMin) + "] to [" + triple(g.indexMax) + "] (" + triple(dims, " x ") +
           ")\n";
    out += "    voxel size  " + triple(g.voxelSize, " x ") + "\n";
    out += "    world box   [" + triple(g.worldMin) + "] to [" + triple(g.worldMax) + "]\n";
    if (g.hasRange)
      out += std::string("    values      ") + (g.valueType == "float" ? "" : "length ") + num(g.valueMin) + " to " +
             num(g.valueMax) + "\n";
    out += "    memory      " + bytes(g.memoryBytes) + (g.denseBytes ? ", dense in narval " + bytes(g.denseBytes) : "") +
           "\n";
  }
  return out;
}

std::string gridInfoJson(const std::string& path, const std::vector<GridInfo>& grids) {
  json all = json::array();
  for (const GridInfo& g : grids) {
    json j = {{"file", path},
              {"name", g.name},
              {"type", g.valueType},
              {"class", g.gridClass},
              {"active_voxels", g.activeVoxels},
              {"index_min", g.indexMin},
              {"index_max", g.indexMax},
              {"voxel_size", g.voxelSize},
              {"world_min", g.worldMin},
              {"world_max", g.worldMax},
              {"memory_bytes", g.memoryBytes},
              {"dense_bytes", g.denseBytes}};
    if (g.hasRange) {
      j["value_min"] = g.valueMin;
      j["value_max"] = g.valueMax;
    }
    all.push_back(j);
  }
  return all.dump(2) + "\n";
}

std::vector<GridInfo> gridInfoFromJson(const std::string& text) {
  std::vector<GridInfo> out;
  for (const json& j : json::parse(text)) {
    GridInfo g;
    g.name = j.at("name").get<std::string>();
    g.valueType = j.at("type").get<std::string>();
    g.gridClass = j.at("class").get<std::string>();
    g.activeVoxels = j.at("active_voxels").get<uint64_t>();
    g.indexMin = j.at("index_min").get<std::array<int64_t, 3>>();
    g.indexMax = j.at("index_max").get<std::array<int64_t, 3>>();
    g.voxelSize = j.at("voxel_size").get<std::array<double, 3>>();
    g.worldMin = j.at("world_min").get<std::array<double, 3>>();
    g.worldMax = j.at("world_max").get<std::array<double, 3>>();
    g.memoryBytes = j.at("memory_bytes").get<uint64_t>();
    g.denseBytes = j.at("dense_bytes").get<uint64_t>();
    g.hasRange = j.contains("value_min");
    if (g.hasRange) {
      g.valueMin = j.at("value_min").get<double>();
      g.valueMax = j.at("value_max").get<double>();
    }
    out.push_back(g);
  }
  return out;
}

}  // namespace narval
