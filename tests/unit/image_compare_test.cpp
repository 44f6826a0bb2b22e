// Image comparison (host/analysis/image_compare.h): ΔE76/ΔE2000 statistics on constructed pairs whose
// differences are derived by hand in the comments, the input errors, the bitmap font, and the two
// maps (ΔE heat map with legend, JND map).
//
// The pairs are built from greys. A linear grey (g, g, g) has X/Xn = Y/Yn = Z/Zn = g (the white is
// the RGB->XYZ matrix applied to (1, 1, 1)), so a* = b* = 0 and L* = 116·cbrt(g) − 16 for
// g > (6/29)^3. Between two greys ΔE76 = |ΔL*| = 116·|cbrt(g1) − cbrt(g2)|, and in CIEDE2000 both
// chromas are 0 (so ΔC' = ΔH' = 0) and ΔE00 = |ΔL*| / S_L with
// S_L = 1 + 0.015 (L̄ − 50)² / sqrt(20 + (L̄ − 50)²) (Sharma, Wu & Dalal 2005, eq. 14).
// The greys used: 0.125 = 0.5³ (L* = 42), 0.216 = 0.6³ (L* = 53.6), 0.125·1.01³ = 0.505³ (L* = 42.58).
#include "analysis/image_compare.h"

#include <gtest/gtest.h>
#include <png.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "core/input_error.h"
#include "image/bitmap_font.h"
#include "image/image.h"
#include "test_support.h"

namespace narval {
namespace {

constexpr float kG0 = 0.125f;                      // 0.5³: L* = 42
constexpr float kGFar = 0.216f;                    // 0.6³: L* = 53.6, ΔE76 = 11.6 from kG0
constexpr float kGNear = 0.125f * 1.030301f;       // 0.505³: L* = 42.58, ΔE76 = 0.58 from kG0
constexpr double kFar76 = 116.0 * (0.6 - 0.5);     // 11.6
constexpr double kNear76 = 116.0 * (0.505 - 0.5);  // 0.58

double lStar(double cubeRoot) { return 116.0 * cubeRoot - 16.0; }
// CIEDE2000 between two greys given the cube roots of their luminances.
double grey2000(double c1, double c2) {
  const double l1 = lStar(c1), l2 = lStar(c2), lBar = (l1 + l2) / 2.0;
  const double d = (lBar - 50.0) * (lBar - 50.0);
  return std::fabs(l1 - l2) / (1.0 + 0.015 * d / std::sqrt(20.0 + d));
}

ImageRGB uniform(int w, int h, float r, float g, float b) {
  ImageRGB im;
  im.width = w;
  im.height = h;
  im.rgb.resize(size_t(w) * size_t(h) * 3);
  for (size_t i = 0; i < im.rgb.size(); i += 3) {
    im.rgb[i] = r;
    im.rgb[i + 1] = g;
    im.rgb[i + 2] = b;
  }
  return im;
}
ImageRGB uniform(int w, int h, float v) { return uniform(w, h, v, v, v); }
void setPixel(ImageRGB& im, int x, int y, float v) {
  float* p = im.pixel(x, y);
  p[0] = p[1] = p[2] = v;
}

// 10x8 = 80 pixels: the reference grey kG0 everywhere; in the test, pixels 0..11 (row-major) are
// grey `far` (ΔE76 11.6 each) and pixels 12..31 grey `near` (ΔE76 0.58 each), the rest equal.
// Mean ΔE76 = (12·11.6 + 20·0.58)/80 = 150.8/80 = 1.885; JND% = 100·12/80 = 15.
// p95: rank ceil(0.95·80) = 76 of 48 zeros, 20 × 0.58, 12 × 11.6 -> 11.6.
struct Pair {
  ImageRGB ref, test;
};
Pair greyPair(float g0, float near, float far) {
  Pair p{uniform(10, 8, g0), uniform(10, 8, g0)};
  for (int i = 0; i < 32; ++i) setPixel(p.test, i % 10, i / 10, i < 12 ? far : near);
  return p;
}

void expectGreyPairStats(const ImageComparison& c) {
  ASSERT_EQ(c.width, 10);
  ASSERT_EQ(c.height, 8);
  EXPECT_NEAR(c.stats76.mean, (12 * kFar76 + 20 * kNear76) / 80.0, 1e-4);
  EXPECT_NEAR(c.stats76.mean, 1.885, 1e-4);
  EXPECT_NEAR(c.stats76.p95, kFar76, 1e-4);
  EXPECT_NEAR(c.stats76.max, kFar76, 1e-4);
  EXPECT_DOUBLE_EQ(c.stats76.jndPercent, 15.0);
  const double far00 = grey2000(0.5, 0.6), near00 = grey2000(0.5, 0.505);
  EXPECT_NEAR(far00, 11.6 / (1.0 + 0.015 * 4.84 / std::sqrt(24.84)), 1e-12);  // L̄ = 47.8
  EXPECT_NEAR(c.stats2000.mean, (12 * far00 + 20 * near00) / 80.0, 1e-4);
  EXPECT_NEAR(c.stats2000.p95, far00, 1e-4);
  EXPECT_NEAR(c.stats2000.max, far00, 1e-4);
  EXPECT_DOUBLE_EQ(c.stats2000.jndPercent, 15.0);
  // Per pixel.
  EXPECT_NEAR(c.dE76[0], kFar76, 1e-4);
  EXPECT_NEAR(c.dE76[12], kNear76, 1e-4);
  EXPECT_NEAR(c.dE2000[12], near00, 1e-4);
  EXPECT_EQ(c.dE76[79], 0.0f);
}

// Reads a PNG back as RGB 8 bit.
ImageRGB8 readPng8(const std::string& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  ImageRGB8 out;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    ADD_FAILURE() << "cannot read " << path << ": " << png.message;
    return out;
  }
  png.format = PNG_FORMAT_RGB;
  out.rgb.resize(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, out.rgb.data(), 0, nullptr)) {
    ADD_FAILURE() << "cannot decode " << path << ": " << png.message;
    png_image_free(&png);
    return ImageRGB8{};
  }
  out.width = int(png.width);
  out.height = int(png.height);
  png_image_free(&png);
  return out;
}

