// A homogeneous medium (cl/types.h Medium): where a ray is inside it, its transmittance, and
// free-flight (distance) sampling. Directions are unit vectors: distances are in scene units.
//
// Distance sampling follows pbrt-v3's HomogeneousMedium::Sample (§15.2.1) with spectral MIS over
// the three channels: a channel c is picked uniformly and t is drawn from sigma_t[c]
// exp(-sigma_t[c] t), so the density of t is the average of the three exponentials (the one-sample
// MIS balance heuristic over channels). Each channel's Tr(t) sigma_s / pdf(t) and Tr(t) /
// survival(t) are then at most 3: no channel's weight explodes when the sigmas differ by orders of
// magnitude, and a zero channel (sigma_t = 0, never stops the ray) is still handled.
#ifndef CANOPY_CL_VOLUME_MEDIUM_H
#define CANOPY_CL_VOLUME_MEDIUM_H

#include "../compat.h"
#include "../types.h"

#ifndef __OPENCL_C_VERSION__
using std::exp;
using std::log1p;
#endif

INLINE float medium_f3_get(float3 v, int i) {
  return i == 0 ? v.x : (i == 1 ? v.y : v.z);
}

// Henyey-Greenstein g of the medium (cl/volume/phase.h).
INLINE float medium_g(const Medium* m) {
  return m->sigma_t.w;
}

INLINE int medium_bounded(const Medium* m) {
  return m->sigma_s.w > 0.5f;
}

// exp(-sigma len) with a zero sigma giving 1 even for len = +inf (0 * inf would be NaN).
INLINE float medium_exp_neg(float sigma, float len) {
  return sigma > 0.0f ? exp(-sigma * len) : 1.0f;
}

// The part [t0, t1] of the ray o + t d, t in [0, tmax], inside the medium; tmax may be +inf.
// Unbounded: all of it. Bounded: slab test against the closed box [bmin, bmax]. A zero direction
// component (either sign) tests the origin against that slab instead of dividing (0 * inf = NaN
// when the origin lies on the slab's plane); the others divide rather than multiply by 1 / d,
// so a denormal component gives +-inf, never NaN. Returns 0 when the part is empty or a single
// point (a ray grazing an edge).
INLINE int medium_clip(const Medium* m, float3 o, float3 d, float tmax, float* t0, float* t1) {
  float lo = 0.0f, hi = tmax;
  if (medium_bounded(m)) {
    for (int i = 0; i < 3; ++i) {
      float oi = medium_f3_get(o, i), di = medium_f3_get(d, i);
      float mn = f4_get(m->bmin, i), mx = f4_get(m->bmax, i);
      if (di == 0.0f) {
        if (!(oi >= mn && oi <= mx)) return 0;
        continue;
      }
      float ta = (mn - oi) / di, tb = (mx - oi) / di;
      lo = fmax(lo, fmin(ta, tb));
      hi = fmin(hi, fmax(ta, tb));
    }
  }
  *t0 = lo;
  *t1 = hi;
  return lo < hi;
}

// Transmittance exp(-sigma_t len) per channel, len >= 0 (may be +inf).
INLINE float3 medium_tr(const Medium* m, float len) {
  return make_float3(medium_exp_neg(m->sigma_t.x, len), medium_exp_neg(m->sigma_t.y, len),
                     medium_exp_neg(m->sigma_t.z, len));
}

// Transmittance along o + t d, t in [0, tmax] (tmax may be +inf): only the part inside the medium
// attenuates.
INLINE float3 medium_transmittance(const Medium* m, float3 o, float3 d, float tmax) {
  float t0, t1;
  if (!medium_clip(m, o, d, tmax, &t0, &t1)) return make_float3(1.0f, 1.0f, 1.0f);
  return medium_tr(m, t1 - t0);
}

// A free-flight distance from u in [0, 1): channel c = min(floor(3u), 2) uniformly, u rescaled to
// [0, 1), t = -log(1 - u') / sigma_t[c] (pbrt-v3 §15.2.1); +inf when sigma_t[c] = 0. For a bounded
// medium t counts from where the ray enters it (medium_clip's t0).
INLINE float medium_sample_distance(const Medium* m, float u) {
  int c = (int)(3.0f * u);
  c = c < 0 ? 0 : (c > 2 ? 2 : c);
  float v = 3.0f * u - (float)c;
  v = fmin(fmax(v, 0.0f), 0.99999994f); // 1 - 2^-24: 3u may round up to the next integer
  float sigma = f4_get(m->sigma_t, c);
  if (!(sigma > 0.0f)) return FLT_INF;
  return -log1p(-v) / sigma;
}

// The density of medium_sample_distance at t >= 0: (1/3) sum_c sigma_t[c] exp(-sigma_t[c] t).
INLINE float medium_distance_pdf(const Medium* m, float t) {
  float p = 0.0f;
  for (int c = 0; c < 3; ++c) {
    float s = f4_get(m->sigma_t, c);
    if (s > 0.0f) p += s * exp(-s * t);
  }
  return p * (1.0f / 3.0f);
}

// P(sampled distance > t) = (1/3) sum_c exp(-sigma_t[c] t): the probability that a free flight
// passes t (a surface or the medium's exit at distance t).
INLINE float medium_survival(const Medium* m, float t) {
  return (medium_exp_neg(m->sigma_t.x, t) + medium_exp_neg(m->sigma_t.y, t) +
          medium_exp_neg(m->sigma_t.z, t)) *
         (1.0f / 3.0f);
}

#endif // CANOPY_CL_VOLUME_MEDIUM_H
