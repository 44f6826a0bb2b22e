// renderer.lightCache as a user drives it: --stats-json reports the cache (cells, bytes, slabs built,
// build time apart from the frames), --frames K builds it once, a light moved with --set changes the
// image and is built anew, and bad values are one line with exit 2 before any rendering.
#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "cli_fixture.h"
#include "exr_bits.h"
#include "image/image.h"

namespace narval::test {
namespace {

class LightCacheCli : public CliFixture {
 protected:
  void SetUp() override {
    ASSERT_EQ(run("make-cloud c.vdb --resolution 24 --seed 4").code, 0);
    // Two lights (a rectangle facing the cloud and a point light) over a cubic box; the dissertation's
    // march, whose shadows the light cache serves (the multiple-scattering cache is named where used).
    write("s.json", R"({
      "materials": [
        {"name": "light", "type": "emitter", "albedo": [6, 6, 6]},
        {"name": "bulb", "type": "emitter", "albedo": [3, 2, 1]},
        {"name": "cloud", "type": "volume", "scattering": [1, 1, 1], "absorption": [0.05, 0.05, 0.05],
         "phaseFunction": "hg", "g": 0.5, "density": 6, "path": "c.vdb"}
      ],
      "primitives": [
        {"name": "rect", "type": "rectangle", "transform": {"position": [0, 0, 4], "scale": [4, 4, 1]},
         "materialName": "light"},
        {"name": "point", "type": "point", "transform": {"position": [-2, 2, -1]}, "materialName": "bulb"},
        {"name": "box", "type": "volume", "transform": {"scale": [2, 2, 2]}, "materialName": "cloud"}
      ],
      "camera": {"position": [0, 0, -6], "lookAt": [0, 0, 0], "vfov": 30},
      "renderer": {"resolution": [24, 18], "algorithm": "raymarch", "lightCache": {"resolution": 32},
                   "raymarch": {"multipleScattering": "none"}},
      "background": [0.05, 0.05, 0.1]
    })");
  }
  nlohmann::json stats(const std::string& file) { return nlohmann::json::parse(readFile(dir_ / file)); }
};

TEST_F(LightCacheCli, FramesBuildTheCacheOnceAndTheStatsReportIt) {
  for (const char* algorithm : {"raymarch", "lobe"}) {
    SCOPED_TRACE(algorithm);
    const RunResult r = run(std::string("render s.json -o a.exr --frames 5 --stats-json a.json --algorithm ") + algorithm);
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json s = stats("a.json");
    EXPECT_EQ(s["light_cache_cells"], nlohmann::json::array({32, 32, 32}));  // a cubic box
    EXPECT_EQ(s["light_cache_builds"], 2);  // one slab per light, for five frames
    EXPECT_EQ(s["light_cache_bytes"], 33 * 33 * 33 * 2 * 4);
    EXPECT_GT(s["light_cache_ms"].get<double>(), 0.0);
    EXPECT_EQ(s["passes"], 5);
    EXPECT_NE(r.out.find("\nlight cache: 32x32x32 cells, 2 lights built in "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(" ms (not in the frame times)\n"), std::string::npos) << r.out;
  }
  // auto: 64 cells where a frame reads at least as many shadows per light as they have nodes (65³ =
  // 274625: 160x120 pixels x 30 steps = 576000), none below (24x18 x 30 = 12960: marched exactly).
  for (const auto& [size, cells] : {std::pair{"160x120", 64}, std::pair{"24x18", 0}}) {
    const RunResult a = run(std::string("render s.json -o c.exr --stats-json c.json --resolution ") + size +
                            " --set renderer.lightCache.resolution=\\\"auto\\\"");
    ASSERT_EQ(a.code, 0) << a.err;
    EXPECT_EQ(stats("c.json")["light_cache_cells"], nlohmann::json::array({cells, cells, cells})) << size;
  }
  const RunResult off = run("render s.json -o b.exr --stats-json b.json --set renderer.lightCache.resolution=0");
  ASSERT_EQ(off.code, 0) << off.err;
  EXPECT_EQ(stats("b.json")["light_cache_cells"], nlohmann::json::array({0, 0, 0}));
  EXPECT_EQ(stats("b.json")["light_cache_builds"], 0);
  EXPECT_EQ(stats("b.json")["light_cache_ms"], 0.0);
  EXPECT_EQ(off.out.find("light cache:"), std::string::npos);
}

// The ray marcher's multiple-scattering cache: built once before the frames and reported apart.
TEST_F(LightCacheCli, TheMultipleScatteringCacheIsBuiltOnceAndReported) {
  const RunResult r = run("render s.json -o m.exr --frames 3 --stats-json m.json --set "
                          "renderer.raymarch.multipleScattering=\\\"cache\\\" --set renderer.raymarch.msCache.layout=\\\"grid\\\" "
                          "--set renderer.raymarch.msCache.resolution=4 --set renderer.raymarch.msCache.paths=6");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json s = stats("m.json");
  EXPECT_EQ(s["ms_cache_cells"], nlohmann::json::array({4, 4, 4}));
  EXPECT_EQ(s["ms_cache_paths"], 6);
  EXPECT_EQ(s["ms_cache_builds"], 1);
  EXPECT_GT(s["ms_cache_ms"].get<double>(), 0.0);
  EXPECT_NE(r.out.find("\nmultiple-scattering cache: 4x4x4 cells, 6 paths per node in "), std::string::npos) << r.out;
  ASSERT_EQ(run("render s.json -o n.exr --stats-json n.json").code, 0);
  EXPECT_EQ(stats("n.json")["ms_cache_builds"], 0);  // none in this scene
  const ImageRGB cached = readExr((dir_ / "m.exr").string()), plain = readExr((dir_ / "n.exr").string());
  double sumCached = 0, sumPlain = 0;
  for (size_t i = 0; i < cached.rgb.size(); ++i) sumCached += cached.rgb[i], sumPlain += plain.rgb[i];
  EXPECT_GT(sumCached, sumPlain);  // light scattered more than once only adds
}

// --target-ms with --frames: the cache is built over the frames in what each leaves of the budget.
// A budget below any launch (0.001 ms) gives each frame one slice (a node at least): after 2 frames
// the cache is partly built, and the stats and the report say how much; after enough frames (5³ nodes,
// sweeps of 1, 1, 2, 2 paths: at most 500 slices) the image is the unbudgeted render's, bit for bit.
// Where the flag cannot apply: one line, exit 2, nothing written.
TEST_F(LightCacheCli, ABudgetBuildsTheCacheOverTheFramesToTheSameImage) {
  const std::string cache = " --set renderer.raymarch.multipleScattering=\\\"cache\\\" --set renderer.raymarch.msCache.layout=\\\"grid\\\" "
                            "--set renderer.raymarch.msCache.resolution=4 "
                            "--set renderer.raymarch.msCache.paths=6";
  RunResult r = run("render s.json -o p.exr --frames 2 --target-ms 0.001 --stats-json p.json" + cache);
  ASSERT_EQ(r.code, 0) << r.err;
  const double progress = stats("p.json")["ms_cache_progress"].get<double>();
  EXPECT_GT(progress, 0.0);
  EXPECT_LT(progress, 1.0);
  EXPECT_NE(r.out.find("% of the paths asked for) in "), std::string::npos) << r.out;
  r = run("render s.json -o b.exr --frames 1000 --target-ms 0.001 --stats-json b.json" + cache);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(stats("b.json")["ms_cache_progress"], 1.0);
  EXPECT_EQ(stats("b.json")["ms_cache_paths"], 6);
  ASSERT_EQ(run("render s.json -o a.exr" + cache).code, 0);
  expectSameBits((dir_ / "a.exr").string(), (dir_ / "b.exr").string(), {"R", "G", "B"});

  r = run("render s.json -o w.exr --frames 2 --target-ms 50 --algorithm lobe");
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.err, "narval: warning: s.json: renderer.raymarch: applies to algorithm \"raymarch\"; algorithm \"lobe\" "
                   "ignores it\nnarval: warning: --target-ms: only the ray marcher's multiple-scattering cache is built within "
                   "a frame budget; this scene's lobe has none, so every frame is drawn whole\n");
  r = run("render s.json -o x.exr --target-ms 50");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "narval: --target-ms requires --frames (see narval --help)\n");
  r = run("render s.json -o x.exr --frames 2 --target-ms 50 --algorithm pathtrace");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("\nnarval: --target-ms: only the real-time algorithms render frames in a budget; the algorithm "
                       "is pathtrace\n"),
            std::string::npos)
      << r.err;  // after the scene's warning that its light cache does not apply
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x.exr"));
}

