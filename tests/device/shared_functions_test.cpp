// shared_functions_test.cpp: the shared kernel headers give the same numbers on the device (PoCL in
// CI) as on the host. tests/device/shared_functions.cl evaluates each function for a batch of inputs;
// the host evaluates the very same code. Integer outputs (Philox) must be identical. Float outputs
// must agree within 4 ulp or 1e-6 relative to their natural scale (1 for cosines and unit-vector
// components, whose zero crossings make per-component relative errors meaningless; the value
// itself otherwise). OpenCL allows its built-ins a few ulp (sqrt 3, exp 3, sin/cos 4, division 2.5
// in OpenCL 1.2 §7.4) and FP_CONTRACT is off on the device (compat.h) and unavailable to the host
// compiler's default x86-64 target, so differences stay at the level of one built-in's rounding.
// The largest differences seen are printed and recorded as test properties.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "cl/cl_runtime.h"
#include "shared/accum.h"
#include "shared/camera.h"
#include "shared/intersect.h"
#include "shared/march.h"
#include "shared/ms_cache.h"
#include "shared/phase.h"
#include "shared/rng.h"
#include "shared/sampling.h"
#include "shared/tracking.h"
#include "unit/host_context.h"
#include "test_support.h"

namespace narval {
const std::map<std::string, std::string>& testKernelSources();
}

namespace {

// ---- float comparison ----

// Distance in units in the last place between two finite floats of any sign (0 for +0/−0).
int64_t ulpDistance(float a, float b) {
  auto ordered = [](float f) {
    int32_t i;
    std::memcpy(&i, &f, sizeof i);
    return i < 0 ? static_cast<int64_t>(INT32_MIN) - i : static_cast<int64_t>(i);
  };
  return std::llabs(ordered(a) - ordered(b));
}

class FloatDiff {
 public:
  explicit FloatDiff(std::string name) : name_(std::move(name)) {}
  // scale: the magnitude the tolerance is relative to; 0 means the values themselves.
  void add(float host, float device, float scale, const std::string& where) {
    ++count_;
    if (std::isnan(host) || std::isnan(device)) {
      if (std::isnan(host) != std::isnan(device)) fail(host, device, where);
      return;
    }
    if (std::isinf(host) || std::isinf(device)) {
      if (host != device) fail(host, device, where);
      return;
    }
    const int64_t ulps = ulpDistance(host, device);
    const double abs = std::fabs(double(host) - device);
    const double ref = scale > 0.0f ? scale : std::max(std::fabs(host), std::fabs(device));
    const double rel = ref > 0.0 ? abs / ref : 0.0;
    maxUlps_ = std::max(maxUlps_, ulps);
    maxRel_ = std::max(maxRel_, rel);
    if (ulps > 4 && rel > 1e-6) fail(host, device, where);
  }
  void report() const {
    std::ostringstream s;
    s << name_ << ": " << count_ << " values, max " << maxUlps_ << " ulp, max scaled difference " << maxRel_;
    std::cout << "[ host/device ] " << s.str() << "\n";
    testing::Test::RecordProperty(name_, s.str());
    EXPECT_EQ(failures_, 0) << name_ << ": " << failures_ << " values outside 4 ulp / 1e-6; first: " << firstFailure_;
  }

