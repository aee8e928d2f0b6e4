// Stage: shade_surface, one queue item (a path whose ray found its closest hit).
// - Adds emission seen by the ray: fully at the camera vertex and after a delta (mirror) bounce;
//   after any other bounce MIS-weighted (power heuristic against the light technique, whose pmf is
//   recomputed from the previous vertex), or not at all without MIS (light sampling then counts
//   all of it), or fully with the BSDF-only sampler.
// - Records the shading point (position, normals, wo, material, throughput) for light_pick, which
//   does next-event estimation in the split passes, and for MIS at the next hit.
// - Samples the BSDF for the next bounce (Russian roulette from the third bounce on).
// max_depth counts the vertices that sample lights, as in pbrt-v4: the last one (depth + 1 ==
// max_depth) still traces its BSDF ray, whose hit (depth == max_depth) only adds the emission it
// finds, MIS-weighted, and ends the path. So max_depth 1 is direct light with MIS, and a mirror
// (which samples no light) reflects emitters at every depth. That ray is traced only where the
// emission it can find has a weight: not from a glossy point of a BRDF sampler, whose direct
// light is complete without it, nor after a non-delta bounce without MIS.
// Returns (continues, shade): whether the path goes on, and whether light_pick must sample lights
// for this shading point.
#ifndef CANOPY_INTEGRATOR_SHADE_SURFACE_H
#define CANOPY_INTEGRATOR_SHADE_SURFACE_H

#include "../bsdf/bsdf.h"
#include "../geometry.h"
#include "../lights/light_sample.h"
#include "../material_mix.h"
#include "../sampler.h"
#include "../shading.h"
#include "../texture.h"
#include "brdf_mis.h"
#include "light_sampler.h"
#include "path_state.h"

// MIS weight of emission found by a BSDF-sampled ray (DESIGN §5). prev_P.w is the solid-angle pdf
// of the BSDF direction, 0 for a delta bounce.
INLINE float shade_emission_weight(const LightSamplerCtx* ls, const SceneBuffers* sc,
                                   const PathBuffers* pb, int path, int depth, int light,
                                   float3 P) {
  float4 prev_P = pb->shade_P[path];
  if (depth == 0 || !(prev_P.w > 0.0f) || ls->kind == SAMPLER_BSDF) return 1.0f;
  // A medium vertex: the phase technique against the segment's light samples (volume_light.h).
  if (HAS_MEDIUM && pb->shade_f[path].w == VOLUME_POINT_FLAG)
    return CANOPY_MIS ? volume_emission_weight(ls, sc, pb, path, light, P) : 0.0f;
  // A glossy point of a BRDF sampler has its direct light complete without its bounce (brdf_mis.h)
  if (HAS_MICROFACET && light_sampler_brdf(ls) && pb->shade_f[path].w == BRDF_POINT_FLAG)
    return 0.0f;
  if (!CANOPY_MIS) return 0.0f; // light sampling alone accounts for it
  float pmf = light_sampler_pmf(ls, xyz_of(prev_P), light_query_normal(pb, path), light);
  float p_light = pmf * light_pdf(&ls->lights[light], xyz_of(prev_P), P);
  return power_heuristic(prev_P.w, p_light);
}

// MIS weight of environment light l found by a ray that escaped along d: as for an emitter hit
// (shade_emission_weight), against the environment's own sampling (light_pick.h samples every
// light at infinity with probability 1, with the pdf env_pdf at the previous vertex's normal).
INLINE float shade_environment_weight(const LightSamplerCtx* ls, const PathBuffers* pb, int path,
                                      int depth, const GLOBAL Light* l, float3 d) {
  float4 prev_P = pb->shade_P[path];
  if (depth == 0 || !(prev_P.w > 0.0f) || ls->kind == SAMPLER_BSDF) return 1.0f;
  if (!CANOPY_MIS) return 0.0f; // light sampling alone accounts for it
  return power_heuristic(prev_P.w, env_pdf(l, &ls->env, env_query_normal(pb, path), d));
}

