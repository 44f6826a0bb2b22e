// phase_polygon_test.cpp: kernels/shared/phase_polygon.h on the host (the code the device runs).
// The contour integral ∮ G dφ against the area integral it replaces,
//   P = ∫_rect p(a·ω) dω = ∫_rect p(a·ω(y)) cos θ_y / |y − x|² dA(y),
// summed here in double precision over an N×N midpoint grid of the rectangle (N large enough that
// the grid's own error, checked by halving N, is far below the tolerance), for lights the axis
// points into, past and away from, HG at g 0, ±0.5, 0.8, 0.9, and the isotropic phase; plus the
// closed values: the whole sphere (a cube around x, six faces) integrates to 1, and the
// isotropic phase gives the solid angle over 4π (a square of side 2 at distance 1 subtends 2π/3).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "shared/phase_polygon.h"

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Rect {
  vec3 corner, u, v;  // corner + s·u + t·v, s, t ∈ [0, 1]
};

double hg(double g, double mu) {
  if (g == 0.0) return 1.0 / (4.0 * kPi);
  const double d = 1.0 + g * g - 2.0 * g * mu;
  return (1.0 - g * g) / (4.0 * kPi * d * std::sqrt(d));
}

// ∫ p(a·ω) dω over the rectangle seen from x by the midpoint rule on an N×N grid (double).
double bruteForce(double g, vec3 x, vec3 a, const Rect& r, int N) {
  const double ux = r.u.x, uy = r.u.y, uz = r.u.z, vx = r.v.x, vy = r.v.y, vz = r.v.z;
  double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
  const double area = std::sqrt(nx * nx + ny * ny + nz * nz);
  nx /= area, ny /= area, nz /= area;
  double sum = 0.0;
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i) {
      const double s = (i + 0.5) / N, t = (j + 0.5) / N;
      const double px = r.corner.x + s * ux + t * vx - x.x, py = r.corner.y + s * uy + t * vy - x.y,
                   pz = r.corner.z + s * uz + t * vz - x.z;
      const double d2 = px * px + py * py + pz * pz, d = std::sqrt(d2);
      const double cosl = std::fabs(px * nx + py * ny + pz * nz) / d;
      const double mu = (px * a.x + py * a.y + pz * a.z) / d;
      sum += hg(g, mu) * cosl / d2;
    }
  return sum * area / (double(N) * double(N));
}

float contour(int kind, float g, vec3 x, vec3 a, const Rect& r) {
  const vec3 p[4] = {r.corner, vec3_add(r.corner, r.u), vec3_add(vec3_add(r.corner, r.u), r.v),
                     vec3_add(r.corner, r.v)};
  vec3 d[4];
  for (int i = 0; i < 4; ++i) d[i] = vec3_normalize(vec3_sub(p[i], x));
  return phase_quad_integral(phase_make(kind, g), vec3_normalize(a), d[0], d[1], d[2], d[3]);
}

struct Case {
  std::string name;
  Rect rect;
  vec3 x, a;
};

// Listing 4.1's light (150x100 at z = 80) from points of the Disney cloud's box, and the default
// cloud's sun (6x6 at z = 20), with the view axis into the light, past its edge, sideways and away.
const Case kCases[] = {
    {"huge light, axis inside", {{-75, -50, 80}, {150, 0, 0}, {0, 100, 0}}, {1, 2, -3}, {0.1f, 0.05f, 1}},
    {"huge light, axis near its edge", {{-75, -50, 80}, {150, 0, 0}, {0, 100, 0}}, {0, 0, 0}, {0.68f, 0.0f, 0.73f}},
    {"huge light, axis sideways", {{-75, -50, 80}, {150, 0, 0}, {0, 100, 0}}, {3, -1, 5}, {1, 0.2f, 0}},
    {"huge light, axis away (antipode inside)", {{-75, -50, 80}, {150, 0, 0}, {0, 100, 0}}, {0, 0, 0}, {0.1f, 0, -1}},
    {"sun, axis inside", {{-3, -3, 20}, {6, 0, 0}, {0, 6, 0}}, {0.5f, 0.3f, 0}, {0, 0, 1}},
    {"sun, axis just outside", {{-3, -3, 20}, {6, 0, 0}, {0, 6, 0}}, {0, 0, -5}, {0.13f, 0.02f, 1}},
    {"sun, axis across", {{-3, -3, 20}, {6, 0, 0}, {0, 6, 0}}, {4, 4, 0}, {-1, 0.3f, 0.4f}},
    {"tilted light close by", {{-2, 1, 1}, {3, 0, 1}, {0, 2, 0.5f}}, {0.2f, 0.1f, -0.5f}, {0.3f, 0.9f, 0.6f}},
};

