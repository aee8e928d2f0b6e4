// Plastic, as in pbrt-v3 (the material Liu et al. 2019's implementation uses): a Lambertian base
// plus a GGX coat with dielectric Fresnel,
//   f = albedo / pi + specular D G2 F_dielectric(wo.h; ior) / (4 |cos i| |cos o|).
// The lobes are simply added (no energy exchange), so it is not energy-conserving for albedo near
// 1. alpha == 0 makes the coat a perfect mirror (a delta lobe of reflectance specular F(cos o)):
// eval and pdf then hold only the diffuse lobe.
//
// Sampling picks the coat with probability p_s (plastic_coat_prob) and the diffuse lobe
// otherwise; pdf is the mixture p_s pdf_coat + (1 - p_s) pdf_diffuse and weight = f cos / pdf.
#ifndef CANOPY_CL_BSDF_PLASTIC_H
#define CANOPY_CL_BSDF_PLASTIC_H

#include "../compat.h"
#include "../kernel_features.h"
#include "../types.h"
#include "bsdf_sample.h"
#include "diffuse.h"
#include "fresnel.h"
#include "microfacet.h"

#if HAS_MATERIAL_PLASTIC

// Probability of sampling the coat: the lobes' albedos estimated as lum(specular) F(cos theta_o)
// (a smooth coat's reflectance) and lum(albedo). Kept in [0.1, 0.9] when both lobes are non-zero,
// so neither is starved where the estimate is off (it ignores roughness and masking); a lobe that
// is zero is never sampled.
INLINE float plastic_coat_prob(const Material* m, float3 wo) {
  float ws = luminance3(xyz_of(m->specular)) * fresnel_dielectric(wo.z, m->ior);
  float wd = luminance3(xyz_of(m->albedo));
  if (!(ws > 0.0f)) return 0.0f;
  if (!(wd > 0.0f)) return 1.0f;
  return clamp(ws / (ws + wd), 0.1f, 0.9f);
}

INLINE float3 plastic_eval(const Material* m, float3 wo, float3 wi) {
  float3 f = diffuse_eval(m, wo, wi);
  if (ggx_is_delta(m->alpha) || !(wo.z > 0.0f) || !(wi.z > 0.0f)) return f;
  int ok;
  float3 h = half_vector(wo, wi, &ok);
  if (!ok) return f;
  float coat = fresnel_dielectric(half_cos(wo, wi, h), m->ior) *
               ggx_reflection(wo, wi, h, ggx_alpha(m->alpha));
  return f + xyz_of(m->specular) * coat;
}

INLINE float plastic_pdf(const Material* m, float3 wo, float3 wi) {
  if (!(wo.z > 0.0f) || !(wi.z > 0.0f)) return 0.0f;
  float ps = plastic_coat_prob(m, wo);
  float pdf = (1.0f - ps) * diffuse_pdf(wo, wi);
  if (ggx_is_delta(m->alpha) || !(ps > 0.0f)) return pdf;
  int ok;
  float3 h = half_vector(wo, wi, &ok);
  if (!ok) return pdf;
  return pdf + ps * ggx_reflection_pdf(wo, wi, h, ggx_alpha(m->alpha));
}

INLINE BsdfSample plastic_sample(const Material* m, float3 wo, float3 u) {
  if (!(wo.z > 0.0f)) return bsdf_sample_absorbed(reflect_z(wo));
  float ps = plastic_coat_prob(m, wo);
  int delta = ggx_is_delta(m->alpha);
  float3 wi;
  if (u.z < ps) {
    if (delta) {
      BsdfSample s = bsdf_sample_absorbed(reflect_z(wo));
      s.weight = xyz_of(m->specular) * (fresnel_dielectric(wo.z, m->ior) / ps);
      s.is_delta = 1;
      return s;
    }
    float alpha = ggx_alpha(m->alpha);
    wi = reflect_about(wo, ggx_sample_visible_normal(wo, alpha, u.x, u.y));
  } else {
    wi = sample_cosine_local(u.x, u.y);
  }
  BsdfSample s = bsdf_sample_absorbed(wi); // below the horizon: absorbed
  if (!(wi.z > 0.0f)) return s;
  float pdf = plastic_pdf(m, wo, wi);
  if (!(pdf > 0.0f)) return s;
  s.pdf = pdf;
  s.weight = plastic_eval(m, wo, wi) * (wi.z / pdf);
  return s;
}

#endif // HAS_MATERIAL_PLASTIC
#endif // CANOPY_CL_BSDF_PLASTIC_H
