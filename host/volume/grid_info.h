// grid_info.h: what a grid file holds, for `narval info` (framing a camera, choosing a density
// multiplier or a temperature scale without Python): each grid's name, value type, class, active
// voxels, index bounding box, voxel size, world bounds, value range and memory.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace narval {

struct GridInfo {
  std::string name;        // .vol: "" (one unnamed grid)
  std::string valueType;   // "float", "vec3s", ...
  std::string gridClass;   // "fog volume", "level set", "staggered", "unknown"; .vol: "fog volume"
  uint64_t activeVoxels = 0;
  std::array<int64_t, 3> indexMin{}, indexMax{};  // active voxels' index bounding box, inclusive
  std::array<double, 3> voxelSize{};              // world units per voxel along each index axis
  // World-space bounds of the active box's extent (voxel i covers [i - 0.5, i + 0.5] in the file's
  // index space) through the file's transform: what narval's "file" grid space places.
  std::array<double, 3> worldMin{}, worldMax{};
  bool hasRange = false;    // false: the type has no scalar range (or no active voxels)
  double valueMin = 0, valueMax = 0;  // float grids: the values; vec3 grids: their lengths
  uint64_t memoryBytes = 0;  // the sparse tree in memory (OpenVDB's memUsage); .vol: the dense floats
  uint64_t denseBytes = 0;   // what narval holds densely as floats over the index box (float grids)
};

// The grids of a .vdb or .vol file. Throws InputError naming the file on anything unreadable
// (a corrupt .vdb is read in a child process, as the loaders do: host/volume/dense_grid.h).
std::vector<GridInfo> inspectGridFile(const std::string& path);
std::vector<GridInfo> inspectVdb(const std::string& path);

// `narval info`'s outputs: one block of lines per grid, or a JSON array of objects.
std::string gridInfoText(const std::string& path, const std::vector<GridInfo>& grids);
std::string gridInfoJson(const std::string& path, const std::vector<GridInfo>& grids);
// gridInfoJson's inverse (the .vdb reader's child process passes its result back as that text).
std::vector<GridInfo> gridInfoFromJson(const std::string& json);

}  // namespace narval
