#include "cl/kernel_args.h"

#include <map>
#include <stdexcept>

namespace narval {
namespace {

// The arguments every narval kernel starts with (device_scene.h binds them; kernel_context.h's
// KERNEL_SCENE_ARGS): the scene, its lights, the density grid (an image, a buffer, or an unused int
// for a homogeneous medium), the majorant grid's cells, the emission grid (likewise) and the
// blackbody table.
const std::vector<std::string> kSceneArgs = {"scene", "lights", "grid", "grid_majorants", "emission_grid",
                                             "emission_table"};

std::vector<std::string> sceneArgsAnd(std::vector<std::string> more) {
  std::vector<std::string> all = kSceneArgs;
  all.insert(all.end(), more.begin(), more.end());
  return all;
}

const std::map<std::string, std::vector<std::string>>& lists() {
  static const std::map<std::string, std::vector<std::string>> all = {
      // counter_buf exists only in the -DCOUNTERS build, as its last argument.
      {"pathtrace", sceneArgsAnd({"accum", "sample_begin", "sample_count", "status_word",
                                  "counter_buf"})},
      {"raymarch", sceneArgsAnd({"march", "light_cache", "ms_cache", "light_cache_nodes", "ms_cache_nodes", "out",
                                 "status_word"})},
      {"lobe", sceneArgsAnd({"march", "lobe", "light_cache", "lobe_directions", "light_cache_nodes", "out",
                             "status_word"})},
      {"light_cache_build", sceneArgsAnd({"march", "light_cache", "light", "cache", "status_word"})},
      {"ms_cache_build", sceneArgsAnd({"ms_cache", "node_first", "node_count", "first", "count", "cache", "status_word"})},
      {"ms_cache_place_view", sceneArgsAnd({"ms_cache", "column_first", "column_count", "cache", "status_word"})},
      {"ms_cache_filter_view", {"ms_cache", "column_first", "column_count", "cache", "values", "residual", "filtered"}},
      {"ms_cache_reproject_view", {"scene", "ms_cache", "previous_cache", "previous_camera", "previous", "placed", "prior"}},
      {"ms_cache_blend_view", {"ms_cache", "target", "prior", "fresh", "drawn"}},
  };
  return all;
}

}  // namespace

const std::vector<std::string>& kernelArgumentNames(const std::string& kernel) {
  const auto found = lists().find(kernel);
  if (found == lists().end()) throw std::logic_error("no argument names listed for kernel '" + kernel + "'");
  return found->second;
}

std::vector<std::string> kernelsWithArgumentNames() {
  std::vector<std::string> names;
  for (const auto& kv : lists()) names.push_back(kv.first);
  return names;
}

NamedKernel::NamedKernel(const cl::Program& program, const std::string& name)
    : kernel_(program, name.c_str()), name_(name), args_(&kernelArgumentNames(name)) {}

cl_uint NamedKernel::index(const std::string& arg) const {
  if (args_)
    for (size_t i = 0; i < args_->size(); ++i)
      if ((*args_)[i] == arg) return cl_uint(i);
  std::string known;
  if (args_)
    for (const std::string& a : *args_) known += (known.empty() ? "" : ", ") + a;
  throw std::logic_error("kernel '" + name_ + "' has no argument '" + arg + "' (its arguments: " + known + ")");
}

}  // namespace narval
