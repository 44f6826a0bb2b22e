#include <chrono>
#include <iostream>

#include "app/commands.h"
#include "scene/input_error.h"
#include "volume/grid.h"

namespace narval {

Command addMakeCloudCommand(CLI::App& app) {
  CLI::App* sub = app.add_subcommand("make-cloud", "Write a procedural cumulus-like cloud as an OpenVDB file");
  struct Args {
    std::string out;
    int resolution = 128;
    uint32_t seed = 1;
  };
  auto a = std::make_shared<Args>();
  sub->add_option("OUT.vdb", a->out, "Output .vdb file")->required();
  sub->add_option("--resolution", a->resolution, "Voxels per side")->check(CLI::Range(8, 2048));
  sub->add_option("--seed", a->seed, "Shape seed");
  return {sub, [a]() {
            const auto t0 = std::chrono::steady_clock::now();
            DenseGrid grid = makeCloud(a->resolution, a->seed);
            writeVdb(a->out, grid, "density", 1.0f / float(a->resolution));
            const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            std::cout << "wrote " << a->out << " (" << a->resolution << "^3, seed " << a->seed << ", " << s
                      << " s)\n";
            return 0;
          }};
}

}  // namespace narval
