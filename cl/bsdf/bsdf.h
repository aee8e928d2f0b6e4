// BSDF interface: evaluation, pdf and sampling of a Material in the local shading frame
// (z = shading normal, wo.z > 0: the caller flips the frame to face wo). Dispatches on
// Material.type; the conductor, plastic, dielectric, coated and diffuse-transmission code is
// compiled only when the kernel has those features (cl/kernel_features.h), so a diffuse-only
// kernel holds no GGX or Fresnel code. A mix (MATERIAL_MIX) never gets here: shade_surface
// resolves it to one of its materials first (cl/material_mix.h).
//   bsdf_eval   f(wo, wi) of the non-delta lobes (0 below the horizon, except rough glass)
//   bsdf_pdf    solid-angle pdf of bsdf_sample's non-delta directions
//   bsdf_sample a direction from u (3 uniforms in [0, 1)): see BsdfSample (bsdf_sample.h); a
//               dielectric's transmitted direction has wi.z < 0
//   bsdf_has_smooth_lobe 0 only for a pure delta BSDF (light sampling is then useless)
//   bsdf_two_sided 1 where light reaches the point from both sides of the surface (diffuse
//               transmission: light samples and the light tree's bounds cover both)
// The coated materials' eval and pdf are stochastic estimates, deterministic per (wo, wi)
// (layered.h).
// `m` points to a private copy of the material record.
#ifndef CANOPY_CL_BSDF_BSDF_H
#define CANOPY_CL_BSDF_BSDF_H

#include "../compat.h"
#include "../kernel_features.h"
#include "../types.h"
#include "bsdf_sample.h"
#include "conductor.h"
#include "dielectric.h"
#include "diffuse.h"
#include "diffuse_transmission.h"
#include "layered.h"
#include "plastic.h"

// The material as a ray arriving from inside sees it (from the side its geometric normal points
// away from): a dielectric's relative index inverts. Called once per hit, before the BSDF.
INLINE void material_face(Material* m, int from_inside) {
#if HAS_MATERIAL_DIELECTRIC
  if (from_inside && m->type == MATERIAL_DIELECTRIC && m->ior > 0.0f) m->ior = 1.0f / m->ior;
#else
  (void)m;
  (void)from_inside;
#endif
}

INLINE float3 bsdf_eval(const Material* m, float3 wo, float3 wi) {
#if HAS_MATERIAL_DIFFUSE_TRANSMISSION
  if (IS_MATERIAL(m, MATERIAL_DIFFUSE_TRANSMISSION)) return diffuse_transmission_eval(m, wo, wi);
#endif
#if HAS_MATERIAL_DIELECTRIC
  if (IS_MATERIAL(m, MATERIAL_DIELECTRIC) || IS_MATERIAL(m, MATERIAL_THIN_DIELECTRIC))
    return dielectric_eval(m, wo, wi);
#endif
#if HAS_MATERIAL_COATED
  if (IS_MATERIAL(m, MATERIAL_COATED_DIFFUSE) || IS_MATERIAL(m, MATERIAL_COATED_CONDUCTOR))
    return layered_eval(m, wo, wi);
#endif
#if HAS_MATERIAL_CONDUCTOR
  if (IS_MATERIAL(m, MATERIAL_CONDUCTOR)) return conductor_eval(m, wo, wi);
#endif
#if HAS_MATERIAL_PLASTIC
  if (IS_MATERIAL(m, MATERIAL_PLASTIC)) return plastic_eval(m, wo, wi);
#endif
  return diffuse_eval(m, wo, wi);
}

INLINE float bsdf_pdf(const Material* m, float3 wo, float3 wi) {
  (void)m; // diffuse_pdf needs no parameters (unused in a diffuse-only kernel)
#if HAS_MATERIAL_DIFFUSE_TRANSMISSION
  if (IS_MATERIAL(m, MATERIAL_DIFFUSE_TRANSMISSION)) return diffuse_transmission_pdf(m, wo, wi);
#endif
#if HAS_MATERIAL_DIELECTRIC
  if (IS_MATERIAL(m, MATERIAL_DIELECTRIC) || IS_MATERIAL(m, MATERIAL_THIN_DIELECTRIC))
    return dielectric_pdf(m, wo, wi);
#endif
#if HAS_MATERIAL_COATED
  if (IS_MATERIAL(m, MATERIAL_COATED_DIFFUSE) || IS_MATERIAL(m, MATERIAL_COATED_CONDUCTOR))
    return layered_pdf(m, wo, wi);
#endif
#if HAS_MATERIAL_CONDUCTOR
  if (IS_MATERIAL(m, MATERIAL_CONDUCTOR)) return conductor_pdf(m, wo, wi);
#endif
#if HAS_MATERIAL_PLASTIC
  if (IS_MATERIAL(m, MATERIAL_PLASTIC)) return plastic_pdf(m, wo, wi);
#endif
  return diffuse_pdf(wo, wi);
}

INLINE BsdfSample bsdf_sample(const Material* m, float3 wo, float3 u) {
#if HAS_MATERIAL_DIFFUSE_TRANSMISSION
  if (IS_MATERIAL(m, MATERIAL_DIFFUSE_TRANSMISSION)) return diffuse_transmission_sample(m, wo, u);
#endif
#if HAS_MATERIAL_DIELECTRIC
  if (IS_MATERIAL(m, MATERIAL_DIELECTRIC) || IS_MATERIAL(m, MATERIAL_THIN_DIELECTRIC))
    return dielectric_sample(m, wo, u);
#endif
#if HAS_MATERIAL_COATED
  if (IS_MATERIAL(m, MATERIAL_COATED_DIFFUSE) || IS_MATERIAL(m, MATERIAL_COATED_CONDUCTOR))
    return layered_sample(m, wo, u);
#endif
#if HAS_MATERIAL_CONDUCTOR
  if (IS_MATERIAL(m, MATERIAL_CONDUCTOR)) return conductor_sample(m, wo, u);
#endif
#if HAS_MATERIAL_PLASTIC
  if (IS_MATERIAL(m, MATERIAL_PLASTIC)) return plastic_sample(m, wo, u);
#endif
  return diffuse_sample(m, wo, u);
}

INLINE int bsdf_has_smooth_lobe(const Material* m) {
#if HAS_MATERIAL_DIELECTRIC
  if (IS_MATERIAL(m, MATERIAL_DIELECTRIC) || IS_MATERIAL(m, MATERIAL_THIN_DIELECTRIC))
    return !dielectric_is_delta(m);
#endif
#if HAS_MATERIAL_COATED
  if (IS_MATERIAL(m, MATERIAL_COATED_DIFFUSE) || IS_MATERIAL(m, MATERIAL_COATED_CONDUCTOR))
    return layered_has_smooth_lobe(m);
#endif
  if (IS_MATERIAL(m, MATERIAL_CONDUCTOR))
    return m->alpha > 0.0f; // not ggx_is_delta: compiled without HAS_GGX too
  return 1;
}

// Whether the BSDF transmits diffusely, so that light from the far side of the surface counts as
// much as light on wo's side: light sampling then takes both sides (light_point.h) and the
// light-tree queries carry no normal (light_query_normal), whose one-sided bound would cull the
// far side's lights.
INLINE int bsdf_two_sided(const Material* m) {
  return IS_MATERIAL(m, MATERIAL_DIFFUSE_TRANSMISSION);
}

#endif // CANOPY_CL_BSDF_BSDF_H
