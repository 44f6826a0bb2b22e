// farm_cli.cpp: writing and running farm jobs for `narval farm` and `narval sweep --scheduler`.
#include "app/farm_cli.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "core/shell_quote.h"
#include "farm/farm_run.h"

namespace fs = std::filesystem;

namespace narval {
namespace {

std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, s >= 100 ? "%.1f s" : "%.3g s", s);
  return buf;
}

}  // namespace

std::string thisNarvalBinary() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("narval") : self.string();
}

int runOrWriteFarmJob(const FarmJob& job, Scheduler scheduler, bool submit, int parallel, const std::string& who) {
  const std::vector<std::string> files = writeFarmFiles(job, scheduler);
  std::cout << "wrote";
  for (const std::string& f : files) std::cout << " " << fs::path(f).filename().string();
  std::cout << " in " << job.jobDir << "\n";
  if (!submit) {
    switch (scheduler) {
      case Scheduler::Slurm: std::cout << "submit with: sh " << shellQuoted(job.jobDir + "/submit.sh") << "\n"; break;
      case Scheduler::OpenJd:
        std::cout << "run with: " << shellJoined(openJdRunCommand(job))
                  << "\n(or submit the folder to Deadline Cloud: deadline bundle submit " << shellQuoted(job.jobDir) << ")\n";
        break;
      case Scheduler::Local: std::cout << "run with: sh " << shellQuoted(job.jobDir + "/run.sh") << "\n"; break;
    }
    return 0;
  }

  const FarmOutcome o = runFarm(job, scheduler, parallel, [&who](const std::string& line) {
    std::cout << who << ": " << line << "\n" << std::flush;
  });
  double taskSum = 0, longest = 0;
  int failed = 0;
  for (const FarmTaskOutcome& t : o.tasks) {
    const std::string what = "task " + std::to_string(t.task) + " " + job.tasks[size_t(t.task)].label;
    if (!t.ok) {
      ++failed;
      std::cerr << "narval: " << who << ": " << what << " failed: no output written; its log: " << job.logPath(t.task)
                << "\n";
      continue;
    }
    if (t.reused) {
      std::cout << what << ": output from an earlier run\n";
      continue;
    }
    // Wall time from task.sh's clock; OpenJD runs narval directly, so there only the render's.
    const double wall = t.wallSeconds >= 0 ? t.wallSeconds : t.renderSeconds;
    taskSum += wall;
    longest = std::max(longest, wall);
    if (t.wallSeconds >= 0)
      std::cout << what << ": " << seconds(t.wallSeconds) << " (rendering " << seconds(t.renderSeconds) << ")\n";
    else
      std::cout << what << ": rendering " << seconds(t.renderSeconds) << "\n";
  }
  const std::string step = job.stepNames[1];  // "Merge", "Collect"
  std::string lower = step;
  lower[0] = char(std::tolower(static_cast<unsigned char>(lower[0])));
  if (failed > 0) {
    std::cerr << "narval: " << who << ": " << failed << " of " << o.tasks.size() << " tasks failed; no " << lower
              << ", " << job.finalOutput << " not written. Run the same command again to run only the missing tasks.\n";
    return 1;
  }
  if (!o.finalDone) {
    std::cerr << "narval: " << who << ": the " << lower << " failed; its log: " << job.finalLogPath() << "\n";
    return 1;
  }
  std::cout << lower << ": " << seconds(o.finalSeconds) << "\n";
  std::cout << "wrote " << job.finalOutput << " (" << o.tasks.size() << " tasks"
            << (o.schedulerIds.empty() ? "" : "; slurm " + o.schedulerIds) << "): tasks " << seconds(taskSum)
            << " in all, longest " << seconds(longest) << ", " << seconds(o.wallSeconds) << " from submission to "
            << lower << "\n";
  return 0;
}

}  // namespace narval
