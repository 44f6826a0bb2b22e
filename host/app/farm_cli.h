// farm_cli.h: what `narval farm` and `narval sweep --scheduler` share: writing a job and, with
// --submit, running it and reporting each task, the final step and the times.
#pragma once

#include <string>

#include "farm/farm_job.h"

namespace narval {

// This narval binary's absolute path (what the tasks run unless --narval names another).
std::string thisNarvalBinary();

// Writes `job`'s files for `scheduler` and says so (the line's start is the caller's), then with
// `submit` runs it (farm_run.h) and reports each task's time and the final step's on stdout; a
// failed task or final step is named on stderr with its log (lines prefixed "narval: WHO: ").
// Returns the exit code: 0, or 1 when something failed (nothing final written).
int runOrWriteFarmJob(const FarmJob& job, Scheduler scheduler, bool submit, int parallel, const std::string& who);

}  // namespace narval