// --ms-cache-out and --ms-cache-in (render/ms_cache_file.h). The grid layout's cache does not depend
// on the camera (its paths start uniformly on the sphere at world-space nodes), so a cache built at
// the scene's pose and read at poses orbited 5°, 30° and 90° about the look-at point gives, with no
// build at all, the very image a cache built there gives, bit for bit. A cache of 4 paths read
// with `paths` 8 goes on to 8 and equals a cache built to 8 in one go.
TEST_F(LightCacheCli, ACacheFileBuiltAtOnePoseDrawsAnother) {
  const std::string cache = " --set renderer.raymarch.multipleScattering=\\\"cache\\\" --set renderer.raymarch.msCache.layout=\\\"grid\\\" "
                            "--set renderer.raymarch.msCache.resolution=4 "
                            "--set renderer.raymarch.msCache.paths=";
  ASSERT_EQ(run("render s.json -o a.exr --ms-cache-out baked/a.mscache" + cache + "4").code, 0);
  ASSERT_TRUE(std::filesystem::exists(dir_ / "baked/a.mscache"));  // its folder made
  for (const double degrees : {5.0, 30.0, 90.0}) {
    SCOPED_TRACE(degrees);
    const double r = degrees * 3.14159265358979 / 180;
    const std::string pose = " --set camera.position=[" + std::to_string(6 * std::sin(r)) + ",0," +
                             std::to_string(-6 * std::cos(r)) + "]";
    RunResult read = run("render s.json -o read.exr --stats-json read.json --ms-cache-in baked/a.mscache" + cache + "4" + pose);
    ASSERT_EQ(read.code, 0) << read.err;
    EXPECT_EQ(stats("read.json")["ms_cache_ms"], 0.0);  // nothing built
    ASSERT_EQ(run("render s.json -o built.exr" + cache + "4" + pose).code, 0);
    expectSameBits((dir_ / "built.exr").string(), (dir_ / "read.exr").string(), {"R", "G", "B"});
  }
  ASSERT_EQ(run("render s.json -o more.exr --stats-json more.json --ms-cache-in baked/a.mscache" + cache + "8").code, 0);
  EXPECT_EQ(stats("more.json")["ms_cache_paths"], 8);
  ASSERT_EQ(run("render s.json -o eight.exr" + cache + "8").code, 0);
  expectSameBits((dir_ / "eight.exr").string(), (dir_ / "more.exr").string(), {"R", "G", "B"});
}