INLINE int2 shade_surface_item(int path, int depth, int max_depth, const SceneBuffers* sc,
                               const PathBuffers* pb, const LightSamplerCtx* ls) {
  int2 out = make_int2(0, 0);
  Hit h = pb->hits[path];
  if (HAS_LIGHT_ENVIRONMENT && h.prim == -1) { // escaped: the environment lights it sees
    float3 d = xyz_of(pb->ray_d[path]);
    float3 sum = make_float3(0.0f, 0.0f, 0.0f);
    for (int j = 0; j < ls->infinite_count; ++j) {
      GLOBAL const Light* l = &ls->lights[ls->light_count + j];
      if (l->type == LIGHT_ENVIRONMENT)
        sum += env_radiance(l, &ls->env, d) * shade_environment_weight(ls, pb, path, depth, l, d);
    }
    float4 L = pb->radiance[path];
    pb->radiance[path] = f4_from3(xyz_of(L) + xyz_of(pb->throughput[path]) * sum, 0.0f);
  }
  if (h.prim < 0) { // escaped, or scattered in the medium (shade_volume.h)
    // and no glossy point: brdf_sample must not act on a stale (or never written) brdf_state
    if (HAS_MICROFACET && light_sampler_brdf(ls)) pb->brdf_state[path] = make_int4(0, 0, 0, 0);
    return out;
  }
  float3 d = xyz_of(pb->ray_d[path]);
  GLOBAL const Primitive* prim = &sc->prims[h.prim];
  float3 P_err;
  float3 P = primitive_hit_point(prim, xyz_of(pb->ray_o[path]), d, h, &P_err);
  float3 Ng = primitive_normal(prim, P);
  float3 N = dot(Ng, d) < 0.0f ? Ng : -Ng; // facing the incoming ray
  float3 wo = -d;
  // Materials reflect on the side the ray arrives from: the shading frame faces wo too, with the
  // interpolated vertex normal of a smooth triangle where it is usable for wo (cl/shading.h).
  float3 Ns =
      shading_normal_fix(N, wo, primitive_shading_normal(prim, sc->shading_normals, h.u, h.v, N));
  // Every ray that leaves this point (the bounce and the shadow rays of light_pick) leaves on N's
  // side, so one origin serves them all: the hit point moved off the surface by its own error
  // bound (cl/shading.h). It is also the shading point recorded for light picking and MIS. (A
  // ray refracted through glass leaves on the other side, from its own origin.)
  float3 P_hit = P;
  P = offset_ray_origin(P, P_err, N);
  float3 beta = xyz_of(pb->throughput[path]);

  if (prim->light >= 0) {
    float3 Le = light_emitted_radiance(&ls->lights[prim->light], Ng, -d);
    float w = shade_emission_weight(ls, sc, pb, path, depth, prim->light, P);
    float4 L = pb->radiance[path];
    pb->radiance[path] = f4_from3(xyz_of(L) + beta * Le * w, 0.0f);
  }
  if (depth >= max_depth) { // the last vertex's BSDF ray: emission only, no material evaluation
    if (HAS_MICROFACET && light_sampler_brdf(ls)) pb->brdf_state[path] = make_int4(0, 0, 0, 0);
    return out;
  }

  // A mix is the material it chooses here (the same for every later use of this point).
  const int mat = HAS_MATERIAL_MIX ? material_resolve_mix(sc->materials, prim->material, P_hit, wo,
                                                          sc->texcoords, sc->textures, sc->texels,
                                                          h.prim, h.u, h.v)
                                   : prim->material;
  Material m = sc->materials[mat];
  // Whether the surface bounds a medium-free inside belongs to the surface (its own material),
  // not to the material a mix chose.
  if (HAS_MATERIAL_MIX ? mat != prim->material : 0)
    m.excludes_medium = sc->materials[prim->material].excludes_medium;
  material_face(&m, dot(Ng, d) > 0.0f); // a ray from inside glass sees the inverse index
  if (HAS_TEXTURES ? (m.albedo_texture | m.alpha_texture | m.transmittance_texture) != 0 : 0) {
    // The textured albedo, alpha and transmittance at the hit, kept for light_pick and brdf_mis
    // (shading_point_material).
    material_apply_textures(&m, sc->texcoords, sc->textures, sc->texels, h.prim, h.u, h.v);
    pb->shade_tex[path] = f4_from3(xyz_of(m.albedo), m.alpha);
    if (HAS_MATERIAL_DIFFUSE_TRANSMISSION ? m.transmittance_texture != 0 : 0)
      pb->shade_tex_t[path] = f4_from3(xyz_of(m.specular), 0.0f);
  }
  // Light reaches a transmitting point from both sides: rays towards the far side leave from
  // an origin offset to that side (light_point.h), and its light-tree queries take no normal.
  const int two_sided = bsdf_two_sided(&m);
  if (HAS_MATERIAL_DIFFUSE_TRANSMISSION)
    pb->shade_back[path] = f4_from3(offset_ray_origin(P_hit, P_err, -N), two_sided ? 1.0f : 0.0f);
  // The vertex's numbers (cl/sampler.h): the light samplers' seed, the BSDF direction, Russian
  // roulette, the lobe choice.
  uint4 ps = pb->rng[path];
  uint light_seed;
  float u1, u2, u_rr, u3;
  if (ps.w == PATH_SAMPLER_SOBOL) {
    ps.z = sampler_vertex_base(depth); // light_pick reads this vertex's dimensions too
    light_seed = path_sampler_hash(ps, PATH_DIM_LIGHT_SEED);
    float2 ub = path_sampler_2d(ps, PATH_DIM_BSDF);
    u1 = ub.x;
    u2 = ub.y;
    // (only where they are read: Russian roulette from depth 2, cl/shading.h; a lobe choice
    // except on diffuse surfaces)
    u_rr = depth >= 2 ? path_sampler_1d(ps, PATH_DIM_RR) : 0.0f;
    u3 = m.type != MATERIAL_DIFFUSE ? path_sampler_1d(ps, PATH_DIM_LOBE) : 0.0f;
    pb->light_u[path] = path_sampler_2d(ps, PATH_DIM_LIGHT_POINT); // once for the whole cut
  } else {
    PathRng r;
    r.state = ps.x;
    light_seed = rng_next_u32(&r);
    u1 = rng_next_float(&r);
    u2 = rng_next_float(&r);
    u_rr = rng_next_float(&r);
    u3 = rng_next_float(&r);
    ps.x = r.state;
  }
  pb->rng[path] = ps;

  int last = depth + 1 >= max_depth; // the BSDF ray only looks for emission (see the top)
  // Light shapes are black diffuse: nothing to pick lights for.
  int black = m.type == MATERIAL_DIFFUSE && !(max3(xyz_of(m.albedo)) > 0.0f);
  out.y = (ls->light_count > 0 || ls->infinite_count > 0) && ls->kind != SAMPLER_BSDF &&
          bsdf_has_smooth_lobe(&m) && !black;
  float mis_flag = CANOPY_MIS ? 1.0f : 0.0f;
  if (HAS_MICROFACET && light_sampler_brdf(ls)) {
    // Glossy points get BRDF-oriented sampling (brdf_mis.h: -1 asks brdf_cut for the cut);
    // brdf-oriented alone takes no tree light sample there.
    int glossy = out.y && ls->light_count > 0 && brdf_material_glossy(&m);
    pb->brdf_state[path] = make_int4(0, glossy ? -1 : 0, 0, 0);
    if (glossy) mis_flag = BRDF_POINT_FLAG;
    // (distant lights are still sampled there: light_pick.h)
    if (glossy && ls->kind == SAMPLER_BRDF_ORIENTED) out.y = ls->infinite_count > 0;
  }
  pb->shade_N[path] = f4_from3(N, uint_as_float_(light_seed));
  pb->shade_f[path] = f4_from3(beta, mis_flag);
  // Whether rays leaving on wo's side travel outside the medium: as the ray that arrived, or at a
  // surface that bounds a medium-free inside (pbrt-v4's MediumInterface), by the side.
  const float outside_medium =
      m.excludes_medium ? (dot(Ng, d) > 0.0f ? 1.0f : 0.0f) : pb->ray_d[path].w;
  pb->shade_wo[path] = f4_from3(wo, outside_medium);
  pb->shade_Ns[path] = f4_from3(Ns, uint_as_float_((uint)mat));
  pb->shade_P[path] = f4_from3(P, 0.0f);
  if (black) return out;

  Frame fr = frame_from(Ns);
  BsdfSample bs = bsdf_sample(&m, frame_to_local(&fr, wo), make_float3(u1, u2, u3));
  // From the last vertex, only a ray whose emission gets a weight (shade_emission_weight).
  // (An environment light gives an escaped ray a weight at glossy points of the BRDF samplers too.)
  int env_weighs = CANOPY_MIS ? light_sampler_has_environment(ls) : 0;
  if (last && !bs.is_delta && ls->kind != SAMPLER_BSDF && !(mis_flag == 1.0f) && !env_weighs)
    return out;
  float3 wi = frame_to_world(&fr, bs.wi);
  // A direction to the other side of the geometric surface than the lobe's would leak light
  // through it (shading normals).
  int through = bs.wi.z < 0.0f; // refracted (cl/bsdf/dielectric.h)
  if (!(through ? dot(wi, N) < 0.0f : dot(wi, N) > 0.0f)) return out;
  beta = beta * bs.weight;
  if (!russian_roulette(&beta, depth, u_rr)) return out;
  if (!(max3(beta) > 0.0f) || !(bs.is_delta || bs.pdf > 0.0f)) return out;
  // 0: emission this ray finds gets full weight. Through rough glass as after a delta bounce: light
  // samples are taken on wo's side only (light_point.h rejects the far side), so the light
  // technique cannot produce a path through the surface. A two-sided point samples lights on both
  // sides, so its transmitted rays are weighted as its reflected ones.
  pb->shade_P[path] = f4_from3(P, bs.is_delta || (through && !two_sided) ? 0.0f : bs.pdf);
  pb->ray_o[path] = f4_from3(through ? offset_ray_origin(P_hit, P_err, -N) : P, 0.0f);
  // Leaving a surface that bounds a medium-free inside, a ray takes the medium of its side (into
  // the inside: none); elsewhere it keeps the one it had.
  float next_outside = outside_medium;
  if (m.excludes_medium) next_outside = dot(wi, Ng) < 0.0f ? 1.0f : 0.0f;
  pb->ray_d[path] = f4_from3(normalize(wi), next_outside);
  pb->throughput[path] = f4_from3(beta, 0.0f);
  out.x = 1;
  return out;
}

#endif // CANOPY_INTEGRATOR_SHADE_SURFACE_H
