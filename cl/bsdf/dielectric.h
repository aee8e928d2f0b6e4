// Smooth dielectrics: pbrt-v4's dielectric at roughness 0 and its thindielectric. Both are two
// delta lobes, reflection with the Fresnel reflectance R and transmission with 1 - R; sampling
// picks one with exactly its probability, so a sample's weight is 1, or for refraction the radiance
// scale 1 / eta^2 (the solid angle narrows entering a denser medium, and a path that leaves gets
// eta^2 back: pbrt-v4 §9.5.2, radiance transport). eval and pdf are 0: light sampling cannot reach
// a light through a delta lobe (bsdf_has_smooth_lobe), so paths find lights through glass by BSDF
// sampling, as in pbrt-v4's path integrator.
// Local frame: z = the shading normal on wo's side, wo.z > 0. m->ior is the index of the far side
// over wo's side: material_face sets it for a ray that arrives from inside.
#ifndef CANOPY_CL_BSDF_DIELECTRIC_H
#define CANOPY_CL_BSDF_DIELECTRIC_H

#include "../compat.h"
#include "../kernel_features.h"
#include "../types.h"
#include "bsdf_sample.h"
#include "fresnel.h"

#if HAS_MATERIAL_DIELECTRIC

// The reflectance of the material at cos_o: one interface (Fresnel), or a thin sheet's two faces
// with every inter-reflection between them, R + T^2 R / (1 - R^2) = 2 R / (1 + R) (pbrt-v4's
// ThinDielectricBxDF; the sheet's thickness does not shift the ray).
INLINE float dielectric_reflectance(const Material* m, float cos_o) {
  float r = fresnel_dielectric(cos_o, m->ior);
  return IS_MATERIAL(m, MATERIAL_THIN_DIELECTRIC) ? 2.0f * r / (1.0f + r) : r;
}

INLINE BsdfSample dielectric_sample(const Material* m, float3 wo, float3 u) {
  BsdfSample s = bsdf_sample_absorbed(reflect_z(wo));
  if (!(wo.z > 0.0f)) return s;
  s.is_delta = 1;
  s.weight = make_float3(1.0f, 1.0f, 1.0f);
  if (u.x < dielectric_reflectance(m, wo.z)) return s; // (total internal reflection: R = 1)
  if (IS_MATERIAL(m, MATERIAL_THIN_DIELECTRIC)) {
    s.wi = -wo;
    return s;
  }
  // Snell: sin_t = sin_o / eta; R < 1 here, so sin_t < 1.
  float eta = m->ior;
  float sin2_t = fmax(0.0f, 1.0f - wo.z * wo.z) / (eta * eta);
  float cos_t = sqrt(fmax(0.0f, 1.0f - sin2_t));
  s.wi = make_float3(-wo.x / eta, -wo.y / eta, -cos_t);
  float scale = 1.0f / (eta * eta);
  s.weight = make_float3(scale, scale, scale);
  return s;
}

#endif // HAS_MATERIAL_DIELECTRIC
#endif // CANOPY_CL_BSDF_DIELECTRIC_H
