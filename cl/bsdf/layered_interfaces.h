// The two interfaces of a coated material (layered.h) and the helpers of its random walk: the
// coat is a dielectric interface (dielectric_interface.h, index m->ior, GGX alpha m->alpha), the
// base a Lambertian reflector or a conductor, seen from above only (the walk reaches the base from
// inside the layer). pbrt-v4 §14.3.
#ifndef CANOPY_CL_BSDF_LAYERED_INTERFACES_H
#define CANOPY_CL_BSDF_LAYERED_INTERFACES_H

#include "../compat.h"
#include "../kernel_features.h"
#include "../rng.h"
#include "../types.h"
#include "../volume/phase.h"
#include "bsdf_sample.h"
#include "dielectric_interface.h"
#include "diffuse.h"
#include "fresnel.h"
#include "microfacet.h"

#if HAS_MATERIAL_COATED

// ---------------------------------------------------------------- the base, seen from above
INLINE int layered_base_is_delta(const Material* m) {
  return m->type == MATERIAL_COATED_CONDUCTOR && ggx_is_delta(m->base_alpha);
}

// The conductor's Fresnel reflectance under the coat: its index relative to the coat's.
INLINE float3 layered_base_fresnel(const Material* m, float c) {
  float s = 1.0f / m->ior;
  return fresnel_conductor(c, xyz_of(m->specular) * s, xyz_of(m->k) * s);
}

INLINE float3 layered_base_eval(const Material* m, float3 wo, float3 wi) {
  float3 zero = make_float3(0.0f, 0.0f, 0.0f);
  if (!(wo.z > 0.0f) || !(wi.z > 0.0f)) return zero;
  if (m->type == MATERIAL_COATED_DIFFUSE) return xyz_of(m->albedo) * CANOPY_INV_PI;
  if (layered_base_is_delta(m)) return zero;
  int ok;
  float3 h = half_vector(wo, wi, &ok);
  if (!ok) return zero;
  return layered_base_fresnel(m, half_cos(wo, wi, h)) *
         ggx_reflection(wo, wi, h, ggx_alpha(m->base_alpha));
}

INLINE float layered_base_pdf(const Material* m, float3 wo, float3 wi) {
  if (!(wo.z > 0.0f) || !(wi.z > 0.0f)) return 0.0f;
  if (m->type == MATERIAL_COATED_DIFFUSE) return wi.z * CANOPY_INV_PI;
  if (layered_base_is_delta(m)) return 0.0f;
  int ok;
  float3 h = half_vector(wo, wi, &ok);
  return ok ? ggx_reflection_pdf(wo, wi, h, ggx_alpha(m->base_alpha)) : 0.0f;
}

INLINE BsdfSample layered_base_sample(const Material* m, float3 wo, float u1, float u2) {
  BsdfSample s = bsdf_sample_absorbed(reflect_z(wo));
  if (!(wo.z > 0.0f)) return s;
  if (layered_base_is_delta(m)) {
    s.weight = layered_base_fresnel(m, wo.z);
    s.is_delta = 1;
    return s;
  }
  s.wi = m->type == MATERIAL_COATED_DIFFUSE
             ? sample_cosine_local(u1, u2)
             : reflect_about(wo, ggx_sample_visible_normal(wo, ggx_alpha(m->base_alpha), u1, u2));
  s.pdf = layered_base_pdf(m, wo, s.wi);
  if (s.pdf > 0.0f)
    s.weight = layered_base_eval(m, wo, s.wi) * (s.wi.z / s.pdf);
  else
    s.pdf = 0.0f;
  return s;
}

// ---------------------------------------------------------------- the walk's pieces
INLINE int layered_valid(BsdfSample s) {
  return (s.is_delta || s.pdf > 0.0f) && max3(s.weight) > 0.0f && s.wi.z != 0.0f;
}

INLINE float layered_power(float f, float g) {
  float d = f * f + g * g;
  return d > 0.0f ? f * f / d : 0.0f;
}

// The smallest normal float (FLT_MIN, which C++ has only from <cfloat>): pbrt-v4 raises the
// thickness to it, and a distance no larger counts as none.
#define LAYERED_MIN_DZ 1.17549435e-38f

// Transmittance across the slab along w: exp(-|dz / w.z|), 1 for no distance (pbrt-v4's Tr).
INLINE float layered_tr(float dz, float3 w) {
  if (fabs(dz) <= LAYERED_MIN_DZ) return 1.0f;
  return fabs(w.z) > 0.0f ? exp(-fabs(dz / w.z)) : 0.0f;
}

INLINE float layered_thickness(const Material* m) {
  return fmax(m->thickness, LAYERED_MIN_DZ);
}

INLINE int layered_has_medium(const Material* m) {
  return max3(xyz_of(m->medium)) > 0.0f;
}

// A uniform in [0, 1) of the walk's generator.
INLINE float layered_u(LtRng* r) {
  return lt_rng_next(r);
}

INLINE uint layered_hash3(float3 v, uint h) {
  h = hash_u32(h ^ float_as_uint_(v.x));
  h = hash_u32(h ^ float_as_uint_(v.y));
  return hash_u32(h ^ float_as_uint_(v.z));
}

INLINE LtRng layered_rng(float3 a, float3 b) {
  LtRng r;
  r.key = layered_hash3(b, layered_hash3(a, 0x6c8e9cf5u));
  r.ctr = 0u;
  return r;
}

INLINE BsdfSample layered_top_sample(const Material* m, float3 w, LtRng* r, int flags,
                                     int radiance) {
  float uc = layered_u(r), u1 = layered_u(r), u2 = layered_u(r);
  return dielectric_interface_sample(w, m->ior, m->alpha, uc, u1, u2, flags, radiance);
}

INLINE float layered_top_eval(const Material* m, float3 wo, float3 wi) {
  return dielectric_interface_eval(wo, wi, m->ior, m->alpha, 1);
}

INLINE float layered_top_pdf(const Material* m, float3 wo, float3 wi, int flags) {
  return dielectric_interface_pdf(wo, wi, m->ior, m->alpha, flags);
}

INLINE int layered_has_smooth_lobe(const Material* m) {
  return m->type == MATERIAL_COATED_DIFFUSE || !dielectric_is_smooth(m->ior, m->alpha) ||
         !layered_base_is_delta(m) || layered_has_medium(m);
}

#endif // HAS_MATERIAL_COATED
#endif // CANOPY_CL_BSDF_LAYERED_INTERFACES_H