// A view cache file read at another pose (30° about the look-at point) is the prior of a camera move
// (kernels/shared/ms_cache_reproject.h): with a budget below any launch its first frame is drawn from
// the file's nodes reprojected, no new path yet (progress 0), and differs from the same frame without
// the file (nothing to draw but the first slices); without a budget the build runs to its paths and
// the image is that of a cache built there from nothing, bit for bit.
TEST_F(LightCacheCli, AViewCacheFileReadAtAnotherPoseIsDrawnReprojected) {
  const std::string view = " --set renderer.raymarch.multipleScattering=\\\"cache\\\" --set renderer.raymarch.msCache.layout=\\\"view\\\" "
                           "--set renderer.raymarch.msCache.tile=1 --set renderer.raymarch.msCache.paths=8";
  ASSERT_EQ(run("render s.json -o a.exr --ms-cache-out v.mscache" + view).code, 0);
  const std::string pose = " --set camera.position=[" + std::to_string(6 * std::sin(3.14159265358979 / 6)) + ",0," +
                           std::to_string(-6 * std::cos(3.14159265358979 / 6)) + "]";
  const std::string budget = " --frames 1 --target-ms 0.001";
  RunResult r = run("render s.json -o prior.exr --stats-json prior.json --ms-cache-in v.mscache" + view + pose + budget);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(stats("prior.json")["ms_cache_progress"], 0.0);
  EXPECT_EQ(stats("prior.json")["nan_pixels"], 0);
  ASSERT_EQ(run("render s.json -o empty.exr" + view + pose + budget).code, 0);
  EXPECT_GT(differingValues((dir_ / "prior.exr").string(), (dir_ / "empty.exr").string(), "R"), 24 * 18 / 4);
  ASSERT_EQ(run("render s.json -o read.exr --ms-cache-in v.mscache" + view + pose).code, 0);
  ASSERT_EQ(run("render s.json -o built.exr" + view + pose).code, 0);
  expectSameBits((dir_ / "built.exr").string(), (dir_ / "read.exr").string(), {"R", "G", "B"});
}

