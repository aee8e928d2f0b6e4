// A dielectric interface seen from either side: pbrt-v4's DielectricBxDF (§9.5 smooth, §9.7
// rough), the building block of glass (dielectric.h) and of the coats of the layered materials
// (layered.h). z = the interface normal; eta = the index below it (z < 0) over the index above.
// wo may lie on either side; a direction on the other side than wo's is a transmission.
//   smooth (alpha == 0 or eta == 1): two delta lobes, Fresnel reflection R and refraction 1 - R;
//   rough: GGX microfacets (Walter et al. 2007) with the generalised half vector
//     h ~ eta_p wi + wo (eta_p = 1 for reflection, else the index of wi's side over wo's),
//     f_r = D G2 F / (4 |cos i| |cos o|),
//     f_t = D G2 (1 - F) |wi.h| |wo.h| / (|cos i| |cos o| (wi.h + wo.h / eta_p)^2),
//   with visible-normal sampling and the Fresnel choice between reflection and refraction.
// `radiance`: radiance transport scales refraction by 1 / eta_p^2 (the solid angle narrows into a
// denser medium, pbrt-v4 §9.5.2); importance transport (the adjoint, 0) does not.
// `flags` (DIELECTRIC_*) restrict sampling and pdf to one lobe, as pbrt-v4's BxDFReflTransFlags.
#ifndef CANOPY_CL_BSDF_DIELECTRIC_INTERFACE_H
#define CANOPY_CL_BSDF_DIELECTRIC_INTERFACE_H

#include "../compat.h"
#include "../kernel_features.h"
#include "bsdf_sample.h"
#include "fresnel.h"
#include "microfacet.h"

#if HAS_GGX

#define DIELECTRIC_REFLECT 1
#define DIELECTRIC_TRANSMIT 2
#define DIELECTRIC_ALL 3

INLINE int dielectric_is_smooth(float eta, float alpha) {
  return eta == 1.0f || ggx_is_delta(alpha);
}

// The generalised half vector of (wo, wi) with wo.z > 0, facing +z, and whether the pair is
// valid: neither direction in the plane, h defined, both on the front of their microfacet.
INLINE float3 dielectric_half(float3 wo, float3 wi, float eta, float* eta_p, int* ok) {
  *eta_p = wi.z > 0.0f ? 1.0f : eta;
  float3 h = wi * *eta_p + wo;
  float l2 = dot(h, h);
  *ok = wo.z > 0.0f && wi.z != 0.0f && l2 > 0.0f;
  if (!*ok) return make_float3(0.0f, 0.0f, 1.0f);
  h = h * (1.0f / sqrt(l2));
  if (h.z < 0.0f) h = -h;
  *ok = !(dot(h, wi) * wi.z < 0.0f) && dot(h, wo) > 0.0f;
  return h;
}

// (wo, wi, eta) with wo moved to the upper side: both directions flipped, eta inverted (the
// interface seen from below is the same interface with the sides' roles swapped).
INLINE float dielectric_upper(float3* wo, float3* wi, float eta) {
  if (wo->z >= 0.0f) return eta;
  *wo = -*wo;
  *wi = -*wi;
  return 1.0f / eta;
}

// f(wo, wi) of the rough interface (0 for a smooth one: its lobes are delta).
INLINE float dielectric_interface_eval(float3 wo, float3 wi, float eta, float alpha, int radiance) {
  if (dielectric_is_smooth(eta, alpha)) return 0.0f;
  eta = dielectric_upper(&wo, &wi, eta);
  float a = ggx_alpha(alpha), eta_p;
  int ok;
  float3 h = dielectric_half(wo, wi, eta, &eta_p, &ok);
  if (!ok) return 0.0f;
  float F = fresnel_dielectric(dot(wo, h), eta);
  if (wi.z > 0.0f) return F * ggx_reflection(wo, wi, h, a);
  // G2 / (|cos i| |cos o|) = 2 / (|zi| Lo + |zo| Li) (microfacet.h): finite at the horizon.
  float lam = fabs(wi.z) * ggx_lambda_len(wo, a) + wo.z * ggx_lambda_len(wi, a);
  float s = dot(wi, h) + dot(wo, h) / eta_p;
  float den = lam * s * s;
  if (!(den > 0.0f)) return 0.0f;
  float ft = ggx_D(h, a) * (1.0f - F) * 2.0f * fabs(dot(wi, h) * dot(wo, h)) / den;
  return radiance ? ft / (eta_p * eta_p) : ft;
}