const uint8_t* px(const ImageRGB8& im, int x, int y) { return &im.rgb[(size_t(y) * im.width + x) * 3]; }
bool isColour(const ImageRGB8& im, int x, int y, int r, int g, int b) {
  const uint8_t* p = px(im, x, y);
  return p[0] == r && p[1] == g && p[2] == b;
}
int countColour(const ImageRGB8& im, int x0, int y0, int x1, int y1, int r, int g, int b) {
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) n += isColour(im, x, y, r, g, b);
  return n;
}

std::string errorOf(const ImageRGB& ref, const ImageRGB& test) {
  try {
    compareImages(ref, test, {}, "ref.exr", "test.exr");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

// ---------------------------------------------------------------- statistics

TEST(CompareImages, IdenticalImagesGiveZero) {
  ImageRGB im = uniform(7, 5, 0.0f);
  for (size_t i = 0; i < im.rgb.size(); ++i) im.rgb[i] = float((i * 37) % 101) / 40.0f;  // 0 .. 2.5
  for (const DisplaySettings d :
       {DisplaySettings{}, DisplaySettings{1.5f, ToneMapping::Reinhard}, DisplaySettings{-2.0f, ToneMapping::Aces}}) {
    const ImageComparison c = compareImages(im, im, d);
    ASSERT_EQ(c.dE76.size(), 35u);
    ASSERT_EQ(c.dE2000.size(), 35u);
    for (size_t i = 0; i < 35; ++i) {
      EXPECT_EQ(c.dE76[i], 0.0f);
      EXPECT_EQ(c.dE2000[i], 0.0f);
    }
    for (const DeltaEStats& s : {c.stats76, c.stats2000}) {
      EXPECT_EQ(s.mean, 0.0);
      EXPECT_EQ(s.p95, 0.0);
      EXPECT_EQ(s.max, 0.0);
      EXPECT_EQ(s.jndPercent, 0.0);
    }
  }
}

TEST(CompareImages, GreyPairGivesTheDerivedMeanAndJnd) {
  const Pair p = greyPair(kG0, kGNear, kGFar);
  expectGreyPairStats(compareImages(p.ref, p.test, {}));
  // Symmetric: swapping the images changes no ΔE.
  expectGreyPairStats(compareImages(p.test, p.ref, {}));
}

TEST(CompareImages, ExposureIsAppliedToBothFirst) {
  // One stop less in the files, +1 stop at display: the same displayed greys as above.
  const Pair p = greyPair(kG0 / 2, kGNear / 2, kGFar / 2);
  expectGreyPairStats(compareImages(p.ref, p.test, {1.0f, ToneMapping::None}));
  // Two stops more in the files, −2 stops at display.
  const Pair q = greyPair(kG0 * 4, kGNear * 4, kGFar * 4);
  expectGreyPairStats(compareImages(q.ref, q.test, {-2.0f, ToneMapping::None}));
  // Without the exposure, the 4x files clip differently: 0.5, 0.515, 0.864 are other greys.
  EXPECT_GT(std::fabs(compareImages(q.ref, q.test, {}).stats76.mean - 1.885), 0.1);
}

TEST(CompareImages, ToneMappingIsAppliedToBothFirst) {
  // Reinhard: x/(1+x) = v for x = v/(1 − v); files holding those x display as the greys above.
  auto inv = [](float v) { return v / (1.0f - v); };
  const Pair p = greyPair(inv(kG0), inv(kGNear), inv(kGFar));
  expectGreyPairStats(compareImages(p.ref, p.test, {0.0f, ToneMapping::Reinhard}));

  // 1.0 against 2.0: both clip to white without tone mapping (ΔE 0); with Reinhard they show as
  // 1/2 and 2/3, ΔE76 = 116·(cbrt(2/3) − cbrt(1/2)).
  const ImageRGB one = uniform(4, 4, 1.0f), two = uniform(4, 4, 2.0f);
  EXPECT_EQ(compareImages(one, two, {}).stats76.max, 0.0);
  const double reinhard = 116.0 * (std::cbrt(2.0 / 3.0) - std::cbrt(0.5));
  const ImageComparison r = compareImages(one, two, {0.0f, ToneMapping::Reinhard});
  EXPECT_NEAR(r.stats76.mean, reinhard, 1e-4);
  EXPECT_DOUBLE_EQ(r.stats76.jndPercent, 100.0);
  EXPECT_NEAR(r.stats2000.mean, grey2000(std::cbrt(0.5), std::cbrt(2.0 / 3.0)), 1e-4);

  // ACES (Narkowicz's fit): f(1) = 2.54/3.16 and f(10) = 1 (saturated above 7.24), so 1.0 against
  // 10.0 gives ΔE76 = 116·(1 − cbrt(2.54/3.16)) = 8.1450 on every pixel.
  const ImageRGB ten = uniform(4, 4, 10.0f);
  const ImageComparison a = compareImages(one, ten, {0.0f, ToneMapping::Aces});
  EXPECT_NEAR(a.stats76.mean, 116.0 * (1.0 - std::cbrt(2.54 / 3.16)), 1e-4);
  EXPECT_NEAR(a.stats76.max, a.stats76.mean, 1e-5);
}

TEST(CompareImages, ColourDifferenceFromPublishedLab) {
  // Linear sRGB red (1, 0, 0) is L* = 53.2408, a* = 80.0925, b* = 67.2032 (D65; Lindbloom's
  // calculator); black is (0, 0, 0), so ΔE76 = sqrt(53.2408² + 80.0925² + 67.2032²) = 117.3272.
  // 5 of 20 pixels red: mean 117.3272/4, JND 25%.
  const ImageRGB ref = uniform(5, 4, 0.0f);
  ImageRGB test = ref;
  for (int x = 0; x < 5; ++x) test.pixel(x, 2)[0] = 1.0f;
  const ImageComparison c = compareImages(ref, test, {});
  EXPECT_NEAR(c.stats76.max, 117.3272, 2e-3);
  EXPECT_NEAR(c.stats76.mean, 117.3272 / 4.0, 1e-3);
  EXPECT_DOUBLE_EQ(c.stats76.jndPercent, 25.0);
  EXPECT_DOUBLE_EQ(c.stats2000.jndPercent, 25.0);
  EXPECT_GT(c.stats2000.max, 2.3);
  EXPECT_LT(c.stats2000.max, c.stats76.max);  // CIEDE2000 compresses large chroma differences
}

TEST(CompareImages, P95IsTheNearestRank) {
  // 20 pixels; test pixel i is the grey (0.5 + 0.01·i)³, so ΔE76_i = 1.16·i (i = 0..19).
  // p95 = rank ceil(0.95·20) = 19 in ascending order = 1.16·18 = 20.88; max = 1.16·19 = 22.04;
  // mean = 1.16·190/20 = 11.02; JND: ΔE > 2.3 for i ≥ 2 (1.16 is under, 2.32 over): 18/20 = 90%.
  const ImageRGB ref = uniform(5, 4, kG0);
  ImageRGB test = ref;
  for (int i = 0; i < 20; ++i) {
    const double c = 0.5 + 0.01 * i;
    setPixel(test, i % 5, i / 5, float(c * c * c));
  }
  const ImageComparison c = compareImages(ref, test, {});
  EXPECT_NEAR(c.stats76.p95, 20.88, 1e-4);
  EXPECT_NEAR(c.stats76.max, 22.04, 1e-4);
  EXPECT_NEAR(c.stats76.mean, 11.02, 1e-4);
  EXPECT_DOUBLE_EQ(c.stats76.jndPercent, 90.0);
  // With 100 pixels rank 95 is the 95th value exactly; with 10, rank ceil(9.5) = 10 is the max.
  const ImageRGB ref10 = uniform(10, 1, kG0);
  ImageRGB test10 = ref10;
  for (int i = 0; i < 10; ++i) {
    const double c3 = 0.5 + 0.01 * i;
    setPixel(test10, i, 0, float(c3 * c3 * c3));
  }
  EXPECT_NEAR(compareImages(ref10, test10, {}).stats76.p95, 1.16 * 9, 1e-4);
}

TEST(CompareImages, SizeMismatchNamesTheTestImage) {
  EXPECT_EQ(errorOf(uniform(12, 8, 0.5f), uniform(10, 8, 0.5f)),
            "test.exr: size 10x8 differs from the reference's 12x8");
  EXPECT_EQ(errorOf(uniform(12, 8, 0.5f), uniform(12, 9, 0.5f)),
            "test.exr: size 12x9 differs from the reference's 12x8");
  // Default names.
  try {
    compareImages(uniform(2, 2, 0.5f), uniform(3, 2, 0.5f), {});
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "test: size 3x2 differs from the reference's 2x2");
  }
}

TEST(CompareImages, NonFiniteValuesAreCountedAndNamed) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  ImageRGB bad = uniform(4, 3, 0.5f);
  bad.rgb[0] = nan;
  bad.rgb[5] = inf;
  bad.rgb[35] = -inf;
  EXPECT_EQ(errorOf(bad, uniform(4, 3, 0.5f)), "ref.exr: holds 3 non-finite values");
  EXPECT_EQ(errorOf(uniform(4, 3, 0.5f), bad), "test.exr: holds 3 non-finite values");
  ImageRGB one = uniform(4, 3, 0.5f);
  one.rgb[7] = nan;
  EXPECT_EQ(errorOf(uniform(4, 3, 0.5f), one), "test.exr: holds 1 non-finite value");
  // The reference is checked first.
  EXPECT_EQ(errorOf(one, bad), "ref.exr: holds 1 non-finite value");
}

