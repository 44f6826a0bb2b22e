// image_io_test.cpp: tone mapping curves (kernels/shared/tonemap.h), the display transform, EXR and
// PNG output (host/image/). Reference values are derived in the comments beside them.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfStringVectorAttribute.h>
#include <ImfIntAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfDoubleAttribute.h>
#include <ImfOutputFile.h>
#include <half.h>
#include <gtest/gtest.h>
#include <png.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "core/input_error.h"
#include "image/display_transform.h"
#include "image/image.h"
#include "shared/tonemap.h"
#include "test_support.h"

namespace fs = std::filesystem;
using narval::ImageRGB;
using narval::ToneMapping;
using narval::test::readFile;
using narval::test::TempDir;
using narval::test::writeFile;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
const float kNaN = std::numeric_limits<float>::quiet_NaN();

uint32_t bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

ImageRGB makeImage(int w, int h, const std::vector<float>& rgb) {
  ImageRGB image;
  image.width = w;
  image.height = h;
  image.rgb = rgb;
  image.rgb.resize(size_t(w) * h * 3, 0.0f);
  return image;
}

// A row of grey pixels, one per value.
ImageRGB greyRow(const std::vector<float>& values) {
  std::vector<float> rgb;
  for (float v : values) rgb.insert(rgb.end(), {v, v, v});
  return makeImage(int(values.size()), 1, rgb);
}

ImageRGB noiseImage(int w, int h, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1000.0f);
  ImageRGB image = makeImage(w, h, {});
  for (float& v : image.rgb) v = u(rng);
  return image;
}

// Reads a PNG back with libpng's simplified API as RGB 8 bit. For an 8-bit sRGB file this is the
// identity on the stored bytes (PngTest.EveryCodeRoundTrips checks that).
std::vector<uint8_t> readPng(const std::string& path, int* width, int* height) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    ADD_FAILURE() << "cannot read " << path << ": " << png.message;
    return {};
  }
  png.format = PNG_FORMAT_RGB;
  std::vector<uint8_t> pixels(PNG_IMAGE_SIZE(png));
  if (!png_image_finish_read(&png, nullptr, pixels.data(), 0, nullptr)) {
    ADD_FAILURE() << "cannot decode " << path << ": " << png.message;
    png_image_free(&png);
    return {};
  }
  *width = int(png.width);
  *height = int(png.height);
  png_image_free(&png);
  return pixels;
}

// Grey values written through writePng, read back (one byte per pixel; R == G == B is checked).
std::vector<int> pngGreys(const std::vector<float>& values, float exposure, ToneMapping tm) {
  TempDir dir;
  const std::string path = dir.file("grey.png");
  narval::writePng(path, greyRow(values), exposure, tm);
  int w = 0, h = 0;
  const std::vector<uint8_t> px = readPng(path, &w, &h);
  EXPECT_EQ(w, int(values.size()));
  EXPECT_EQ(h, 1);
  std::vector<int> out;
  for (size_t i = 0; i + 2 < px.size(); i += 3) {
    EXPECT_EQ(px[i], px[i + 1]);
    EXPECT_EQ(px[i], px[i + 2]);
    out.push_back(px[i]);
  }
  return out;
}

// Lowers the file size limit for the scope (SIGXFSZ ignored, so writes past it fail with EFBIG):
// a write that fails half-way, even as root, for whom directory permissions stop nothing.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &old_);
    oldHandler_ = signal(SIGXFSZ, SIG_IGN);
    rlimit lim = old_;
    lim.rlim_cur = bytes;
    ok_ = setrlimit(RLIMIT_FSIZE, &lim) == 0;
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_);
    signal(SIGXFSZ, oldHandler_);
  }
  bool ok() const { return ok_; }

 private:
  rlimit old_{};
  void (*oldHandler_)(int) = nullptr;
  bool ok_ = false;
};

template <typename F>
std::string runtimeErrorOf(F f) {
  try {
    f();
  } catch (const narval::InputError& e) {
    return std::string("InputError: ") + e.what();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no exception)";
}

template <typename F>
std::string inputErrorOf(F f) {
  try {
    f();
  } catch (const narval::InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("not an InputError: ") + e.what();
  }
  return "(no exception)";
}

}  // namespace

// ---------------------------------------------------------------- tone mapping curves