 private:
  void fail(float host, float device, const std::string& where) {
    if (failures_++ == 0) {
      std::ostringstream s;
      s.precision(9);
      s << where << ": host " << host << ", device " << device;
      firstFailure_ = s.str();
    }
  }
  std::string name_;
  int count_ = 0, failures_ = 0;
  int64_t maxUlps_ = 0;
  double maxRel_ = 0.0;
  std::string firstFailure_;
};

// ---- running kernels ----

// Where a value came from, for failure messages.
std::string at(size_t i) { return "item " + std::to_string(i); }

class SharedOnDevice : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (narval::listDevices().empty()) return;
    rt_ = new narval::ClRuntime("");
    // MEDIUM_HOMOGENEOUS: grid.h reads density 1, as the host's grid_view with NULL data.
    program_ = new cl::Program(
        narval::buildProgram(*rt_, "shared_functions.cl", "-DMEDIUM_HOMOGENEOUS", &narval::testKernelSources()));
  }
  static void TearDownTestSuite() {
    delete program_;
    delete rt_;
    program_ = nullptr;
    rt_ = nullptr;
  }
  void SetUp() override {
    if (!rt_) NARVAL_SKIP_WITHOUT_DEVICE();
  }

  template <typename T>
  static cl::Buffer input(const std::vector<T>& v) {
    return cl::Buffer(rt_->context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(T),
                      const_cast<T*>(v.data()));
  }
  template <typename T>
  static cl::Buffer constant(const T& s) {
    return cl::Buffer(rt_->context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof(T), const_cast<T*>(&s));
  }
  // Sets the kernel's arguments in order, runs n work-items and reads `outputs` values of type T
  // from the argument at position outArg (a fresh buffer).
  template <typename T, typename... Args>
  static std::vector<T> run(const char* name, size_t n, size_t outputs, int outArg, Args... args) {
    cl::Kernel kernel(*program_, name);
    cl::Buffer out(rt_->context, CL_MEM_WRITE_ONLY, outputs * sizeof(T));
    int index = 0;
    auto set = [&](auto a) {
      if (index == outArg) kernel.setArg(index++, out);
      kernel.setArg(index++, a);
    };
    (set(args), ...);
    if (index == outArg) kernel.setArg(index++, out);
    kernel.setArg(index, static_cast<cl_uint>(n));
    rt_->queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(n), cl::NullRange);
    std::vector<T> result(outputs);
    rt_->queue.enqueueReadBuffer(out, CL_TRUE, 0, outputs * sizeof(T), result.data());
    return result;
  }

  // Runs `kernel`, a function f(g, x) with one float output per item, at every (g[i], x[i]) and
  // compares what it writes with the host's host(g[i], x[i]) (scale as in FloatDiff::add).
  template <typename HostFn>
  static void compareGx(const char* kernel, const std::string& name, HostFn host, const std::vector<float>& g,
                        const std::vector<float>& x, float scale) {
    const size_t n = g.size();
    const std::vector<float> dev = run<float>(kernel, n, n, 2, input(g), input(x));
    FloatDiff diff(name);
    for (size_t i = 0; i < n; ++i) diff.add(host(g[i], x[i]), dev[i], scale, at(i));
    diff.report();
  }

  static narval::ClRuntime* rt_;
  static cl::Program* program_;
};
narval::ClRuntime* SharedOnDevice::rt_ = nullptr;
cl::Program* SharedOnDevice::program_ = nullptr;

const std::vector<float>& testGs() {
  static const std::vector<float> gs = {-0.999999f, -0.99f, -0.9f, -0.5f, -1e-5f, 0.0f,
                                        1e-5f,      0.3f,   0.9f,  0.99f, 0.999999f};
  return gs;
}

// ---- tests ----

TEST_F(SharedOnDevice, PhaseHgEval) {
  std::vector<float> g, mu;
  for (float gv : testGs())
    for (int k = 0; k <= 400; ++k) {
      g.push_back(gv);
      mu.push_back(k == 400 ? 1.0f : -1.0f + k / 200.0f);
    }
  compareGx("sf_phase_hg_eval", "phase_hg_eval", phase_hg_eval, g, mu, 0.0f);
}

TEST_F(SharedOnDevice, PhaseHgSampleCos) {
  std::mt19937 gen(1);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::vector<float> g, u;
  for (float gv : testGs())
    for (int k = 0; k < 1000; ++k) {
      g.push_back(gv);
      u.push_back(k == 0 ? 0.0f : (k == 1 ? 0.99999994f : uni(gen)));
    }
  compareGx("sf_phase_hg_sample_cos", "phase_hg_sample_cos", phase_hg_sample_cos, g, u, 1.0f);
}

