// Exact unpolarised Fresnel reflectance at a smooth interface, seen from outside (cos_i >= 0):
// a dielectric of relative index eta (the plastic coat) and a conductor of complex index
// eta + i k (per RGB channel). Compiled only for scenes with a glossy material or glass.
#ifndef CANOPY_CL_BSDF_FRESNEL_H
#define CANOPY_CL_BSDF_FRESNEL_H

#include "../compat.h"
#include "../kernel_features.h"

#if HAS_FRESNEL

// Dielectric: the average of the s- and p-polarised reflectances (Fresnel equations, e.g. Born &
// Wolf §1.5.2; pbrt-v3 §8.2.1). Light arriving from the side of index 1 (eta < 1 also works:
// total internal reflection returns 1).
INLINE float fresnel_dielectric(float cos_i, float eta) {
  cos_i = clamp(cos_i, 0.0f, 1.0f);
  if (!(eta > 0.0f)) return 1.0f;
  // Snell: cos_t^2 = 1 - (1 - cos_i^2) / eta^2 = ((eta^2 - 1) + cos_i^2) / eta^2, summed in this
  // order so eta near 1 keeps cos_t exact at grazing angles (no 1 - (1 - x) cancellation).
  float cos2_t_eta2 = (eta * eta - 1.0f) + cos_i * cos_i;
  if (cos2_t_eta2 <= 0.0f) return 1.0f; // total internal reflection
  float cos_t = sqrt(cos2_t_eta2) / eta;
  float ds = cos_i + eta * cos_t, dp = eta * cos_i + cos_t;
  if (!(ds > 0.0f) || !(dp > 0.0f)) return 1.0f; // cos_i = cos_t = 0: grazing, full reflection
  float rs = (cos_i - eta * cos_t) / ds;
  float rp = (eta * cos_i - cos_t) / dp;
  return clamp(0.5f * (rs * rs + rp * rp), 0.0f, 1.0f);
}

// Conductor, one channel: the exact reflectance of an absorbing medium with complex index
// eta + i k (Born & Wolf §14.2; the a^2 + b^2 form of Heckbert's "Fresnel equations" notes and
// pbrt-v3 §8.2.1). With s = sin^2, c = cos of the angle of incidence:
//   a^2 + b^2 = sqrt((eta^2 - k^2 - s)^2 + 4 eta^2 k^2),  a^2 = (a^2 + b^2 + eta^2 - k^2 - s) / 2
//   Rs = (a^2 + b^2 - 2 a c + c^2) / (a^2 + b^2 + 2 a c + c^2)
//   Rp = Rs (c^2 (a^2 + b^2) - 2 a c s + s^2) / (c^2 (a^2 + b^2) + 2 a c s + s^2)
// Both quotients are of non-negative terms (no cancellation in the denominators); the only 0/0
// cases are the index-matched limits, which return full reflection at grazing incidence.
INLINE float fresnel_conductor1(float c, float eta, float k) {
  c = clamp(c, 0.0f, 1.0f);
  float c2 = c * c;
  float s = fmax(0.0f, 1.0f - c2);
  float eta2 = eta * eta, k2 = k * k;
  float t0 = (eta2 - k2 - 1.0f) + c2; // eta^2 - k^2 - s, without rounding s = 1 - c^2 first
  float ab2 = sqrt(t0 * t0 + 4.0f * eta2 * k2);
  float a = sqrt(fmax(0.0f, 0.5f * (ab2 + t0)));
  float num_s = ab2 - 2.0f * a * c + c2, den_s = ab2 + 2.0f * a * c + c2;
  float rs = den_s > 0.0f ? fmax(0.0f, num_s) / den_s : 1.0f;
  float t1 = c2 * ab2 + s * s, t2 = 2.0f * a * c * s;
  float rp = (t1 + t2) > 0.0f ? rs * fmax(0.0f, t1 - t2) / (t1 + t2) : rs;
  return clamp(0.5f * (rs + rp), 0.0f, 1.0f);
}

INLINE float3 fresnel_conductor(float c, float3 eta, float3 k) {
  return make_float3(fresnel_conductor1(c, eta.x, k.x), fresnel_conductor1(c, eta.y, k.y),
                     fresnel_conductor1(c, eta.z, k.z));
}

#endif // HAS_FRESNEL
#endif // CANOPY_CL_BSDF_FRESNEL_H