// The solid-angle pdf of dielectric_interface_sample's direction wi (0 for a smooth interface).
INLINE float dielectric_interface_pdf(float3 wo, float3 wi, float eta, float alpha, int flags) {
  if (dielectric_is_smooth(eta, alpha)) return 0.0f;
  eta = dielectric_upper(&wo, &wi, eta);
  float a = ggx_alpha(alpha), eta_p;
  int ok;
  float3 h = dielectric_half(wo, wi, eta, &eta_p, &ok);
  if (!ok) return 0.0f;
  float R = fresnel_dielectric(dot(wo, h), eta);
  float pr = (flags & DIELECTRIC_REFLECT) ? R : 0.0f;
  float pt = (flags & DIELECTRIC_TRANSMIT) ? 1.0f - R : 0.0f;
  if (!(pr + pt > 0.0f)) return 0.0f;
  // Visible normals: D_wo(h) = G1(wo) (wo.h) D(h) / wo.z = 2 (wo.h) D(h) / (zo + Lo) (Heitz 2018).
  float d_vis_over_wh = 2.0f * ggx_D(h, a) / (wo.z + ggx_lambda_len(wo, a));
  if (wi.z > 0.0f) return d_vis_over_wh * 0.25f * pr / (pr + pt); // dh/dwi = 1 / (4 wo.h)
  float s = dot(wi, h) + dot(wo, h) / eta_p;
  float den = s * s;
  if (!(den > 0.0f)) return 0.0f;
  // dh/dwi = |wi.h| / (wi.h + wo.h / eta_p)^2 (Walter et al. 2007, eq. 17, pbrt-v4 eq. 9.36).
  return d_vis_over_wh * dot(wo, h) * fabs(dot(wi, h)) / den * pt / (pr + pt);
}

// Refraction of wo (on h's side) through a surface of normal h: Snell with relative index eta.
// 0 on total internal reflection.
INLINE int dielectric_refract(float3 wo, float3 h, float eta, float3* wi) {
  float cos_i = dot(wo, h);
  float sin2_t = fmax(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return 0;
  float cos_t = sqrt(1.0f - sin2_t);
  *wi = wo * (-1.0f / eta) + h * (cos_i / eta - cos_t);
  return 1;
}

// A direction from (uc, u1, u2): uc picks reflection with probability R / (R + T) of the allowed
// lobes, (u1, u2) the visible microfacet normal. A rough sample's pdf and weight are
// dielectric_interface_pdf and _eval * |cos i| / pdf at the returned pair.
INLINE BsdfSample dielectric_interface_sample(float3 wo, float eta, float alpha, float uc, float u1,
                                              float u2, int flags, int radiance) {
  int below = wo.z < 0.0f;
  float3 none = make_float3(0.0f, 0.0f, 0.0f);
  eta = dielectric_upper(&wo, &none, eta);
  BsdfSample s = bsdf_sample_absorbed(reflect_z(wo));
  if (!(wo.z > 0.0f)) return s;
  if (dielectric_is_smooth(eta, alpha)) {
    float R = fresnel_dielectric(wo.z, eta);
    float pr = (flags & DIELECTRIC_REFLECT) ? R : 0.0f;
    float pt = (flags & DIELECTRIC_TRANSMIT) ? 1.0f - R : 0.0f;
    if (!(pr + pt > 0.0f)) return s;
    s.is_delta = 1;
    float w;
    if (uc < pr / (pr + pt)) {
      w = R / (pr / (pr + pt)); // f / pdf: the lobe's reflectance over its choice probability
    } else {
      // Snell: sin_t = sin_o / eta; R < 1 here, so sin_t < 1.
      float sin2_t = fmax(0.0f, 1.0f - wo.z * wo.z) / (eta * eta);
      float cos_t = sqrt(fmax(0.0f, 1.0f - sin2_t));
      s.wi = make_float3(-wo.x / eta, -wo.y / eta, -cos_t);
      w = (1.0f - R) / (pt / (pr + pt));
      if (radiance) w /= eta * eta;
    }
    s.weight = make_float3(w, w, w);
    if (below) s.wi = -s.wi;
    return s;
  }
  float a = ggx_alpha(alpha);
  float3 h = ggx_sample_visible_normal(wo, a, u1, u2);
  float R = fresnel_dielectric(dot(wo, h), eta);
  float pr = (flags & DIELECTRIC_REFLECT) ? R : 0.0f;
  float pt = (flags & DIELECTRIC_TRANSMIT) ? 1.0f - R : 0.0f;
  if (!(pr + pt > 0.0f)) return s;
  float3 wi;
  if (uc < pr / (pr + pt)) {
    wi = reflect_about(wo, h);
    if (!(wi.z > 0.0f)) return s;
  } else {
    if (!dielectric_refract(wo, h, eta, &wi) || !(wi.z < 0.0f)) return s;
  }
  float pdf = dielectric_interface_pdf(wo, wi, eta, a, flags);
  float f = dielectric_interface_eval(wo, wi, eta, a, radiance);
  s.wi = below ? -wi : wi;
  if (!(pdf > 0.0f)) return s;
  float w = f * fabs(wi.z) / pdf;
  s.pdf = pdf;
  s.weight = make_float3(w, w, w);
  return s;
}

#endif // HAS_GGX
#endif // CANOPY_CL_BSDF_DIELECTRIC_INTERFACE_H
