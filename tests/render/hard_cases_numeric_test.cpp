// Numerical hard cases (issue 5): extreme phase asymmetry, extinction 0 / 1e-8 / 1e6, albedo exactly
// 1 with a huge bounce cap, albedo 0. Each test derives its expectation beside it, for the path
// tracer (kernels/pathtrace.cl), the ray marcher (kernels/raymarch.cl) and the Lobe Estimator
// (kernels/lobe.cl) wherever the case applies. Images are tiny and spp low: the file runs in seconds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "render/realtime_renderer.h"
#include "render/scene_upload.h"
#include "render_fixture.h"

namespace narval::test {
namespace {

const auto& kAlgorithms = kHardCaseRenderers;

size_t nonFinite(const ImageRGB& img) {
  size_t n = 0;
  for (float v : img.rgb) n += !std::isfinite(v);
  return n;
}

// Every value of channel c equals want[c] exactly (bit for bit).
void expectEverywhere(const ImageRGB& img, const float want[3], const std::string& what) {
  size_t wrong = 0;
  float firstBad = 0;
  for (size_t i = 0; i < img.rgb.size(); ++i)
    if (img.rgb[i] != want[i % 3]) {
      if (!wrong) firstBad = img.rgb[i];
      ++wrong;
    }
  EXPECT_EQ(wrong, 0u) << what << ": of " << img.rgb.size() << " values; first wrong " << firstBad;
}

// A homogeneous box (2 × 2 × 1, centred at the origin) with the given material fields, a point light
// and a rectangle light, background bg; camera on −z looking at the box through `vfov`.
std::string boxScene(const std::string& material, const std::string& lights, const std::string& bg,
                     double vfov, const std::string& renderer) {
  return R"({
    "materials": [
      {"name": "light", "type": "emitter", "albedo": [2, 3, 4]},
      {"name": "medium", "type": "volume", )" + material + R"(}
    ],
    "primitives": [)" + lights + R"(
      {"name": "box", "type": "volume", "transform": {"position": [0, 0, 0], "scale": [2, 2, 1]},
       "materialName": "medium"}
    ],
    "camera": {"position": [0, 0, -10], "lookAt": [0, 0, 0], "up": [0, 1, 0], "vfov": )" +
         std::to_string(vfov) + R"(},
    "renderer": )" + renderer + R"(,
    "background": )" + bg + "}";
}
const std::string kPointLight =
    R"({"name": "pl", "type": "point", "transform": {"position": [1.5, 2, -2]}, "materialName": "light"},)";
// Rectangle light behind the box, facing it, 40 × 40: with vfov 2° every camera ray hits it.
const std::string kRectBehind =
    R"({"name": "rect", "type": "rectangle", "transform": {"position": [0, 0, 5], "scale": [40, 40, 1]},
       "materialName": "light"},)";
const std::string kSmallRenderer = R"({"resolution": [8, 8], "spp": 4, "bounces": 8})";

// ---------------------------------------------------------------------------------------------
// (1) Phase asymmetry g ∈ {−0.999999, −1e−7, 0, 1e−7, 0.999999}. HG at |g| = 0.999999 peaks at
// p(±1) = (1 + |g|)/(4π(1 − |g|)²) ≈ 1.6e11 (finite in float, max 3.4e38) and its sampling formula
// divides by 2g, so g = ±1e−7 must take the isotropic branch (or cancel cleanly) instead of
// producing 0/0; g = 0 is the isotropic case itself. Nothing in the estimators is unbounded for
// |g| < 1, so each algorithm must give a finite image with status word 0 (no STATUS_* bit; the
// kernels would set STATUS_NAN if a pixel were non-finite) and no non-finite pixel. The scene has a
// point light beside the box (lights the medium: phase_eval on every NEE / in-scatter term) and a
// rectangle light behind it (seen through the medium at μ ≈ 1, the forward peak for g → 1).
// Near |g| = 1 the HG peak is a few float steps of μ wide: phase_sample evaluates the pdf at the
// cosine rebuilt from the returned direction, which can exceed 1 by an ulp, and phase_hg_eval clamps
// it (without the clamp the denominator went negative, the pdf NaN, and the path tracer dropped
// ~15-23% of paths with STATUS_NEGATIVE_PDF: this test caught that).