// A cache file is refused, one line naming the first setting that differs, exit 2, nothing written,
// for another medium, another light, another cache setting, another pose for the grid layout aimed at
// the camera (closure camera), and another image size for the view layout (its columns are the
// image's); so are what is not a cache file and the flags where no cache is drawn.
TEST_F(LightCacheCli, ACacheFileIsRefusedForAnotherSceneNamingWhatDiffers) {
  const std::string grid = " --set renderer.raymarch.multipleScattering=\\\"cache\\\" --set renderer.raymarch.msCache.layout=\\\"grid\\\" "
                            "--set renderer.raymarch.msCache.resolution=4 "
                           "--set renderer.raymarch.msCache.paths=2";
  const std::string view = " --set renderer.raymarch.multipleScattering=\\\"cache\\\" --set renderer.raymarch.msCache.layout=\\\"view\\\" "
                           "--set renderer.raymarch.msCache.tile=4 --set renderer.raymarch.msCache.paths=2";
  ASSERT_EQ(run("render s.json -o a.exr --ms-cache-out g.mscache" + grid).code, 0);
  ASSERT_EQ(run("render s.json -o a.exr --ms-cache-out v.mscache" + view).code, 0);
  ASSERT_EQ(run("render s.json -o a.exr --ms-cache-out c.mscache" + grid + " --set renderer.raymarch.msCache.closure=\\\"camera\\\"").code, 0);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--ms-cache-in g.mscache" + grid + " --set materials.2.density=5",
       "narval: --ms-cache-in: g.mscache: built for another scene or cache setting (materials[2].density is 6 in "
       "g.mscache, 5 in the scene)\n"},
      {"--ms-cache-in g.mscache" + grid + " --set primitives.1.transform.position=[-2,2,-2]",
       "narval: --ms-cache-in: g.mscache: built for another scene or cache setting (primitives[1].transform.position[2] "
       "is -1 in g.mscache, -2 in the scene)\n"},
      {"--ms-cache-in g.mscache" + grid + " --set renderer.raymarch.msCache.resolution=8",
       "narval: --ms-cache-in: g.mscache: built for another scene or cache setting (renderer.raymarch.msCache.resolution "
       "is 4 in g.mscache, 8 in the scene)\n"},
      {"--ms-cache-in c.mscache" + grid + " --set renderer.raymarch.msCache.closure=\\\"camera\\\" --set camera.position=[1,0,-6]",
       "narval: --ms-cache-in: c.mscache: built for another scene or cache setting (camera.position[0] is 0 in "
       "c.mscache, 1 in the scene)\n"},
      {"--ms-cache-in v.mscache" + view + " --resolution 12x9",
       "narval: --ms-cache-in: v.mscache: built for another scene or cache setting (renderer.resolution[0] is 24 in "
       "v.mscache, 12 in the scene)\n"},
      {"--ms-cache-in s.json" + grid,
       "narval: --ms-cache-in: s.json: not a multiple-scattering cache (narval render --ms-cache-out writes one)\n"},
      {"--ms-cache-in g.mscache --algorithm lobe",
       "narval: warning: s.json: renderer.raymarch: applies to algorithm \"raymarch\"; algorithm \"lobe\" ignores "
       "it\nnarval: --ms-cache-in: only the ray marcher's multiple-scattering cache is kept in a file; the scene has none "
       "(algorithm raymarch, renderer.raymarch.multipleScattering \"cache\")\n"},
      {"--ms-cache-out o.mscache",
       "narval: --ms-cache-out: only the ray marcher's multiple-scattering cache is kept in a file; the scene has none "
       "(algorithm raymarch, renderer.raymarch.multipleScattering \"cache\")\n"},
  };
  for (const auto& [flags, message] : cases) {
    const RunResult r = run("render s.json -o x.exr " + flags);
    EXPECT_EQ(r.code, 2) << flags;
    EXPECT_EQ(r.err, message) << flags;
  }
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x.exr"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "o.mscache"));
}