TEST_F(SharedOnDevice, PhaseSample) {
  std::mt19937 gen(2);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  std::vector<float> in;
  const size_t n = 5000;
  for (size_t i = 0; i < n; ++i) {
    const vec3 w = sample_uniform_sphere(uni(gen), uni(gen));
    in.insert(in.end(), {testGs()[i % testGs().size()], w.x, w.y, w.z, uni(gen), uni(gen)});
  }
  const std::vector<float> dev = run<float>("sf_phase_sample", n, 4 * n, 1, input(in));
  FloatDiff dir("phase_sample direction"), pdf("phase_sample pdf");
  for (size_t i = 0; i < n; ++i) {
    const float* a = &in[6 * i];
    float p = 0.0f;
    const vec3 w = phase_sample(phase_make(PHASE_HG, a[0]), vec3_make(a[1], a[2], a[3]), a[4], a[5], &p);
    // The direction is built from μ = phase_hg_sample_cos (above: within 1e-6 of the host's on
    // every device) and sin θ = sqrt(1 − μ²), whose slope |μ|/sin θ magnifies a difference δμ near
    // θ = 0 or π: |δw| ≤ δμ (1 + 1/sin θ). On PoCL this stays a few ulp; a GPU's pow/log (4 ulp
    // allowed by OpenCL) differ in μ, so the bound scales 1e-6 by that slope.
    const float mu = std::fabs(vec3_dot(w, vec3_make(a[1], a[2], a[3])));
    const float scale = 1.0f + 1.0f / std::max(std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 1e-3f);
    dir.add(w.x, dev[4 * i], scale, at(i));
    dir.add(w.y, dev[4 * i + 1], scale, at(i));
    dir.add(w.z, dev[4 * i + 2], scale, at(i));
    // The pdf is HG at the cosine of the direction returned (phase.h). For |g| near 1 that is steep
    // in μ, so the last-bit differences of the direction above are magnified; compare instead with
    // the host's phase_pdf of the device's own direction, which must agree to a few ulp.
    (void)p;
    const vec3 wDev = vec3_make(dev[4 * i], dev[4 * i + 1], dev[4 * i + 2]);
    pdf.add(phase_pdf(phase_make(PHASE_HG, a[0]), vec3_make(a[1], a[2], a[3]), wDev), dev[4 * i + 3], 0.0f, at(i));
  }
  dir.report();
  pdf.report();
}

// Philox outputs are integers: bit-identical, for the Random123 known-answer counters (see
// tests/unit/rng_test.cpp) and 10⁴ random counters and keys.
TEST_F(SharedOnDevice, PhiloxIsBitIdentical) {
  std::vector<cl_uint> in = {0, 0, 0, 0, 0, 0,
                             0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu,
                             0x243f6a88u, 0x85a308d3u, 0x13198a2eu, 0x03707344u, 0xa4093822u, 0x299f31d0u};
  std::mt19937 gen(3);
  for (int i = 0; i < 10000 * 6; ++i) in.push_back(gen());
  const size_t n = in.size() / 6;
  const std::vector<cl_uint> dev = run<cl_uint>("sf_philox", n, 4 * n, 1, input(in));
  EXPECT_EQ(dev[0], 0x6627e8d5u);
  EXPECT_EQ(dev[4], 0x408f276du);
  EXPECT_EQ(dev[8], 0xd16cfe09u);
  size_t mismatches = 0;
  for (size_t i = 0; i < n; ++i) {
    const uint c[4] = {in[6 * i], in[6 * i + 1], in[6 * i + 2], in[6 * i + 3]};
    uint h[4];
    rng_philox4x32(c, in[6 * i + 4], in[6 * i + 5], h);
    for (int k = 0; k < 4; ++k) mismatches += h[k] != dev[4 * i + k];
  }
  EXPECT_EQ(mismatches, 0u);
  std::cout << "[ host/device ] philox: " << n << " blocks, " << mismatches << " differing words\n";
}

