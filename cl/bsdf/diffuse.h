// Lambertian reflection: f = albedo / pi, cosine-weighted sampling.
#ifndef CANOPY_CL_BSDF_DIFFUSE_H
#define CANOPY_CL_BSDF_DIFFUSE_H

#include "../compat.h"
#include "../types.h"
#include "bsdf_sample.h"

INLINE float3 diffuse_eval(const Material* m, float3 wo, float3 wi) {
  if (!(wo.z > 0.0f) || !(wi.z > 0.0f)) return make_float3(0.0f, 0.0f, 0.0f);
  return xyz_of(m->albedo) * CANOPY_INV_PI;
}

INLINE float diffuse_pdf(float3 wo, float3 wi) {
  if (!(wo.z > 0.0f) || !(wi.z > 0.0f)) return 0.0f;
  return wi.z * CANOPY_INV_PI;
}

// Cosine-weighted direction (Malley's method: uniform on the disk, projected up), pdf cos / pi.
INLINE float3 sample_cosine_local(float u1, float u2) {
  float r = sqrt(u1);
  float phi = 2.0f * CANOPY_PI * u2;
  return make_float3(r * cos(phi), r * sin(phi), sqrt(fmax(0.0f, 1.0f - u1)));
}

INLINE BsdfSample diffuse_sample(const Material* m, float3 wo, float3 u) {
  float3 wi = sample_cosine_local(u.x, u.y);
  BsdfSample s = bsdf_sample_absorbed(wi);
  s.pdf = diffuse_pdf(wo, wi);
  if (s.pdf > 0.0f) s.weight = xyz_of(m->albedo); // (albedo / pi) cos / (cos / pi)
  return s;
}

#endif // CANOPY_CL_BSDF_DIFFUSE_H
