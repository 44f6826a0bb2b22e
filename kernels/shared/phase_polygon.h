/* phase_polygon.h: the phase function integrated over the solid angle of a polygon,
 *   P = ∫_Ω p(a·ω) dω,
 * a the propagation direction before scattering, Ω the directions from the scattering point to a convex
 * polygon (a rectangle light). The ray marcher's single scattering of a uniform rectangle light is then
 * Le·P·(its transmittance), without march_light_phase_sum's point or K×K approximation: a light as large
 * as Listing 4.1's (150x100 units, 80 behind the Disney cloud) seen through HG(0.9) is far from a point.
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
 * Each edge, a great-circle arc, is integrated along its chord (phase_polygon_edge): no trigonometry,
 * bounded at the pole (G/sin²θ → p(1)/2); close to the area integral for Listing 4.1's light (86° × 64°)
 * at g up to 0.9 and a 6-unit light 20 units away (bench/RESULTS.md; tests/unit/phase_polygon_test.cpp
 * within its tolerance). Counter-clockwise about its inside, φ grows along an edge whose great circle has a
 * on its inner side; the contour counts ∫ G dφ from θ = 0 outwards: the polygon's integral when it
 * holds a or neither pole. */
#ifndef NARVAL_PHASE_POLYGON_H
#define NARVAL_PHASE_POLYGON_H

#include "shared/phase.h"

/* One edge's share of the contour integral, ∫ G dφ from unit direction v0 to v1 (n = v0 × v1, which
 * the caller has). Along the chord p(t) = (1 − t)·v0 + t·v1, ω = p/|p| and the azimuth about a turns at
 * dφ/dt = a·(ω × dω/dt)/(1 − μ²) = a·(v0 × v1)/(|p|²·(1 − μ²))   (p × p' = v0 × v1),
 * so the share is a·(v0 × v1)·∫₀¹ G(μ)/((1 − μ²)·|p|²) dt: no trigonometry in the integrand.
 * Quadrature: 4-point Gauss–Legendre on 1, 2 or 4 equal panels as the chord is under 2.5, under 5 or
 * more phase widths 1 − |g| (HG halves within about 1 − |g| rad): one panel for a 17° light at g 0.8,
 * four for Listing 4.1's 86° edges at g 0.9. */
static inline float phase_polygon_edge(phase_params p, vec3 a, vec3 v0, vec3 v1, vec3 n) {
  const float node[4] = {0.06943184420297371f, 0.33000947820757187f, 0.6699905217924281f, 0.9305681557970263f};
  const float weight[4] = {0.17392742256872692f, 0.3260725774312731f, 0.3260725774312731f, 0.17392742256872692f};
  /* The chord |v1 − v0| ≤ the arc ≤ π/2 · the chord: a measure of the arc without trigonometry. */
  const float chord = vec3_length(vec3_sub(v1, v0));
  const float width = phase_width(p);
  const int panels = chord < 2.5f * width ? 1 : chord < 5.0f * width ? 2 : 4;
  const float inv = 1.0f / (float)panels;
  float sum = 0.0f;
  for (int q = 0; q < panels; ++q)
    for (int k = 0; k < 4; ++k) {
      const float t = ((float)q + node[k]) * inv;
      const vec3 c = vec3_add(vec3_scale(v0, 1.0f - t), vec3_scale(v1, t));
      const float c2 = vec3_dot(c, c);
      sum += weight[k] * phase_cap_over_sin2(p, vec3_dot(a, c) / nv_sqrt(c2)) / c2;
    }
  return vec3_dot(a, n) * sum * inv;
}

/* P = ∫ p(a·ω) dω over the spherical quadrilateral with unit corners v0..v3 in order (either winding;
 * convex, as a rectangle seen from off its plane, hence in an open hemisphere). If the corners' mean
 * faces away from a, it integrates about −a with the phase mirrored (phase_scaled by −1:
 * p'(a'·ω) = p(a·ω) for a' = −a), so the quad never holds the axis's antipode, where the integrand is
 * unbounded; should it still (a quad nearly a hemisphere wide), 2π·G(−1) = 1 is added back, the part
 * the contour does not see. A clockwise quad negates every edge's share, so takes the negated sum. */
static inline float phase_quad_integral(phase_params p, vec3 a, vec3 v0, vec3 v1, vec3 v2, vec3 v3) {
  const vec3 mean = vec3_add(vec3_add(v0, v1), vec3_add(v2, v3));
  if (vec3_dot(mean, a) < 0.0f) {
    a = vec3_scale(a, -1.0f);
    p = phase_scaled(p, -1.0f);
  }
  const vec3 n0 = vec3_cross(v0, v1), n1 = vec3_cross(v1, v2), n2 = vec3_cross(v2, v3), n3 = vec3_cross(v3, v0);
  /* Counter-clockwise about the inside: the first edge's normal on the side of the mean. */
  const float sign = vec3_dot(n0, mean) < 0.0f ? -1.0f : 1.0f;
  const float sum = phase_polygon_edge(p, a, v0, v1, n0) + phase_polygon_edge(p, a, v1, v2, n1) +
                    phase_polygon_edge(p, a, v2, v3, n2) + phase_polygon_edge(p, a, v3, v0, n3);
  const int holds_minus_a = sign * vec3_dot(a, n0) < 0.0f && sign * vec3_dot(a, n1) < 0.0f &&
                            sign * vec3_dot(a, n2) < 0.0f && sign * vec3_dot(a, n3) < 0.0f;
  return nv_fmax(0.0f, sign * sum + (holds_minus_a ? 1.0f : 0.0f));
}

#endif