// The view layout: columns of 4x4 pixels over the 24x18 image (6 x 5, the last row 2 pixels tall),
// 8 slices by default, reported as such; a key of the other layout is named in one warning.
TEST_F(LightCacheCli, TheViewLayoutIsReportedAsColumnsRowsAndSlices) {
  const RunResult r = run("render s.json -o v.exr --stats-json v.json --set "
                          "renderer.raymarch.multipleScattering=\\\"cache\\\" --set renderer.raymarch.msCache.layout=\\\"view\\\" "
                          "--set renderer.raymarch.msCache.tile=4 --set renderer.raymarch.msCache.paths=4 "
                          "--set renderer.raymarch.msCache.resolution=8");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "narval: warning: s.json: renderer.raymarch.msCache.resolution: applies to layout \"grid\"; "
                   "\"view\" ignores it\n");
  const nlohmann::json s = stats("v.json");
  EXPECT_EQ(s["ms_cache_cells"], nlohmann::json::array({6, 5, 8}));
  EXPECT_EQ(s["ms_cache_layout"], "view");
  EXPECT_EQ(s["ms_cache_paths"], 4);
  EXPECT_EQ(s["nan_pixels"], 0);
  EXPECT_NE(r.out.find("multiple-scattering cache: 6x5x8 columns x rows x slices, 4 paths per node, filtered (sigma "
                       "1.5 columns, twiced) in "),
            std::string::npos)
      << r.out;
}

// The view layout's filter is reported with its settings (the text line and the stats); given
// with the grid layout, its keys are named in one warning each and the stats say it is off.
TEST_F(LightCacheCli, TheViewFilterIsReportedAndTheGridLayoutIgnoresIt) {
  const std::string cache =
      "--set renderer.raymarch.multipleScattering=\\\"cache\\\" --set renderer.raymarch.msCache.paths=4 "
      "--set renderer.raymarch.msCache.tile=4 --set renderer.raymarch.msCache.filter=1 ";
  RunResult r = run("render s.json -o v.exr --stats-json v.json " + cache +
                    "--set renderer.raymarch.msCache.layout=\\\"view\\\"");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  nlohmann::json s = stats("v.json");
  EXPECT_EQ(s["ms_cache_filter"], 1.0);
  EXPECT_EQ(s["ms_cache_filter_twicing"], true);  // by default wherever the filter is on
  EXPECT_EQ(s["nan_pixels"], 0);
  EXPECT_NE(r.out.find("multiple-scattering cache: 6x5x8 columns x rows x slices, 4 paths per node, filtered (sigma "
                       "1 columns, twiced) in "),
            std::string::npos)
      << r.out;
  r = run("render s.json -o t.exr --stats-json t.json " + cache +
          "--set renderer.raymarch.msCache.layout=\\\"view\\\" --set renderer.raymarch.msCache.filterTwicing=false");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_EQ(stats("t.json")["ms_cache_filter_twicing"], false);
  EXPECT_EQ(stats("t.json")["nan_pixels"], 0);
  EXPECT_NE(r.out.find(", filtered (sigma 1 columns) in "), std::string::npos) << r.out;
  r = run("render s.json -o g.exr --stats-json g.json " + cache + "--set renderer.raymarch.msCache.layout=\\\"grid\\\"");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err,
            "narval: warning: s.json: renderer.raymarch.msCache.tile: applies to layout \"view\"; \"grid\" "
            "ignores it\n"
            "narval: warning: s.json: renderer.raymarch.msCache.filter: applies to layout \"view\"; \"grid\" "
            "ignores it\n");
  s = stats("g.json");
  EXPECT_EQ(s["ms_cache_filter"], 0.0);
}

