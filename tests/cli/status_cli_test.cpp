// The status word as a user meets it: `narval render` prints one "narval: warning: ..." line per
// STATUS_* bit the kernels raised (render_common.cpp, statusWarnings) and --stats-json carries them
// as status {nan, negative_pdf, iteration_cap}. Two bits are reachable from a valid scene file, so
// the binary is run on such scenes; the third is not:
// - STATUS_NEGATIVE_PDF cannot be raised by a scene the loader accepts: σ ≥ 0 is enforced, |g| = 1
//   (HG a delta, pdf 0) is clamped to 0.9999, and a grid's maxValue (hence the majorant) is computed
//   by the loader from the data it checked finite, so no majorant falls below σt. It is proven live
//   through the library (tests/render/status_word_test.cpp, a Scene/DenseGrid edited after
//   loading) and on the host (tests/unit/status_word_host_test.cpp).
// - STATUS_UNKNOWN_KIND (status.unknown_kind) cannot either: the host refuses a phase function or
//   light kind the kernels do not know before it builds anything (tests/render/kernel_features_test.cpp);
//   a kernel raises it in tests/device/shared_functions_test.cpp.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "cli/cli_fixture.h"
#include "test_support.h"

namespace narval {
namespace {

using test::readFile;
using test::RunResult;

class StatusCli : public test::CliFixture {};

const std::string kNanLine = "narval: warning: the kernel produced non-finite samples (dropped)\n";
const std::string kPdfLine = "narval: warning: the kernel met a non-positive pdf\n";
const std::string kCapLine = "narval: warning: a loop hit its iteration cap (tracking walk or majorant DDA)\n";

bool contains(const std::string& text, const std::string& line) { return text.find(line) != std::string::npos; }

// A 2 × 2 × 1 box at the origin with material "medium" (`medium` holds its fields), a point light
// (material "light", intensity 1) at the box centre, camera on −z with vfov 20°.
std::string boxScene(const std::string& medium, const std::string& renderer) {
  return R"({
    "materials": [
      {"name": "light", "type": "emitter", "albedo": [1, 1, 1]},
      {"name": "medium", "type": "volume", )" + medium + R"(}
    ],
    "primitives": [
      {"name": "pl", "type": "point", "transform": {"position": [0, 0, 0]}, "materialName": "light"},
      {"name": "box", "type": "volume", "transform": {"scale": [2, 2, 1]}, "materialName": "medium"}
    ],
    "camera": {"position": [0, 0, -10], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 20},
    "renderer": )" + renderer + R"(,
    "background": [1, 1, 1]
  })";
}

// STATUS_NAN from a valid value that overflows: `--set` makes the point light's intensity 3e38 W/sr
// (finite, non-negative: the loader takes it). The ray marcher's in-scatter term scales I by 1/d²
// first (march_light_sum), and the centre pixel of a 3 × 3 image looks straight through the light
// at the box centre, so its midpoint samples lie within Δ/2 = 1/120 of it: I/d² ≥ 3e38·14400 = +inf
// in float, and the pixel's L is non-finite. The kernel writes 0 and raises STATUS_NAN; the binary
// exits 0, prints exactly the NaN warning (and neither other status line), and the stats say
// status.nan = true, the other two false, nan_pixels 0. Control: without --set the same command
// prints no status line and status.nan = false.
TEST_F(StatusCli, OverflowingLightPrintsTheNanWarning) {
  write("scene.json", boxScene(R"("scattering": [1, 1, 1], "absorption": [0.1, 0.1, 0.1],
                                  "phaseFunction": "isotropic", "density": 1)",
                               R"({"resolution": [3, 3], "spp": 1, "bounces": 1})"));
  const RunResult clean = run("render scene.json -o clean.exr --algorithm raymarch --stats-json clean.json");
  ASSERT_EQ(clean.code, 0) << clean.err;
  EXPECT_FALSE(contains(clean.err, kNanLine)) << clean.err;
  EXPECT_EQ(nlohmann::json::parse(readFile(dir_ / "clean.json"))["status"]["nan"], false);

  const RunResult r = run("render scene.json -o out.exr --algorithm raymarch --set materials.0.albedo=[3e38,3e38,3e38] "
                          "--stats-json stats.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, kNanLine)) << r.err;
  EXPECT_FALSE(contains(r.err, kPdfLine)) << r.err;
  EXPECT_FALSE(contains(r.err, kCapLine)) << r.err;
  const nlohmann::json stats = nlohmann::json::parse(readFile(dir_ / "stats.json"));
  EXPECT_EQ(stats["status"]["nan"], true);
  EXPECT_EQ(stats["status"]["negative_pdf"], false);
  EXPECT_EQ(stats["status"]["iteration_cap"], false);
  EXPECT_EQ(stats["nan_pixels"], 0);
}

// STATUS_ITERATION_CAP from a valid but over-dense scene: σs = σa = 5e8 over a .vol grid that is 0
// but for one voxel, so the path tracer's global majorant is 1e9 per unit while almost every
// tentative collision is null. The one camera ray (1 × 1 image) enters the box at t ≈ 9.5, where an
// ulp of t (9.5e-7) is about a thousand mean steps (1e-9): t cannot advance, and the delta walk
// stops at its cap of 10⁷ steps (tracking.h), about a second. Expected: exit 0, exactly the cap
// warning, status.iteration_cap = true and the other two false.
TEST_F(StatusCli, OverDenseGridPrintsTheIterationCapWarning) {
  std::string vol = "4 4 4\n";
  for (int i = 0; i < 64; ++i) vol += i == 1 + 4 * (1 + 4 * 1) ? "1\n" : "0\n";
  write("grid.vol", vol);
  write("scene.json", boxScene(R"("scattering": [5e8, 5e8, 5e8], "absorption": [5e8, 5e8, 5e8],
                                  "phaseFunction": "isotropic", "density": 1, "path": "grid.vol")",
                               R"({"resolution": [1, 1], "spp": 1, "bounces": 1})"));
  const RunResult r = run("render scene.json -o out.exr --stats-json stats.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, kCapLine)) << r.err;
  EXPECT_FALSE(contains(r.err, kNanLine)) << r.err;
  EXPECT_FALSE(contains(r.err, kPdfLine)) << r.err;
  const nlohmann::json stats = nlohmann::json::parse(readFile(dir_ / "stats.json"));
  EXPECT_EQ(stats["status"]["iteration_cap"], true);
  EXPECT_EQ(stats["status"]["nan"], false);
  EXPECT_EQ(stats["status"]["negative_pdf"], false);
}

}  // namespace
}  // namespace narval
