// commands.h: the narval subcommands. Each registers its options on the CLI11 app and returns the
// function that runs it (exit code; errors propagate as exceptions to main).
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace narval {

struct Command {
  CLI::App* sub = nullptr;
  std::function<int()> run;
};

Command addRenderCommand(CLI::App& app);
Command addDevicesCommand(CLI::App& app);
Command addMakeCloudCommand(CLI::App& app);
Command addCompareCommand(CLI::App& app);
Command addSweepCommand(CLI::App& app);
Command addViewCommand(CLI::App& app);
Command addInfoCommand(CLI::App& app);
Command addMergeCommand(CLI::App& app);
Command addFarmCommand(CLI::App& app);
Command addSceneCommand(CLI::App& app);

}  // namespace narval
