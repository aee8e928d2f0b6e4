// Rough conductor: GGX microfacet reflection D G2 F / (4 |cos i| |cos o|) with the exact Fresnel
// reflectance of the complex index eta + i k (m->specular holds eta, m->k holds k, per RGB
// channel). alpha == 0 is a perfect mirror, a delta lobe: eval and pdf are 0 and sampling returns
// the mirror direction with weight F(cos theta_o).
#ifndef CANOPY_CL_BSDF_CONDUCTOR_H
#define CANOPY_CL_BSDF_CONDUCTOR_H

#include "../compat.h"
#include "../kernel_features.h"
#include "../types.h"
#include "bsdf_sample.h"
#include "fresnel.h"
#include "microfacet.h"

#if HAS_MATERIAL_CONDUCTOR

INLINE float3 conductor_fresnel(const Material* m, float cos_i) {
  return fresnel_conductor(cos_i, xyz_of(m->specular), xyz_of(m->k));
}

INLINE float3 conductor_eval(const Material* m, float3 wo, float3 wi) {
  float3 zero = make_float3(0.0f, 0.0f, 0.0f);
  if (ggx_is_delta(m->alpha) || !(wo.z > 0.0f) || !(wi.z > 0.0f)) return zero;
  int ok;
  float3 h = half_vector(wo, wi, &ok);
  if (!ok) return zero;
  float alpha = ggx_alpha(m->alpha);
  return conductor_fresnel(m, half_cos(wo, wi, h)) * ggx_reflection(wo, wi, h, alpha);
}

INLINE float conductor_pdf(const Material* m, float3 wo, float3 wi) {
  if (ggx_is_delta(m->alpha) || !(wo.z > 0.0f) || !(wi.z > 0.0f)) return 0.0f;
  int ok;
  float3 h = half_vector(wo, wi, &ok);
  if (!ok) return 0.0f;
  return ggx_reflection_pdf(wo, wi, h, ggx_alpha(m->alpha));
}

INLINE BsdfSample conductor_sample(const Material* m, float3 wo, float3 u) {
  if (!(wo.z > 0.0f)) return bsdf_sample_absorbed(reflect_z(wo));
  if (ggx_is_delta(m->alpha)) {
    BsdfSample s = bsdf_sample_absorbed(reflect_z(wo));
    s.weight = conductor_fresnel(m, wo.z);
    s.is_delta = 1;
    return s;
  }
  float alpha = ggx_alpha(m->alpha);
  float3 wi = reflect_about(wo, ggx_sample_visible_normal(wo, alpha, u.x, u.y));
  BsdfSample s = bsdf_sample_absorbed(wi); // below the horizon: absorbed
  if (!(wi.z > 0.0f)) return s;
  // pdf and weight from the half vector of the returned pair, so both equal what bsdf_pdf and
  // bsdf_eval give for (wo, wi). weight = f cos / pdf = F G2 / G1(wo) (Heitz 2018, eq. 19)
  //   = F zi (zo + Lo) / (zi Lo + zo Li), with L = ggx_lambda_len.
  int ok;
  float3 h = half_vector(wo, wi, &ok);
  if (!ok) return s;
  s.pdf = ggx_reflection_pdf(wo, wi, h, alpha);
  if (!(s.pdf > 0.0f)) {
    s.pdf = 0.0f;
    return s;
  }
  float lo = ggx_lambda_len(wo, alpha), li = ggx_lambda_len(wi, alpha);
  float den = wi.z * lo + wo.z * li;
  float g = den > 0.0f ? wi.z * (wo.z + lo) / den : 0.0f;
  s.weight = conductor_fresnel(m, half_cos(wo, wi, h)) * g;
  return s;
}

#endif // HAS_MATERIAL_CONDUCTOR
#endif // CANOPY_CL_BSDF_CONDUCTOR_H
