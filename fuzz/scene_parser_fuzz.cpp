// scene_parser_fuzz.cpp: libFuzzer target for the scene loader (host/scene/: JSON parse, --set
// overrides, validation, volume path resolution).
//
// Input: optional leading lines "--set PATH=VALUE" (each one override, as on the command line),
// then the scene's JSON text. The scene is named SCENE_DIR/scene.json, where SCENE_DIR is a folder
// in the temporary directory holding empty cloud.vol and cloud.vdb, so "path": "cloud.vol" resolves
// and the fuzzer gets past volume materials. parseScene only checks that a volume file exists
// (stat); it never opens or loads it.
//
// Contract: parseScene returns a scene or throws narval::InputError with one line "SCENE: ...";
// any other exception, crash, sanitizer report or leak is a finding (fuzz_check.h).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

#include <unistd.h>

#include "fuzz_check.h"
#include "scene/scene.h"

namespace {

std::string scenePath;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("narval-scene-fuzz-" + std::to_string(getuid()));
  fs::create_directories(dir);
  for (const char* name : {"cloud.vol", "cloud.vdb"}) std::ofstream(dir / name, std::ios::app);
  scenePath = (dir / "scene.json").string();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> overrides;
  size_t pos = 0;
  static const std::string kSet = "--set ";
  while (input.compare(pos, kSet.size(), kSet) == 0) {
    size_t eol = input.find('\n', pos);
    if (eol == std::string::npos) eol = input.size();
    overrides.push_back(input.substr(pos + kSet.size(), eol - pos - kSet.size()));
    pos = eol == input.size() ? eol : eol + 1;
  }
  try {
    const narval::Scene scene = narval::parseScene(input.substr(pos), scenePath, overrides);
    // What the renderer relies on once the loader has accepted a scene.
    int volumes = 0;
    for (const narval::Primitive& p : scene.primitives) {
      if (p.materialIndex < 0 || size_t(p.materialIndex) >= scene.materials.size())
        narval::fuzz::fail("primitive \"" + p.name + "\" has no material");
      volumes += p.type == narval::PrimitiveType::Volume;
    }
    if (volumes > 1) narval::fuzz::fail("more than one volume primitive accepted");
    if (scene.renderer.width < 1 || scene.renderer.height < 1) narval::fuzz::fail("empty image accepted");
  } catch (const narval::InputError& e) {
    narval::fuzz::checkInputError(e, scenePath);
  }
  return 0;
}
