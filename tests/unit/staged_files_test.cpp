// StagedFiles (host/core/staged_files.h): outputs land together or not at all.
#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/staged_files.h"
#include "test_support.h"

namespace narval {
namespace {

namespace fs = std::filesystem;

TEST(StagedFiles, NothingChangesUntilCommitAndAllChangesThen) {
  test::TempDir dir{"narval_staged"};
  const std::string exr = (dir.path() / "out.exr").string(), json = (dir.path() / "out.json").string();
  test::writeFile(exr, "old exr");
  test::writeFile(json, "old json");
  {
    StagedFiles staged;
    const std::string a = staged.stage(exr), b = staged.stage(json);
    EXPECT_EQ(fs::path(a).parent_path(), dir.path());  // beside the final path: one file system
    EXPECT_EQ(fs::path(a).extension(), ".exr");
    writeTextAtomic(a, "new exr");
    writeTextAtomic(b, "new json");
    EXPECT_EQ(test::readFile(exr), "old exr");
    EXPECT_EQ(test::readFile(json), "old json");
    staged.commit();
  }
  EXPECT_EQ(test::readFile(exr), "new exr");
  EXPECT_EQ(test::readFile(json), "new json");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"out.exr", "out.json"}));
}

// A step that fails after the first output was written: the old files stay, the staged one goes.
TEST(StagedFiles, AFailureOnTheWayLeavesTheOldFilesAlone) {
  test::TempDir dir{"narval_staged"};
  const std::string exr = (dir.path() / "out.exr").string(), json = (dir.path() / "out.json").string();
  test::writeFile(exr, "old exr");
  test::writeFile(json, "old json");
  try {
    StagedFiles staged;
    writeTextAtomic(staged.stage(exr), "new exr");
    throw std::runtime_error("the stats could not be computed");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(test::readFile(exr), "old exr");
  EXPECT_EQ(test::readFile(json), "old json");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"out.exr", "out.json"}));
  // A staged file that was never written: commit fails naming the final path, and changes nothing.
  StagedFiles missing;
  missing.stage(exr);
  EXPECT_THROW(missing.commit(), std::runtime_error);
  EXPECT_EQ(test::readFile(exr), "old exr");
}

}  // namespace
}  // namespace narval
