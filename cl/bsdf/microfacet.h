// GGX (Trowbridge-Reitz) microfacet distribution with height-correlated Smith masking-shadowing
// and visible-normal sampling, in the local shading frame (z = normal). alpha = roughness^2 > 0;
// callers treat alpha == 0 as a delta lobe and never call these. Compiled only for scenes with a
// glossy material or glass (HAS_GGX), so a diffuse-only kernel holds no GGX code.
//
// Every formula is arranged to stay finite for any alpha ggx_alpha gives (>= 1e-7) and for
// directions at the horizon: no 1 - x cancellations, no tan, no division by a cosine that may be 0.
#ifndef CANOPY_CL_BSDF_MICROFACET_H
#define CANOPY_CL_BSDF_MICROFACET_H

#include "../compat.h"
#include "../kernel_features.h"

#if HAS_GGX

// The alpha the GGX functions get: a positive material alpha is raised to 1e-7 (a lobe far
// narrower than the float resolution of a direction, ~6e-8) so that alpha^2 and D(n) =
// 1 / (pi alpha^2) stay normal floats; alpha <= 0 (or NaN) means a delta lobe (callers check
// ggx_is_delta first).
#define GGX_ALPHA_MIN 1e-7f
INLINE int ggx_is_delta(float alpha) {
  return !(alpha > 0.0f);
}
INLINE float ggx_alpha(float alpha) {
  return fmax(alpha, GGX_ALPHA_MIN);
}

// D(h) = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2) (Walter et al. 2007, eq. 33). For unit h the
// bracket is (h.x^2 + h.y^2) + h.z^2 alpha^2; dividing it by alpha^2 gives
// s = (h.x^2 + h.y^2) / alpha^2 + h.z^2 and D = 1 / (pi alpha^2 s^2). The naive form rounds
// the bracket to 0 near h = n for alpha < ~2.4e-4 in float; this one is exact there (s = 1).
INLINE float ggx_D(float3 h, float alpha) {
  float a2 = alpha * alpha;
  float s = (h.x * h.x + h.y * h.y) / a2 + h.z * h.z;
  return 1.0f / ((CANOPY_PI * a2 * s) * s);
}

// |w.z| (1 + 2 Lambda(w)) = sqrt(w.z^2 + alpha^2 (w.x^2 + w.y^2)), with Smith's
// Lambda(w) = (sqrt(1 + alpha^2 tan^2 theta) - 1) / 2 (Heitz 2014, eq. 72) multiplied through by
// |w.z|: no tan (infinite at the horizon) and no sqrt(..) - 1 cancellation.
INLINE float ggx_lambda_len(float3 w, float alpha) {
  return sqrt(w.z * w.z + alpha * alpha * (w.x * w.x + w.y * w.y));
}

// Height-correlated G2 = 1 / (1 + Lambda(wo) + Lambda(wi)) (Heitz 2014, eq. 99). With
// L = ggx_lambda_len: G2 = 2 |zo| |zi| / (|zi| Lo + |zo| Li).
INLINE float ggx_G2(float3 wo, float3 wi, float alpha) {
  float zo = fabs(wo.z), zi = fabs(wi.z);
  float den = zi * ggx_lambda_len(wo, alpha) + zo * ggx_lambda_len(wi, alpha);
  return den > 0.0f ? 2.0f * zo * zi / den : 0.0f;
}

// G1(w) = 1 / (1 + Lambda(w)) = 2 |z| / (|z| + L).
INLINE float ggx_G1(float3 w, float alpha) {
  float z = fabs(w.z);
  float den = z + ggx_lambda_len(w, alpha);
  return den > 0.0f ? 2.0f * z / den : 0.0f;
}

// The microfacet reflection term without Fresnel, D G2 / (4 |cos i| |cos o|), for wo and wi in the
// upper hemisphere and h their unit half vector. The cosines cancel against G2's numerator:
// D / (2 (|zi| Lo + |zo| Li)), finite where one of the directions is at the horizon.
INLINE float ggx_reflection(float3 wo, float3 wi, float3 h, float alpha) {
  float den = fabs(wi.z) * ggx_lambda_len(wo, alpha) + fabs(wo.z) * ggx_lambda_len(wi, alpha);
  if (!(den > 0.0f)) return 0.0f;
  return ggx_D(h, alpha) / (2.0f * den);
}

// Unit half vector of a reflection pair in the upper hemisphere; 0 when wo + wi vanishes.
INLINE float3 half_vector(float3 wo, float3 wi, int* ok) {
  float3 hs = wo + wi;
  float l2 = dot(hs, hs);
  *ok = l2 > 0.0f;
  return *ok ? hs * (1.0f / sqrt(l2)) : make_float3(0.0f, 0.0f, 1.0f);
}

// Solid-angle pdf of wi = reflect(wo, h) with h drawn from the visible normals:
// D_wo(h) / (4 |wo.h|), D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z (Heitz 2018, eq. 1 and 17),
// which is G1(wo) D(h) / (4 wo.z) = D(h) / (2 (zo + Lo)). Reflections only: 0 below the horizon.
INLINE float ggx_reflection_pdf(float3 wo, float3 wi, float3 h, float alpha) {
  if (!(wo.z > 0.0f) || !(wi.z > 0.0f) || !(dot(wo, h) > 0.0f)) return 0.0f;
  float den = wo.z + ggx_lambda_len(wo, alpha);
  return ggx_D(h, alpha) / (2.0f * den);
}

// A visible normal for wo (wo.z > 0), from u1, u2 in [0, 1): the spherical-cap form of Dupuy &
// Benyoub 2023 ("Sampling Visible GGX Normals with Spherical Caps", Listing 3). In the
// configuration stretched to alpha = 1 the visible normals are wo_s + c with c uniform on the
// cap z > -wo_s.z of the unit sphere, z = 1 - t with t = u2 (1 + wo_s.z) uniform. sin theta
// comes from t (2 - t) = 1 - z^2 and the normal's z from (1 + wo_s.z)(1 - u2) = z + wo_s.z,
// without cancellation near the poles.
INLINE float3 ggx_sample_visible_normal(float3 wo, float alpha, float u1, float u2) {
  float3 ws = normalize(make_float3(alpha * wo.x, alpha * wo.y, wo.z));
  float one_plus_wz = 1.0f + ws.z;
  float t = u2 * one_plus_wz;
  float sin_t = sqrt(fmax(0.0f, t * (2.0f - t)));
  float phi = 2.0f * CANOPY_PI * u1;
  float3 hs =
      make_float3(sin_t * cos(phi) + ws.x, sin_t * sin(phi) + ws.y, one_plus_wz * (1.0f - u2));
  float3 h = make_float3(alpha * hs.x, alpha * hs.y, hs.z); // unstretch
  float l2 = dot(h, h);
  return l2 > 0.0f ? h * (1.0f / sqrt(l2)) : make_float3(0.0f, 0.0f, 1.0f);
}

// The cosine between each direction of a reflection pair and its half vector (wo.h == wi.h in
// exact arithmetic), as a symmetric expression so that a Fresnel factor of it keeps
// f(wo, wi) == f(wi, wo) exact in float.
INLINE float half_cos(float3 wo, float3 wi, float3 h) {
  return 0.5f * (dot(wo, h) + dot(wi, h));
}

INLINE float3 reflect_about(float3 wo, float3 h) {
  return h * (2.0f * dot(wo, h)) - wo;
}

#endif // HAS_GGX
#endif // CANOPY_CL_BSDF_MICROFACET_H
