// Stage: shade_volume, one queue item (a path whose ray found its closest hit, or none), before
// shade_surface, in scenes with a medium (DESIGN §5). The part of the ray inside the medium up to
// the closest hit is the bounce's segment:
// - It gets direct light from the medium (volume_light.h) when the scene has lights to sample and
//   the medium scatters: the segment, the path throughput at its start and a free-flight distance
//   are recorded for light_pick, whose split queue then holds a segment root for the path.
// - The free-flight distance (channel MIS over sigma_t, cl/volume/medium.h) also decides the
//   path: a distance before the segment's end scatters it there when it continues (max_depth
//   counts medium and surface vertices alike), with weight Tr sigma_s / pdf and a direction from
//   the Henyey-Greenstein phase function; otherwise the path reaches its hit with weight
//   Tr / P(reach). On a path's last vertex nothing continues: the hit is shaded with weight Tr, and
//   the medium's share of that bounce is the segment's direct light alone.
// - The ray after the last vertex (depth == max_depth: a surface's BSDF ray that looks only for
//   emission, shade_surface.h) neither scatters nor samples lights: what is scattered along it
//   is light of a longer path. Its hit's emission is weighted by Tr.
// Returns 1 if the path's segment gets light samples.
#ifndef CANOPY_INTEGRATOR_SHADE_VOLUME_H
#define CANOPY_INTEGRATOR_SHADE_VOLUME_H

#include "../sampler.h"
#include "volume_light.h"

// An unbounded segment (a ray that leaves an unbounded medium) is sampled up to where every
// scattering channel's transmittance is below e^-VOLUME_TAIL (4e-18): what lies beyond cannot
// change a float result.
#define VOLUME_TAIL 40.0f

INLINE int shade_volume_item(int path, int depth, int max_depth, const SceneBuffers* sc,
                             const PathBuffers* pb, const LightSamplerCtx* ls) {
  Medium m = sc->medium[0];
  Hit h = pb->hits[path];
  float3 o = xyz_of(pb->ray_o[path]);
  float3 d = xyz_of(pb->ray_d[path]);
  float t_hit = h.prim >= 0 ? h.t : FLT_INF;
  pb->seg_o[path] = f4_from3(o, -1.0f);
  if (pb->ray_d[path].w != 0.0f) return 0; // inside an object that excludes the medium
  float t0 = 0.0f, t1 = 0.0f;
  if (!medium_clip(&m, o, d, t_hit, &t0, &t1) || !(t1 > t0)) return 0;
  float full = t1 - t0; // +inf for a ray that never leaves an unbounded medium
  float3 beta = xyz_of(pb->throughput[path]);
  float3 sigma_s = xyz_of(m.sigma_s);
  if (!(max3(sigma_s) > 0.0f)) { // absorption only: nothing scatters
    if (h.prim >= 0) pb->throughput[path] = f4_from3(beta * medium_tr(&m, full), 0.0f);
    return 0;
  }
  float3 a = o + d * t0;
  float len = full;
  if (!(full < FLT_INF)) {
    float s = FLT_INF; // the smallest sigma_t of the scattering channels
    for (int c = 0; c < 3; ++c)
      if (f4_get(m.sigma_s, c) > 0.0f) s = fmin(s, f4_get(m.sigma_t, c));
    len = VOLUME_TAIL / s;
  }
  // The segment's numbers (cl/sampler.h): its light samplers' seed, the free-flight distance,
  // the phase-function direction, Russian roulette.
  uint4 ps = pb->rng[path];
  uint seed;
  float u_free, u1, u2, u_rr;
  if (ps.w == PATH_SAMPLER_SOBOL) {
    ps.z = sampler_vertex_base(depth);
    seed = path_sampler_hash(ps, PATH_DIM_SEGMENT_SEED);
    u_free = path_sampler_1d(ps, PATH_DIM_MEDIUM_DISTANCE);
    float2 up = path_sampler_2d(ps, PATH_DIM_PHASE);
    u1 = up.x;
    u2 = up.y;
    u_rr = depth >= 2 ? path_sampler_1d(ps, PATH_DIM_MEDIUM_RR) : 0.0f; // read from depth 2
  } else {
    PathRng r;
    r.state = ps.x;
    seed = rng_next_u32(&r);
    u_free = rng_next_float(&r);
    u1 = rng_next_float(&r);
    u2 = rng_next_float(&r);
    u_rr = rng_next_float(&r);
    ps.x = r.state;
  }
  pb->rng[path] = ps;
  float t_free = medium_sample_distance(&m, u_free);
  int lights = ls->light_count > 0 && ls->kind != SAMPLER_BSDF && len > 0.0f && depth < max_depth;
  pb->seg_o[path] = f4_from3(a, lights ? len : -1.0f);
  pb->seg_d[path] = f4_from3(d, t_free);
  pb->seg_beta[path] = f4_from3(beta, uint_as_float_(seed));
  int continues = depth + 1 < max_depth;
  pb->seg_phase[path] = continues && CANOPY_MIS ? 1.0f : 0.0f;

  if (continues && t_free < len) {
    // Scatter at the free-flight point (Tr sigma_s / pdf <= 3 per channel: channel MIS).
    float3 x = a + d * t_free;
    beta = beta * medium_tr(&m, t_free) * sigma_s * (1.0f / medium_distance_pdf(&m, t_free));
    int alive = max3(beta) > 0.0f && russian_roulette(&beta, depth, u_rr); // as at surfaces
    float pdf = 0.0f;
    float3 wi = phase_hg_sample(m.sigma_t.w, d, u1, u2, &pdf);
    Hit hs = h;
    hs.prim = alive && pdf > 0.0f ? HIT_SCATTERED : -1; // -1: the path ends here
    pb->hits[path] = hs;
    // The vertex and its segment, for MIS at the next hit (volume_emission_weight).
    pb->shade_P[path] = f4_from3(x, pdf);
    pb->scatter_seg_o[path] = f4_from3(a, len);
    pb->scatter_seg_d[path] = f4_from3(d, t_free);
    pb->shade_f[path] = f4_from3(beta, VOLUME_POINT_FLAG);
    pb->ray_o[path] = f4_from3(x, 0.0f);
    pb->ray_d[path] = f4_from3(wi, 0.0f);
    pb->throughput[path] = f4_from3(beta, 0.0f);
    return lights;
  }
  // The path reaches its hit (an escaped ray has nothing left to weight); nothing reaches it
  // through a medium that dense: the path ends.
  if (h.prim >= 0) {
    float3 tr = medium_tr(&m, full);
    if (continues) tr = tr * (1.0f / medium_survival(&m, full));
    beta = beta * tr;
    pb->throughput[path] = f4_from3(beta, 0.0f);
    if (!(max3(beta) > 0.0f)) {
      h.prim = -1;
      pb->hits[path] = h;
    }
  }
  return lights;
}

// shade_surface's result (continues, split roots) for a path after shade_volume: a path that
// scattered in the medium continues from there, and a segment with light samples adds a root
// (scatter_shade writes it before the surface point's).
INLINE int2 shade_counts_with_volume(int2 c, int path, const PathBuffers* pb) {
  if (pb->hits[path].prim == HIT_SCATTERED) c.x = 1;
  c.y += pb->seg_o[path].w >= 0.0f ? 1 : 0;
  return c;
}

#endif // CANOPY_INTEGRATOR_SHADE_VOLUME_H
