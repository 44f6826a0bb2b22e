#include <algorithm>
#include <chrono>
#include <iostream>

#include "app/cli_common.h"
#include "app/commands.h"
#include "core/input_error.h"
#include "volume/dense_grid.h"

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
  sub->add_option("--resolution", a->resolution, "Voxels per side")->check(between(8, 2048));
  sub->add_option("--seed", a->seed, "Shape seed");
  return {sub, [a]() {
            checkOutputWritable(a->out, "OUT.vdb");  // its folder made, before any work
            const auto t0 = std::chrono::steady_clock::now();
            // Slab by slab (about 256 MiB each, whole leaf nodes): the dense cloud is never held
            // (a 1024^3 one would be 4 GiB, 2048^3 32 GiB). Same file as writeVdb(makeCloud(...)).
            const int r = a->resolution;
            const size_t slice = size_t(r) * size_t(r) * sizeof(float);
            const int slab = std::max(8, int((size_t(256) << 20) / slice) / 8 * 8);
            writeVdbSlabs(
                a->out, r, r, r, slab, [&](int z0, int z1, float* out) { makeCloudSlab(r, a->seed, z0, z1, out); },
                "density", 1.0f / float(r));
            const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            std::cout << "wrote " << a->out << " (" << a->resolution << "^3, seed " << a->seed << ", " << s
                      << " s)\n";
            return 0;
          }};
}

}  // namespace narval