// The exact accumulator is integer arithmetic on the float's bits: the device's 128-bit words equal
// the host's for samples of every exponent the range takes (and NaN, inf, out of range, both signs),
// added to a start with all carry and borrow paths busy (low word near 2^64, high word odd).
TEST_F(SharedOnDevice, AccumAddSampleIsBitIdentical) {
  std::vector<float> in = {0.0f, -0.0f, 1.0f, -1.0f, std::ldexp(1.0f, -64), std::ldexp(1.0f, -66),
                           std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                           std::ldexp(1.0f, 40), std::nextafter(std::ldexp(1.0f, 40), 0.0f), 1e-45f};
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> m(-1.0f, 1.0f);
  std::uniform_int_distribution<int> e(-90, 41);
  while (in.size() % 3 != 0 || in.size() < 30000) in.push_back(std::ldexp(m(gen), e(gen)));
  const std::vector<cl_ulong> start = {0xfffffffffffffff0ull, 0x8000000000000001ull, 5u, 0u, 0xffffffffffffffffull,
                                       3u, 1u, 0u};
  const size_t n = in.size() / 3;
  const std::vector<cl_ulong> dev = run<cl_ulong>("sf_accum_add_sample", n, ACCUM_WORDS * n, 2, input(in), input(start));
  size_t mismatches = 0;
  for (size_t i = 0; i < n; ++i) {
    uint64_t h[ACCUM_WORDS];
    for (int w = 0; w < ACCUM_WORDS; ++w) h[w] = start[size_t(w)];
    accum_add_sample(h, vec3_make(in[3 * i], in[3 * i + 1], in[3 * i + 2]));
    for (int w = 0; w < ACCUM_WORDS; ++w) mismatches += h[w] != dev[ACCUM_WORDS * i + size_t(w)];
  }
  EXPECT_EQ(mismatches, 0u);
  std::cout << "[ host/device ] accum_add_sample: " << n << " samples, " << mismatches << " differing words\n";
}

// rng_uniform is integer arithmetic plus an exact conversion: identical floats.
TEST_F(SharedOnDevice, RngUniformIsBitIdentical) {
  std::vector<cl_uint> in;
  for (cl_uint i = 0; i < 2000; ++i) in.insert(in.end(), {i % 7u, i * 2654435761u, i / 3u});
  const size_t n = in.size() / 3;
  const std::vector<float> dev = run<float>("sf_rng_uniform", n, 8 * n, 1, input(in));
  size_t mismatches = 0;
  for (size_t i = 0; i < n; ++i) {
    rng_state r = rng_init(in[3 * i], in[3 * i + 1], in[3 * i + 2]);
    for (int k = 0; k < 8; ++k) mismatches += rng_uniform(&r) != dev[8 * i + k];
  }
  EXPECT_EQ(mismatches, 0u);
}

camera_params testCamera(float lensRadius) {
  camera_params c{};
  const vec3 fwd = vec3_normalize(vec3_make(1.0f, -0.5f, 0.2f));
  const vec3 right = vec3_normalize(vec3_cross(fwd, vec3_make(0.0f, 1.0f, 0.0f)));
  const vec3 up = vec3_cross(right, fwd);
  c.position = {1.0f, 2.0f, 3.0f, 0.0f};
  c.forward = {fwd.x, fwd.y, fwd.z, 0.0f};
  c.right = {right.x, right.y, right.z, 0.0f};
  c.up = {up.x, up.y, up.z, 0.0f};
  c.tan_half_vfov = 0.36397023f;  // tan 20°
  c.aspect = 64.0f / 48.0f;
  c.lens_radius = lensRadius;
  c.focus_distance = 5.0f;
  c.width = 64;
  c.height = 48;
  return c;
}

TEST_F(SharedOnDevice, CameraRay) {
  std::mt19937 gen(4);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const size_t n = 4000;
  std::vector<float> in;
  for (size_t i = 0; i < n; ++i) in.insert(in.end(), {64.0f * uni(gen), 48.0f * uni(gen), uni(gen), uni(gen)});
  for (float lens : {0.0f, 0.2f}) {
    const camera_params cam = testCamera(lens);
    const std::vector<float> dev = run<float>("sf_camera_ray", n, 6 * n, 2, constant(cam), input(in));
    FloatDiff origin(lens > 0 ? "camera_ray origin (thin lens)" : "camera_ray origin (pinhole)");
    FloatDiff dir(lens > 0 ? "camera_ray direction (thin lens)" : "camera_ray direction (pinhole)");
    for (size_t i = 0; i < n; ++i) {
      const ray3 r = camera_ray(&cam, in[4 * i], in[4 * i + 1], in[4 * i + 2], in[4 * i + 3]);
      // Origins are near |position| = 3.7: scale 4.
      origin.add(r.origin.x, dev[6 * i], 4.0f, at(i));
      origin.add(r.origin.y, dev[6 * i + 1], 4.0f, at(i));
      origin.add(r.origin.z, dev[6 * i + 2], 4.0f, at(i));
      dir.add(r.dir.x, dev[6 * i + 3], 1.0f, at(i));
      dir.add(r.dir.y, dev[6 * i + 4], 1.0f, at(i));
      dir.add(r.dir.z, dev[6 * i + 5], 1.0f, at(i));
    }
    origin.report();
    dir.report();
  }
}