TEST(TonemapTest, ReinhardReferenceValues) {
  // x / (1 + x): 1 -> 1/2, 3 -> 3/4, 0 -> 0; exact in float.
  EXPECT_EQ(tonemap_reinhard(0.0f), 0.0f);
  EXPECT_EQ(tonemap_reinhard(1.0f), 0.5f);
  EXPECT_EQ(tonemap_reinhard(3.0f), 0.75f);
  EXPECT_LT(tonemap_reinhard(1e6f), 1.0f);
}

TEST(TonemapTest, AcesNarkowiczReferenceValues) {
  // f(x) = x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)
  // f(0) = 0 / 0.14 = 0.
  EXPECT_EQ(tonemap_aces(0.0f), 0.0f);
  // f(1) = (2.51 + 0.03) / (2.43 + 0.59 + 0.14) = 2.54 / 3.16 = 0.803797468...
  EXPECT_NEAR(tonemap_aces(1.0f), 2.54 / 3.16, 1e-6);
  // f(0.18) = 0.18(0.4518 + 0.03) / (0.18(0.4374 + 0.59) + 0.14) = 0.086724 / 0.324932 = 0.266899...
  EXPECT_NEAR(tonemap_aces(0.18f), 0.086724 / 0.324932, 1e-6);
  // f crosses 1 at the root of 0.08x^2 - 0.56x - 0.14 = 0, x = 7.24166; clamped to 1 above.
  EXPECT_LT(tonemap_aces(7.2f), 1.0f);
  EXPECT_EQ(tonemap_aces(7.3f), 1.0f);
  EXPECT_EQ(tonemap_aces(100.0f), 1.0f);
  EXPECT_EQ(tonemap_aces(3.0e38f), 1.0f);  // no inf/inf = NaN for huge input
  EXPECT_EQ(tonemap_aces(kInf), 1.0f);
  // Negative input is treated as 0 (the raw rational function tends to 2.51/2.43 at -inf).
  EXPECT_EQ(tonemap_aces(-0.001f), 0.0f);
  EXPECT_EQ(tonemap_aces(-100.0f), 0.0f);
  EXPECT_TRUE(std::isnan(tonemap_aces(kNaN)));
  // Monotone non-decreasing on [0, 10].
  float prev = 0.0f;
  for (int i = 0; i <= 10000; ++i) {
    const float y = tonemap_aces(i * 0.001f);
    ASSERT_GE(y, prev) << "x = " << i * 0.001f;
    prev = y;
  }
}

TEST(TonemapTest, ApplyDispatchesByKind) {
  EXPECT_EQ(tonemap_apply(TONEMAP_NONE, 2.5f), 2.5f);
  EXPECT_EQ(tonemap_apply(TONEMAP_REINHARD, 1.0f), 0.5f);
  EXPECT_EQ(tonemap_apply(TONEMAP_ACES, 1.0f), tonemap_aces(1.0f));
  for (int kind : {TONEMAP_NONE, TONEMAP_REINHARD, TONEMAP_ACES}) {
    EXPECT_EQ(tonemap_apply(kind, -5.0f), 0.0f) << kind;  // also avoids Reinhard's pole at -1
    EXPECT_EQ(tonemap_apply(kind, 0.0f), 0.0f) << kind;
  }
  // The host enum and the shared defines agree.
  EXPECT_EQ(narval::toneMappingKind(ToneMapping::None), TONEMAP_NONE);
  EXPECT_EQ(narval::toneMappingKind(ToneMapping::Reinhard), TONEMAP_REINHARD);
  EXPECT_EQ(narval::toneMappingKind(ToneMapping::Aces), TONEMAP_ACES);
}

TEST(TonemapTest, SrgbPublishedBreakpoints) {
  // IEC 61966-2-1: encode is 12.92x up to 0.0031308 -> 0.04045 (12.92 * 0.0031308 = 0.040449936),
  // decode is x/12.92 up to 0.04045 -> 0.0031308 (0.04045 / 12.92 = 0.00313080495).
  EXPECT_NEAR(srgb_encode(0.0031308f), 0.04045f, 1e-6f);
  EXPECT_NEAR(srgb_decode(0.04045f), 0.0031308f, 1e-8f);
  // The power branch meets the linear one there: 1.055 * 0.0031308^(1/2.4) - 0.055 = 0.0404499075.
  EXPECT_NEAR(srgb_encode(0.0031309f), 0.04045f, 1e-5f);
  EXPECT_NEAR(srgb_decode(0.040451f), 0.0031308f, 1e-7f);
  EXPECT_EQ(srgb_encode(0.0f), 0.0f);
  EXPECT_EQ(srgb_decode(0.0f), 0.0f);
  EXPECT_NEAR(srgb_encode(1.0f), 1.0f, 1e-6f);
  EXPECT_NEAR(srgb_decode(1.0f), 1.0f, 1e-6f);
  // 1.055 * 0.5^(1/2.4) - 0.055 = 1.055 * 0.7491535 - 0.055 = 0.7353570.
  EXPECT_NEAR(srgb_encode(0.5f), 0.7353570f, 1e-6f);
  // ((0.5 + 0.055) / 1.055)^2.4 = 0.5260664^2.4 = 0.2140411.
  EXPECT_NEAR(srgb_decode(0.5f), 0.2140411f, 1e-6f);
}

