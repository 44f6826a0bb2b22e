// renderer.storage "bricks" from the command line (issue 6, item 6): a generated cloud rendered
// from sparse bricks gives the buffer storage's pixels, bit for bit, and --stats-json says which
// storage the kernels were built for. (The --storage flag's list of values is render_command.cpp's;
// --set reaches renderer.storage whatever that list holds.)
#include <nlohmann/json.hpp>

#include "cli_fixture.h"
#include "image/image.h"

namespace narval::test {
namespace {

class BricksCli : public CliFixture {
 protected:
  void SetUp() override {
    ASSERT_EQ(run("make-cloud c.vdb --resolution 24 --seed 5").code, 0);
    write("s.json", R"({
      "materials": [
        {"name": "light", "type": "emitter", "albedo": [2, 2, 2]},
        {"name": "cloud", "type": "volume", "scattering": [1, 1, 1], "absorption": [0.1, 0.1, 0.1],
         "density": 4, "path": "c.vdb"}
      ],
      "primitives": [
        {"name": "rect", "type": "rectangle", "transform": {"position": [0, 0, 3], "scale": [4, 4, 1]},
         "materialName": "light"},
        {"name": "box", "type": "volume", "transform": {"scale": [2, 2, 2]}, "materialName": "cloud"}
      ],
      "camera": {"position": [0, 0, -6], "lookAt": [0, 0, 0], "vfov": 30},
      "renderer": {"resolution": [8, 8], "spp": 2}
    })");
  }
};

TEST_F(BricksCli, BricksRenderTheBuffersPixels) {
  for (const char* algorithm : {"pathtrace", "raymarch"}) {
    for (const char* storage : {"buffer", "bricks"}) {
      const RunResult r = run(std::string("render s.json -o ") + storage + ".exr --algorithm " + algorithm +
                              " --stats-json " + storage + ".json --set renderer.storage=\\\"" + storage + "\\\"");
      ASSERT_EQ(r.code, 0) << r.err;
      EXPECT_EQ(r.err.find("narval: warning"), std::string::npos) << r.err;  // (PoCL may print its compiler's)
      EXPECT_EQ(nlohmann::json::parse(readFile(dir_ / (std::string(storage) + ".json")))["storage"], storage);
    }
    const ImageRGB bricks = readExr((dir_ / "bricks.exr").string()), buffer = readExr((dir_ / "buffer.exr").string());
    EXPECT_EQ(bricks.rgb, buffer.rgb) << algorithm;
    EXPECT_FALSE(bricks.rgb.empty());
  }
}

}  // namespace
}  // namespace narval::test