TEST_F(SharedOnDevice, UniformSphere) {
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const size_t n = 5000;
  std::vector<float> in = {0.0f, 0.0f, 0.99999994f, 0.99999994f, 0.5f, 0.25f};
  while (in.size() < 2 * n) in.push_back(uni(gen));
  const std::vector<float> dev = run<float>("sf_uniform_sphere", n, 3 * n, 1, input(in));
  FloatDiff diff("sample_uniform_sphere");
  for (size_t i = 0; i < n; ++i) {
    const vec3 v = sample_uniform_sphere(in[2 * i], in[2 * i + 1]);
    diff.add(v.x, dev[3 * i], 1.0f, at(i));
    diff.add(v.y, dev[3 * i + 1], 1.0f, at(i));
    diff.add(v.z, dev[3 * i + 2], 1.0f, at(i));
  }
  diff.report();
}

// Random rays (some hitting, some missing) plus the special cases of tracking_test.cpp:
// axis-parallel rays (±0 components, infinite slab bounds) and rays lying in a face plane (0·∞).
TEST_F(SharedOnDevice, IntersectBox) {
  std::mt19937 gen(6);
  std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
  std::vector<float> in = {-1, 0.5f, 0.5f, 1, 0, 0, 2, 3, 4,      -1, 5, 0.5f, 1, 0, 0, 2, 3, 4,
                           1, 5, 2, -0.0f, -1, 0, 2, 3, 4,        0, -1, 0.5f, 0, 1, 0, 1, 1, 1,
                           1, -1, 0.5f, 0, 1, 0, 1, 1, 1,         0.5f, 1, 2, 0, 0, 1, 2, 3, 4};
  // Box [0, hx] × [0, 2] × [0, 3], hx in [1, 3]; origins in [−3, 3]³; every other ray aimed at a
  // point inside the box (a hit), the others in random directions (mostly misses).
  for (int k = 0; in.size() < 9 * 5000; ++k) {
    const float hx = 2.0f + uni(gen);
    const vec3 o = vec3_make(3 * uni(gen), 3 * uni(gen), 3 * uni(gen));
    const vec3 target = vec3_make(hx * (0.5f + 0.5f * uni(gen)), 1.0f + uni(gen), 1.5f + 1.5f * uni(gen));
    const vec3 d = k % 2 ? vec3_normalize(vec3_sub(target, o))
                         : vec3_normalize(vec3_make(uni(gen), uni(gen), uni(gen)));
    in.insert(in.end(), {o.x, o.y, o.z, d.x, d.y, d.z, hx, 2.0f, 3.0f});
  }
  const size_t n = in.size() / 9;
  const std::vector<float> dev = run<float>("sf_intersect_box", n, 3 * n, 1, input(in));
  FloatDiff diff("intersect_box t_near/t_far");
  size_t hitMismatches = 0, hits = 0;
  for (size_t i = 0; i < n; ++i) {
    const float* a = &in[9 * i];
    float tn = 0.0f, tf = 0.0f;
    const int hit = intersect_box(vec3_make(a[0], a[1], a[2]), vec3_make(a[3], a[4], a[5]), vec3_make(a[6], a[7], a[8]), &tn, &tf);
    hitMismatches += static_cast<float>(hit) != dev[3 * i];
    hits += hit;
    // Parameters are distances up to ~10: scale them by max(1, |t|).
    diff.add(tn, dev[3 * i + 1], std::max(1.0f, std::fabs(tn)), at(i));
    diff.add(tf, dev[3 * i + 2], std::max(1.0f, std::fabs(tf)), at(i));
  }
  EXPECT_EQ(hitMismatches, 0u);
  EXPECT_GT(hits, n / 4);  // the batch exercises both outcomes
  EXPECT_LT(hits, n);
  diff.report();
}

