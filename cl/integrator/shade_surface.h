// Stage: shade_surface, one queue item (a path whose ray found its closest hit).
// - Adds emission seen by the ray: fully at the camera vertex, MIS-weighted (power heuristic
//   against the light technique, whose pmf is recomputed from the previous vertex) after a bounce.
// - Records the shading point for light_pick (which does next-event estimation in the split
//   passes) and for MIS at the next hit.
// - Samples the diffuse BSDF for the next bounce (Russian roulette from the third bounce on).
// Returns (continues, shade): whether the path goes on, and whether light_pick must sample lights
// for this shading point.
#ifndef CANOPY_INTEGRATOR_SHADE_SURFACE_H
#define CANOPY_INTEGRATOR_SHADE_SURFACE_H

#include "../geometry.h"
#include "../light_sample.h"
#include "../rng.h"
#include "../shading.h"
#include "light_sampler.h"
#include "path_state.h"

INLINE int2 shade_surface_item(int path, int depth, int max_depth, const SceneBuffers* sc,
                               const PathBuffers* pb, const LightSamplerCtx* ls) {
  int2 out = make_int2(0, 0);
  Hit h = pb->hits[path];
  if (h.prim < 0) return out; // escaped: no environment light
  float3 d = xyz_of(pb->ray_d[path]);
  GLOBAL const Primitive* prim = &sc->prims[h.prim];
  float3 P_err;
  float3 P = primitive_hit_point(prim, xyz_of(pb->ray_o[path]), d, h, &P_err);
  float3 Ng = primitive_normal(prim, P);
  float3 N = dot(Ng, d) < 0.0f ? Ng : -Ng; // facing the incoming ray
  // Every ray that leaves this point (the bounce and the shadow rays of light_pick) leaves on N's
  // side, so one origin serves them all: the hit point moved off the surface by its own error
  // bound (cl/shading.h). It is also the shading point recorded for light picking and MIS.
  P = offset_ray_origin(P, P_err, N);
  float3 beta = xyz_of(pb->throughput[path]);

  if (prim->light >= 0) {
    float3 Le = light_emitted_radiance(&ls->lights[prim->light], Ng, -d);
    float w = 1.0f;
    float4 prev_P = pb->shade_P[path];
    if (depth > 0 && prev_P.w > 0.0f) {
      float3 prev_N = xyz_of(pb->shade_N[path]);
      float pmf = light_sampler_pmf(ls, xyz_of(prev_P), prev_N, prim->light);
      float p_light = pmf * light_pdf(&ls->lights[prim->light], xyz_of(prev_P), P);
      w = power_heuristic(prev_P.w, p_light);
    }
    float4 L = pb->radiance[path];
    pb->radiance[path] = f4_from3(xyz_of(L) + beta * Le * w, 0.0f);
  }

  PathRng r;
  r.state = pb->rng[path];
  float3 albedo = xyz_of(sc->materials[prim->material].albedo);
  uint light_seed = rng_next_u32(&r);
  float u1 = rng_next_float(&r);
  float u2 = rng_next_float(&r);
  float u_rr = rng_next_float(&r);
  pb->rng[path] = r.state;

  int continues = depth + 1 < max_depth;
  out.y = ls->light_count > 0 && max3(albedo) > 0.0f;
  pb->shade_N[path] = f4_from3(N, uint_as_float_(light_seed));
  pb->shade_f[path] = f4_from3(beta * albedo * CANOPY_INV_PI, continues ? 1.0f : 0.0f);
  pb->shade_P[path] = f4_from3(P, 0.0f);
  if (!continues) return out;

  // Cosine-weighted bounce: albedo/pi * cos / (cos/pi) = albedo.
  float3 wo = sample_cosine_hemisphere(N, u1, u2);
  float pdf = dot(N, wo) * CANOPY_INV_PI;
  beta = beta * albedo;
  if (depth >= 2) {
    float q = fmin(max3(beta), 0.95f);
    if (u_rr >= q) return out;
    beta = beta / q;
  }
  if (!(max3(beta) > 0.0f) || !(pdf > 0.0f)) return out;
  pb->shade_P[path] = f4_from3(P, pdf);
  pb->ray_o[path] = f4_from3(P, 0.0f);
  pb->ray_d[path] = f4_from3(wo, 0.0f);
  pb->throughput[path] = f4_from3(beta, 0.0f);
  out.x = 1;
  return out;
}

#endif // CANOPY_INTEGRATOR_SHADE_SURFACE_H