// Moving the point light is a new cache: the image changes where its light reaches the cloud.
TEST_F(LightCacheCli, MovingALightChangesTheImage) {
  ASSERT_EQ(run("render s.json -o a.exr --stats-json a.json").code, 0);
  const RunResult r =
      run("render s.json -o b.exr --stats-json b.json --set primitives.1.transform.position=[2,-2,-1]");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(stats("b.json")["light_cache_builds"], 2);
  const ImageRGB a = readExr((dir_ / "a.exr").string()), b = readExr((dir_ / "b.exr").string());
  int differing = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) differing += a.rgb[i] != b.rgb[i];
  EXPECT_GT(differing, int(a.rgb.size()) / 10);
}

// With the phase integrated exactly, the K×K points of areaLightSamples are not used: one warning
// line names the key, and the image is the one rendered without it, bit for bit. Control: on this
// scene (a 4x4 rectangle 4 units from the cloud) the same key does change the points' image.
TEST_F(LightCacheCli, ExactAreaLightPhaseIgnoresAreaLightSamplesWithAWarning) {
  const RunResult a = run("render s.json -o a.exr --set renderer.raymarch.areaLightPhase=\\\"exact\\\"");
  ASSERT_EQ(a.code, 0) << a.err;
  EXPECT_EQ(a.err, "");
  const RunResult b = run("render s.json -o b.exr --set renderer.raymarch.areaLightPhase=\\\"exact\\\" "
                          "--set renderer.raymarch.areaLightSamples=4");
  ASSERT_EQ(b.code, 0) << b.err;
  EXPECT_EQ(b.err, "narval: warning: s.json: renderer.raymarch.areaLightSamples: applies to areaLightPhase "
                   "\"points\"; \"exact\" ignores it\n");
  const ImageRGB ia = readExr((dir_ / "a.exr").string()), ib = readExr((dir_ / "b.exr").string());
  EXPECT_EQ(ia.rgb, ib.rgb);
  ASSERT_EQ(run("render s.json -o c.exr").code, 0);
  ASSERT_EQ(run("render s.json -o d.exr --set renderer.raymarch.areaLightSamples=4").code, 0);
  EXPECT_NE(readExr((dir_ / "c.exr").string()).rgb, readExr((dir_ / "d.exr").string()).rgb);
}

