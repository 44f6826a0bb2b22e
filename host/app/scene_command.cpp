// narval scene: the scene format as the loader reads it. --resolved prints a scene as narval will
// render it, every default written out (what bench/ scripts read instead of restating defaults);
// --keys prints the loader's key table (docs/scene-format.md is checked against it).
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "app/commands.h"
#include "core/input_error.h"
#include "scene/scene.h"

namespace narval {
namespace {

struct SceneArgs {
  std::string scene;
  std::vector<std::string> sets;
  bool resolved = false, keys = false;
};

nlohmann::json keyTableJson() {
  nlohmann::json out = nlohmann::json::array();
  for (const SceneKey& k : sceneKeyTable())
    out.push_back({{"key", k.key}, {"type", k.type}, {"range", k.range}, {"defaults", k.defaults},
                   {"required", k.required}});
  return out;
}

}  // namespace

Command addSceneCommand(CLI::App& app) {
  CLI::App* sub = app.add_subcommand(
      "scene", "Print a scene as narval renders it (--resolved), or the scene format's keys (--keys)");
  auto a = std::make_shared<SceneArgs>();
  sub->add_option("SCENE.json", a->scene, "Scene file (with --resolved)");
  sub->add_option("--set", a->sets, "Override a scene value: dotted.path=value (repeatable)");
  sub->add_flag("--resolved", a->resolved, "Print the scene as JSON with every default filled in");
  sub->add_flag("--keys", a->keys, "Print every key of the scene format: type, default(s), range, required (JSON)");
  return {sub, [a]() {
            if (a->keys) {
              if (a->resolved || !a->scene.empty() || !a->sets.empty())
                throw inputError("--keys", "", "takes no scene, --set or --resolved (it lists the format's keys)");
              std::cout << keyTableJson().dump(2) << "\n";
              return 0;
            }
            if (!a->resolved) throw inputError("narval scene", "", "give --resolved (with a SCENE.json) or --keys");
            if (a->scene.empty()) throw inputError("--resolved", "", "needs a SCENE.json");
            const Scene scene = loadScene(a->scene, a->sets);
            for (const std::string& w : scene.warnings) std::cerr << "narval: warning: " << w << "\n";
            std::cout << scene.document.dump(2) << "\n";
            return 0;
          }};
}

}  // namespace narval
