// scene_format_doc_test.cpp: docs/scene-format.md against the loader. Every key the loader looks
// up must be documented there, and every key documented must be one the loader looks up.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "core/input_error.h"
#include "scene/scene.h"
#include "test_support.h"

namespace narval {
namespace {

namespace fs = std::filesystem;

// Scenes that between them take every branch of the loader (both material types, a homogeneous
// and a gridded medium, both forms of emission, every primitive type, every renderer block, both
// Lobe Estimator variants). The loader asks for a key whether or not the scene gives it, so most
// keys come from any scene; the branches add the rest.
std::vector<std::string> schemaScenes(const std::string& vdb) {
  const std::string common = R"(
    "camera": {"position": [0, 0, -5], "lookAt": [0, 0, 0]},
    "background": [0.1, 0.1, 0.1])";
  const std::string lights = R"(
      {"type": "rectangle", "materialName": "light", "transform": {"position": [0, 0, 3]}},
      {"type": "point", "materialName": "light", "transform": {"position": [0, 3, 0]}},)";
  return {
      R"({"materials": [
            {"name": "light", "type": "emitter", "albedo": [1, 1, 1]},
            {"name": "fog", "type": "volume", "scattering": [1, 1, 1], "absorption": [0.1, 0.1, 0.1],
             "phaseFunction": "hg", "g": 0.5, "emission": {"color": [1, 0.5, 0.2], "scale": 2}}],
          "primitives": [)" + lights + R"(
            {"type": "volume", "materialName": "fog"}],
          "renderer": {"resolution": [8, 8], "algorithm": "raymarch",
                       "raymarch": {"multipleScattering": "cache", "msCache": {}}, "lightCache": {},
                       "pathtrace": {}},)" + common + "}",
      R"({"materials": [
            {"name": "light", "type": "emitter", "albedo": [1, 1, 1]},
            {"name": "fire", "type": "volume", "scattering": [1, 1, 1], "absorption": [1, 1, 1],
             "path": ")" + vdb + R"(", "grid": "density", "gridSpace": "file",
             "emission": {"temperature": "temperature", "temperatureOffset": 0, "temperatureScale": 1000}}],
          "primitives": [)" + lights + R"(
            {"type": "volume", "materialName": "fire"}],
          "renderer": {"resolution": [8, 8], "algorithm": "lobe", "lobe": {"variant": "eq7"}},)" + common + "}",
      R"({"materials": [
            {"name": "light", "type": "emitter", "albedo": [1, 1, 1]},
            {"name": "glow", "type": "volume", "scattering": [1, 1, 1], "absorption": [1, 1, 1],
             "path": ")" + vdb + R"(", "emission": {"grid": "heat", "color": [1, 1, 1]}}],
          "primitives": [)" + lights + R"(
            {"type": "volume", "materialName": "glow"}],
          "renderer": {"resolution": [8, 8], "algorithm": "lobe", "lobe": {"variant": "corrected"}},)" + common + "}",
  };
}

// The keys a markdown document names: the first cell of a table row, in backticks.
std::set<std::string> documentedKeys(const std::string& markdown) {
  std::set<std::string> keys;
  const std::regex row(R"(^\|\s*`([^`]+)`\s*\|)");
  std::istringstream in(markdown);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_search(line, m, row)) keys.insert(m[1]);
  }
  return keys;
}

std::string listOf(const std::set<std::string>& keys) {
  std::string out;
  for (const std::string& k : keys) out += "\n  " + k;
  return out.empty() ? " (none)" : out;
}

TEST(SceneFormatDoc, DocumentsExactlyTheKeysTheLoaderReads) {
  test::TempDir tmp{"narval_schema"};
  const std::string vdb = (fs::path(tmp.path()) / "grid.vdb").string();
  std::ofstream(vdb).put('\n');  // the loader only checks that a volume file exists

  std::set<std::string> asked;
  for (const std::string& text : schemaScenes(vdb)) {
    std::set<std::string> keys;
    try {
      parseScene(text, (fs::path(tmp.path()) / "scene.json").string(), {}, &keys);
    } catch (const InputError& e) {
      ADD_FAILURE() << "a schema scene failed to load: " << e.what();
    }
    asked.insert(keys.begin(), keys.end());
  }
  // The shipped scenes as well, where their data is present (they may use keys the above do not).
  for (const auto& entry : fs::directory_iterator(fs::path(NARVAL_SOURCE_DIR) / "scenes")) {
    if (entry.path().extension() != ".json") continue;
    try {
      std::set<std::string> keys;
      parseScene(test::readFile(entry.path()), entry.path().string(), {}, &keys);
      asked.insert(keys.begin(), keys.end());
    } catch (const InputError& e) {
      std::printf("[ scene format ] %s not read: %s\n", entry.path().filename().c_str(), e.what());
    }
  }
  const std::string docPath = std::string(NARVAL_SOURCE_DIR) + "/docs/scene-format.md";
  ASSERT_TRUE(fs::exists(docPath)) << docPath;
  const std::set<std::string> documented = documentedKeys(test::readFile(docPath));

  std::set<std::string> undocumented, unknown;
  for (const std::string& k : asked)
    if (!documented.count(k)) undocumented.insert(k);
  for (const std::string& k : documented)
    if (!asked.count(k)) unknown.insert(k);
  EXPECT_TRUE(undocumented.empty()) << "keys the loader reads that docs/scene-format.md does not document:"
                                    << listOf(undocumented);
  EXPECT_TRUE(unknown.empty()) << "keys docs/scene-format.md documents that the loader does not read:"
                               << listOf(unknown);
  EXPECT_GT(asked.size(), 60u);  // the schema scenes reached the loader's branches
  if (const char* dump = std::getenv("NARVAL_DUMP_SCENE_KEYS")) {
    std::ofstream out(dump);
    for (const std::string& k : asked) out << k << "\n";
  }
}

}  // namespace
}  // namespace narval