TEST_F(LightCacheCli, BadValuesAreOneLineAndExitTwo) {
  const struct {
    const char* set;
    const char* message;  // the whole of stderr: one line
  } cases[] = {
      {"renderer.lightCache.resolution=\\\"high\\\"",
       "narval: s.json: renderer.lightCache.resolution: expected \"auto\" or a number of cells (0 = off), got \"high\"\n"},
      {"renderer.lightCache.resolution=-3",
       "narval: s.json: renderer.lightCache.resolution: must be at least 0, got -3\n"},
      {"renderer.lightCache.resolution=2000",
       "narval: s.json: renderer.lightCache.resolution: must be at most 1024, got 2000\n"},
      {"renderer.lightCache.resolution=2.5",
       "narval: s.json: renderer.lightCache.resolution: expected an integer, got 2.5\n"},
      {"renderer.raymarch.minTransmittance=1",
       "narval: s.json: renderer.raymarch.minTransmittance: must be in [0, 1) (0 = never stop), got 1\n"},
      {"renderer.lobe.viewSteps=0", "narval: s.json: renderer.lobe.viewSteps: must be at least 1, got 0\n"},
      {"renderer.lobe.firstHitSteps=0", "narval: s.json: renderer.lobe.firstHitSteps: must be at least 1, got 0\n"},
      {"renderer.raymarch.octaves=4 --set renderer.raymarch.multipleScattering=\\\"cache\\\"",
       "narval: s.json: renderer.raymarch.octaves: applies only with multipleScattering \"octaves\"\n"},
      {"renderer.raymarch.multipleScattering=\\\"fog\\\"",
       "narval: s.json: renderer.raymarch.multipleScattering: unknown value \"fog\" (allowed: none, octaves, cache)\n"},
      {"renderer.raymarch.msCache.closure=\\\"vmf\\\"",
       "narval: s.json: renderer.raymarch.msCache.closure: unknown value \"vmf\" (allowed: linear, camera)\n"},
      {"renderer.raymarch.msCache.resolution=0",
       "narval: s.json: renderer.raymarch.msCache.resolution: must be at least 1, got 0\n"},
      {"renderer.raymarch.msCache.layout=\\\"froxels\\\"",
       "narval: s.json: renderer.raymarch.msCache.layout: unknown value \"froxels\" (allowed: grid, view)\n"},
      {"renderer.raymarch.shadowWeighting=\\\"cosine\\\"",
       "narval: s.json: renderer.raymarch.shadowWeighting: unknown value \"cosine\" (allowed: area, phase)\n"},
      {"renderer.raymarch.msCache.direct=true --set renderer.raymarch.msCache.layout=\\\"grid\\\"",
       "narval: s.json: renderer.raymarch.msCache.direct: needs closure \"camera\" or layout \"view\" (a node must "
       "hold the light scattered towards the camera)\n"},
      {"renderer.raymarch.msCache.tile=0", "narval: s.json: renderer.raymarch.msCache.tile: must be at least 1, got 0\n"},
      {"renderer.raymarch.msCache.tile=\\\"big\\\"",
       "narval: s.json: renderer.raymarch.msCache.tile: expected \"auto\" or pixels per column side, got \"big\"\n"},
      {"renderer.raymarch.quality=\\\"ultra\\\"",
       "narval: s.json: renderer.raymarch.quality: unknown value \"ultra\" (allowed: draft, interactive, high)\n"},
      {"renderer.raymarch.msCache.slices=1",
       "narval: s.json: renderer.raymarch.msCache.slices: must be at least 2, got 1\n"},
      {"renderer.raymarch.msCache.filter=-1",
       "narval: s.json: renderer.raymarch.msCache.filter: must be non-negative, got -1\n"},
      {"renderer.raymarch.msCache.filter=9",
       "narval: s.json: renderer.raymarch.msCache.filter: must be at most 8 (columns), got 9\n"},
      {"renderer.raymarch.msCache.filterTwicing=true --set renderer.raymarch.msCache.filter=0",
       "narval: s.json: renderer.raymarch.msCache.filterTwicing: needs filter > 0 (it filters the filter's "
       "residual)\n"},
      {"renderer.raymarch.msCache.filterTwicing=1",
       "narval: s.json: renderer.raymarch.msCache.filterTwicing: expected a boolean, got number\n"},
      {"renderer.raymarch.msCache.filter=\\\"wide\\\"",
       "narval: s.json: renderer.raymarch.msCache.filter: expected a number, got string\n"},
      {"renderer.raymarch.msCache.closure=\\\"linear\\\" --set renderer.raymarch.msCache.layout=\\\"view\\\"",
       "narval: s.json: renderer.raymarch.msCache.closure: must be \"camera\" with layout \"view\" (its paths aim at "
       "the camera)\n"},
      {"renderer.raymarch.shadowAreaSamples=0",
       "narval: s.json: renderer.raymarch.shadowAreaSamples: must be at least 1, got 0\n"},
      {"renderer.raymarch.areaLightSamples=17",
       "narval: s.json: renderer.raymarch.areaLightSamples: must be at most 16, got 17\n"},
      {"renderer.raymarch.areaLightPhase=\\\"disc\\\"",
       "narval: s.json: renderer.raymarch.areaLightPhase: unknown value \"disc\" (allowed: points, exact)\n"},
      {"renderer.lobe.areaLightPhase=3",
       "narval: s.json: renderer.lobe.areaLightPhase: expected a string, got number\n"},
      {"renderer.lobe.shadowAreaSamples=0", "narval: s.json: renderer.lobe.shadowAreaSamples: must be at least 1, got 0\n"},
      {"renderer.lobe.variant=\\\"eq8\\\"",
       "narval: s.json: renderer.lobe.variant: unknown value \"eq8\" (allowed: eq7, corrected)\n"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.set);
    const RunResult r = run(std::string("render s.json -o x.exr --set ") + c.set);
    EXPECT_EQ(r.code, 2);
    EXPECT_EQ(r.err, c.message);
    EXPECT_FALSE(std::filesystem::exists(dir_ / "x.exr"));
  }
}

}  // namespace
}  // namespace narval::test
