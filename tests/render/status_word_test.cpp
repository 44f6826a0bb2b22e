// The status word is live (issue 5, numerical hard cases): every STATUS_* bit that a kernel can
// raise is raised here, through the real device path (RenderResult.stats.status as the renderers
// read it back), for every kernel where it can occur. The clean assertions elsewhere
// (`status == 0` in hard_cases_*, analytic_scenes, raymarch, lobe tests) are worth something only
// because of these: a bit that could never be set would pass them all.
//
//   bit                   pathtrace                         raymarch              lobe
//   STATUS_NAN            light NaN; density NaN (walks)    light NaN; density    light NaN; density
//   STATUS_NEGATIVE_PDF   majorant below σt; HG g = 1       — (nothing sampled)   — (nothing sampled)
//   STATUS_ITERATION_CAP  delta and ratio tracking cap      DDA budget            DDA budget
//
// The loaders keep most of these out of a scene file (non-finite numbers and densities, |g| = 1,
// a grid maxValue other than its maximum are refused or fixed), so the tests hand the renderers a
// Scene or DenseGrid edited after loading, as a caller of the library can. Caps: an over-dense
// scene reaches the tracking cap without help (one test, and tests/cli/status_cli_test.cpp); the
// rest shrink the caps at build time with ClRuntime::extraBuildOptions (-D NARVAL_TRACKING_MAX_STEPS,
// -D NARVAL_DDA_BUDGET; tracking.h and majorant_dda.h derive the defaults). Host-side checks of the same
// code paths: tests/unit/status_word_host_test.cpp.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "render/realtime_renderer.h"
#include "render_fixture.h"
#include "volume/dense_grid.h"