TEST(HardCasesNumeric, ExtremePhaseAsymmetryIsFiniteForEveryAlgorithm) {
  for (const double g : {-0.999999, -1e-7, 0.0, 1e-7, 0.999999}) {
    char gs[64];
    std::snprintf(gs, sizeof gs, "%.9g", g);
    const Scene scene = sceneFromJson(boxScene(
        std::string(R"("scattering": [0.8, 0.8, 0.8], "absorption": [0.1, 0.1, 0.1], "phaseFunction": "hg", "g": )") +
            gs + R"(, "density": 2)",
        kPointLight + kRectBehind, "[0.1, 0.2, 0.3]", 20, kSmallRenderer));
    for (const char* alg : kAlgorithms) {
      const RenderResult r = renderWith(scene, alg);
      EXPECT_EQ(r.stats.status, 0u) << alg << " g = " << gs;
      EXPECT_EQ(r.stats.status & STATUS_NAN, 0u) << alg << " g = " << gs;
      EXPECT_EQ(r.stats.nanPixels, 0) << alg << " g = " << gs;
      EXPECT_EQ(nonFinite(r.image), 0u) << alg << " g = " << gs;
    }
  }
}

// g = ±1 would make HG a delta function (its density is 0 except at μ = ±1, where it is infinite):
// the loader clamps it to ±0.9999 and says so in Scene::warnings (text pinned by
// tests/unit/scene_load_test.cpp). The clamped scene then renders finite for every algorithm.
TEST(HardCasesNumeric, PhaseGOfPlusMinusOneIsClampedWithAWarningAndRendersFinite) {
  for (const int sign : {1, -1}) {
    const std::string gs = sign > 0 ? "1" : "-1";
    const Scene scene = sceneFromJson(boxScene(
        R"("scattering": [0.8, 0.8, 0.8], "absorption": [0.1, 0.1, 0.1], "phaseFunction": "hg", "g": )" + gs +
            R"(, "density": 2)",
        kPointLight + kRectBehind, "[0.1, 0.2, 0.3]", 20, kSmallRenderer));
    EXPECT_EQ(scene.materials[1].phaseParameter, sign * 0.9999f);
    EXPECT_EQ(scene.warnings, (std::vector<std::string>{
                                  "test_scene.json: materials[1].g: g = " + gs +
                                  " makes the hg phase function degenerate; clamped to " +
                                  (sign > 0 ? "0.9999" : "-0.9999")}));
    for (const char* alg : kAlgorithms) {
      const RenderResult r = renderWith(scene, alg);
      EXPECT_EQ(r.stats.status, 0u) << alg << " g = " << gs;
      EXPECT_EQ(r.stats.status & STATUS_NAN, 0u) << alg << " g = " << gs;
      EXPECT_EQ(r.stats.nanPixels, 0) << alg << " g = " << gs;
      EXPECT_EQ(nonFinite(r.image), 0u) << alg << " g = " << gs;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// (2a) σt = 0 (density multiplier 0; σs, σa nonzero per unit density). The medium is then absent:
// the path tracer's majorant is 0, so every camera ray passes the box without a collision and returns
// what it hits (Le of the rectangle, or the background); the ray marcher has S_k = 0 and T = e^0 = 1,
// so L = 0 + 1·L_b = L_b exactly (provided the 0/σt of its energy-conserving step is guarded); the
// Lobe Estimator finds no density > 0 on the segment and returns L_b exactly. Spp copies of an exact
// value average to that value bit for bit (the exact sum of accum.h; see RenderAccumulation.
// MillionSamplesOfAConstantStayExact), so each image equals the expectation exactly.
//   Scene A: vfov 2°, rectangle light (2, 3, 4) behind the box fills the image: every pixel = Le.
//   Scene B: no rectangle, a point light (not visible to camera rays), background (0.25, 0.5, 0.75),
//            vfov 40°, rays through and beside the box: every pixel = background.
TEST(HardCasesNumeric, ZeroExtinctionGivesExactlyTheLightOrBackground) {
  const std::string mat =
      R"("scattering": [0.5, 0.6, 0.7], "absorption": [0.2, 0.2, 0.2], "phaseFunction": "hg", "g": 0.3, "density": 0)";
  const Scene a = sceneFromJson(boxScene(mat, kRectBehind, "[0, 0, 0]", 2, kSmallRenderer));
  const Scene b = sceneFromJson(boxScene(mat, kPointLight, "[0.25, 0.5, 0.75]", 40, kSmallRenderer));
  const float le[3] = {2, 3, 4}, bg[3] = {0.25f, 0.5f, 0.75f};
  for (const char* alg : kAlgorithms) {
    const RenderResult ra = renderWith(a, alg), rb = renderWith(b, alg);
    expectEverywhere(ra.image, le, std::string(alg) + " light behind an empty box");
    expectEverywhere(rb.image, bg, std::string(alg) + " background through an empty box");
    EXPECT_EQ(ra.stats.status | rb.stats.status, 0u) << alg;
  }
}

// (2b) σt = 1e−8 (σa = 1e−8, σs = 0), no lights, background 1, vfov 20°. The exact pixel value is
// the Beer–Lambert transmittance exp(−1e−8·ℓ) with ℓ ≤ the box's longest chord (√(2² + 2² + 1²) = 3)
// so 1 ≥ L ≥ exp(−3e−8) ≈ 1 − 3e−8: the bound on the deviation is 1 − exp(−1e−8·ℓ) ≤ 3e−8, below
// half an ulp of 1 (2^−24 ≈ 6e−8) — a float result is 1 or 0.99999994. Per algorithm:
//   path tracer: analogue absorption, each sample is 1 (passes) or 0 (absorbed, probability
//     ≤ 3e−8): over 8·8·8 = 512 samples the chance of any absorption is ≤ 1.5e−5 (and the fixed seed
//     makes the run deterministic), so every pixel is within 1e−6 of 1.
//   ray marcher: T = Π e^{−σt·Δ} in float, ≥ 1 − 60 ulp-sized roundings: within 1e−5 of 1.
//   lobe: L_b·mean Tr(x0 → P_i) + 0 (σs = 0 → albedo 0); the lobe depth depth_factor/σ̄t = 2e9 would
//     leave the box, and the kernel's clamp (depth_factor < σ̄t·rest fails) puts c at the box exit:
//     finite, and the image is within 1e−5 of 1.
// All images: no non-finite value, status 0, never above 1 (a transmittance never exceeds 1).
TEST(HardCasesNumeric, NearlyTransparentMediumIsCloseToTheBackground) {
  const Scene scene = sceneFromJson(boxScene(
      R"("scattering": [0, 0, 0], "absorption": [1e-8, 1e-8, 1e-8], "phaseFunction": "isotropic", "density": 1)",
      "", "[1, 1, 1]", 20, R"({"resolution": [8, 8], "spp": 8, "bounces": 8})"));
  for (const char* alg : kAlgorithms) {
    const RenderResult r = renderWith(scene, alg);
    EXPECT_EQ(r.stats.status, 0u) << alg;
    EXPECT_EQ(nonFinite(r.image), 0u) << alg;
    const double tol = std::string(alg) == "pathtrace" ? 1e-6 : 1e-5;
    float lo = 2, hi = -1;
    for (float v : r.image.rgb) lo = std::min(lo, v), hi = std::max(hi, v);
    EXPECT_LE(hi, 1.0f) << alg;
    EXPECT_GE(lo, 1.0 - tol) << alg;
  }
}

// (2c) σt = 1e6 (σs = σa = 5e5, albedo ½) in the unit-thick box in front of the rectangle light
// (vfov 2°: every camera ray enters the front face, x, y within ±0.2 of the axis). Transmittance
// through the box is exp(−1e6) = 0 in any floating-point format.
//   path tracer: the first collision is ~1e−6 past the entry face; a walk that starts there either is
//     absorbed, hits the bounce cap (8), or escapes through the front face towards −z, where only
//     the background (0) lies. Every NEE shadow ray towards the light (behind the box, z = 5) crosses
//     ≥ 0.5 units of medium (the box's half-thickness or, leaving through a side |x| = 1 or |y| = 1,
//     at least 0.8 units), so its transmittance is exp(−≥5e5) = 0. Hence every pixel is exactly 0,
//     the run finishes (≤ 8 bounces per path) and nothing is NaN.
//   ray marcher: the first step has Δ = 1/60, T = e^{−1e6/60} = 0 after it; the in-scatter S_k carries
//     the shadow transmittance e^{−1e6·(≥0.5)} = 0; so L = 0 and L + T·L_b = 0 exactly.
//   lobe: not 0 by design of Eq. 7. The homogeneous box puts x0 exactly at the entry (first sample
//     has density > 0), c = x0 + 20/1e6·ω, P_i = c + 1·d_i; lobe points in front of the box
//     (d_i·ω < −2e−5, about half for isotropic directions) give segments x0 → P_i that leave the box
//     at once, Tr = 1, so the pixel is L_b·k/n with k the number of such points (L_b = Le: the
//     rectangle behind the box). The in-scatter term is 0 (shadow rays cross ≥ 0.5 units). So the
//     check is: finite, status 0, and 0 ≤ pixel ≤ Le per channel, with all three channels the same
//     fraction of Le (the transmittances are grey).
TEST(HardCasesNumeric, VeryDenseBoxBlocksTheLight) {
  const Scene scene = sceneFromJson(boxScene(
      R"("scattering": [5e5, 5e5, 5e5], "absorption": [5e5, 5e5, 5e5], "phaseFunction": "isotropic", "density": 1)",
      kRectBehind, "[0, 0, 0]", 2, R"({"resolution": [8, 8], "spp": 4, "bounces": 8})"));
  const float zero[3] = {0, 0, 0};
  for (const char* alg : {"pathtrace", "raymarch"}) {
    const RenderResult r = renderWith(scene, alg);
    expectEverywhere(r.image, zero, alg);
    EXPECT_EQ(r.stats.status, 0u) << alg;
    EXPECT_EQ(r.stats.nanPixels, 0) << alg;
  }
  const RenderResult r = renderWith(scene, "lobe+eq7");
  EXPECT_EQ(r.stats.status, 0u);
  EXPECT_EQ(nonFinite(r.image), 0u);
  const double le[3] = {2, 3, 4};
  for (size_t p = 0; p < 64; ++p) {
    const double f0 = r.image.rgb[p * 3] / le[0];
    EXPECT_GE(f0, 0.0) << "pixel " << p;
    EXPECT_LE(f0, 1.0) << "pixel " << p;
    for (int c = 1; c < 3; ++c) EXPECT_NEAR(r.image.rgb[p * 3 + c] / le[c], f0, 1e-6) << "pixel " << p;
  }
}

// ---------------------------------------------------------------------------------------------
// (3a) Albedo exactly 1 (σa = 0) with bounces = 10000: the white furnace (no lights, background 1).
// As in analytic_scenes_test WhiteFurnaceHomogeneousIsExactlyOne: for a grey medium the analogue
// walk never changes the throughput and every path ends by escaping to the background 1, so every
// sample and every pixel is exactly 1.0f. With optical thickness ≤ 3·2.2·density 2 ≈ 13, reaching
// 10000 real collisions is impossible in practice; the huge cap must not change any arithmetic
// (e.g. no per-bounce factor, no float counter loss). Path tracer only: the real-time kernels are
// single-scatter approximations and make no furnace claim.
TEST(HardCasesNumeric, WhiteFurnaceWithTenThousandBouncesIsExactlyOne) {
  const Scene scene = sceneFromJson(boxScene(
      R"("scattering": [1, 1, 1], "absorption": [0, 0, 0], "phaseFunction": "hg", "g": 0.5, "density": 2)", "",
      "[1, 1, 1]", 40, R"({"resolution": [8, 8], "spp": 16, "bounces": 10000})"));
  const RenderResult r = render(scene);
  const float one[3] = {1, 1, 1};
  expectEverywhere(r.image, one, "pathtrace furnace");
  EXPECT_EQ(r.stats.status, 0u);
}

// (3b) Albedo 0 (σs = 0, σa = 0.7) against a light: the absorption box of render_fixture.h, where
// L = Le·exp(−σa/cos θ). Path tracer: each sample is Le or 0 with p = T ≈ 0.5, so with 8·8 px ×
// 1024 spp = 65536 Bernoulli samples the image mean has relative standard error
// √(T(1−T)/65536)/T ≈ 0.39%; 2% is > 5σ. Ray marcher and lobe are deterministic: ray marcher
// L = T·L_b with T the product of e^{−σa·Δ} over 60 steps = exp(−σa·ℓ) up to float rounding (1e−4
// relative); the lobe's L_b·mean Tr(x0 → P_i) is not Beer–Lambert along the view ray (it averages
// over the lobe), so for it only 0 ≤ L ≤ Le and finiteness are claimed.
TEST(HardCasesNumeric, ZeroAlbedoMatchesBeerLambert) {
  const Scene scene = sceneFromJson(absorptionBoxJson(R"({"resolution": [8, 8], "spp": 1024, "bounces": 3})"));
  const camera_params c = buildDeviceScene(scene, nullptr).params.camera;
  double expected = 0;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) expected += absorptionBoxTransmittance(c, x, y) / 64.0;
  {
    const RenderResult r = render(scene);
    for (int ch = 0; ch < 3; ++ch) {
      const ChannelStats s = channelStats(r.image, ch);
      EXPECT_NEAR(s.mean / kAbsorptionBoxLe[ch], expected, 0.02 * expected) << "pathtrace channel " << ch;
    }
    EXPECT_EQ(r.stats.status, 0u);
  }
  {
    const RenderResult r = renderWith(scene, "raymarch");
    EXPECT_EQ(r.stats.status, 0u);
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x)
        for (int ch = 0; ch < 3; ++ch) {
          const double want = kAbsorptionBoxLe[ch] * absorptionBoxTransmittance(c, x, y);
          EXPECT_NEAR(r.image.rgb[size_t((y * 8 + x) * 3 + ch)], want, 1e-4 * want) << "raymarch " << x << "," << y;
        }
  }
  {
    const RenderResult r = renderWith(scene, "lobe+eq7");
    EXPECT_EQ(r.stats.status, 0u);
    EXPECT_EQ(nonFinite(r.image), 0u);
    for (size_t i = 0; i < r.image.rgb.size(); ++i) {
      EXPECT_GE(r.image.rgb[i], 0.0f);
      EXPECT_LE(r.image.rgb[i], float(kAbsorptionBoxLe[i % 3]));
    }
  }
}

}  // namespace
}  // namespace narval::test
