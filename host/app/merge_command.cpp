// merge_command.cpp: `narval merge PART.exr... -o OUT.exr` (render/render_merge.h).
#include <filesystem>
#include <iostream>
#include <memory>

#include "app/cli_common.h"
#include "app/commands.h"
#include "core/input_error.h"
#include "core/staged_files.h"
#include "image/image.h"
#include "render/render_common.h"
#include "render/render_merge.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

struct MergeArgs {
  std::vector<std::string> parts;
  std::string out;
  bool quiet = false;
};

int runMerge(const MergeArgs& a) {
  const fs::path out(a.out);
  if (out.extension() != ".exr") throw inputError("-o", "", "the output must be an .exr file, got '" + a.out + "'");
  const fs::path png = fs::path(out).replace_extension(".png");
  std::error_code ec;
  for (const std::string& p : a.parts)
    if (fs::weakly_canonical(p, ec) == fs::weakly_canonical(out, ec))
      throw inputError("-o", "", a.out + " is one of the parts; write the merge to another file");
  checkOutputWritable(out.string(), "-o");
  checkOutputWritable(png.string(), "-o");

  const MergedRender m = mergeRenderParts(a.parts);
  const RenderStats& s = m.result.stats;
  StagedFiles staged;
  writeRenderExr(staged.stage(out.string()), m.result, m.identity);
  writePng(staged.stage(png.string()), m.result.image, m.identity.exposure, m.identity.toneMapping);
  staged.commit();
  for (const std::string& w : statusWarnings(s.status)) std::cerr << "narval: warning: " << w << "\n";
  if (!a.quiet)
    std::cout << "wrote " << out.string() << " and " << png.string() << " (" << s.width << "x" << s.height << ", "
              << s.spp << " spp from " << a.parts.size() << (a.parts.size() == 1 ? " part" : " parts") << ", "
              << s.seconds << " s of rendering)\n";
  return 0;
}

}  // namespace

Command addMergeCommand(CLI::App& app) {
  CLI::App* sub = app.add_subcommand(
      "merge",
      "Add path-traced renders of disjoint sample ranges (render --samples A:B) into the render of their union "
      "[0, N): the bits of one --spp N render");
  auto a = std::make_shared<MergeArgs>();
  sub->add_option("PART.exr", a->parts, "The parts, in any order; together they must hold samples [0, N) exactly")
      ->required();
  sub->add_option("-o,--output", a->out, "Output .exr (the .png goes beside it)")->required();
  sub->add_flag("-q,--quiet", a->quiet, "Print only errors and warnings");
  return {sub, [a]() { return runMerge(*a); }};
}

}  // namespace narval
