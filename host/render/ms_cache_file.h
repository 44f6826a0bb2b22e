// ms_cache_file.h: the ray marcher's multiple-scattering cache on disk (`narval render --ms-cache-out`
// writes one, `--ms-cache-in` reads it): its nodes and progress (DeviceMsCache::snapshot) with the
// settings its paths depend on, so a scene is baked once and drawn from other camera poses. A cache
// that does not depend on the camera (layout grid, closure linear or hg) keeps no camera or image
// size in its settings; one aimed at the camera (layout view, closure camera) does, and is refused
// for another pose. Refused, as --resume is, by naming the first setting that differs.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "core/input_error.h"
#include "render/device_ms_cache.h"
#include "scene/scene.h"

namespace narval {

struct MsCacheFile {
  nlohmann::json settings;  // msCacheSettings of the scene it was built for
  MsCacheSnapshot snapshot;
};

// What the cache's paths depend on: renderSettings (render_exr.h: the scene less the display and
// real-time keys, less the light cache) with renderer.raymarch.multipleScattering and msCache (less
// paths, which a read cache may go on refining to, and the filter, which only reads the nodes), less
// the camera and the image size where the cache does not depend on them.
nlohmann::json msCacheSettings(const Scene& scene);

// The refusal of `flag` (--ms-cache-in, --ms-cache-out) for a scene that draws no such cache.
InputError msCacheFlagWithoutCache(const std::string& flag);

// Atomically; std::runtime_error "PATH: cannot write: ..." when it cannot.
void writeMsCacheFile(const std::string& path, const MsCacheFile& file);
// InputError naming `path` (and `flag`) when it cannot be read, is not a cache, is cut short, or was
// built for settings other than `scene`'s (the first that differs, named).
MsCacheFile readMsCacheFile(const std::string& path, const std::string& flag, const Scene& scene);

}  // namespace narval
