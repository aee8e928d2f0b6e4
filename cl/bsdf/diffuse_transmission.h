// pbrt-v4's DiffuseTransmissionBxDF: f = R / pi for wi on wo's side of the surface and T / pi on
// the other (R = albedo, T = specular; both already scaled and clamped by the loaders). Sampled
// as pbrt-v4 does: the reflected or the transmitted cosine lobe, chosen by max(R) : max(T).
// Compiled only with HAS_MATERIAL_DIFFUSE_TRANSMISSION.
#ifndef CANOPY_CL_BSDF_DIFFUSE_TRANSMISSION_H
#define CANOPY_CL_BSDF_DIFFUSE_TRANSMISSION_H

#include "../compat.h"
#include "../types.h"
#include "bsdf_sample.h"
#include "diffuse.h"

INLINE float3 diffuse_transmission_eval(const Material* m, float3 wo, float3 wi) {
  if (!(wo.z > 0.0f) || wi.z == 0.0f || !(wi.z == wi.z)) return make_float3(0.0f, 0.0f, 0.0f);
  return xyz_of(wi.z > 0.0f ? m->albedo : m->specular) * CANOPY_INV_PI;
}

// The probability of the reflected lobe (pbrt-v4: max R / (max R + max T)); -1 when both are 0.
INLINE float diffuse_transmission_pr(const Material* m) {
  float pr = max3(xyz_of(m->albedo)), pt = max3(xyz_of(m->specular));
  pr = pr > 0.0f ? pr : 0.0f;
  pt = pt > 0.0f ? pt : 0.0f;
  return pr + pt > 0.0f ? pr / (pr + pt) : -1.0f;
}

INLINE float diffuse_transmission_pdf(const Material* m, float3 wo, float3 wi) {
  float pr = diffuse_transmission_pr(m);
  if (!(wo.z > 0.0f) || !(pr >= 0.0f) || wi.z == 0.0f) return 0.0f;
  return fabs(wi.z) * CANOPY_INV_PI * (wi.z > 0.0f ? pr : 1.0f - pr);
}

INLINE BsdfSample diffuse_transmission_sample(const Material* m, float3 wo, float3 u) {
  float pr = diffuse_transmission_pr(m);
  float3 wi = sample_cosine_local(u.x, u.y);
  if (!(wo.z > 0.0f) || !(pr >= 0.0f)) return bsdf_sample_absorbed(wi);
  int reflect = u.z < pr;
  if (!reflect) wi.z = -wi.z;
  BsdfSample s = bsdf_sample_absorbed(wi);
  s.pdf = diffuse_transmission_pdf(m, wo, wi);
  // (R or T / pi) |cos| / (|cos| / pi times the lobe's probability)
  if (s.pdf > 0.0f)
    s.weight =
        reflect ? xyz_of(m->albedo) * (1.0f / pr) : xyz_of(m->specular) * (1.0f / (1.0f - pr));
  return s;
}

#endif // CANOPY_CL_BSDF_DIFFUSE_TRANSMISSION_H