TEST(TonemapTest, SrgbRoundTrip) {
  for (int i = 0; i <= 100000; ++i) {
    const float x = i * 1e-5f;
    ASSERT_NEAR(srgb_decode(srgb_encode(x)), x, 1e-6f) << "x = " << x;
    ASSERT_NEAR(srgb_encode(srgb_decode(x)), x, 1e-6f) << "x = " << x;
  }
}

// ---------------------------------------------------------------- display transform, ImageRGB

TEST(ImageTest, PixelRowZeroIsTop) {
  ImageRGB image = makeImage(3, 2, {});
  image.pixel(2, 1)[1] = 7.0f;
  EXPECT_EQ(image.rgb[(1 * 3 + 2) * 3 + 1], 7.0f);
}

TEST(ImageTest, DisplayTransformNonFiniteAndRange) {
  const float one = narval::exposureScale(0.0f);
  EXPECT_EQ(one, 1.0f);
  EXPECT_EQ(narval::exposureScale(1.0f), 2.0f);
  EXPECT_EQ(narval::exposureScale(-2.0f), 0.25f);
  for (ToneMapping tm : {ToneMapping::None, ToneMapping::Reinhard, ToneMapping::Aces}) {
    EXPECT_EQ(narval::displayLinear(kNaN, one, tm), 0.0f);
    EXPECT_EQ(narval::displayLinear(kInf, one, tm), 1.0f);
    EXPECT_EQ(narval::displayLinear(-kInf, one, tm), 0.0f);
    EXPECT_EQ(narval::displayLinear(-3.0f, one, tm), 0.0f);
    EXPECT_EQ(narval::displayLinear(0.0f, one, tm), 0.0f);
    EXPECT_EQ(narval::displayLinear(3.0e38f, 4.0f, tm), 1.0f);  // overflows to +inf after exposure
  }
  // Without tone mapping the linear value is only clipped (the `compare` default).
  EXPECT_EQ(narval::displayLinear(0.3f, one, ToneMapping::None), 0.3f);
  EXPECT_EQ(narval::displayLinear(1.7f, one, ToneMapping::None), 1.0f);
  EXPECT_EQ(narval::displayTo8Bit(0.0f), 0);
  EXPECT_EQ(narval::displayTo8Bit(1.0f), 255);
  EXPECT_EQ(narval::displayTo8Bit(0.5f), 128);  // 127.5 + 0.5 = 128
}

// ---------------------------------------------------------------- EXR

