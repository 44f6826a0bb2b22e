// What a render leaves on disk: every output path is proven writable before any work (exit 2,
// nothing rendered, existing files untouched, checked byte for byte), --stats-json makes its folder
// as -o does, and the EXR's header carries typed metadata other tools read (pbrt-v4's, OpenEXR's
// standard date) and narval's provenance (version, command line, --set overrides).
#include <gtest/gtest.h>

#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfStringAttribute.h>
#include <ImfStringVectorAttribute.h>

#include <cmath>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/cli_fixture.h"
#include "cli/fog_scene.h"
#include "image/image.h"

namespace narval {
namespace {

namespace fs = std::filesystem;

class OutputsCli : public test::CliFixture {
 protected:
  void SetUp() override {
    write("s.json", test::fogSceneJson(12, 8, 2));
    write("blocker", "a file where a folder would have to be");
    write("old.exr", "precious exr");
    write("old.json", "precious stats");
    std::filesystem::create_directory(dir_ / "folder.json");
  }
  // A refused command: exit 2, exactly `message`, and the folder as it was (the inputs, byte for byte).
  void expectRefused(const std::string& args, const std::string& message) {
    SCOPED_TRACE(args);
    const test::RunResult r = run(args);
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err, message);
    EXPECT_EQ(outputs({"s.json", "blocker", "old.exr", "old.json", "folder.json"}), std::vector<std::string>{});
    EXPECT_EQ(test::readFile(dir_ / "old.exr"), "precious exr");
    EXPECT_EQ(test::readFile(dir_ / "old.json"), "precious stats");
  }
};

TEST_F(OutputsCli, UnwritableOutputsAreRefusedBeforeAnyWork) {
  // The folder of an output cannot be made (a file is in the way), or the output is a folder.
  expectRefused("render s.json -o old.exr --stats-json blocker/stats.json",
                "narval: --stats-json: cannot write blocker/stats.json: cannot create its folder: Not a directory\n");
  expectRefused("render s.json -o blocker/x.exr --stats-json old.json",
                "narval: -o: cannot write blocker/x.exr: cannot create its folder: Not a directory\n");
  expectRefused("render s.json -o old.exr --stats-json folder.json",
                "narval: --stats-json: cannot write folder.json: it is a folder\n");
  writeExr((dir_ / "a.exr").string(), ImageRGB{2, 2, std::vector<float>(12, 0.5f)});
  const test::RunResult c = run("compare a.exr a.exr --heatmap blocker/heat.png");
  EXPECT_EQ(c.code, 2);
  EXPECT_EQ(c.err, "narval: --heatmap: cannot write blocker/heat.png: cannot create its folder: Not a directory\n");
  fs::remove(dir_ / "a.exr");
  expectRefused("sweep s.json --spp 1,2 -o blocker/sweep",
                "narval: -o: cannot write blocker/sweep/sweep.json: cannot create its folder: Not a directory\n");
}

TEST_F(OutputsCli, StatsJsonMakesItsFolderAndEverythingLandsTogether) {
  const test::RunResult r = run("render s.json -o imgs/fog.exr --stats-json stats/deep/fog.json");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* f : {"imgs/fog.exr", "imgs/fog.png", "stats/deep/fog.json"}) EXPECT_TRUE(fs::exists(dir_ / f)) << f;
  // No staging file is left beside the outputs.
  for (const char* folder : {"imgs", "stats/deep"})
    for (const auto& e : fs::directory_iterator(dir_ / folder))
      EXPECT_EQ(e.path().filename().string().find(".staged"), std::string::npos) << e.path();
  EXPECT_EQ(nlohmann::json::parse(test::readFile(dir_ / "stats/deep/fog.json"))["spp"], 2);
}

template <typename A>
const A* typed(const Imf::Header& h, const char* name) {
  return h.findTypedAttribute<A>(name);
}

