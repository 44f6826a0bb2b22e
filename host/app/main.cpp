// narval: command line entry. Exit codes (DESIGN.md): 0 success, 2 bad input or usage, 1 any other
// failure, 130 interrupted. Errors are one line on stderr.
#include <cstdio>
#include <iostream>
#include <vector>

#include "app/cli_common.h"
#include "app/commands.h"
#include "cl/cl_runtime.h"
#include "core/input_error.h"
#include "render/render_exr.h"

int main(int argc, char** argv) {
  narval::recordCommandLine(argc, argv);  // for the EXRs' narval:command_line
  CLI::App app{"narval: OpenCL renderer for participating media"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("narval ") + NARVAL_VERSION);
  const std::vector<narval::Command> commands = {narval::addRenderCommand(app), narval::addDevicesCommand(app),
                                                 narval::addMakeCloudCommand(app), narval::addCompareCommand(app),
                                                 narval::addSweepCommand(app),
                                                 narval::addViewCommand(app), narval::addInfoCommand(app),
                                                 narval::addMergeCommand(app), narval::addFarmCommand(app),
                                                 narval::addSceneCommand(app)};
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ValidationError& e) {  // a value out of range: the message says what is allowed
    std::cerr << "narval: " << e.what() << "\n";
    return 2;
  } catch (const CLI::ParseError& e) {
    const std::string unknown = narval::unknownFlag(app, argc, argv);
    std::cerr << "narval: " << (unknown.empty() ? std::string(e.what()) + " (see narval --help)" : unknown) << "\n";
    return 2;
  }
  try {
    for (const narval::Command& c : commands)
      if (c.sub->parsed()) return c.run();
    return 2;
  } catch (const narval::InputError& e) {
    std::cerr << "narval: " << e.what() << "\n";
    return 2;
  } catch (const narval::ProgramBuildError& e) {
    std::cerr << "narval: " << e.what() << "\n";
    return 1;
  } catch (const cl::Error& e) {
    std::cerr << "narval: OpenCL error in " << e.what() << ": " << narval::clErrorName(e.err()) << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "narval: " << e.what() << "\n";
    return 1;
  }
}
