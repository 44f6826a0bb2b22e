// make_cloud.cpp: a procedural cumulus-like cloud, deterministic for (resolution, seed).
// Recipe (model space, y up, the cloud base at y = 0):
//   1. 8-20 spheres ("blobs") from a counter-based hash of (seed, index): a large central blob, base blobs
//      on a flattened disc (larger, taller near the centre), children on earlier blobs' upper hemispheres (towers).
//   2. Signed distance d = smooth union of the spheres (polynomial smooth-min, width kSmooth).
//   3. Displacement d' = d - kAmp * n, n in [-1, 1] billowy fractal gradient noise (kOctaves octaves).
//   4. Density = smoothstep(0, kEdge, -d') (soft edges) * smoothstep(0, kBaseFade, y) (flat base).
//   5. The model's bounding box (blob extents + largest displacement) is fitted uniformly, centred, into
//      [kFit, 1 - kFit]^3 and sampled at voxel centres (i + 0.5) / resolution (shape independent of the
//      resolution); voxels centred within kCloudMargin of a face are exactly 0 (the fit stays clear of them).
// Only integer hashing and float arithmetic in a fixed order: the same bits on every run, for any thread
// count and any split into z slabs (each voxel is computed independently).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "volume/dense_grid.h"

namespace narval {
namespace {

constexpr float kSmooth = 0.06f;    // smooth-union width (model units)
constexpr float kAmp = 0.05f;       // noise displacement amplitude (model units)
constexpr float kEdge = 0.035f;     // soft-edge width (model units)
constexpr float kBaseFade = 0.07f;  // density ramps from 0 at the base to 1 this far above it
constexpr float kFreq = 5.0f;       // first octave: lattice cells per model unit
constexpr int kOctaves = 4;
constexpr float kFit = 0.1f;  // the model box is fitted into [kFit, 1 - kFit] (> kCloudMargin)
static_assert(kFit > kCloudMargin, "the fitted cloud must stay clear of the zero margin");

// 32-bit integer hash (Chris Wellons' "lowbias32").
inline uint32_t hash32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

inline uint32_t hash3(int x, int y, int z, uint32_t s) {
  return hash32(uint32_t(x) + hash32(uint32_t(y) + hash32(uint32_t(z) + s)));
}

// Uniform in [0, 1) from 24 hash bits (exact in float).
inline float unit(uint32_t h) { return float(h >> 8) * (1.0f / 16777216.0f); }

// Counter-based stream of uniforms for blob placement: value k depends only on (seed, k).
struct Stream {
  uint32_t key;
  uint32_t counter = 0;
  explicit Stream(uint32_t seed) : key(hash32(seed ^ 0x5bd1e995u) + 0x9e3779b9u) {}
  uint32_t bits() { return hash32(key ^ hash32(counter++ * 0x9e3779b9u + 0x7f4a7c15u)); }
  float uniform() { return unit(bits()); }
};

inline float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
inline float lerp(float a, float b, float t) { return a + t * (b - a); }
inline float smoothstep(float e0, float e1, float x) {
  float t = (x - e0) / (e1 - e0);
  t = std::min(1.0f, std::max(0.0f, t));
  return t * t * (3.0f - 2.0f * t);
}

// Improved-Perlin gradient: one of 12 cube-edge directions (16 cases, 4 repeated).
inline float grad(uint32_t h, float x, float y, float z) {
  switch (h >> 28) {
    case 0: return x + y;
    case 1: return -x + y;
    case 2: return x - y;
    case 3: return -x - y;
    case 4: return x + z;
    case 5: return -x + z;
    case 6: return x - z;
    case 7: return -x - z;
    case 8: return y + z;
    case 9: return -y + z;
    case 10: return y - z;
    case 11: return -y - z;
    case 12: return x + y;
    case 13: return -x + y;
    case 14: return -y + z;
    default: return -y - z;
  }
}

// Gradient noise, roughly in [-1, 1].
float gradientNoise(float x, float y, float z, uint32_t s) {
  const float fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
  const int ix = int(fx), iy = int(fy), iz = int(fz);
  const float tx = x - fx, ty = y - fy, tz = z - fz;
  const float u = fade(tx), v = fade(ty), w = fade(tz);
  const float n000 = grad(hash3(ix, iy, iz, s), tx, ty, tz);
  const float n100 = grad(hash3(ix + 1, iy, iz, s), tx - 1, ty, tz);
  const float n010 = grad(hash3(ix, iy + 1, iz, s), tx, ty - 1, tz);
  const float n110 = grad(hash3(ix + 1, iy + 1, iz, s), tx - 1, ty - 1, tz);
  const float n001 = grad(hash3(ix, iy, iz + 1, s), tx, ty, tz - 1);
  const float n101 = grad(hash3(ix + 1, iy, iz + 1, s), tx - 1, ty, tz - 1);
  const float n011 = grad(hash3(ix, iy + 1, iz + 1, s), tx, ty - 1, tz - 1);
  const float n111 = grad(hash3(ix + 1, iy + 1, iz + 1, s), tx - 1, ty - 1, tz - 1);
  return lerp(lerp(lerp(n000, n100, u), lerp(n010, n110, u), v), lerp(lerp(n001, n101, u), lerp(n011, n111, u), v),
              w);
}

// Billowy fractal noise: sum over octaves of 2.5|noise| - 0.6 (rounded puffs between sharp inward
// creases, mean near 0), clamped to [-1, 1] so the displacement bound kAmp is exact.
float billow(float x, float y, float z, uint32_t seed) {
  float sum = 0.0f, amp = 1.0f, norm = 0.0f, f = kFreq;
  for (int o = 0; o < kOctaves; ++o) {
    const uint32_t s = hash32(seed + 0x632be5abu * uint32_t(o + 1));
    // Per-octave offsets keep the octaves' lattice points apart.
    const float off = 0.37f * float(o);
    sum += amp * (2.5f * std::fabs(gradientNoise(x * f + off, y * f - off, z * f + 2.0f * off, s)) - 0.6f);
    norm += amp;
    amp *= 0.5f;
    f *= 2.0f;
  }
  return std::min(1.0f, std::max(-1.0f, sum / norm));
}

struct Blob {
  float x, y, z, r;
};

std::vector<Blob> placeBlobs(uint32_t seed) {
  Stream rnd(seed);
  const int n = 8 + int(rnd.bits() % 13u);  // 8..20
  std::vector<Blob> blobs;
  blobs.reserve(size_t(n));
  const float r0 = 0.24f + 0.05f * rnd.uniform();
  blobs.push_back({0.0f, 0.8f * r0, 0.0f, r0});
  constexpr float kTwoPi = 6.283185307f;
  for (int k = 1; k < n; ++k) {
    const float choice = rnd.uniform();
    if (k >= 2 && choice < 0.5f) {
      const Blob& p = blobs[size_t(rnd.bits() % uint32_t(k))];
      const float theta = kTwoPi * rnd.uniform();
      const float cosPhi = 0.45f + 0.5f * rnd.uniform();
      const float sinPhi = std::sqrt(1.0f - cosPhi * cosPhi);
      const float r = p.r * (0.55f + 0.2f * rnd.uniform());
      const float reach = 0.85f * p.r;
      blobs.push_back({p.x + reach * sinPhi * std::cos(theta), p.y + reach * cosPhi, p.z + reach * sinPhi * std::sin(theta), r});
    } else {
      const float theta = kTwoPi * rnd.uniform();
      const float t = std::sqrt(rnd.uniform());  // 0 centre .. 1 rim
      const float rad = 0.32f * t;
      const float r = (0.20f - 0.07f * t) * (0.85f + 0.3f * rnd.uniform());
      const float y = r * (0.4f + 0.4f * rnd.uniform()) + 0.12f * (1.0f - t);
      blobs.push_back({rad * std::cos(theta), y, 0.85f * rad * std::sin(theta), r});
    }
  }
  return blobs;
}

// Polynomial smooth minimum (Quilez): <= min(a, b), equal to it when |a - b| >= k.
inline float smin(float a, float b, float k) {
  const float h = std::max(k - std::fabs(a - b), 0.0f) / k;
  return std::min(a, b) - h * h * k * 0.25f;
}

}  // namespace

void makeCloudSlab(int resolution, uint32_t seed, int z0, int z1, float* out) {
  if (resolution < 8) throw std::invalid_argument("makeCloud: resolution must be at least 8");
  if (z0 < 0 || z1 < z0 || z1 > resolution) throw std::invalid_argument("makeCloudSlab: slices out of range");
  const std::vector<Blob> blobs = placeBlobs(seed);
  const uint32_t noiseSeed = hash32(seed ^ 0xa136aaadu);

  // Model bounding box: every point with density > 0 lies within d < kAmp of the union, which is
  // within kSmooth / 4 below the plain minimum; below y = 0 the base fade is 0.
  const float pad = kAmp + 0.25f * kSmooth;
  float lo[3] = {1e30f, 0.0f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
  for (const Blob& b : blobs) {
    const float c[3] = {b.x, b.y, b.z};
    for (int a = 0; a < 3; ++a) {
      if (a != 1) lo[a] = std::min(lo[a], c[a] - b.r - pad);
      hi[a] = std::max(hi[a], c[a] + b.r + pad);
    }
  }
  const float extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  const float scale = (1.0f - 2.0f * kFit) / extent;  // model -> normalised
  const float invScale = 1.0f / scale;
  // q = p * invScale + qOff, with the model box centred in the unit cube.
  float qOff[3];
  for (int a = 0; a < 3; ++a) qOff[a] = 0.5f * (lo[a] + hi[a]) - 0.5f * invScale;

  std::fill(out, out + size_t(resolution) * size_t(resolution) * size_t(z1 - z0), 0.0f);
  const float invRes = 1.0f / float(resolution);
  std::vector<float> coord(static_cast<size_t>(resolution));  // normalised voxel centres
  for (int i = 0; i < resolution; ++i) coord[size_t(i)] = (float(i) + 0.5f) * invRes;
  const float lowEdge = kCloudMargin, highEdge = 1.0f - kCloudMargin;

  tbb::parallel_for(tbb::blocked_range<int>(z0, z1), [&](const tbb::blocked_range<int>& range) {
    for (int k = range.begin(); k != range.end(); ++k) {
      const float pz = coord[size_t(k)];
      if (pz < lowEdge || pz > highEdge) continue;
      const float qz = pz * invScale + qOff[2];
      for (int j = 0; j < resolution; ++j) {
        const float py = coord[size_t(j)];
        if (py < lowEdge || py > highEdge) continue;
        const float qy = py * invScale + qOff[1];
        if (qy <= 0.0f) continue;  // below the base
        const float base = smoothstep(0.0f, kBaseFade, qy);
        float* row = out + size_t(resolution) * (size_t(j) + size_t(resolution) * size_t(k - z0));
        for (int i = 0; i < resolution; ++i) {
          const float px = coord[size_t(i)];
          if (px < lowEdge || px > highEdge) continue;
          const float qx = px * invScale + qOff[0];
          float d = 1e30f;
          for (const Blob& b : blobs) {
            const float dx = qx - b.x, dy = qy - b.y, dz = qz - b.z;
            d = smin(d, std::sqrt(dx * dx + dy * dy + dz * dz) - b.r, kSmooth);
          }
          if (d >= kAmp) continue;  // d' = d - kAmp * n >= 0 for every n: density 0
          float edge = 1.0f;
          if (d > -(kAmp + kEdge)) {  // otherwise d' <= -kEdge: fully inside
            const float disp = d - kAmp * billow(qx, qy, qz, noiseSeed);
            edge = smoothstep(0.0f, kEdge, -disp);
          }
          row[i] = edge * base;
        }
      }
    }
  });
}

DenseGrid makeCloud(int resolution, uint32_t seed) {
  if (resolution < 8) throw std::invalid_argument("makeCloud: resolution must be at least 8");
  const uint64_t bytes = uint64_t(resolution) * uint64_t(resolution) * uint64_t(resolution) * sizeof(float);
  if (bytes > kMaxDenseGridBytes) {
    throw std::invalid_argument("makeCloud: resolution " + std::to_string(resolution) + " needs " +
                                std::to_string(bytes >> 20) + " MiB of floats, over the " +
                                std::to_string(kMaxDenseGridBytes >> 20) + " MiB limit of a dense grid");
  }
  DenseGrid grid;
  grid.nx = grid.ny = grid.nz = resolution;
  grid.source = "procedural cloud (seed " + std::to_string(seed) + ")";
  grid.data.resize(size_t(resolution) * size_t(resolution) * size_t(resolution));
  makeCloudSlab(resolution, seed, 0, resolution, grid.data.data());
  grid.maxValue = *std::max_element(grid.data.begin(), grid.data.end());
  return grid;
}

}  // namespace narval
