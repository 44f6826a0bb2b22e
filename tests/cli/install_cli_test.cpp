// `cmake --install` into a fresh prefix: the installed binary runs from there, outside the source
// and build trees (its kernels are embedded), renders a scene, and the reference pages come along.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "cli/cli_fixture.h"
#include "cli/fog_scene.h"

namespace narval {
namespace {

namespace fs = std::filesystem;

class InstallCli : public test::CliFixture {};

TEST_F(InstallCli, TheInstalledBinaryRendersFromItsPrefix) {
  const fs::path prefix = dir_ / "prefix";
  const test::RunResult install = runCommand("cmake --install '" + std::string(NARVAL_BUILD_DIR) + "' --prefix '" +
                                             prefix.string() + "'");
  ASSERT_EQ(install.code, 0) << install.out << install.err;
  const fs::path binary = prefix / "bin" / "narval";
  ASSERT_TRUE(fs::exists(binary));
  for (const char* page : {"scene-format.md", "cli.md", "realtime.md", "images/cloud_sun.png"})  // the README's links
    EXPECT_TRUE(fs::exists(prefix / "share" / "doc" / "narval" / "docs" / page)) << page;
  EXPECT_TRUE(fs::exists(prefix / "share" / "doc" / "narval" / "README.md"));

  const test::RunResult version = runCommand("'" + binary.string() + "' --version");
  EXPECT_EQ(version.code, 0);
  EXPECT_EQ(version.out, "narval " NARVAL_VERSION_TEXT "\n");

  fs::create_directories(dir_ / "elsewhere");
  write("elsewhere/fog.json", test::fogSceneJson(8, 6, 2));
  const test::RunResult render =
      runCommand("cd elsewhere && '" + binary.string() + "' render fog.json -o out/fog.exr --quiet");
  ASSERT_EQ(render.code, 0) << render.err;
  EXPECT_EQ(render.err, "");
  EXPECT_TRUE(fs::exists(dir_ / "elsewhere" / "out" / "fog.exr"));
  EXPECT_TRUE(fs::exists(dir_ / "elsewhere" / "out" / "fog.png"));
}

}  // namespace
}  // namespace narval