medium_params homogeneousMedium(nv_float4 sa, nv_float4 ss, float majorant, int grey) {
  medium_params m{};
  m.world_to_index.row[0] = {1, 0, 0, 0};
  m.world_to_index.row[1] = {0, 1, 0, 0};
  m.world_to_index.row[2] = {0, 0, 1, 0};
  m.dims = {1, 1, 1, 0};
  m.sigma_a = sa;
  m.sigma_s = ss;
  m.majorant = majorant;
  m.grey = grey;
  return m;
}

TEST_F(SharedOnDevice, TrackingRatioHomogeneous) {
  const medium_params m = homogeneousMedium({0.1f, 0.5f, 2.0f, 0}, {0.3f, 0.25f, 1.0f, 0}, 3.0f, 0);
  std::mt19937 gen(7);
  std::uniform_real_distribution<float> uni(0.0f, 5.0f);
  std::vector<float> in;
  for (int i = 0; i < 3000; ++i) in.insert(in.end(), {uni(gen), uni(gen)});  // t > t_max included: Tr = 1
  const size_t n = in.size() / 2;
  const std::vector<float> dev = run<float>("sf_tracking_ratio", n, 3 * n, 2, constant(m), input(in));
  const grid_view h = {nullptr, 1, 1, 1};
  FloatDiff diff("tracking_ratio (homogeneous)");
  for (size_t i = 0; i < n; ++i) {
    rng_state rng = rng_init(1u, static_cast<uint>(i), 0u);
    uint status = 0u;
    const vec3 tr = tracking_ratio(narval::test::hostContext(&m, &h, &status), vec3_splat(0.0f), vec3_make(0, 0, 1),
                                   in[2 * i], in[2 * i + 1], 0.0f, &rng);
    diff.add(tr.x, dev[3 * i], 0.0f, at(i));
    diff.add(tr.y, dev[3 * i + 1], 0.0f, at(i));
    diff.add(tr.z, dev[3 * i + 2], 0.0f, at(i));
  }
  diff.report();
}

// Delta/spectral tracking in a chromatic homogeneous medium, same streams on both sides: the walks
// consume the same random numbers, so every walk must end in the same event at (almost) the same
// place with (almost) the same weight. A one-ulp difference in a logf could in principle flip a
// comparison; none is tolerated here, so such a flip would be reported.
TEST_F(SharedOnDevice, TrackingDeltaChromaticHomogeneous) {
  const medium_params m = homogeneousMedium({0.1f, 0.4f, 0.05f, 0}, {0.3f, 0.5f, 1.6f, 0}, 2.0f, 0);
  const size_t n = 20000;
  std::vector<float> in(n);
  for (size_t i = 0; i < n; ++i) in[i] = 0.2f + 3.0f * (i % 100) / 100.0f;
  const cl_uint seed = 11u;
  const std::vector<float> dev = run<float>("sf_tracking_delta", n, 5 * n, 3, constant(m), input(in), seed);
  const grid_view h = {nullptr, 1, 1, 1};
  FloatDiff dist("tracking_delta collision distance"), beta("tracking_delta throughput");
  size_t eventMismatches = 0;
  for (size_t i = 0; i < n; ++i) {
    rng_state rng = rng_init(seed, static_cast<uint>(i), 0u);
    uint status = 0u;
    vec3 b = vec3_splat(1.0f);
    float t = -1.0f;
    const int e = tracking_delta(narval::test::hostContext(&m, &h, &status), vec3_splat(0.0f), vec3_make(0, 0, 1),
                                 0.0f, in[i], &rng, &b, &t);
    if (static_cast<float>(e) != dev[5 * i]) {
      ++eventMismatches;
      continue;
    }
    if (e == TRACK_SCATTERED) dist.add(t, dev[5 * i + 1], std::max(1.0f, t), at(i));
    beta.add(b.x, dev[5 * i + 2], 0.0f, at(i));
    beta.add(b.y, dev[5 * i + 3], 0.0f, at(i));
    beta.add(b.z, dev[5 * i + 4], 0.0f, at(i));
  }
  EXPECT_EQ(eventMismatches, 0u);
  dist.report();
  beta.report();
}

