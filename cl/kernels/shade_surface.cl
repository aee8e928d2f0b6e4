// Stage 3: shading. For each path in the queue: add emission seen directly by the camera, pick one
// light uniformly, sample a point on it and push a shadow work item with the unoccluded
// contribution, then sample the diffuse BSDF for the next bounce (Russian roulette from the
// third bounce on). Emission found by BSDF rays after the first hit is not added: next-event
// estimation already accounts for every light (the MIS renderer adds it with weights).
#include "light_sample.h"
#include "rng.h"
#include "shading.h"
#include "types.h"
#include "geometry.h"

__kernel void shade_surface(int depth, int max_depth, float ray_eps, int light_count,
                            __global const int* queue_in, int count,
                            __global int* queue_out, __global int* counters,
                            __global float4* ray_o, __global float4* ray_d,
                            __global float4* throughput, __global float4* radiance,
                            __global uint* rng_state, __global const Hit* hits,
                            __global const Primitive* prims, __global const Material* materials,
                            __global const Light* lights, __global ShadowItem* shadow_queue) {
  int i = get_global_id(0);
  if (i >= count) return;
  int path = queue_in[i];
  Hit h = hits[path];
  if (h.prim < 0) return; // escaped: no environment light
  float3 d = ray_d[path].xyz;
  float3 P = ray_o[path].xyz + d * h.t;
  __global const Primitive* prim = &prims[h.prim];
  float3 Ng = primitive_normal(prim, P);
  float3 N = dot(Ng, d) < 0.0f ? Ng : -Ng; // face the incoming ray
  float3 beta = throughput[path].xyz;

  if (depth == 0 && prim->light >= 0) {
    float3 Le = light_emitted_radiance(&lights[prim->light], Ng, -d);
    radiance[path] += (float4)(beta * Le, 0.0f);
  }

  Rng r;
  r.state = rng_state[path];
  float3 albedo = materials[prim->material].albedo.xyz;
  float3 origin = offset_ray_origin(P, N, ray_eps);

  // Next-event estimation with one uniformly chosen light.
  float u_pick = rng_next_float(&r);
  float u1 = rng_next_float(&r);
  float u2 = rng_next_float(&r);
  if (light_count > 0 && max3(albedo) > 0.0f) {
    int li = min((int)(u_pick * (float)light_count), light_count - 1);
    float pmf = 1.0f / (float)light_count;
    LightSample s = sample_light(&lights[li], P, u1, u2);
    float cos_n = dot(N, s.wi);
    if (s.pdf > 0.0f && cos_n > 0.0f && max3(s.Li) > 0.0f) {
      float3 f = albedo * CANOPY_INV_PI;
      float3 c = beta * f * s.Li * (cos_n / (s.pdf * pmf));
      float3 to = P + s.wi * s.dist - origin;
      float dist = length(to);
      if (dist > 0.0f && isfinite(c.x + c.y + c.z)) {
        int slot = atomic_inc(&counters[1]);
        ShadowItem item;
        item.origin = (float4)(origin, fmax(dist - 2.0f * ray_eps, 0.0f));
        item.dir = (float4)(to / dist, as_float(path));
        item.contribution = (float4)(c, 0.0f);
        shadow_queue[slot] = item;
      }
    }
  }

  // Continue the path with a cosine-weighted bounce: albedo/pi * cos / (cos/pi) = albedo.
  float u3 = rng_next_float(&r);
  float u4 = rng_next_float(&r);
  float u_rr = rng_next_float(&r);
  rng_state[path] = r.state;
  if (depth + 1 >= max_depth) return;
  beta *= albedo;
  if (depth >= 2) {
    float q = fmin(max3(beta), 0.95f);
    if (u_rr >= q) return;
    beta /= q;
  }
  if (!(max3(beta) > 0.0f)) return;
  float3 wo = sample_cosine_hemisphere(N, u3, u4);
  ray_o[path] = (float4)(origin, 0.0f);
  ray_d[path] = (float4)(wo, 0.0f);
  throughput[path] = (float4)(beta, 0.0f);
  queue_out[atomic_inc(&counters[0])] = path;
}