namespace narval::test {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
const char* const kAlgorithms[] = {"pathtrace", "raymarch", "lobe"};

// `majorant`: the path tracer's (RenderOptions::majorant); the tests of what a global σ̄ does over
// mostly empty space name "global".
RenderResult renderOn(ClRuntime& rt, Scene scene, const DenseGrid* grid, const std::string& algorithm,
                      const std::string& majorant = "grid") {
  RenderOptions o;
  o.majorant = majorant;
  if (algorithm == "pathtrace") return renderPathtrace(rt, scene, grid, o);
  if (!algorithmFromName(algorithm, &scene.renderer.algorithm)) throw std::invalid_argument(algorithm);
  return renderRealtime(rt, scene, grid, 1, o);
}
RenderResult renderWith(const Scene& scene, const DenseGrid* grid, const std::string& algorithm,
                        const std::string& majorant = "grid") {
  return renderOn(runtime(), scene, grid, algorithm, majorant);
}

// Build options added to every program built on the shared runtime while it lives (the program
// cache keys on them, so capped and normal programs never mix).
struct ExtraBuildOptions {
  explicit ExtraBuildOptions(const std::string& o) { runtime().extraBuildOptions = o; }
  ~ExtraBuildOptions() { runtime().extraBuildOptions.clear(); }
};

// Material "medium" (index 1) in a 2 × 2 × 1 box at the origin; material "light" (index 0, an
// emitter of intensity 2) on a point light beside the box when `light`; camera on −z, vfov 20°
// (the box fills the middle of the 8 × 8 image, the corners see the background).
Scene boxScene(const std::string& medium, bool light, const std::string& background, int spp = 4,
               const std::string& resolution = "[8, 8]") {
  const std::string pointLight =
      R"({"name": "pl", "type": "point", "transform": {"position": [1.5, 2, -2]}, "materialName": "light"},)";
  return sceneFromJson(R"({
    "materials": [
      {"name": "light", "type": "emitter", "albedo": [2, 2, 2]},
      {"name": "medium", "type": "volume", )" + medium + R"(}
    ],
    "primitives": [)" + (light ? pointLight : std::string()) + R"(
      {"name": "box", "type": "volume", "transform": {"position": [0, 0, 0], "scale": [2, 2, 1]},
       "materialName": "medium"}
    ],
    "camera": {"position": [0, 0, -10], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": 20},
    "renderer": {"resolution": )" + resolution + R"(, "spp": )" + std::to_string(spp) + R"(, "bounces": 4},
    "background": )" + background + "}");
}
const std::string kGrey = R"("scattering": [1, 1, 1], "absorption": [0.1, 0.1, 0.1], "phaseFunction": "isotropic")";

DenseGrid uniformGrid(int n, float value) {
  DenseGrid g;
  g.nx = g.ny = g.nz = n;
  g.data.assign(g.voxelCount(), value);
  g.maxValue = value;
  return g;
}
// All zeros but one voxel of density 1 near the centre: a global majorant of σt with almost only
// null collisions under it.
DenseGrid sparseGrid(int n) {
  DenseGrid g = uniformGrid(n, 0.0f);
  g.data[size_t(n / 2) + size_t(n) * (size_t(n / 2) + size_t(n) * size_t(n / 2))] = 1.0f;
  g.maxValue = 1.0f;
  return g;
}

size_t nonFinite(const ImageRGB& img) {
  size_t n = 0;
  for (float v : img.rgb) n += !std::isfinite(v);
  return n;
}
float maxValue(const ImageRGB& img) {
  float m = 0;
  for (float v : img.rgb) m = std::max(m, v);
  return m;
}

// ---- STATUS_NAN ---------------------------------------------------------------------------------

// A NaN light intensity (JSON has no NaN and the loader refuses non-finite numbers, so it is set
// on the loaded Scene). Every estimate of light at a point in the lit medium multiplies it: the
// path tracer's NEE term (radiance·tr·f·w), the ray marcher's in-scatter S (I/d²·phase·Tr), the
// lobe's in_sum (Tr·I·f/d²). So every pixel whose ray meets the medium is non-finite before the
// pixel check, which must write 0 and raise exactly STATUS_NAN; the other pixels see background 0.
// Expected: status == STATUS_NAN, image all finite and exactly 0, nan_pixels 0. Control: the same
// scene with intensity 2 renders status 0 and a lit medium (max > 0), so the zeros are the check's.
TEST(StatusWord, NanLightIntensityRaisesNanAndWritesZeroForEveryKernel) {
  Scene lit = boxScene(kGrey + R"(, "density": 1)", true, "[0, 0, 0]");
  Scene poisoned = lit;
  poisoned.materials[0].albedo = {kNaN, kNaN, kNaN};
  for (const char* alg : kAlgorithms) {
    const RenderResult control = renderWith(lit, nullptr, alg);
    EXPECT_EQ(control.stats.status, 0u) << alg;
    EXPECT_GT(maxValue(control.image), 0.0f) << alg;
    const RenderResult r = renderWith(poisoned, nullptr, alg);
    EXPECT_EQ(r.stats.status, STATUS_NAN) << alg;
    EXPECT_EQ(r.stats.nanPixels, 0) << alg;
    EXPECT_EQ(nonFinite(r.image), 0u) << alg;
    EXPECT_EQ(maxValue(r.image), 0.0f) << alg;
  }
}

// A NaN voxel (loaders refuse them; a grid handed over directly is not checked) in a 5³ grid of
// 0.5: its trilinear support, index [1.5, 3.5]³ around the box centre, reads NaN (NaN·weight is NaN
// even at weight 0). No lights, background 1: nothing but the view ray's own loop reads density,
// so each kernel must flag the NaN where it meets it instead of taking it for empty space —
//   path tracer: the delta walk's null-collision probability 1 − pa − ps is NaN (before: taken as a
//     null collision, the path escaped to the background and nothing was flagged);
//   ray marcher: the sample's density fails `rho > 0` (before: skipped as empty, silently);
//   lobe: the first-hit search skips it, but the lobe transmittances x0 → P_i cross it (τ NaN), so
//     the pixel is non-finite and the pixel check flags it.
// The centre pixels' rays cross the support, so every kernel sees it. Expected: status ==
// STATUS_NAN exactly, every pixel finite. Control: the grid without the NaN renders status 0.
TEST(StatusWord, NanDensityRaisesNanForEveryKernel) {
  DenseGrid clean = uniformGrid(5, 0.5f);
  DenseGrid poisoned = clean;
  poisoned.data[size_t(2 + 5 * (2 + 5 * 2))] = kNaN;
  const Scene scene = boxScene(kGrey + R"(, "density": 1)", false, "[1, 1, 1]", 16);
  for (const char* alg : kAlgorithms) {
    EXPECT_EQ(renderWith(scene, &clean, alg).stats.status, 0u) << alg;
    const RenderResult r = renderWith(scene, &poisoned, alg);
    EXPECT_EQ(r.stats.status, STATUS_NAN) << alg;
    EXPECT_EQ(nonFinite(r.image), 0u) << alg;
    EXPECT_EQ(r.stats.nanPixels, 0) << alg;
  }
}

// ---- STATUS_NEGATIVE_PDF (path tracer only: the real-time kernels sample nothing) ---------------

// A grid whose maxValue (0.5) understates its data (1 everywhere; loaders compute maxValue, so only
// a caller can get this wrong). The path tracer's global majorant (--majorant global)
// σ̄ = σt·0.5·(1 + 1e-5) is then about half of σt(x) inside the box: the delta walk's null-collision
// probability 1 − σt(x)/σ̄ ≈ −1 and ratio tracking's weight likewise are negative at every tentative
// collision where the density exceeds 0.5 (all of the interior), so exactly STATUS_NEGATIVE_PDF.
// The majorant grid (the path tracer's default, and the real-time kernels' empty-space skipping)
// is built from the data itself, not maxValue: status 0. Control: the same grid with its true
// maxValue renders status 0 with the global majorant.
TEST(StatusWord, UnderstatedMajorantIsANegativePdfForThePathTracer) {
  DenseGrid truthful = uniformGrid(4, 1.0f);
  DenseGrid understated = truthful;
  understated.maxValue = 0.5f;
  const Scene scene = boxScene(kGrey + R"(, "density": 1)", true, "[0, 0, 0]");
  EXPECT_EQ(renderWith(scene, &truthful, "pathtrace", "global").stats.status, 0u);
  const RenderResult r = renderWith(scene, &understated, "pathtrace", "global");
  EXPECT_EQ(r.stats.status, STATUS_NEGATIVE_PDF);
  EXPECT_EQ(nonFinite(r.image), 0u);
  EXPECT_EQ(renderWith(scene, &understated, "pathtrace", "grid").stats.status, 0u);
  EXPECT_EQ(renderWith(scene, &understated, "raymarch").stats.status, 0u);
  EXPECT_EQ(renderWith(scene, &understated, "lobe").stats.status, 0u);
}

// Henyey–Greenstein with g = 1 exactly (the loader clamps ±1 to ±0.9999, tests/render/
// hard_cases_numeric_test.cpp, so it is set on the loaded Scene). Phase sampling then returns
// μ = 1 (s = 0 in the inverse CDF), i.e. w_out = w_in, and its pdf p(μ) = (1 − g)(1 + g)/(4π d^{3/2})
// has a zero numerator: 0, or 0/0 = NaN where the rebuilt cosine rounds to exactly 1 (d = 0). The
// path tracer must stop that path with STATUS_NEGATIVE_PDF (plus STATUS_NAN for the 0/0 cases) at
// the first real scattering event, which some of the 64·4 paths through a box of optical depth ~1
// surely have. Expected: NEGATIVE_PDF set, no bit other than NAN besides it, image finite.
TEST(StatusWord, PhaseFunctionDeltaIsANegativePdfForThePathTracer) {
  Scene scene = boxScene(R"("scattering": [1, 1, 1], "absorption": [0.1, 0.1, 0.1], "phaseFunction": "hg",
                            "g": 0.5, "density": 1)",
                         true, "[0, 0, 0]");
  EXPECT_EQ(renderWith(scene, nullptr, "pathtrace").stats.status, 0u);
  scene.materials[1].phaseParameter = 1.0f;
  const RenderResult r = renderWith(scene, nullptr, "pathtrace");
  EXPECT_TRUE(r.stats.status & STATUS_NEGATIVE_PDF) << r.stats.status;
  EXPECT_EQ(r.stats.status & ~(STATUS_NEGATIVE_PDF | STATUS_NAN), 0u) << r.stats.status;
  EXPECT_EQ(nonFinite(r.image), 0u);
}

