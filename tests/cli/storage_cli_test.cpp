// --storage (issue 6): the density grid as a 3D image or a float buffer, chosen on the command line
// as an override of renderer.storage; --stats-json reports what the kernels were built for.
#include <nlohmann/json.hpp>

#include "cli_fixture.h"
#include "image/image.h"

namespace narval::test {
namespace {

class StorageCli : public CliFixture {
 protected:
  void SetUp() override {
    ASSERT_EQ(run("make-cloud c.vdb --resolution 16 --seed 3").code, 0);
    write("s.json", R"({
      "materials": [
        {"name": "light", "type": "emitter", "albedo": [2, 2, 2]},
        {"name": "cloud", "type": "volume", "scattering": [1, 1, 1], "absorption": [0.1, 0.1, 0.1],
         "density": 4, "path": "c.vdb", "gridSpace": "unit"}
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
  std::string storageOf(const std::string& options) {
    const RunResult r = run("render s.json -o out.exr --stats-json st.json " + options);
    EXPECT_EQ(r.code, 0) << r.err;
    return nlohmann::json::parse(readFile(dir_ / "st.json"))["storage"];
  }
};

TEST_F(StorageCli, TheFlagOverridesTheSceneAndTheStatsSayWhatWasBuilt) {
  EXPECT_EQ(storageOf("--storage buffer"), "buffer");
  EXPECT_EQ(storageOf("--storage image"), "image");
  EXPECT_EQ(storageOf("--storage image --algorithm raymarch"), "image");
  // auto: the buffer on CPU devices (PoCL's is named pthread-...), the image on GPUs.
  if (run("devices").out.find("pthread") != std::string::npos)
    EXPECT_EQ(storageOf("--set renderer.storage=\"auto\" --device pthread"), "buffer");
}

TEST_F(StorageCli, AnUnknownStorageIsAUsageError) {
  const RunResult r = run("render s.json --storage texture");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: --storage: texture not in {auto,image,buffer,bricks}\n");
  EXPECT_FALSE(std::filesystem::exists(dir_ / "s.exr"));
}

// Sparse bricks (issue 6, item 6) give the buffer storage's pixels bit for bit (the same corner
// values through the same filter arithmetic, kernels/shared/grid.h), for the path tracer and the
// ray marcher alike, and --stats-json names the storage.
TEST_F(StorageCli, BricksRenderTheBuffersPixels) {
  for (const char* algorithm : {"pathtrace", "raymarch"}) {
    for (const char* storage : {"buffer", "bricks"}) {
      const RunResult r = run(std::string("render s.json -o ") + storage + ".exr --algorithm " + algorithm +
                              " --stats-json " + storage + ".json --storage " + storage);
      ASSERT_EQ(r.code, 0) << r.err;
      EXPECT_EQ(r.err.find("narval: warning"), std::string::npos) << r.err;
      EXPECT_EQ(nlohmann::json::parse(readFile(dir_ / (std::string(storage) + ".json")))["storage"], storage);
    }
    const ImageRGB bricks = readExr((dir_ / "bricks.exr").string()), buffer = readExr((dir_ / "buffer.exr").string());
    EXPECT_EQ(bricks.rgb, buffer.rgb) << algorithm;
    EXPECT_FALSE(bricks.rgb.empty());
  }
}

}  // namespace
}  // namespace narval::test
