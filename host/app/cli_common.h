// cli_common.h: small pieces several subcommands share (option parsing, loading a scene's grid,
// writing text outputs).
#pragma once

#include <string>
#include <utility>

#include <CLI/CLI.hpp>

#include "cl/cl_runtime.h"
#include "core/atomic_file.h"  // writeTextAtomic
#include "render/scene_grids.h"  // loadSceneGrids
#include "scene/scene.h"
#include "volume/dense_grid.h"

namespace narval {

// "WxH" -> {W, H} (positive); `what` names the option in the InputError.
std::pair<int, int> parseSize(const std::string& text, const std::string& what);

// "A:B" -> {A, B}: the sample indices [A, B) of --samples, 0 <= A < B < 2^31; `what` names the
// option in the InputError.
std::pair<int, int> parseSampleRange(const std::string& text, const std::string& what);

// --resolution WxH as the scene override "renderer.resolution=[W,H]" (parseSize's errors name the flag).
std::string resolutionOverride(const std::string& text);

// Numeric checks whose messages read like the scene loader's ("--spp: must be at least 1, got 0"),
// not CLI11's range text with a 309-digit bound.
CLI::Validator atLeast(long long min);
CLI::Validator between(long long min, long long max);
// The first flag of argv that the parsed command does not take, with the flag it probably meant
// ("-spp", "--res" for --resolution, a near miss), as one line; "" when every flag is known. Asked
// when CLI11 refuses the arguments: it names a mistyped required flag as missing instead.
std::string unknownFlag(const CLI::App& app, int argc, char** argv);
CLI::Validator greaterThanZero();  // any finite number > 0

// --threads N on a subcommand that opens a device: PoCL's worker threads on a CPU device (it sets
// POCL_MAX_PTHREAD_COUNT before the OpenCL platform is first asked for, so it must be parsed before
// any device is opened); other OpenCL drivers ignore it.
void addThreadsOption(CLI::App* sub);

// Before any work: makes `path`'s folder (as the writers would) and proves a file can be created
// there (a temporary, removed again), so a render never runs only to fail at its last step.
// InputError "OPTION: cannot write PATH: REASON" (exit 2) otherwise; an existing file at `path` is
// not touched. An empty `path` (the option not given) passes.
void checkOutputWritable(const std::string& path, const std::string& option);

// Fails with "--local-size: WxH is N work-items; DEVICE takes at most M per group" (exit 2)
// when the shape cannot be launched on the device, instead of CL_INVALID_WORK_GROUP_SIZE later.
void checkLocalSize(int lx, int ly, const cl::Device& device, const std::string& deviceName);


}  // namespace narval