// ---- STATUS_ITERATION_CAP -----------------------------------------------------------------------

// Delta tracking, genuinely: σt = 1e9 (σs = σa = 5e8, valid values) over a grid that is empty but
// for one voxel, with the global majorant, so σ̄ = 1e9·(1 + 1e-5) while nearly every tentative
// collision is null. (The majorant grid skips the empty cells, but stands still just the same
// where the walk reaches the first occupied cell, whose near half voxel still has density 0.) The camera
// ray enters the box at t ≈ 9.5 where an ulp of t is 9.5e-7, a thousand mean steps (1e-9): t cannot
// advance at all, and the walk runs into the default cap of 10⁷ steps (tracking.h) and ends
// absorbed. One pixel, one sample, no lights: exactly STATUS_ITERATION_CAP and the pixel 0 (the
// background 1 would show through if the walk had escaped). Also measures what the cap costs.
TEST(StatusWord, OverDenseGridHitsTheTrackingCapWithoutHelp) {
  const DenseGrid grid = sparseGrid(8);
  const Scene scene = boxScene(R"("scattering": [5e8, 5e8, 5e8], "absorption": [5e8, 5e8, 5e8],
                                  "phaseFunction": "isotropic", "density": 1)",
                               false, "[1, 1, 1]", 1, "[1, 1]");
  const auto t0 = std::chrono::steady_clock::now();
  const RenderResult r = renderWith(scene, &grid, "pathtrace", "global");
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.stats.status, STATUS_ITERATION_CAP);
  EXPECT_EQ(r.image.rgb[0], 0.0f);
  std::printf("[ status ] one walk of 10^7 steps (the cap): %.2f s of kernel time, %.2f s in all\n",
              r.stats.kernelSeconds, s);
}

