#include "render/light_selection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "shared/light.h"

namespace narval {
namespace {

constexpr double kPi = 3.14159265358979323846;

using D3 = std::array<double, 3>;

D3 d3(const nv_float4& v) { return {v.x, v.y, v.z}; }
double meanRgb(const nv_float4& v) { return (double(v.x) + v.y + v.z) / 3.0; }

// Points of the medium in world space with their weights: voxel centres of the density grid on a
// lattice of at most 32 per axis, weighted by their density; a homogeneous medium's box on an 8³
// lattice, equally.
struct WeightedPoint {
  D3 p;
  double w;
};

std::vector<WeightedPoint> mediumPoints(const DeviceScene& ds) {
  std::vector<WeightedPoint> out;
  if (!ds.params.has_medium) return out;
  const nv_affine toWorld = affineInverse(ds.params.medium.world_to_index);
  auto world = [&](double x, double y, double z) {
    D3 w;
    for (int r = 0; r < 3; ++r) {
      const nv_float4& row = toWorld.row[r];
      w[size_t(r)] = row.x * x + row.y * y + row.z * z + row.w;
    }
    return w;
  };
  if (!ds.grid) {
    const nv_float4 dims = ds.params.medium.dims;
    constexpr int n = 8;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
          out.push_back({world((i + 0.5) / n * dims.x, (j + 0.5) / n * dims.y, (k + 0.5) / n * dims.z), 1.0});
    return out;
  }
  const DenseGrid& g = *ds.grid;
  const int stride = std::max({1, (g.nx + 31) / 32, (g.ny + 31) / 32, (g.nz + 31) / 32});
  for (int z = stride / 2; z < g.nz; z += stride)
    for (int y = stride / 2; y < g.ny; y += stride)
      for (int x = stride / 2; x < g.nx; x += stride) {
        const double rho = g.at(x, y, z);
        if (rho > 0) out.push_back({world(x + 0.5, y + 0.5, z + 0.5), rho});
      }
  return out;
}

// ∫ Le dω of light l at point x, unshadowed: an area light as 4×4 patches (each cos θ_l·ΔA/d², zero
// behind it: the rectangle's corner and edges), any other light as its one point, I/d²; mean over
// the channels.
double fluenceAt(const light_params& l, const D3& x) {
  const vec3 xf = vec3_make(float(x[0]), float(x[1]), float(x[2]));
  if (light_has_area(&l)) {
    constexpr int n = 4;
    const D3 c = d3(l.corner), eu = d3(l.edge_u), ev = d3(l.edge_v), nrm = d3(l.normal);
    double sum = 0;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double s = (i + 0.5) / n, t = (j + 0.5) / n;
        const D3 y{c[0] + s * eu[0] + t * ev[0], c[1] + s * eu[1] + t * ev[1], c[2] + s * eu[2] + t * ev[2]};
        const D3 to{x[0] - y[0], x[1] - y[1], x[2] - y[2]};
        const double d2 = to[0] * to[0] + to[1] * to[1] + to[2] * to[2];
        if (!(d2 > 0)) continue;
        const double cosL = (to[0] * nrm[0] + to[1] * nrm[1] + to[2] * nrm[2]) / std::sqrt(d2);
        if (cosL > 0) sum += cosL / d2;
      }
    return meanRgb(l.radiance) * sum * double(l.normal.w) / (n * n);
  }
  light_point_view v;
  if (!light_view_from(&l, xf, &v)) return 0.0;
  const double r = v.range;
  return (double(v.intensity.x) + v.intensity.y + v.intensity.z) / 3.0 / (r * r);
}

double lightPower(const light_params& l) {
  if (!light_known(l.type)) throw std::logic_error("lightPower: unknown light type " + std::to_string(l.type));
  return light_power(&l);
}

}  // namespace

std::vector<double> lightSelectionWeights(const DeviceScene& ds, LightSampling mode) {
  const size_t n = size_t(ds.params.num_lights);
  std::vector<double> w(n, 0.0);
  switch (mode) {
    case LightSampling::All: std::fill(w.begin(), w.end(), 1.0); return w;
    case LightSampling::Power:
      for (size_t i = 0; i < n; ++i) w[i] = lightPower(ds.lights[i]);
      return w;
    case LightSampling::Fluence: {
      const std::vector<WeightedPoint> points = mediumPoints(ds);
      for (size_t i = 0; i < n; ++i)
        for (const WeightedPoint& p : points) w[i] += p.w * fluenceAt(ds.lights[i], p.p);
      return w;
    }
  }
  throw std::logic_error("lightSelectionWeights: unknown mode");
}

void assignLightSelection(DeviceScene& ds, LightSampling mode) {
  const size_t n = size_t(ds.params.num_lights);
  ds.params.light_sampling = mode == LightSampling::All ? LIGHT_SAMPLING_ALL : LIGHT_SAMPLING_ONE;
  if (mode == LightSampling::All) {
    for (size_t i = 0; i < n; ++i) ds.lights[i].select_prob = 1.0f;  // each light its own strategy
    return;
  }
  const std::vector<double> w = lightSelectionWeights(ds, mode);
  double total = 0;
  for (double x : w) total += x;
  const double uniformShare = mode == LightSampling::Fluence ? kFluenceUniformShare : 0.0;
  for (size_t i = 0; i < n; ++i) {
    // No light has a positive weight (all dark, or no medium point sees any): pick uniformly.
    const double share = total > 0 && std::isfinite(total) ? w[i] / total : 1.0 / double(n);
    ds.lights[i].select_prob = float((1 - uniformShare) * share + uniformShare / double(n));
  }
}

}  // namespace narval