TEST(ExrTest, RoundTripIsBitExactWithAttributes) {
  TempDir dir;
  const std::string path = dir.file("round.exr");
  ImageRGB image = noiseImage(7, 5, 1);
  const std::vector<float> special = {
      0.0f, -0.0f, 1.0f, -1.0f, -3.5f, 0.1f, 1e-40f /* denormal */,
      std::numeric_limits<float>::denorm_min(), -std::numeric_limits<float>::denorm_min(),
      std::numeric_limits<float>::min(), std::numeric_limits<float>::max(),
      -std::numeric_limits<float>::max(), 1e30f, 65504.0f, 65520.0f /* beyond half */, 1e-8f,
      kInf, -kInf, kNaN};
  for (size_t i = 0; i < special.size(); ++i) image.rgb[i * 2] = special[i];
  const std::vector<std::pair<std::string, std::string>> attributes = {
      {"spp", "1024"}, {"seed", "7"}, {"narval.scene", "clouds/a b.json"}, {"empty", ""}};
  std::vector<narval::ExrAttribute> typed;
  for (const auto& [name, value] : attributes) typed.push_back({name, value});
  // Numbers stored typed, read back as the fewest digits that give the same value.
  typed.push_back({"count", 42});
  typed.push_back({"ratio", 0.1f});
  typed.push_back({"seconds", 0.1});
  typed.push_back({"big", 4294967295.0});
  typed.push_back({"list", std::vector<std::string>{"a=1", "b c"}});
  narval::writeExr(path, image, typed);

  const ImageRGB back = narval::readExr(path);
  ASSERT_EQ(back.width, 7);
  ASSERT_EQ(back.height, 5);
  ASSERT_EQ(back.rgb.size(), image.rgb.size());
  for (size_t i = 0; i < image.rgb.size(); ++i)
    ASSERT_EQ(bits(back.rgb[i]), bits(image.rgb[i])) << "index " << i << " value " << image.rgb[i];

  std::map<std::string, std::string> expected(attributes.begin(), attributes.end());
  expected.insert({{"count", "42"}, {"ratio", "0.1"}, {"seconds", "0.1"}, {"big", "4294967295"}, {"list", "a=1\nb c"}});
  // Every header has OpenEXR's two float attributes besides (their defaults, 1).
  expected.insert({{"pixelAspectRatio", "1"}, {"screenWindowWidth", "1"}});
  EXPECT_EQ(narval::readExrAttributes(path), expected);
  {
    Imf::InputFile typedFile(path.c_str());
    const Imf::Header& h = typedFile.header();
    ASSERT_NE(h.findTypedAttribute<Imf::IntAttribute>("count"), nullptr);
    ASSERT_NE(h.findTypedAttribute<Imf::FloatAttribute>("ratio"), nullptr);
    ASSERT_NE(h.findTypedAttribute<Imf::DoubleAttribute>("seconds"), nullptr);
    ASSERT_NE(h.findTypedAttribute<Imf::StringVectorAttribute>("list"), nullptr);
    EXPECT_EQ(h.findTypedAttribute<Imf::DoubleAttribute>("big")->value(), 4294967295.0);
  }
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"round.exr"});  // no temporary left

  // 32-bit float R, G, B, ZIP compressed.
  Imf::InputFile file(path.c_str());
  EXPECT_EQ(file.header().compression(), Imf::ZIP_COMPRESSION);
  int channels = 0;
  for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it, ++channels)
    EXPECT_EQ(it.channel().type, Imf::FLOAT) << it.name();
  EXPECT_EQ(channels, 3);
}

TEST(ExrTest, OverwritesAnExistingFile) {
  TempDir dir;
  const std::string path = dir.file("out.exr");
  narval::writeExr(path, makeImage(2, 2, {1, 2, 3}));
  narval::writeExr(path, makeImage(3, 1, {4, 5, 6}), {{"pass", "2"}});
  const ImageRGB back = narval::readExr(path);
  EXPECT_EQ(back.width, 3);
  EXPECT_EQ(back.height, 1);
  EXPECT_EQ(back.rgb[0], 4.0f);
  EXPECT_EQ(narval::readExrAttributes(path).at("pass"), "2");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.exr"});
}

TEST(ExrTest, ReadsAnyDataWindowAndHalfChannels) {
  // Written directly with OpenEXR: data window (10,20)-(13,22), HALF channels plus an extra one.
  TempDir dir;
  const std::string path = dir.file("window.exr");
  const Imath::Box2i window(Imath::V2i(10, 20), Imath::V2i(13, 22));
  Imf::Header header(Imath::Box2i(Imath::V2i(0, 0), Imath::V2i(31, 31)), window);
  for (const char* c : {"R", "G", "B", "A"}) header.channels().insert(c, Imf::Channel(Imf::HALF));
  std::vector<half> data(4 * 3 * 4);
  for (size_t i = 0; i < data.size(); ++i) data[i] = half(float(i) * 0.5f);  // exact in half
  Imf::FrameBuffer frame;
  const char* names[] = {"R", "G", "B", "A"};
  for (int c = 0; c < 4; ++c)
    frame.insert(names[c], Imf::Slice::Make(Imf::HALF, &data[c], window, 4 * sizeof(half), 16 * sizeof(half)));
  {
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(frame);
    out.writePixels(3);
  }
  const ImageRGB image = narval::readExr(path);
  ASSERT_EQ(image.width, 4);
  ASSERT_EQ(image.height, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(image.pixel(x, y)[c], float(data[(y * 4 + x) * 4 + c])) << x << "," << y << "," << c;
}

TEST(ExrTest, MissingChannelIsAnInputError) {
  TempDir dir;
  const std::string path = dir.file("grey.exr");
  Imf::Header header(2, 2);
  header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
  std::vector<float> y(4, 0.5f);
  Imf::FrameBuffer frame;
  frame.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(y.data()), sizeof(float), 2 * sizeof(float)));
  {
    Imf::OutputFile out(path.c_str(), header);
    out.setFrameBuffer(frame);
    out.writePixels(2);
  }
  EXPECT_EQ(inputErrorOf([&] { narval::readExr(path); }), path + ": no R channel (channels: Y)");
}