// Delta tracking with the cap forced to 4 steps: the same one-voxel grid, σt = 100 (σs = σa = 50),
// no lights, background 1, the global majorant (the majorant grid would skip the empty cells, and
// some walks would reach the voxel within 4 steps). A camera ray crossing the box (ℓ ≥ 1) has Poisson(σ̄ℓ ≥ 100) tentative
// collisions, nearly all null, so every such walk hits the cap (P(≤ 4 | mean 100) ≈ 1e-37): exactly
// STATUS_ITERATION_CAP, and those pixels 0. Control: the default cap (σ̄ℓ ≤ 100·3 ≪ 10⁷) gives 0.
TEST(StatusWord, DeltaTrackingCapRaisesIterationCap) {
  const DenseGrid grid = sparseGrid(8);
  const Scene scene = boxScene(R"("scattering": [50, 50, 50], "absorption": [50, 50, 50],
                                  "phaseFunction": "isotropic", "density": 1)",
                               false, "[1, 1, 1]");
  EXPECT_EQ(renderWith(scene, &grid, "pathtrace", "global").stats.status, 0u);
  const ExtraBuildOptions capped("-DNARVAL_TRACKING_MAX_STEPS=4");
  const RenderResult r = renderWith(scene, &grid, "pathtrace", "global");
  EXPECT_EQ(r.stats.status, STATUS_ITERATION_CAP);
  const int centre = 4 * 8 + 4;
  for (int c = 0; c < 3; ++c) EXPECT_EQ(r.image.rgb[size_t(centre) * 3 + c], 0.0f);
}

