#include "render/scene_grids.h"

#include "core/input_error.h"

namespace narval {

SceneGrids loadSceneGrids(const Scene& scene, SceneGridStorage& storage) {
  for (const Primitive& p : scene.primitives) {
    if (p.type != PrimitiveType::Volume) continue;
    const Material& m = scene.materials.at(size_t(p.materialIndex));
    if (m.path.empty()) return {};
    storage.density = loadGrid(m.path, m.gridName);
    const Emission& e = m.emission;
    if (e.grid.empty()) return {&storage.density};
    if (e.grid == m.gridName) return {&storage.density, &storage.density};
    const std::string key = "materials[" + std::to_string(p.materialIndex) + "].emission." +
                            (e.kind == EmissionKind::Blackbody ? "temperature" : "grid");
    const std::string ext = gridFileExtension(m.path);
    if (ext != ".vdb")
      throw inputError(scene.sourcePath, key, "names a grid, but " + m.path + " is not an OpenVDB file (a " +
                                                  ext + " file holds one unnamed grid)");
    try {
      storage.emission = loadGrid(m.path, e.grid);
    } catch (const InputError& error) {
      // The loader names the file and its own key ("grid"); this grid is the emission's.
      std::string what = error.what();
      const std::string prefix = m.path + ": grid: ";
      if (what.compare(0, prefix.size(), prefix) == 0) what = m.path + ": " + what.substr(prefix.size());
      throw inputError(scene.sourcePath, key, what);
    }
    return {&storage.density, &storage.emission};
  }
  return {};
}

}  // namespace narval
