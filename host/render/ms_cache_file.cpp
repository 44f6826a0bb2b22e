#include "render/ms_cache_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>

#include "core/atomic_file.h"
#include "core/input_error.h"
#include "render/render_exr.h"
#include "shared/ms_cache.h"

namespace narval {
namespace {
const char kMagic[] = "narval multiple-scattering cache 1\n";

// The view layout's camera (MsCacheSnapshot::camera), as the floats and sizes of camera_params.
nlohmann::json cameraJson(const camera_params& c) {
  const auto v = [](const nv_float4& f) { return nlohmann::json::array({f.x, f.y, f.z}); };
  return {{"position", v(c.position)}, {"forward", v(c.forward)}, {"right", v(c.right)}, {"up", v(c.up)},
          {"tan_half_vfov", c.tan_half_vfov}, {"aspect", c.aspect}, {"lens_radius", c.lens_radius},
          {"focus_distance", c.focus_distance}, {"width", c.width}, {"height", c.height}};
}
camera_params cameraFromJson(const nlohmann::json& j) {
  const auto v = [&](const char* k) {
    const nlohmann::json& a = j.at(k);
    return nv_float4{a.at(0).get<float>(), a.at(1).get<float>(), a.at(2).get<float>(), 0.0f};
  };
  camera_params c{};
  c.position = v("position");
  c.forward = v("forward");
  c.right = v("right");
  c.up = v("up");
  c.tan_half_vfov = j.at("tan_half_vfov").get<float>();
  c.aspect = j.at("aspect").get<float>();
  c.lens_radius = j.at("lens_radius").get<float>();
  c.focus_distance = j.at("focus_distance").get<float>();
  c.width = j.at("width").get<int>();
  c.height = j.at("height").get<int>();
  return c;
}
}  // namespace

nlohmann::json msCacheSettings(const Scene& scene) {
  nlohmann::json doc = renderSettings(scene);
  const MsCacheSettings& mc = scene.renderer.raymarch.msCache;
  // The view layout's nodes hold their camera (a file read at another pose is reprojected); the grid
  // layout's aimed at the camera (closure camera) are for that pose only; the others for any.
  const bool view = mc.layout == MsCacheLayout::View, towardsCamera = view || mc.closure == MsCacheClosure::Camera;
  if (view || !towardsCamera) doc.erase("camera");
  if (!towardsCamera && doc.contains("renderer")) doc["renderer"].erase("resolution");
  const nlohmann::json& raymarch = scene.document.at("renderer").at("raymarch");
  nlohmann::json ms = raymarch.at("msCache");
  // Keys the nodes' running means do not depend on: the paths to go on to, and how a lookup reads
  // the nodes (the filter's copy is made again from the means).
  for (const char* k : {"paths", "filter", "filterTwicing"})
    ms.erase(k);
  doc["renderer"].erase("lightCache");  // the march's shadows, which the cache's paths do not read
  doc["renderer"].erase("algorithm");   // the ray marcher's, wherever the viewer starts
  doc["renderer"]["raymarch"] = {{"multipleScattering", raymarch.at("multipleScattering")}, {"msCache", ms}};
  return doc;
}

InputError msCacheFlagWithoutCache(const std::string& flag) {
  return inputError(flag, "", "only the ray marcher's multiple-scattering cache is kept in a file; the scene has none "
                              "(algorithm raymarch, renderer.raymarch.multipleScattering \"cache\")");
}

void writeMsCacheFile(const std::string& path, const MsCacheFile& file) {
  const MsCacheSnapshot& s = file.snapshot;
  const nlohmann::json header = {{"settings", file.settings},
                                 {"nodes", s.nodes.size() / MS_CACHE_STRIDE},
                                 {"stride", MS_CACHE_STRIDE},
                                 {"paths", s.paths},
                                 {"sweep_paths", s.sweepPaths},
                                 {"sweep_node", s.sweepNode},
                                 {"placed", s.placed},
                                 {"camera", cameraJson(s.camera)}};
  const std::string head = std::string(kMagic) + header.dump() + "\n";
  AtomicFile out(path);
  if (std::fwrite(head.data(), 1, head.size(), out.file()) != head.size() ||
      std::fwrite(s.nodes.data(), sizeof(float), s.nodes.size(), out.file()) != s.nodes.size())
    out.fail(std::strerror(errno));
  out.commit();
}

MsCacheFile readMsCacheFile(const std::string& path, const std::string& flag, const Scene& scene) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw inputError(flag, path, std::string("cannot read: ") + std::strerror(errno));
  std::string magic(sizeof kMagic - 1, '\0'), line;
  in.read(magic.data(), std::streamsize(magic.size()));
  const InputError notACache =
      inputError(flag, path, "not a multiple-scattering cache (narval render --ms-cache-out writes one)");
  if (!in || magic != kMagic || !std::getline(in, line)) throw notACache;
  MsCacheFile f;
  size_t nodes = 0;
  try {
    const nlohmann::json h = nlohmann::json::parse(line);
    if (h.at("stride").get<int>() != MS_CACHE_STRIDE) throw notACache;
    f.settings = h.at("settings");
    nodes = h.at("nodes").get<size_t>();
    MsCacheSnapshot& s = f.snapshot;
    s.paths = h.at("paths").get<int>();
    s.sweepPaths = h.at("sweep_paths").get<int>();
    s.sweepNode = h.at("sweep_node").get<uint64_t>();
    s.placed = h.at("placed").get<uint64_t>();
    if (h.contains("camera")) s.camera = cameraFromJson(h.at("camera"));  // absent before view files held it
  } catch (const nlohmann::json::exception&) {
    throw notACache;
  }
  const std::string mine = msCacheSettings(scene).dump(), theirs = f.settings.dump();
  if (mine != theirs)
    throw inputError(flag, path,
                     "built for another scene or cache setting (" +
                         settingsDifference(theirs, path, mine, "the scene") + ")");
  if (nodes > std::numeric_limits<size_t>::max() / (MS_CACHE_STRIDE * sizeof(float))) throw notACache;
  f.snapshot.nodes.resize(nodes * MS_CACHE_STRIDE);
  in.read(reinterpret_cast<char*>(f.snapshot.nodes.data()), std::streamsize(f.snapshot.nodes.size() * sizeof(float)));
  if (size_t(in.gcount()) != f.snapshot.nodes.size() * sizeof(float) || in.peek() != EOF)
    throw inputError(flag, path,
                     "cut short or overlong: " + std::to_string(nodes) + " nodes of " + std::to_string(MS_CACHE_STRIDE) +
                         " floats expected");
  return f;
}

}  // namespace narval