// UINT channels (the path tracer's accumulator words) round-trip bit for bit, every 32-bit value
// included (a FLOAT conversion would merge values above 2^24); the one-read form gives the same
// pixels, words and attributes as the separate reads, and the header form the size; a FLOAT channel
// asked for as UINT is refused by name.
TEST(ExrTest, UintChannelsRoundTripBitExactInOneRead) {
  TempDir dir;
  const std::string path = dir.file("words.exr");
  const ImageRGB image = noiseImage(5, 3, 2);
  std::vector<narval::ExrUintChannel> words = {{"accum.R.w0", {}}, {"accum.R.w1", {}}};
  std::mt19937 rng(9);
  for (auto& c : words)
    for (int i = 0; i < 15; ++i) c.values.push_back(i == 0 ? 0xffffffffu : i == 1 ? 16777217u : uint32_t(rng()));
  narval::writeExr(path, image, {{"narval:spp", 12}}, words);
  const auto separate = narval::readExrUintChannels(path, {"accum.R.w0", "accum.R.w1"});
  const narval::ExrContents once = narval::readExrWithUintChannels(path, {"accum.R.w0", "accum.R.w1"});
  for (size_t c = 0; c < words.size(); ++c) {
    EXPECT_EQ(separate[c].values, words[c].values) << words[c].name;
    EXPECT_EQ(once.uints[c].values, words[c].values) << words[c].name;
  }
  EXPECT_EQ(std::memcmp(once.image.rgb.data(), image.rgb.data(), image.rgb.size() * sizeof(float)), 0);
  EXPECT_EQ(once.attributes.at("narval:spp"), "12");
  const narval::ExrHeader header = narval::readExrHeader(path);
  EXPECT_EQ(header.width, 5);
  EXPECT_EQ(header.height, 3);
  EXPECT_EQ(header.attributes, narval::readExrAttributes(path));
  EXPECT_EQ(inputErrorOf([&] { narval::readExrUintChannels(path, {"R"}); }), path + ": R: not a UINT channel");
  EXPECT_EQ(inputErrorOf([&] { narval::readExrWithUintChannels(path, {"accum.G.w0"}); }),
            path + ": no accum.G.w0 channel (channels: B, G, R, accum.R.w0, accum.R.w1)");
}

TEST(ExrTest, MissingFileIsAnInputError) {
  TempDir dir;
  const std::string path = dir.file("missing.exr");
  EXPECT_EQ(inputErrorOf([&] { narval::readExr(path); }), path + ": file not found");
  EXPECT_EQ(inputErrorOf([&] { narval::readExrAttributes(path); }), path + ": file not found");
  EXPECT_EQ(inputErrorOf([&] { narval::readExr(dir.path().string()); }),
            dir.path().string() + ": is a directory, not an EXR file");
}

TEST(ExrTest, GarbageFileIsAnInputError) {
  TempDir dir;
  const std::string path = dir.file("garbage.exr");
  writeFile(path, "this is not an image\n");
  EXPECT_EQ(inputErrorOf([&] { narval::readExr(path); }), path + ": not an OpenEXR file");
  writeFile(path, "");
  EXPECT_EQ(inputErrorOf([&] { narval::readExr(path); }), path + ": not an OpenEXR file");
}

