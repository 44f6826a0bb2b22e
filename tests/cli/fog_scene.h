// fog_scene.h: the CLI tests' path-traced scene: a scattering slab lit from behind, multiple
// bounces, so samples differ from pixel to pixel and from pass to pass, and every word of the
// accumulator's fixed-point sums below the top one is busy.
#pragma once

#include <string>

namespace narval::test {

inline std::string fogSceneJson(int width, int height, long long spp) {
  return R"({
  "materials": [
    {"name": "light", "type": "emitter", "albedo": [3, 3, 3]},
    {"name": "fog", "type": "volume", "scattering": [0.9, 0.8, 0.7], "absorption": [0.1, 0.1, 0.1],
     "phaseFunction": "hg", "g": 0.5, "density": 2}
  ],
  "primitives": [
    {"name": "rect", "type": "rectangle", "transform": {"position": [0, 0, 3], "scale": [4, 4, 1]},
     "materialName": "light"},
    {"name": "box", "type": "volume", "transform": {"position": [0, 0, 0], "scale": [2, 2, 2]},
     "materialName": "fog"}
  ],
  "camera": {"position": [0, 0, -6], "lookAt": [0, 0, 0], "vfov": 30},
  "renderer": {"resolution": [)" +
         std::to_string(width) + ", " + std::to_string(height) + R"(], "spp": )" + std::to_string(spp) +
         R"(, "bounces": 6, "seed": 7, "exposure": 1}
})";
}

}  // namespace narval::test
