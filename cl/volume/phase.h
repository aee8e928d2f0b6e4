// The Henyey-Greenstein phase function (pbrt-v3 §11.2; sampling §15.2.3).
//
// Convention: theta is the angle between the light's direction of travel before and after
// scattering. A path traced from the camera along unit d that scatters and continues towards the
// light along wi carries light arriving along -wi and leaving along -d, so cos theta = dot(wi, d):
// g > 0 (forward scattering) puts wi around d.
#ifndef CANOPY_CL_VOLUME_PHASE_H
#define CANOPY_CL_VOLUME_PHASE_H

#include "../compat.h"
#include "../shading.h"

// |g| is clamped here: g = +-1 is a delta (0 / 0 below), and at 0.9999 the lobe (1 - cos theta ~
// (1 - g)^2 = 1e-8) is already narrower than the float cosines near 1 resolve (2^-24), so a larger
// |g| would change nothing a float direction can show.
#define PHASE_HG_G_MAX 0.9999f

INLINE float phase_hg_clamp_g(float g) {
  return fmin(fmax(g, -PHASE_HG_G_MAX), PHASE_HG_G_MAX);
}

// p(theta) = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos theta)^{3/2}), normalised over the sphere.
// 1 + g^2 - 2 g cos is rewritten as a sum of non-negative terms, (1 - g)^2 + 2 g (1 - cos) for
// g >= 0 and (1 + g)^2 + 2 |g| (1 + cos) for g < 0: no cancellation at the peak when |g| -> 1
// (1 - g and 1 - cos are exact there), and g = 0 gives exactly 1 / (4 pi).
INLINE float phase_hg(float g, float cos_theta) {
  g = phase_hg_clamp_g(g);
  float c = fmin(fmax(cos_theta, -1.0f), 1.0f);
  float den = g >= 0.0f ? (1.0f - g) * (1.0f - g) + 2.0f * g * (1.0f - c)
                        : (1.0f + g) * (1.0f + g) - 2.0f * g * (1.0f + c);
  return (1.0f - g) * (1.0f + g) / (4.0f * CANOPY_PI * den * sqrt(den));
}

// The direction wi of the next ray for a path travelling along unit d, with density
// phase_hg(g, dot(wi, d)) over the sphere; *pdf = that density at the returned direction.
//
// Inverse CDF: with xi = u1, pbrt's cos theta = (1 + g^2 - ((1 - g^2) / (1 - g + 2 g xi))^2) / (2
// g) is rewritten as the two exact products (q = 1 - g + 2 g xi = (1 - g)(1 - xi) + (1 + g) xi > 0)
//   1 - cos theta = 2 (1 - g)^2 (1 - xi) (1 + g xi) / q^2,  1 + g xi = (1 - xi) + (1 + g) xi,
//   1 + cos theta = 2 (1 + g)^2 xi (1 - g (1 - xi)) / q^2,  1 - g (1 - xi) = xi + (1 - g)(1 - xi),
// every factor a sum of non-negative terms: no 1 / g (g = 0 is exactly uniform, no small-g branch),
// no cancellation for |g| -> 1, and sin theta = sqrt((1 - cos)(1 + cos)) keeps its precision near
// both poles. cos theta is taken from whichever of the two is smaller.
INLINE float3 phase_hg_sample(float g, float3 d, float u1, float u2, float* pdf) {
  float gc = phase_hg_clamp_g(g);
  float xi = fmin(fmax(u1, 0.0f), 1.0f);
  float q = (1.0f - gc) * (1.0f - xi) + (1.0f + gc) * xi;
  float inv_q2 = 1.0f / (q * q);
  float one_minus =
      2.0f * (1.0f - gc) * (1.0f - gc) * (1.0f - xi) * ((1.0f - xi) + (1.0f + gc) * xi) * inv_q2;
  float one_plus =
      2.0f * (1.0f + gc) * (1.0f + gc) * xi * (xi + (1.0f - gc) * (1.0f - xi)) * inv_q2;
  float cos_t = one_minus < one_plus ? 1.0f - one_minus : one_plus - 1.0f;
  float sin_t = sqrt(fmax(0.0f, one_minus * one_plus));
  float phi = 2.0f * CANOPY_PI * u2;
  float3 t, b;
  onb_from(d, &t, &b);
  float3 wi = normalize(t * (sin_t * cos(phi)) + b * (sin_t * sin(phi)) + d * cos_t);
  *pdf = phase_hg(g, dot(wi, d));
  return wi;
}

#endif // CANOPY_CL_VOLUME_PHASE_H