TEST_F(OutputsCli, TheExrHeaderIsTypedAndSaysHowItWasMade) {
  const test::RunResult r =
      run("render s.json -o fog.exr --set renderer.seed=5 --set materials.1.g=0.25 --tonemap aces --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  Imf::InputFile file((dir_ / "fog.exr").c_str());
  const Imf::Header& h = file.header();
  // pbrt-v4's names, typed as pbrt-v4 writes them.
  ASSERT_NE(typed<Imf::IntAttribute>(h, "samplesPerPixel"), nullptr);
  EXPECT_EQ(typed<Imf::IntAttribute>(h, "samplesPerPixel")->value(), 2);
  ASSERT_NE(typed<Imf::FloatAttribute>(h, "renderTimeSeconds"), nullptr);
  EXPECT_GT(typed<Imf::FloatAttribute>(h, "renderTimeSeconds")->value(), 0.0f);
  // OpenEXR's standard date, and utcOffset in seconds (a whole number of quarter hours).
  ASSERT_NE(typed<Imf::StringAttribute>(h, "capDate"), nullptr);
  EXPECT_TRUE(std::regex_match(typed<Imf::StringAttribute>(h, "capDate")->value(),
                               std::regex(R"(\d{4}:\d\d:\d\d \d\d:\d\d:\d\d)")));
  ASSERT_NE(typed<Imf::FloatAttribute>(h, "utcOffset"), nullptr);
  EXPECT_EQ(std::fmod(typed<Imf::FloatAttribute>(h, "utcOffset")->value(), 900.0f), 0.0f);
  // narval's numbers as numbers.
  ASSERT_NE(typed<Imf::IntAttribute>(h, "narval:spp"), nullptr);
  EXPECT_EQ(typed<Imf::IntAttribute>(h, "narval:spp")->value(), 2);
  ASSERT_NE(typed<Imf::IntAttribute>(h, "narval:bounces"), nullptr);
  EXPECT_EQ(typed<Imf::IntAttribute>(h, "narval:bounces")->value(), 6);
  ASSERT_NE(typed<Imf::DoubleAttribute>(h, "narval:seed"), nullptr);
  EXPECT_EQ(typed<Imf::DoubleAttribute>(h, "narval:seed")->value(), 5.0);
  ASSERT_NE(typed<Imf::IntAttribute>(h, "narval:status"), nullptr);
  EXPECT_EQ(typed<Imf::IntAttribute>(h, "narval:status")->value(), 0);
  ASSERT_NE(typed<Imf::FloatAttribute>(h, "narval:exposure"), nullptr);
  EXPECT_EQ(typed<Imf::FloatAttribute>(h, "narval:exposure")->value(), 1.0f);  // fog_scene.h
  ASSERT_NE(typed<Imf::StringAttribute>(h, "narval:tone_mapping"), nullptr);
  EXPECT_EQ(typed<Imf::StringAttribute>(h, "narval:tone_mapping")->value(), "aces");
  // How it was made.
  ASSERT_NE(typed<Imf::StringAttribute>(h, "narval:version"), nullptr);
  EXPECT_EQ(typed<Imf::StringAttribute>(h, "narval:version")->value(), NARVAL_VERSION_TEXT);
  ASSERT_NE(typed<Imf::StringAttribute>(h, "narval:command_line"), nullptr);
  EXPECT_EQ(typed<Imf::StringAttribute>(h, "narval:command_line")->value(),
            std::string(NARVAL_BINARY) +
                " render s.json -o fog.exr --set renderer.seed=5 --set materials.1.g=0.25 --tonemap aces --quiet");
  ASSERT_NE(typed<Imf::StringVectorAttribute>(h, "narval:overrides"), nullptr);
  EXPECT_EQ(typed<Imf::StringVectorAttribute>(h, "narval:overrides")->value(),
            (std::vector<std::string>{"renderer.seed=5", "materials.1.g=0.25", "renderer.toneMapping=\"aces\""}));
}

}  // namespace
}  // namespace narval