TEST(PhasePolygon, MatchesTheAreaIntegralForHgAndIsotropic) {
  const float gs[] = {0.0f, 0.5f, -0.5f, 0.8f, 0.9f};
  for (const Case& c : kCases)
    for (float g : gs) {
      const vec3 a = vec3_normalize(c.a);
      const double ref = bruteForce(g, c.x, a, c.rect, 1600);
      const double coarse = bruteForce(g, c.x, a, c.rect, 800);
      ASSERT_LT(std::fabs(ref - coarse), 2e-4 * ref + 1e-7) << c.name << " g " << g << ": the grid is too coarse";
      const float got = contour(PHASE_HG, g, c.x, a, c.rect);
      // 4-point Gauss panels per edge (as many as the arc holds phase widths): within 0.3% (+1e-6).
      EXPECT_NEAR(got, ref, 3e-3 * ref + 1e-6) << c.name << " g " << g;
      if (g == 0.0f) {
        EXPECT_NEAR(contour(PHASE_ISOTROPIC, 0.3f, c.x, a, c.rect), ref, 5e-3 * ref + 1e-6) << c.name;
      }
    }
}

TEST(PhasePolygon, ClosedValues) {
  // A square of side 2 at distance 1 subtends a sixth of the sphere: isotropic P = (4π/6)/(4π)
  // (one 4-point panel per 90° edge: within 1e-4).
  const Rect face{{-1, -1, 1}, {2, 0, 0}, {0, 2, 0}};
  EXPECT_NEAR(contour(PHASE_ISOTROPIC, 0.0f, vec3_make(0, 0, 0), vec3_make(0, 0, 1), face), 1.0 / 6.0, 1e-4 / 6.0);
  // The six faces of a cube around x cover the sphere: HG integrates to 1 for any axis and g.
  const Rect faces[6] = {{{-1, -1, 1}, {2, 0, 0}, {0, 2, 0}},  {{-1, -1, -1}, {2, 0, 0}, {0, 2, 0}},
                         {{-1, 1, -1}, {2, 0, 0}, {0, 0, 2}},  {{-1, -1, -1}, {2, 0, 0}, {0, 0, 2}},
                         {{1, -1, -1}, {0, 2, 0}, {0, 0, 2}},  {{-1, -1, -1}, {0, 2, 0}, {0, 0, 2}}};
  const vec3 axes[3] = {vec3_make(0, 0, 1), vec3_make(0.3f, -0.5f, 0.81f), vec3_make(1, 1, 1)};
  for (float g : {0.0f, 0.6f, 0.9f, -0.7f})
    for (const vec3& axis : axes) {
      double sum = 0.0;
      for (const Rect& r : faces) sum += contour(PHASE_HG, g, vec3_make(0, 0, 0), vec3_normalize(axis), r);
      EXPECT_NEAR(sum, 1.0, 2e-3) << "g " << g;
    }
  // So does Mie (phase_mie.h: its Draine lobe's cap integral in closed form), in each of the fit's
  // ranges; 20 µm droplets put a third of the scattering within 0.1 rad of the axis.
  for (float d : {0.5f, 3.0f, 20.0f})
    for (const vec3& axis : axes) {
      double sum = 0.0;
      for (const Rect& r : faces) sum += contour(PHASE_MIE, d, vec3_make(0, 0, 0), vec3_normalize(axis), r);
      EXPECT_NEAR(sum, 1.0, 2e-3) << "d " << d;
    }
}

}  // namespace
