// pbrt-v4's MixMaterial (materials.h, ChooseMaterial): a mix is one of its two materials at each
// shading point, the second with probability `amount` (a constant or a float texture's value at
// the point), chosen deterministically from a hash of the point, wo and the mix, so that every
// evaluation and sample of the point's BSDF sees the same material. shade_surface resolves the
// mix once at the hit and records the chosen material for the later stages (light_pick,
// brdf_mis), which never see a mix. Compiled into the kernels only for scenes with a mix
// (HAS_MATERIAL_MIX).
#ifndef CANOPY_CL_MATERIAL_MIX_H
#define CANOPY_CL_MATERIAL_MIX_H

#include "compat.h"
#include "kernel_features.h"
#include "rng.h"
#include "texture.h"
#include "types.h"

// A uniform number in [0, 1) on the 2^-24 grid from the hit point P, the direction wo and the mix
// material's index: P(u < a) = a for every a on that grid (0.25, 0.5, ...), and within 2^-24 of
// a otherwise.
INLINE float mix_choice_uniform(float3 P, float3 wo, int index) {
  uint h = hash_u32(float_as_uint_(P.x) ^ 0x9e3779b9U);
  h = hash_u32(h ^ float_as_uint_(P.y));
  h = hash_u32(h ^ float_as_uint_(P.z));
  h = hash_u32(h ^ float_as_uint_(wo.x));
  h = hash_u32(h ^ float_as_uint_(wo.y));
  h = hash_u32(h ^ float_as_uint_(wo.z));
  h = hash_u32(h ^ (uint)index);
  return (float)(h >> 8) * 0x1p-24f;
}

// The probability that mix `m` chooses its second material at (u, v) of scene triangle `tri`.
INLINE float mix_amount_at(GLOBAL const Material* m, GLOBAL const float2* texcoords,
                           GLOBAL const Texture* textures, GLOBAL const float* texels, int tri,
                           float bu, float bv) {
#if HAS_TEXTURES
  if (m->mix_amount_texture > 0)
    return texture_eval(textures, texels, m->mix_amount_texture - 1,
                        triangle_uv(texcoords, tri, bu, bv))
        .x;
#else
  (void)texcoords;
  (void)textures;
  (void)texels;
  (void)tri;
  (void)bu;
  (void)bv;
#endif
  return m->mix_amount;
}

// The material that material `index` is at hit point P seen from wo (scene triangle `tri` at
// barycentrics (bu, bv), for an amount texture): `index` itself unless it is a mix, else the
// choice of each nested mix in turn (at most MATERIAL_MIX_MAX_DEPTH, as the loaders allow).
INLINE int material_resolve_mix(GLOBAL const Material* materials, int index, float3 P, float3 wo,
                                GLOBAL const float2* texcoords, GLOBAL const Texture* textures,
                                GLOBAL const float* texels, int tri, float bu, float bv) {
  for (int depth = 0; depth < MATERIAL_MIX_MAX_DEPTH && materials[index].type == MATERIAL_MIX;
       ++depth) {
    GLOBAL const Material* m = &materials[index];
    float a = mix_amount_at(m, texcoords, textures, texels, tri, bu, bv);
    // pbrt-v4: amount <= 0 is the first, >= 1 the second (u < a gives both; NaN: the first).
    index = m->mix_material[mix_choice_uniform(P, wo, index) < a ? 1 : 0];
  }
  return index;
}

#endif // CANOPY_CL_MATERIAL_MIX_H