TEST(ExrTest, TruncatedFileIsAnInputError) {
  TempDir dir;
  const std::string good = dir.file("good.exr");
  narval::writeExr(good, noiseImage(64, 64, 2));
  const std::string bytes = readFile(good);
  for (size_t keep : {size_t(8), size_t(200), bytes.size() / 2, bytes.size() - 1}) {
    const std::string path = dir.file("cut.exr");
    writeFile(path, bytes.substr(0, keep));
    const std::string message = inputErrorOf([&] { narval::readExr(path); });
    EXPECT_EQ(message.rfind(path + ": corrupt OpenEXR file: ", 0), 0u) << "kept " << keep << ": " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST(ExrTest, FailedWriteLeavesExistingFileUntouched) {
  // The write fails half-way (file size limit: works as root too) at several points: in the
  // header, in the pixel data, and at the very last byte (the line offset table, which OpenEXR
  // writes in ~OutputFile and whose errors it swallows, or the final flush).
  TempDir dir;
  const std::string path = dir.file("keep.exr");
  const ImageRGB big = noiseImage(64, 64, 3);
  narval::writeExr(path, big);
  const size_t fullSize = readFile(path).size();
  narval::writeExr(path, makeImage(1, 1, {0.25f, 0.5f, 0.75f}), {{"old", "yes"}});
  const std::string before = readFile(path);
  for (size_t limit : {size_t(100), size_t(4096), fullSize / 2, fullSize - 1}) {
    std::string message;
    {
      FileSizeLimit cap(limit);
      ASSERT_TRUE(cap.ok());
      message = runtimeErrorOf([&] { narval::writeExr(path, big); });
    }
    EXPECT_EQ(message.rfind(path + ": cannot write: ", 0), 0u) << "limit " << limit << ": " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(readFile(path), before) << "limit " << limit;
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.exr"}) << "limit " << limit;
  }
  EXPECT_EQ(narval::readExrAttributes(path).at("old"), "yes");
}

TEST(ExrTest, UnwritableDirectoryLeavesExistingFileUntouched) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root: permissions stop no write (FailedWrite covers it)";
  TempDir dir;
  const std::string path = dir.file("keep.exr");
  narval::writeExr(path, makeImage(1, 1, {1, 2, 3}));
  const std::string before = readFile(path);
  fs::permissions(dir.path(), fs::perms::owner_read | fs::perms::owner_exec);
  EXPECT_EQ(runtimeErrorOf([&] { narval::writeExr(path, makeImage(2, 2, {})); }),
            path + ": cannot write: Permission denied");
  fs::permissions(dir.path(), fs::perms::owner_all);
  EXPECT_EQ(readFile(path), before);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.exr"});
}

TEST(ExrTest, WriteErrorsNameTheFile) {
  TempDir dir;
  const std::string nowhere = dir.file("no/such/dir/out.exr");
  EXPECT_EQ(runtimeErrorOf([&] { narval::writeExr(nowhere, makeImage(1, 1, {})); }),
            nowhere + ": cannot write: No such file or directory");
  const std::string path = dir.file("out.exr");
  EXPECT_EQ(runtimeErrorOf([&] { narval::writeExr(path, ImageRGB{}); }), path + ": cannot write: empty image (0x0)");
  // An attribute whose name clashes with a standard, non-string attribute.
  const std::string message = runtimeErrorOf([&] { narval::writeExr(path, makeImage(1, 1, {}), {{"channels", "x"}}); });
  EXPECT_EQ(message.rfind(path + ": cannot write: attribute \"channels\": ", 0), 0u) << message;
  EXPECT_TRUE(dir.entries().empty());
}

// ---------------------------------------------------------------- PNG

TEST(PngTest, KnownValuesWithoutToneMapping) {
  // srgb(0.5) = 1.055 * 0.5^(1/2.4) - 0.055 = 0.7353570; * 255 = 187.516; + 0.5 = 188.016 -> 188.
  // srgb(0.25) = 1.055 * 0.25^(1/2.4) - 0.055 = 0.5370987; * 255 = 136.960; + 0.5 -> 137.
  // srgb(0.1) = 1.055 * 0.1^(1/2.4) - 0.055 = 0.3491902; * 255 = 89.044; + 0.5 -> 89.
  // srgb(0.001) = 12.92 * 0.001 = 0.01292; * 255 = 3.295; + 0.5 -> 3 (the linear segment).
  // 1 -> 255 and 0 -> 0; above 1 clips; NaN -> 0, +inf -> 255, -inf and negatives -> 0.
  EXPECT_EQ(pngGreys({0.0f, 1.0f, 0.5f, 0.25f, 0.1f, 0.001f, 2.0f, kNaN, kInf, -kInf, -1.0f}, 0.0f,
                     ToneMapping::None),
            (std::vector<int>{0, 255, 188, 137, 89, 3, 255, 0, 255, 0, 0}));
}

TEST(PngTest, ExposureScalesBeforeTheCurve) {
  // 0.25 * 2^1 = 0.5 -> 188; 0.125 * 2^1 = 0.25 -> 137; 0.5 * 2 = 1 -> 255.
  EXPECT_EQ(pngGreys({0.25f, 0.125f, 0.5f}, 1.0f, ToneMapping::None), (std::vector<int>{188, 137, 255}));
  // 0.5 * 2^-1 = 0.25 -> 137.
  EXPECT_EQ(pngGreys({0.5f}, -1.0f, ToneMapping::None), (std::vector<int>{137}));
  // Reinhard after exposure: 0.25 * 2^2 = 1 -> 1 / 2 = 0.5 -> 188 (not reinhard(0.25) * 4 = 0.8).
  EXPECT_EQ(pngGreys({0.25f}, 2.0f, ToneMapping::Reinhard), (std::vector<int>{188}));
}

TEST(PngTest, ToneMappedValues) {
  // Reinhard: 1 -> 0.5 -> 188; 3 -> 0.75 -> srgb 0.8808250 * 255 = 224.610 + 0.5 -> 225.
  EXPECT_EQ(pngGreys({0.0f, 1.0f, 3.0f, kInf}, 0.0f, ToneMapping::Reinhard), (std::vector<int>{0, 188, 225, 255}));
  // ACES: 1 -> 2.54 / 3.16 = 0.8037975 -> srgb 0.9082305 * 255 = 231.599 + 0.5 -> 232;
  // 100 -> 1 -> 255.
  EXPECT_EQ(pngGreys({0.0f, 1.0f, 100.0f}, 0.0f, ToneMapping::Aces), (std::vector<int>{0, 232, 255}));
}

TEST(PngTest, EveryCodeRoundTrips) {
  // linear = srgb_decode(k / 255) comes back as code k for every k: the 8-bit step is exact and
  // the reader applies no gamma conversion of its own.
  std::vector<float> values;
  std::vector<int> codes;
  for (int k = 0; k < 256; ++k) {
    values.push_back(srgb_decode(k / 255.0f));
    codes.push_back(k);
  }
  EXPECT_EQ(pngGreys(values, 0.0f, ToneMapping::None), codes);
}

TEST(PngTest, LayoutChannelsAndRows) {
  TempDir dir;
  const std::string path = dir.file("layout.png");
  // 2x2: row 0 (top) red, green; row 1 blue, white.
  narval::writePng(path, makeImage(2, 2, {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1}), 0.0f, ToneMapping::None);
  int w = 0, h = 0;
  const std::vector<uint8_t> px = readPng(path, &w, &h);
  EXPECT_EQ(w, 2);
  EXPECT_EQ(h, 2);
  EXPECT_EQ(px, (std::vector<uint8_t>{255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255}));
  // 8-bit RGB, marked sRGB (an sRGB chunk).
  const std::string bytes = readFile(path);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
  EXPECT_NE(bytes.find("sRGB"), std::string::npos);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"layout.png"});
}