// Ratio tracking with the cap forced to 6 steps: a 16³ grid of density 1 everywhere (so ratio
// tracking walks, unlike the homogeneous closed form) and σt = 20. Delta tracking there hits a real
// collision at its first tentative one with probability ρ/(ρmax(1 + 1e-5)) ≈ 1 except in the half
// voxel (1/32 unit) inside each face where the trilinear density ramps down to 0.5, thinner than a
// mean free path (0.05), so 6 null collisions in a row essentially never happen — the control
// without lights (no shadow rays) shows status 0 under the same cap. Shadow rays towards the point
// light cross ~0.2–1.5 units of medium, Poisson(σ̄ℓ ≈ 4–30) tentative collisions, each with weight
// 1 − σt/σ̄ ≈ 1e-5 (after 6 the product is ~1e-30, still a normal float and not 0, so the walk goes
// on): most reach the cap. Expected with the light: exactly STATUS_ITERATION_CAP. Control: the
// default cap renders the lit scene with status 0. The shadow rays' Russian roulette is off here:
// with it, a walk whose transmittance is 1e-5 after one step survives each further step with
// probability 1/4 (tracking.h), so few would live to the cap.
TEST(StatusWord, RatioTrackingCapRaisesIterationCap) {
  const DenseGrid grid = uniformGrid(16, 1.0f);
  const std::string medium = R"("scattering": [10, 10, 10], "absorption": [10, 10, 10], "phaseFunction": "isotropic",
                                "density": 1)";
  Scene lit = boxScene(medium, true, "[0, 0, 0]");
  const Scene dark = boxScene(medium, false, "[1, 1, 1]");
  lit.renderer.pathtrace.shadowRoulette = 0.0f;
  EXPECT_EQ(renderWith(lit, &grid, "pathtrace").stats.status, 0u);
  const ExtraBuildOptions capped("-DNARVAL_TRACKING_MAX_STEPS=6");
  EXPECT_EQ(renderWith(dark, &grid, "pathtrace").stats.status, 0u);
  const RenderResult r = renderWith(lit, &grid, "pathtrace");
  EXPECT_EQ(r.stats.status, STATUS_ITERATION_CAP);
  EXPECT_EQ(nonFinite(r.image), 0u);
}

// The real-time kernels' only open-ended loop is the DDA under every march (majorant_dda.h; all other
// loops run to scene parameters). With its budget forced to 1 iteration, a walk yields its first
// segment and then stops short of t_end, which flags STATUS_ITERATION_CAP. A uniform 8³ grid gets
// 8³ majorant cells (chooseMajorantResolution), so every view ray through the box crosses ≥ 2 cells
// and caps. Expected: exactly STATUS_ITERATION_CAP for raymarch and lobe, finite images. Control: the
// default budget (cells_x + cells_y + cells_z + 3 = 27 ≥ the 8 + 8 + 8 − 1 = 23 a walk can use)
// gives status 0.
TEST(StatusWord, DdaBudgetRaisesIterationCapForTheRealtimeKernels) {
  const DenseGrid grid = uniformGrid(8, 0.5f);
  const Scene scene = boxScene(kGrey + R"(, "density": 1)", true, "[0, 0, 0]");
  for (const char* alg : {"raymarch", "lobe"}) EXPECT_EQ(renderWith(scene, &grid, alg).stats.status, 0u) << alg;
  const ExtraBuildOptions capped("-DNARVAL_DDA_BUDGET=1");
  for (const char* alg : {"raymarch", "lobe"}) {
    const RenderResult r = renderWith(scene, &grid, alg);
    EXPECT_EQ(r.stats.status, STATUS_ITERATION_CAP) << alg;
    EXPECT_EQ(nonFinite(r.image), 0u) << alg;
  }
}

}  // namespace
}  // namespace narval::test
