// Equiangular sampling of a distance along a ray segment towards a point (Kulla & Fajardo 2012,
// "Importance Sampling Techniques for Path Tracing in Participating Media", equi-angular
// sampling), and the power heuristic that combines it with free-flight sampling.
//
// For the segment o + t d, t in [0, len] (d unit) and a point c: delta = dot(c - o, d) is the
// foot of the perpendicular from c, D the distance from c to the line. Sampling the angle
// theta = atan((t - delta) / D) uniformly between its values theta_a (t = 0) and theta_b (t = len)
// gives pdf(t) = D / (Theta (D^2 + (t - delta)^2)), Theta = theta_b - theta_a: the 1 / r^2 of a
// point light, exactly.
//
// Numerics (every input finite, results finite):
// - Theta is atan2(D len, D^2 - delta (len - delta)), the identity atan x - atan y =
//   atan2(x - y, 1 + x y) with x, y the tangents at the two ends: the difference of two angles
//   near +-pi/2 (a light far from a short segment, Theta ~ 1e-12) would cancel completely.
// - The sample is t = r sin(phi) / cos(theta_a + phi), phi = u Theta, r = |c - o| (the law of sines
//   in the triangle o, c, x(t)), with cos(theta_a + phi) = (D cos phi + delta sin phi) / r:
//   measured from the segment's start, never from theta near +-pi/2, so it has the same precision
//   as Theta.
// - D = |cross(c - o, d)| is clamped below at EQUIANGULAR_D_REL (max |o_i| + max |c_i|), a few
//   times the float error of c - o and of D itself, and at 1e-18 (its square stays a normal float):
//   for a light on the line (D = 0) the density would be a non-integrable 1 / (t - delta)^2.
//   The clamp keeps the density normalised (a Cauchy bump as narrow as the coordinates resolve).
// - len <= 0 or Theta == 0 (len below what D len resolves): no sample, pdf 0 (the caller skips it).
// - len = +inf (a ray leaving an unbounded medium) is allowed: theta_b = pi / 2. A u within
//   rounding of 1 can then give t = +inf with pdf 0 (no sample).
#ifndef CANOPY_CL_VOLUME_EQUIANGULAR_H
#define CANOPY_CL_VOLUME_EQUIANGULAR_H

#include "../compat.h"

#define EQUIANGULAR_D_REL 4.76837158e-7f // 2^-21: eight float epsilons (2^-24) of the coordinates

// The geometry shared by the sample and the density, so the two agree bit for bit.
typedef struct EquiangularGeom {
  float delta; // dot(c - o, d)
  float dist;  // D, clamped
  float theta; // Theta = theta_b - theta_a in [0, pi]
} EquiangularGeom;

INLINE EquiangularGeom equiangular_geom(float3 o, float3 d, float len, float3 c) {
  EquiangularGeom g;
  float3 oc = c - o;
  g.delta = dot(oc, d);
  float scale = max3(fabs(o)) + max3(fabs(c));
  g.dist = fmax(length(cross(oc, d)), fmax(EQUIANGULAR_D_REL * scale, 1e-18f));
  if (!(len > 0.0f))
    g.theta = 0.0f;
  else if (len < FLT_INF)
    g.theta = atan2(g.dist * len, g.dist * g.dist - g.delta * (len - g.delta));
  else // theta_b = pi / 2: Theta = pi / 2 - theta_a, the angle of (-delta, D)
    g.theta = atan2(g.dist, -g.delta);
  return g;
}

INLINE float equiangular_density(const EquiangularGeom* g, float len, float t) {
  if (!(g->theta > 0.0f) || !(t >= 0.0f && t <= len)) return 0.0f;
  float x = t - g->delta;
  // D / (D^2 + x^2) first: the product Theta (D^2 + x^2) could underflow for a huge D.
  return g->dist / (g->dist * g->dist + x * x) / g->theta;
}

// The density of equiangular_sample at t over [0, len]; 0 outside it.
INLINE float equiangular_pdf(float3 o, float3 d, float len, float3 c, float t) {
  EquiangularGeom g = equiangular_geom(o, d, len, c);
  return equiangular_density(&g, len, t);
}

// t in [0, len] with density proportional to 1 / (D^2 + (t - delta)^2) from u in [0, 1);
// *pdf = equiangular_pdf at t (0: no sample, see above).
INLINE float equiangular_sample(float3 o, float3 d, float len, float3 c, float u, float* pdf) {
  EquiangularGeom g = equiangular_geom(o, d, len, c);
  if (!(g.theta > 0.0f)) {
    *pdf = 0.0f;
    return 0.0f;
  }
  float r = sqrt(g.dist * g.dist + g.delta * g.delta);
  float phi = u * g.theta;
  float sp = sin(phi), cp = cos(phi);
  // cos(theta_a + phi) with cos theta_a = D / r, sin theta_a = -delta / r.
  float cos_end = (g.dist / r) * cp + (g.delta / r) * sp;
  float t = cos_end > 0.0f ? r * sp / cos_end : len;
  t = fmin(fmax(t, 0.0f), len);
  *pdf = equiangular_density(&g, len, t);
  return t;
}

// Power heuristic (beta = 2) weight of technique a against b: a^2 / (a^2 + b^2), written as
// 1 / (1 + (b / a)^2) so huge densities (a peaked equiangular pdf) do not overflow.
INLINE float volume_mis_weight(float pdf_a, float pdf_b) {
  if (!(pdf_a > 0.0f)) return 0.0f;
  if (!(pdf_b > 0.0f)) return 1.0f;
  float r = pdf_b / pdf_a;
  if (r != r) return 0.5f; // both +inf
  return 1.0f / (1.0f + r * r);
}

#endif // CANOPY_CL_VOLUME_EQUIANGULAR_H
