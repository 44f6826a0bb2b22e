// narval view, run headless from scripts under Xvfb (scripts/setup.sh installs it with Mesa): what P
// writes is what `narval render` draws from the JSON beside it, bit for bit, for all three
// algorithms; the screenshot is that frame's PNG byte for byte; frames are counted per resolution
// while the camera moves; bad input is one line and exit 2 before any window opens.
#include <cstdlib>
#include <cmath>
#include <cstring>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "cli/cli_fixture.h"
#include "cli/exr_bits.h"
#include "cli/fog_scene.h"
#include "image/image.h"

namespace narval::test {
namespace {

namespace fs = std::filesystem;

// Xvfb with a 24-bit screen: the window's pixels are the frame's, exactly.
const std::string kXvfb = "xvfb-run -a -s '-screen 0 640x480x24'";

class ViewCli : public CliFixture {
 protected:
  void SetUp() override {
    ASSERT_EQ(std::system("command -v xvfb-run > /dev/null"), 0)
        << "xvfb-run is missing: scripts/setup.sh installs xvfb (the viewer's tests need a display)";
    // The fog scene as the ray marcher with a multiple-scattering cache of the grid layout, 64 paths a node.
    nlohmann::json scene = nlohmann::json::parse(fogSceneJson(64, 48, 12));
    scene["renderer"]["algorithm"] = "raymarch";
    scene["renderer"]["raymarch"] = {{"multipleScattering", "cache"},
                                     {"msCache", {{"layout", "grid"}, {"resolution", 4}, {"paths", 64}}}};
    write("fog.json", scene.dump(2));
  }
  nlohmann::json stats(const std::string& name) { return nlohmann::json::parse(readFile(dir_ / name)); }
  void expectSamePixels(const std::string& a, const std::string& b, const std::vector<std::string>& channels) {
    expectSameBits((dir_ / a).string(), (dir_ / b).string(), channels);
  }
};

TEST_F(ViewCli, SnapshotsAreWhatRenderDrawsFromTheirJson) {
  write("moves.txt",
        "frames 1\n"
        "drag left 25 -8\n"
        "frames 1\n"
        "key P            # a snapshot completes the cache first (here the budget already has)\n"
        "frames 1\n"
        "key 3\n"
        "scroll 1.5\n"
        "frames 1\n"
        "key ]\n"
        "key P\n"
        "frames 1\n"
        "key 1\n"
        "drag right 6 -4\n"
        "frames 2\n"
        "key ]\n"
        "key ]\n"
        "frames 2\n"
        "key P\n"
        "frames 1\n");
  const RunResult v = run("view fog.json --script moves.txt --screenshot shot.png --target-ms 1e9 --output-dir snaps "
                          "--stats-json stats.json",
                          kXvfb);
  ASSERT_EQ(v.code, 0) << v.err;
  // Path tracer: a moving frame restarts (1 spp), a still one adds 1 (2), ]] makes it 4 a frame
  // (6, 10), and the last frame adds the 2 left of the scene's 12.
  EXPECT_NE(v.out.find("narval view: wrote snaps/fog_view_001.exr, .png and .json (raymarch, 64x48)\n"),
            std::string::npos) << v.out;
  EXPECT_NE(v.out.find("narval view: wrote snaps/fog_view_002.exr, .png and .json (lobe, 64x48)\n"),
            std::string::npos) << v.out;
  EXPECT_NE(v.out.find("narval view: wrote snaps/fog_view_003.exr, .png and .json (pathtrace, 64x48, 12 spp)\n"),
            std::string::npos) << v.out;
  EXPECT_EQ(stats("stats.json")["frames"], 10);

  const std::vector<std::pair<std::string, std::vector<std::string>>> snaps = {
      {"001", {"R", "G", "B", "medium"}},
      {"002", {"R", "G", "B", "medium"}},
      {"003", {"R", "G", "B", "medium", "accum.R.w0", "accum.R.w1", "accum.R.w2", "accum.G.w0", "accum.B.w0", "accum.B.w3",
               "accum.rejected"}}};
  for (const auto& [n, channels] : snaps) {
    SCOPED_TRACE("snapshot " + n);
    const std::string json = "snaps/fog_view_" + n + ".json";
    const nlohmann::json written = nlohmann::json::parse(readFile(dir_ / json));
    EXPECT_NE(written["camera"]["position"], nlohmann::json::parse(fogSceneJson(64, 48, 12))["camera"]["position"]);
    const RunResult r = run("render " + json + " -o again_" + n + ".exr");
    ASSERT_EQ(r.code, 0) << r.err;
    expectSamePixels("snaps/fog_view_" + n + ".exr", "again_" + n + ".exr", channels);
    EXPECT_EQ(readFile(dir_ / ("snaps/fog_view_" + n + ".png")), readFile(dir_ / ("again_" + n + ".png")));
  }
  // The window showed the last frame pixel for pixel.
  EXPECT_EQ(readFile(dir_ / "shot.png"), readFile(dir_ / "again_003.png"));
}

// Without --output-dir, P writes into out/ (made then), never beside the user's files.
TEST_F(ViewCli, SnapshotsGoToOutByDefault) {
  write("p.txt", "frames 1\nkey P\nframes 1\n");
  const RunResult v = run("view fog.json --script p.txt --target-ms 1e9", kXvfb);
  ASSERT_EQ(v.code, 0) << v.err;
  EXPECT_NE(v.out.find("narval view: wrote out/fog_view_001.exr, .png and .json"), std::string::npos) << v.out;
  EXPECT_TRUE(fs::exists(dir_ / "out" / "fog_view_001.exr"));
  EXPECT_FALSE(fs::exists(dir_ / "fog_view_001.exr"));
}

TEST_F(ViewCli, MovingFramesAreSmallerAndCountedPerResolution) {
  write("moves.txt",
        "frames 2\n"
        "drag left 10 0\n"
        "frames 1\n"
        "hold W 0.1\n"
        "frames 1\n"
        "scroll 1\n"
        "frames 3\n");
  // A target no frame meets: every frame after a move is an eighth of the size; still frames are
  // full size (the first frame is full size too: nothing is measured yet).
  RunResult v = run("view fog.json --script moves.txt --target-ms 1e-6 --stats-json small.json", kXvfb);
  ASSERT_EQ(v.code, 0) << v.err;
  EXPECT_EQ(stats("small.json")["frames_per_resolution"], nlohmann::json({{"64x48", 4}, {"8x6", 3}}));
  EXPECT_NE(v.out.find("narval view: 7 frames (64x48: 4, 8x6: 3) on "), std::string::npos) << v.out;
  // A target every frame meets: all full size. --frames adds still frames after the script. No
  // display this time: the headless run starts an Xvfb of its own.
  v = run("view fog.json --script moves.txt --target-ms 1e9 --frames 9 --stats-json large.json",
          "env -u DISPLAY -u WAYLAND_DISPLAY");
  ASSERT_EQ(v.code, 0) << v.err;
  EXPECT_EQ(stats("large.json")["frames_per_resolution"], nlohmann::json({{"64x48", 9}}));
  // Per resolution, the median frame and the largest after the first (the first builds the programs):
  // no smaller than the median (four frames: the median is at most the second largest).
  const nlohmann::json small = stats("small.json")["per_resolution"];
  EXPECT_GE(small["64x48"]["frame_ms_max_after_first"].get<double>(), small["64x48"]["frame_ms_median"].get<double>());
  EXPECT_GT(small["8x6"]["frame_ms_max_after_first"].get<double>(), 0.0);
  EXPECT_EQ(stats("large.json")["per_resolution"]["64x48"]["frames"], 9);
}

TEST_F(ViewCli, LiveErrorAgainstTheReferenceAtItsPoseOnly) {
  ASSERT_EQ(run("render fog.json -o reference.exr").code, 0);
  // Five frames: the viewer refines the cache one launch a frame, complete at the fourth.
  write("still.txt", "frames 5\n");
  RunResult v = run("view fog.json --reference reference.exr --script still.txt --stats-json at.json", kXvfb);
  ASSERT_EQ(v.code, 0) << v.err;
  // The same kernels, settings and cache: the frame is the reference, ΔE 0.
  EXPECT_EQ(stats("at.json")["reference"], nlohmann::json({{"mean_delta_e76", 0.0}, {"jnd_percent", 0.0}}));
  write("away.txt", "frames 1\ndrag left 40 0\nframes 1\n");
  v = run("view fog.json --reference reference.exr --script away.txt --stats-json away.json", kXvfb);
  ASSERT_EQ(v.code, 0) << v.err;
  EXPECT_FALSE(stats("away.json").contains("reference"));
}

// The window's own input path, driven by real X events (xdotool, XTEST): a left drag of 20 pixels
// orbits by 5 degrees, the key P writes a snapshot. The path tracer goes idle at its 4 spp, so the
// viewer waits for the events; --frames 9 ends it (4 frames, 4 after the drag, 1 for P).
TEST_F(ViewCli, MouseAndKeysOfTheWindowDriveTheSameControls) {
  ASSERT_EQ(std::system("command -v xdotool > /dev/null"), 0) << "xdotool is missing: scripts/setup.sh installs it";
  write("drive.sh",
        "'" + std::string(NARVAL_BINARY) +
            "' view fog.json --algorithm pathtrace --set renderer.spp=4 --frames 9 --target-ms 1e9 "
            "--output-dir snaps --stats-json stats.json > view.out 2> view.err &\n"
            "viewer=$!\n"
            // Bounded: a viewer that exits before its window shows must fail the test, not hang it.
            "window=$(timeout 120 xdotool search --sync --onlyvisible --name 'narval view' | head -n 1)\n"
            "[ -n \"$window\" ] || { wait $viewer; exit 3; }\n"
            "sleep 1\n"
            "xdotool mousemove --window \"$window\" 20 24 mousedown 1\n"
            "xdotool mousemove --window \"$window\" 40 24 mouseup 1\n"
            "sleep 1\n"
            "xdotool key p\n"
            "wait $viewer\n");
  const RunResult v = runCommand(kXvfb + " sh drive.sh");
  ASSERT_EQ(v.code, 0) << v.err << readFile(dir_ / "view.err");
  const nlohmann::json written = nlohmann::json::parse(readFile(dir_ / "snaps/fog_view_001.json"));
  // Yaw 5 degrees about +y of the camera at (0, 0, -6) looking at the origin: the offset rotates by
  // -5 degrees, x = -6 · sin(-5°) = 0.52293, z = -6 · cos(5°) = -5.97717.
  const nlohmann::json& p = written["camera"]["position"];
  EXPECT_NEAR(p[0].get<double>(), 6.0 * std::sin(5.0 * M_PI / 180.0), 1e-4) << p;
  EXPECT_NEAR(p[1].get<double>(), 0.0, 1e-5) << p;
  EXPECT_NEAR(p[2].get<double>(), -6.0 * std::cos(5.0 * M_PI / 180.0), 1e-4) << p;
  EXPECT_EQ(written["renderer"]["spp"], 4);
  EXPECT_EQ(stats("stats.json")["frames"], 9);
  const RunResult r = run("render snaps/fog_view_001.json -o again.exr");
  ASSERT_EQ(r.code, 0) << r.err;
  expectSamePixels("snaps/fog_view_001.exr", "again.exr", {"R", "G", "B", "medium", "accum.R.w0", "accum.R.w2"});
}

TEST_F(ViewCli, WithoutADisplayOneLineAndExit2) {
  // Interactive: a window nobody can see is no use.
  RunResult v = run("view fog.json", "env -u DISPLAY -u WAYLAND_DISPLAY");
  EXPECT_EQ(v.code, 2);
  EXPECT_EQ(v.err,
            "narval: view: no display to open a window on (DISPLAY is not set); run it in a desktop session, or "
            "headless with --script or --frames (narval then starts Xvfb itself)\n");
  // Headless, but no Xvfb on PATH to start.
  v = run("view fog.json --frames 1 --screenshot shot.png", "env -u DISPLAY -u WAYLAND_DISPLAY PATH=/nonexistent");
  EXPECT_EQ(v.code, 2);
  EXPECT_EQ(v.err,
            "narval: view: no display to open a window on (DISPLAY is not set) and no Xvfb to start for a headless "
            "run (Debian: apt-get install xvfb)\n");
  EXPECT_FALSE(fs::exists(dir_ / "shot.png"));
}

TEST_F(ViewCli, BadInputIsFoundBeforeAnyWindow) {
  // No display either: each mistake is reported before the window would be opened.
  const std::string noDisplay = "env -u DISPLAY -u WAYLAND_DISPLAY";
  write("bad.txt", "frames 1\nkey Z\n");
  RunResult v = run("view fog.json --script bad.txt", noDisplay);
  EXPECT_EQ(v.code, 2);
  EXPECT_EQ(v.err, "narval: bad.txt:2: unknown key 'Z' (keys: 1 2 3 [ ] P R H F)\n");
  v = run("view fog.json --script missing.txt", noDisplay);
  EXPECT_EQ(v.code, 2);
  EXPECT_EQ(v.err, "narval: missing.txt: cannot open the script\n");
  v = run("view fog.json --frames 2 --screenshot shot.jpg", noDisplay);
  EXPECT_EQ(v.code, 2);
  EXPECT_EQ(v.err, "narval: --screenshot: the screenshot must be a .png file, got 'shot.jpg'\n");
  v = run("view fog.json --screenshot shot.png", noDisplay);
  EXPECT_EQ(v.code, 2);
  EXPECT_EQ(v.err, "narval: --screenshot: needs --script or --frames (the screenshot is of the last frame)\n");
  ASSERT_EQ(run("render fog.json -o small.exr --resolution 32x24").code, 0);
  v = run("view fog.json --reference small.exr", noDisplay);
  EXPECT_EQ(v.code, 2);
  EXPECT_EQ(v.err, "narval: --reference: small.exr is 32x24; the scene renders 64x48\n");
  EXPECT_FALSE(fs::exists(dir_ / "shot.png"));
}

}  // namespace
}  // namespace narval::test
