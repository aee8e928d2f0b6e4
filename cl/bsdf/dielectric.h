// Glass: pbrt-v4's dielectric (smooth or rough) and its thindielectric, in the local shading
// frame (z on wo's side, wo.z > 0; a transmitted wi has wi.z < 0). m->ior is the index of the far
// side over wo's side: material_face sets it for a ray that arrives from inside.
// - Smooth (alpha == 0) and thin: two delta lobes, reflection with the Fresnel reflectance R and
//   transmission with 1 - R; sampling picks one with exactly its probability, so a sample's weight
//   is 1, or for refraction the radiance scale 1 / eta^2 (pbrt-v4 §9.5.2). eval and pdf are 0:
//   light sampling cannot reach a light through a delta lobe (bsdf_has_smooth_lobe), so paths
//   find lights through smooth glass by BSDF sampling, as in pbrt-v4's path integrator.
// - Rough (alpha = m->alpha > 0, GGX): microfacet reflection and transmission
//   (dielectric_interface.h); eval and pdf cover both hemispheres. Light samples are taken on wo's
//   side only, so a refracted direction is reached by BSDF sampling alone (shade_surface.h gives
//   the emission it finds full weight).
#ifndef CANOPY_CL_BSDF_DIELECTRIC_H
#define CANOPY_CL_BSDF_DIELECTRIC_H

#include "../compat.h"
#include "../kernel_features.h"
#include "../types.h"
#include "bsdf_sample.h"
#include "dielectric_interface.h"
#include "fresnel.h"

#if HAS_MATERIAL_DIELECTRIC

// Smooth glass or a thin sheet: delta lobes only.
INLINE int dielectric_is_delta(const Material* m) {
  return IS_MATERIAL(m, MATERIAL_THIN_DIELECTRIC) || dielectric_is_smooth(m->ior, m->alpha);
}

INLINE float3 dielectric_eval(const Material* m, float3 wo, float3 wi) {
  float f = dielectric_is_delta(m) ? 0.0f : dielectric_interface_eval(wo, wi, m->ior, m->alpha, 1);
  return make_float3(f, f, f);
}

INLINE float dielectric_pdf(const Material* m, float3 wo, float3 wi) {
  if (dielectric_is_delta(m)) return 0.0f;
  return dielectric_interface_pdf(wo, wi, m->ior, m->alpha, DIELECTRIC_ALL);
}

INLINE BsdfSample dielectric_sample(const Material* m, float3 wo, float3 u) {
  if (!(wo.z > 0.0f)) return bsdf_sample_absorbed(reflect_z(wo));
  if (IS_MATERIAL(m, MATERIAL_THIN_DIELECTRIC)) {
    // The reflectance of the sheet's two faces with every inter-reflection between them,
    // R + T^2 R / (1 - R^2) = 2 R / (1 + R) (pbrt-v4's ThinDielectricBxDF; the sheet's thickness
    // does not shift the ray); the rest passes straight on.
    BsdfSample s = bsdf_sample_absorbed(reflect_z(wo));
    float r = fresnel_dielectric(wo.z, m->ior);
    s.is_delta = 1;
    s.weight = make_float3(1.0f, 1.0f, 1.0f);
    if (!(u.z < 2.0f * r / (1.0f + r))) s.wi = -wo;
    return s;
  }
  return dielectric_interface_sample(wo, m->ior, m->alpha, u.z, u.x, u.y, DIELECTRIC_ALL, 1);
}

#endif // HAS_MATERIAL_DIELECTRIC
#endif // CANOPY_CL_BSDF_DIELECTRIC_H