TEST(PngTest, FailedWriteLeavesExistingFileUntouched) {
  TempDir dir;
  const std::string path = dir.file("keep.png");
  const ImageRGB big = noiseImage(64, 64, 4);  // values in [0, 1000): exposure -10 spreads them
  narval::writePng(path, big, -10.0f, ToneMapping::None);
  const size_t fullSize = readFile(path).size();
  ASSERT_GT(fullSize, 10000u);  // noise does not compress
  narval::writePng(path, makeImage(1, 1, {0.5f, 0.5f, 0.5f}), 0.0f, ToneMapping::None);
  const std::string before = readFile(path);
  for (size_t limit : {size_t(10), size_t(1000), fullSize / 2, fullSize - 1}) {
    std::string message;
    {
      FileSizeLimit cap(limit);
      ASSERT_TRUE(cap.ok());
      message = runtimeErrorOf([&] { narval::writePng(path, big, -10.0f, ToneMapping::None); });
    }
    EXPECT_EQ(message.rfind(path + ": cannot write: ", 0), 0u) << "limit " << limit << ": " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(readFile(path), before);
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.png"});
  }
  const std::string nowhere = dir.file("missing/out.png");
  EXPECT_EQ(runtimeErrorOf([&] { narval::writePng(nowhere, big, 0.0f, ToneMapping::None); }),
            nowhere + ": cannot write: No such file or directory");
}