// ---------------------------------------------------------------- font and text

TEST(BitmapFont, CoversTheLabelCharacters) {
  const std::string required = "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ%.-: ";
  std::set<std::vector<uint8_t>> seen;
  for (char c : required) {
    EXPECT_TRUE(fontHasGlyph(c)) << c;
    const uint8_t* g = fontGlyph(c);
    std::vector<uint8_t> rows(g, g + kFontHeight);
    for (uint8_t r : rows) EXPECT_LT(r, 32) << c;  // 5 columns
    EXPECT_TRUE(seen.insert(rows).second) << "glyph of '" << c << "' repeats another";
  }
  // Lower case draws as upper case; unknown characters as '?'.
  EXPECT_EQ(fontGlyph('j'), fontGlyph('J'));
  EXPECT_FALSE(fontHasGlyph('@'));
  EXPECT_EQ(fontGlyph('@'), fontGlyph('?'));
  EXPECT_EQ(fontTextWidth("", 3), 0);
  EXPECT_EQ(fontTextWidth("A", 1), 5);
  EXPECT_EQ(fontTextWidth("JND", 2), (3 * 6 - 1) * 2);
}

TEST(BitmapFont, DrawTextScalesAndClips) {
  ImageRGB8 im{12, 16, std::vector<uint8_t>(12 * 16 * 3, 0)};
  // '1' is ..#.. / .##.. / ..#.. x4 / .###. ; at scale 2 from (0, 0).
  drawText(im, 0, 0, "1", 2, 10, 20, 30);
  EXPECT_TRUE(isColour(im, 4, 0, 10, 20, 30));
  EXPECT_TRUE(isColour(im, 5, 1, 10, 20, 30));
  EXPECT_TRUE(isColour(im, 0, 0, 0, 0, 0));
  EXPECT_TRUE(isColour(im, 2, 2, 10, 20, 30));   // row 1 ".##.."
  EXPECT_TRUE(isColour(im, 2, 4, 0, 0, 0));      // row 2 "..#.."
  EXPECT_TRUE(isColour(im, 2, 12, 10, 20, 30));  // row 6 ".###."
  EXPECT_EQ(countColour(im, 0, 0, 12, 16, 10, 20, 30), (1 + 2 + 1 + 1 + 1 + 1 + 3) * 4);
  // Partly or wholly outside: clipped, no crash.
  drawText(im, -7, -5, "88", 3, 1, 1, 1);
  drawText(im, 10, 14, "WIDE TEXT", 1, 1, 1, 1);
  drawText(im, 1000, -1000, "X", 1, 1, 1, 1);
  EXPECT_GT(countColour(im, 0, 0, 12, 16, 1, 1, 1), 0);
}

