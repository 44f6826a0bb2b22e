/* phase_polygon.h: the phase function integrated over the solid angle of a polygon,
 *   P = ∫_Ω p(a·ω) dω,
 * a the propagation direction before scattering (the view direction, away from the camera) and Ω
 * the directions from the scattering point to a convex polygon (a rectangle light's corners seen
 * from x). The ray marcher's single scattering of a uniform rectangle light of radiance Le is then
 * Le·P·(its transmittance), with no point or K×K approximation of the phase (march_light_phase_sum):
 * a light as large as Listing 4.1's (150x100 units, 80 behind the Disney cloud, filling the view)
 * seen through HG(0.9) is far from a point at its centre.
 *
 * Why a contour integral: p depends on ω only through θ, its angle to a, so in polar coordinates
 * (θ, φ) about a, dω = sin θ dθ dφ and with the cap integral
 *   G(μ) = ∫_{μ}^{1} p(μ') dμ'     (μ = cos θ; 2π·G(μ) is p's mass within angle θ of a)
 * Green's theorem turns ∫∫_Ω ∂G/∂θ dθ dφ into ∮_{∂Ω} G dφ (Arvo 1995, "Applications of irradiance
 * tensors to the simulation of non-Lambertian phenomena", does the same for powers of the cosine).
 * HG's cap integral is closed: ∫ (1 + g² − 2gμ)^{−3/2} dμ = (1/g)(1 + g² − 2gμ)^{−1/2}, so
 *   G(μ) = (1 − g²)/(4πg) · (1/(1 − g) − 1/s),  s = √(1 + g² − 2gμ),
 * written here without the cancellation at small g:
 *   1/(1 − g) − 1/s = (s² − (1 − g)²)/((1 − g)·s·(s + 1 − g)) = 2g(1 − μ)/((1 − g)·s·(s + 1 − g)),
 *   G(μ) = (1 + g)(1 − μ)/(2π·s·(s + 1 − g))      (g = 0: (1 − μ)/(4π), isotropic; G(−1) = 1/(2π)).
 *
 * Each edge is an arc of a great circle, walked along its chord (phase_polygon_edge), where the
 * integrand has no trigonometry and stays bounded at the pole (G/sin²θ → p(1)/2): 8-point
 * Gauss–Legendre per edge is within 0.05% of the area integral for a 6-unit light 20 units away at
 * g up to 0.95, the axis sliding across its edge, and within 0.5% for a light 80° wide
 * (tests/unit/phase_polygon_test.cpp). With the polygon traversed counter-clockwise about its
 * inside, φ grows along an edge whose great circle has a on its inner side. The contour counts
 * ∫ G dφ from θ = 0 outwards: the polygon's integral when it holds a or neither pole. */
#ifndef NARVAL_PHASE_POLYGON_H
#define NARVAL_PHASE_POLYGON_H

#include "shared/phase.h"

/* G(μ)/(1 − μ²), what the contour integrand needs (below): (1 + g)/(2π·s·(s + 1 − g)·(1 + μ)) for
 * HG, 1/(4π(1 + μ)) isotropic; finite at the pole μ = 1 (p(1)/2), unbounded only at μ = −1. */
static inline float phase_polygon_cap_over_sin2(int kind, float g, float mu) {
  mu = nv_fmin(1.0f, nv_fmax(-1.0f, mu));
  const float one_plus = nv_fmax(1.0f + mu, 1e-7f);
  switch (PHASE_KIND(kind)) {
    case PHASE_ISOTROPIC: return NV_INV_4PI / one_plus;
    case PHASE_HG: {
      const float s = nv_sqrt(phase_hg_denominator(g, mu));
      return (1.0f + g) / (2.0f * NV_PI * s * (s + 1.0f - g) * one_plus);
    }
    default: return 0.0f; /* unknown: reported at the kernel's entry */
  }
}

/* One edge's share of the contour integral, ∫ G dφ from unit direction v0 to unit direction v1.
 * Along the chord p(t) = (1 − t)·v0 + t·v1, ω = p/|p| and the azimuth about a turns at
 * dφ/dt = a·(ω × dω/dt)/(1 − μ²) = a·(v0 × v1)/(|p|²·(1 − μ²))   (p × p' = v0 × v1),
 * so the share is a·(v0 × v1)·∫₀¹ G(μ)/((1 − μ²)·|p|²) dt: no trigonometry, 8-point Gauss–Legendre. */
static inline float phase_polygon_edge(int kind, float g, vec3 a, vec3 v0, vec3 v1) {
  const float node[8] = {0.019855071751231856f, 0.10166676129318664f, 0.2372337950418355f, 0.4082826787521751f,
                         0.5917173212478249f,   0.7627662049581645f,  0.8983332387068134f, 0.9801449282487681f};
  const float weight[8] = {0.05061426814518813f, 0.11119051722668724f, 0.15685332293894364f, 0.18134189168918100f,
                           0.18134189168918100f, 0.15685332293894364f, 0.11119051722668724f, 0.05061426814518813f};
  const float turn = vec3_dot(a, vec3_cross(v0, v1));
  float sum = 0.0f;
  for (int k = 0; k < 8; ++k) {
    const vec3 p = vec3_add(vec3_scale(v0, 1.0f - node[k]), vec3_scale(v1, node[k]));
    const float p2 = vec3_dot(p, p);
    sum += weight[k] * phase_polygon_cap_over_sin2(kind, g, vec3_dot(a, p) / nv_sqrt(p2)) / p2;
  }
  return turn * sum;
}

/* P = ∫ p(a·ω) dω over the convex spherical polygon with unit corner directions v[0..count-1]
 * (either winding), which must lie in an open hemisphere (a rectangle seen from a point off its
 * plane does). When the corners' mean faces away from a, the integral is taken about −a with −g
 * (p_g(a·ω) = p_{−g}(−a·ω)), so that the polygon never holds the axis's antipode, where the
 * integrand is unbounded; should it still (a polygon nearly a hemisphere wide), 2π·G(−1) = 1 is
 * added back, the part of the region the contour does not see. */
static inline float phase_polygon_integral(int kind, float g, vec3 a, NV_PRIVATE const vec3* v, int count) {
  vec3 mean = vec3_splat(0.0f);
  for (int i = 0; i < count; ++i) mean = vec3_add(mean, v[i]);
  if (vec3_dot(mean, a) < 0.0f) {
    a = vec3_scale(a, -1.0f);
    g = -g;
  }
  /* Counter-clockwise about the inside: the first edge's normal on the side of the mean. */
  const int flip = vec3_dot(vec3_cross(v[0], v[1]), mean) < 0.0f;
  float sum = 0.0f;
  int holds_minus_a = 1;
  for (int i = 0; i < count; ++i) {
    const vec3 p = v[flip ? count - 1 - i : i], q = v[flip ? (2 * count - 2 - i) % count : (i + 1) % count];
    holds_minus_a &= vec3_dot(a, vec3_cross(p, q)) < 0.0f;
    sum += phase_polygon_edge(kind, g, a, p, q);
  }
  if (holds_minus_a) sum += 1.0f;
  return nv_fmax(0.0f, sum);
}

#endif
