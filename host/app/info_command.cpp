#include <iostream>
#include <memory>
#include <string>

#include "app/commands.h"
#include "volume/grid_info.h"

namespace narval {

Command addInfoCommand(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("info", "Describe the grids of a .vdb or .vol file (bounds, voxel size, values)");
  auto path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  sub->add_option("FILE", *path, "A .vdb or .vol file")->required();
  sub->add_flag("--json", *json, "Print a JSON array, one object per grid");
  return {sub, [path, json]() {
            const std::vector<GridInfo> grids = inspectGridFile(*path);
            std::cout << (*json ? gridInfoJson(*path, grids) : gridInfoText(*path, grids));
            return 0;
          }};
}

}  // namespace narval