// ---------------------------------------------------------------- displayImage

TEST(DisplayImageTest, MatchesWritePng) {
  test::TempDir dir;
  ImageRGB im = uniform(6, 3, 0.0f);
  for (size_t i = 0; i < im.rgb.size(); ++i) im.rgb[i] = float(i) / 9.0f;
  for (const DisplaySettings d : {DisplaySettings{}, DisplaySettings{0.5f, ToneMapping::Aces}}) {
    writePng(dir.file("a.png"), im, d.exposureStops, d.toneMapping);
    const ImageRGB8 png = readPng8(dir.file("a.png"));
    const ImageRGB8 mem = displayImage(im, d);
    EXPECT_EQ(mem.width, 6);
    EXPECT_EQ(mem.height, 3);
    EXPECT_EQ(mem.rgb, png.rgb);
  }
}

// ---------------------------------------------------------------- heat map

TEST(Heatmap, ViridisRampWithLegendRows) {
  // 64x10: column x holds ΔE = x/63·12.5 (the scale's top is 10, so x ≥ 51 saturates).
  const int w = 64, h = 10;
  std::vector<float> dE(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) dE[size_t(y) * w + x] = float(x) / 63.0f * 12.5f;
  dE[0] = 5.0f;  // mid-scale
  dE[1] = std::numeric_limits<float>::quiet_NaN();
  dE[2] = -1.0f;
  const ImageRGB8 im = deltaEHeatmapImage(dE, w, h, 10.0f);
  // The legend adds 23 rows at widths under 400 (23·s, s = clamp(width/200, 1, 4)).
  ASSERT_EQ(im.width, w);
  ASSERT_EQ(im.height, h + 23);
  // Viridis ends: 0 -> #440154, top -> #fde725 (matplotlib's first and last entries in 8 bit).
  EXPECT_TRUE(isColour(im, 0, 5, 0x44, 0x01, 0x54));
  EXPECT_TRUE(isColour(im, 63, 5, 0xfd, 0xe7, 0x25));
  EXPECT_TRUE(isColour(im, 55, 5, 0xfd, 0xe7, 0x25));  // above the scale: saturated
  EXPECT_TRUE(isColour(im, 1, 0, 0xfd, 0xe7, 0x25));   // NaN: off the scale
  EXPECT_TRUE(isColour(im, 2, 0, 0x44, 0x01, 0x54));   // negative: bottom
  // Mid-scale: 127.5/255 of the way, between matplotlib's entries 112 and 128 (15.5/16 of the way):
  // (0.128240, 0.565104, 0.550766) -> (33, 144, 140) (viridis's familiar #21918c is entry 128).
  EXPECT_TRUE(isColour(im, 0, 0, 33, 144, 140))
      << int(px(im, 0, 0)[0]) << "," << int(px(im, 0, 0)[1]) << "," << int(px(im, 0, 0)[2]);
  // Perceptually ordered: the luma rises along the ramp.
  double last = -1;
  for (int x = 3; x < 51; ++x) {
    const uint8_t* p = px(im, x, 5);
    const double luma = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    EXPECT_GT(luma, last) << x;
    last = luma;
  }
  // The legend: black background rows, the colour bar (rows h+3 .. h+10) running from the bottom
  // colour to the top colour, white tick marks, white label text.
  EXPECT_TRUE(isColour(im, 30, h + 1, 0, 0, 0));
  EXPECT_TRUE(isColour(im, 0, h + 5, 0x44, 0x01, 0x54));
  EXPECT_TRUE(isColour(im, 63, h + 5, 0xfd, 0xe7, 0x25));
  EXPECT_TRUE(isColour(im, 0, h + 11, 255, 255, 255));                   // tick at 0
  EXPECT_TRUE(isColour(im, 63, h + 11, 255, 255, 255));                  // tick at the max
  EXPECT_TRUE(isColour(im, 31, h + 11, 255, 255, 255));                  // tick at max/2
  EXPECT_GT(countColour(im, 0, h + 14, 12, h + 21, 255, 255, 255), 5);   // "0"
  EXPECT_GT(countColour(im, 50, h + 14, 64, h + 21, 255, 255, 255), 5);  // "10"
  EXPECT_GT(countColour(im, 26, h + 14, 38, h + 21, 255, 255, 255), 5);  // "5"
  // "0" at the left edge is the '0' glyph: its top row .###. at x = 1..3.
  EXPECT_TRUE(isColour(im, 0, h + 14, 0, 0, 0));
  EXPECT_TRUE(isColour(im, 1, h + 14, 255, 255, 255));
}