// Kinds: every kernel's entry flags a phase function, light or emission kind it does not know
// (STATUS_UNKNOWN_KIND), and the switches give such a kind nothing: phase_eval 0, phase_sample's
// pdf 0, no light sample. Known kinds: status 0 and their ordinary values.
TEST_F(SharedOnDevice, UnknownKindsSetTheStatusBitAndSendNothing) {
  scene_params s{};
  s.has_medium = 1;
  s.medium.phase = phase_make(PHASE_HG, 0.5f);
  s.num_lights = 2;
  std::vector<light_params> lights(2);
  lights[0].type = LIGHT_POINT;
  lights[0].corner = nv_float4{0, 0, 2, 0};
  lights[0].radiance = nv_float4{1, 1, 1, 0};
  lights[1].type = LIGHT_RECTANGLE;
  auto probe = [&]() { return run<cl_uint>("sf_scene_kinds", 1, 4, 2, constant(s), input(lights)); };
  auto bits = [](float f) {
    cl_uint u;
    std::memcpy(&u, &f, sizeof u);
    return u;
  };
  // HG(0.5) at μ = 1: (1 − g²) / (4π (1 − g)³) = 0.75 / (4π · 0.125) = 0.477465 (phase.h).
  std::vector<cl_uint> out = probe();
  EXPECT_EQ(out[0], 0u);
  const vec3 w = vec3_make(0.0f, 0.0f, 1.0f);
  EXPECT_NEAR(phase_hg_eval(0.5f, 1.0f), 0.75f / (4.0f * float(M_PI) * 0.125f), 1e-6f);
  float value;
  std::memcpy(&value, &out[1], sizeof value);
  EXPECT_NEAR(value, phase_eval(phase_make(PHASE_HG, 0.5f), w, w), 1e-6f);
  EXPECT_EQ(out[3], 1u);

  s.medium.phase.kind = 7;
  out = probe();
  EXPECT_EQ(out[0], STATUS_UNKNOWN_KIND);
  EXPECT_EQ(out[1], bits(0.0f));
  EXPECT_EQ(out[2], bits(0.0f));
  EXPECT_EQ(out[3], 1u);  // the light is still a known point light

  s.medium.phase = phase_make(PHASE_ISOTROPIC, 0.0f);
  lights[1].type = 5;  // the second light: the status says so, the first still lights
  out = probe();
  EXPECT_EQ(out[0], STATUS_UNKNOWN_KIND);
  EXPECT_EQ(out[1], bits(1.0f / (4.0f * float(M_PI))));
  EXPECT_EQ(out[3], 1u);
  lights[0].type = 5;
  out = probe();
  EXPECT_EQ(out[0], STATUS_UNKNOWN_KIND);
  EXPECT_EQ(out[3], 0u);  // an unknown light sends nothing

  s.has_medium = 0;  // without a medium the phase kind is not looked at
  s.medium.phase.kind = 7;
  lights[0].type = lights[1].type = LIGHT_POINT;
  EXPECT_EQ(probe()[0], 0u);

  // Emission kinds: an unknown one, and an emitting medium reaching a kernel built without
  // -DEMISSION (this one), which could not show its light.
  s.has_medium = 1;
  s.medium.phase = phase_make(PHASE_ISOTROPIC, 0.0f);
  s.medium.emission.kind = 9;
  EXPECT_EQ(probe()[0], STATUS_UNKNOWN_KIND);
  s.medium.emission.kind = EMISSION_COLOR;
  EXPECT_EQ(probe()[0], STATUS_UNKNOWN_KIND);
  s.medium.emission.kind = EMISSION_NONE;
  EXPECT_EQ(probe()[0], 0u);
}

// The real-time kinds (march_params, lobe_params, ms_cache_params): the area-light phase, the cache's closure and the lobe
// variant. Known values: status 0, and the device computes what the host does (a 2x2 rectangle 2
// units along +z, seen along +z, at its centre and exactly; the HG closure's 4πR·p_HG(gμ) with
// μ = 0.3). An unknown one sets STATUS_UNKNOWN_KIND and its switch gives nothing.
TEST_F(SharedOnDevice, UnknownRealtimeKindsSetTheStatusBitAndSendNothing) {
  march_params mp{};
  lobe_params lp{};
  ms_cache_params mc{};
  std::vector<light_params> lights(1);
  lights[0].type = LIGHT_RECTANGLE;
  lights[0].corner = nv_float4{-1, -1, 2, 0};
  lights[0].edge_u = nv_float4{2, 0, 0, 0};
  lights[0].edge_v = nv_float4{0, 2, 0, 0};
  lights[0].normal = nv_float4{0, 0, -1, 4};  // emits towards −z, at the origin; w = its area
  lights[0].radiance = nv_float4{3, 3, 3, 0};
  auto probe = [&]() { return run<cl_uint>("sf_realtime_kinds", 1, 3, 4, constant(mp), constant(lp), constant(mc), input(lights)); };
  auto value = [](cl_uint u) {
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
  };
  const vec3 w = vec3_make(0, 0, 1);
  for (int phase : {AREA_LIGHT_POINTS, AREA_LIGHT_EXACT})
    for (int closure : {MS_CACHE_CLOSURE_LINEAR, MS_CACHE_CLOSURE_CAMERA}) {
      mp.area_light_phase = phase;
      mc.closure = closure;
      const std::vector<cl_uint> out = probe();
      EXPECT_EQ(out[0], 0u);
      const float host = march_light_phase(&lights[0], vec3_make(0, 0, 0), phase_make(PHASE_HG, 0.5f), w, phase, 1).x;
      EXPECT_GT(host, 0.0f);
      EXPECT_NEAR(value(out[1]), host, 1e-5f * host) << "phase " << phase;
      const float closed = ms_cache_closure(closure, 2.0f, 0.8f, vec3_make(0, 0, 0.9f), w);
      EXPECT_NEAR(value(out[2]), closed, 1e-5f * closed) << "closure " << closure;
    }
  // The camera closure: the node's R is already the in-scattering towards the camera.
  EXPECT_EQ(ms_cache_closure(MS_CACHE_CLOSURE_CAMERA, 2.0f, 0.8f, vec3_make(0, 0, 0.9f), w), 2.0f);
  // The linear closure forwards: R(1 + g·m·w) = 2·(1 + 0.8·0.9).
  EXPECT_NEAR(ms_cache_closure(MS_CACHE_CLOSURE_LINEAR, 2.0f, 0.8f, vec3_make(0, 0, 0.9f), w), 2 * 1.72, 1e-5);
  mp.area_light_phase = 3;
  std::vector<cl_uint> out = probe();
  EXPECT_EQ(out[0], STATUS_UNKNOWN_KIND);
  EXPECT_EQ(value(out[1]), 0.0f);
  mp.area_light_phase = AREA_LIGHT_EXACT;
  mc.closure = 1;  // the removed HG closure's id
  out = probe();
  EXPECT_EQ(out[0], STATUS_UNKNOWN_KIND);
  EXPECT_EQ(value(out[2]), 0.0f);
  mc.closure = MS_CACHE_CLOSURE_LINEAR;
  lp.variant = 2;
  EXPECT_EQ(probe()[0], STATUS_UNKNOWN_KIND);
  lp.variant = LOBE_CORRECTED;
  EXPECT_EQ(probe()[0], 0u);
  mc.layout = MS_CACHE_LAYOUT_VIEW;
  EXPECT_EQ(probe()[0], 0u);
  mc.layout = 2;
  EXPECT_EQ(probe()[0], STATUS_UNKNOWN_KIND);
  mc.layout = MS_CACHE_LAYOUT_GRID;
  mp.shadow_weighting = SHADOW_WEIGHTING_PHASE;
  EXPECT_EQ(probe()[0], 0u);
  mp.shadow_weighting = 2;
  EXPECT_EQ(probe()[0], STATUS_UNKNOWN_KIND);
}

}  // namespace