TEST(Heatmap, WrittenPngMatchesAndScalesTheLegend) {
  test::TempDir dir;
  const int w = 420, h = 30;  // s = 2: 46 legend rows
  std::vector<float> dE(size_t(w) * h, 1.0f);
  writeDeltaEHeatmap(dir.file("heat.png"), dE, w, h, 2.3f);
  const ImageRGB8 png = readPng8(dir.file("heat.png"));
  EXPECT_EQ(png.width, w);
  EXPECT_EQ(png.height, h + 46);
  EXPECT_EQ(png.rgb, deltaEHeatmapImage(dE, w, h, 2.3f).rgb);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"heat.png"});  // no temporary left
  // Bad arguments.
  EXPECT_THROW(deltaEHeatmapImage(dE, w, h + 1, 10.0f), std::invalid_argument);
  EXPECT_THROW(deltaEHeatmapImage(dE, w, h, 0.0f), std::invalid_argument);
}

// ---------------------------------------------------------------- JND map

TEST(JndMap, RedExactlyOverTheJndWithThePercentagePrinted) {
  // 64x48, reference grey kG0; in the lower half, every 3rd pixel of every 2nd row is kGFar
  // (ΔE76 11.6, red) and the pixel after it kGNear (0.58, grey).
  const int w = 64, h = 48;
  const ImageRGB ref = uniform(w, h, kG0);
  ImageRGB test = ref;
  for (int y = 24; y < h; y += 2)
    for (int x = 0; x + 1 < w; x += 3) {
      setPixel(test, x, y, kGFar);
      setPixel(test, x + 1, y, kGNear);
    }
  const ImageComparison c = compareImages(ref, test, {});
  const int over = 12 * 21;  // rows 24, 26, ..., 46 and x = 0, 3, ..., 60
  EXPECT_DOUBLE_EQ(c.stats76.jndPercent, 100.0 * over / (w * h));
  test::TempDir dir;
  writeJndMap(dir.file("jnd.png"), test, {}, c.dE76, c.stats76.jndPercent);
  const ImageRGB8 im = readPng8(dir.file("jnd.png"));
  ASSERT_EQ(im.width, w);
  ASSERT_EQ(im.height, h);
  EXPECT_EQ(im.rgb, jndMapImage(test, {}, c.dE76, c.stats76.jndPercent).rgb);
  // Outside the label box (top-left, 11 rows): red exactly where ΔE76 > 2.3, grey elsewhere, the
  // grey being the displayed luminance: kG0 shows as 99 (sRGB of 0.125), kGNear as 101.
  const ImageRGB8 shown = displayImage(test, {});
  int red = 0;
  for (int y = 11; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const uint8_t* p = px(im, x, y);
      if (c.dE76[size_t(y) * w + x] > 2.3f) {
        EXPECT_TRUE(isColour(im, x, y, 255, 0, 0)) << x << "," << y;
        ++red;
      } else {
        EXPECT_TRUE(p[0] == p[1] && p[1] == p[2]) << x << "," << y;
        EXPECT_NEAR(p[0], px(shown, x, y)[0], 1) << x << "," << y;
      }
    }
  EXPECT_EQ(red, over);
  EXPECT_TRUE(isColour(im, 5, 30, 99, 99, 99));
  EXPECT_TRUE(isColour(im, 3, 24, 255, 0, 0));
  EXPECT_TRUE(isColour(im, 4, 24, 101, 101, 101));
  // The label "JND 8.20%" (252/3072 = 8.203%): yellow text on a black box
  // 2 + width("JND 8.20%") + 2 = 2 + 53 + 2 = 57 pixels wide, 11 high.
  ASSERT_EQ(fontTextWidth("JND 8.20%", 1), 53);
  EXPECT_GT(countColour(im, 0, 0, 57, 11, 255, 255, 0), 40);
  EXPECT_TRUE(isColour(im, 56, 5, 0, 0, 0));
  EXPECT_TRUE(isColour(im, 57, 5, 99, 99, 99));
  EXPECT_TRUE(isColour(im, 5, 10, 0, 0, 0));
  EXPECT_TRUE(isColour(im, 5, 11, 99, 99, 99));
  // The text is exactly the string drawn: compare with drawText on a black box.
  ImageRGB8 label{57, 11, std::vector<uint8_t>(57 * 11 * 3, 0)};
  drawText(label, 2, 2, "JND 8.20%", 1, 255, 255, 0);
  for (int y = 0; y < 11; ++y)
    for (int x = 0; x < 57; ++x)
      for (int k = 0; k < 3; ++k) ASSERT_EQ(px(im, x, y)[k], px(label, x, y)[k]) << x << "," << y;
}

TEST(JndMap, UsesTheDisplayTransform) {
  // Luminance grey of a coloured pixel: (1, 0, 0) shows as Y = 0.2126 -> sRGB 0.4984 -> 127;
  // with −1 stop (0.5, 0, 0): Y = 0.1063 -> 0.3596 -> 92.
  const ImageRGB im = uniform(40, 30, 1.0f, 0.0f, 0.0f);
  const std::vector<float> zero(40 * 30, 0.0f);
  EXPECT_TRUE(isColour(jndMapImage(im, {}, zero, 0.0), 20, 20, 127, 127, 127));
  EXPECT_TRUE(isColour(jndMapImage(im, {-1.0f, ToneMapping::None}, zero, 0.0), 20, 20, 92, 92, 92));
  EXPECT_THROW(jndMapImage(im, {}, std::vector<float>(10, 0.0f), 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace narval
