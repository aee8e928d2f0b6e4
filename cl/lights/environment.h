// Environment lights (LIGHT_ENVIRONMENT, cl/types.h): radiance from every direction, constant or
// from an image map, and their importance sampling. A map is piecewise constant (each texel's
// radiance over its patch of the map's square): directions are drawn by choosing a texel with the
// alias method, with probability proportional to its luminance times the solid angle of its patch
// (so that a texel's share of the samples follows its share of the light), then a uniform point of
// the patch. Two projections: equirectangular (the JSON format's default) and pbrt-v4's equal-area
// octahedral square (Clarberg 2008). A constant environment is sampled by the cosine about the
// shading point's normal. Compiles as OpenCL C and as C++ (cl/compat.h).
#ifndef CANOPY_CL_LIGHTS_ENVIRONMENT_H
#define CANOPY_CL_LIGHTS_ENVIRONMENT_H

#include "../compat.h"
#include "../light_tree/discrete.h"
#include "../shading.h"
#include "../types.h"
#include "light_sample.h"


// The device buffers of every environment map, concatenated (host/render/environment_map.h):
// texels (rgb radiance), each texel's probability, and each map's alias table (local indices).
typedef struct EnvBuffers {
  GLOBAL const float4* texels;
  GLOBAL const float* pmf;
  GLOBAL const float* alias_prob;
  GLOBAL const int* alias_index;
} EnvBuffers;

INLINE float3 env_to_map(const GLOBAL Light* l, float3 w) {
  return make_float3(dot(xyz_of(l->e1), w), dot(xyz_of(l->e2), w), dot(xyz_of(l->n), w));
}
INLINE float3 env_from_map(const GLOBAL Light* l, float3 m) {
  return xyz_of(l->e1) * m.x + xyz_of(l->e2) * m.y + xyz_of(l->n) * m.z;
}

// Equirectangular. The solid angle of (du, dv) is 2 pi^2 sin(theta) du dv.
INLINE float2 env_equirect_uv(float3 m) {
  float phi = atan2(m.y, m.x);
  if (phi < 0.0f) phi += 2.0f * CANOPY_PI;
  float theta = acos(fmin(fmax(m.z, -1.0f), 1.0f));
  return make_float2(phi * (0.5f / CANOPY_PI), theta * (1.0f / CANOPY_PI));
}
INLINE float3 env_equirect_dir(float2 uv) {
  float phi = 2.0f * CANOPY_PI * uv.x, theta = CANOPY_PI * uv.y;
  float st = sin(theta);
  return make_float3(st * cos(phi), st * sin(phi), cos(theta));
}

// Equal-area octahedral square <-> sphere (Clarberg 2008; pbrt-v4's EqualAreaSquareToSphere and
// EqualAreaSphereToSquare, with atan in place of its polynomial). The solid angle of (du, dv) is
// 4 pi du dv.
INLINE float3 env_octahedral_dir(float2 uv) {
  float u = 2.0f * uv.x - 1.0f, v = 2.0f * uv.y - 1.0f;
  float up = fabs(u), vp = fabs(v);
  float sd = 1.0f - (up + vp); // signed distance from the diagonal
  float r = 1.0f - fabs(sd);
  float phi = (r == 0.0f ? 1.0f : (vp - up) / r + 1.0f) * (0.25f * CANOPY_PI);
  float z = sd >= 0.0f ? 1.0f - r * r : -(1.0f - r * r);
  float s = r * sqrt(fmax(0.0f, 2.0f - r * r));
  float cp = cos(phi), sp = sin(phi);
  return make_float3(u < 0.0f ? -cp * s : cp * s, v < 0.0f ? -sp * s : sp * s, z);
}
INLINE float2 env_octahedral_uv(float3 d) {
  float x = fabs(d.x), y = fabs(d.y), z = fabs(d.z);
  float r = sqrt(fmax(0.0f, 1.0f - z));
  float a = fmax(x, y), b = fmin(x, y);
  float phi = a == 0.0f ? 0.0f : atan(b / a) * (2.0f / CANOPY_PI);
  if (x < y) phi = 1.0f - phi;
  float v = phi * r;
  float u = r - v;
  if (d.z < 0.0f) {
    float t = u;
    u = 1.0f - v;
    v = 1.0f - t;
  }
  u = d.x < 0.0f ? -u : u;
  v = d.y < 0.0f ? -v : v;
  return make_float2(0.5f * (u + 1.0f), 0.5f * (v + 1.0f));
}

INLINE uint env_width(const GLOBAL Light* l) {
  return float_as_uint_(l->p.y);
}
INLINE uint env_height(const GLOBAL Light* l) {
  return float_as_uint_(l->p.z);
}
INLINE uint env_first_texel(const GLOBAL Light* l) {
  return float_as_uint_(l->p.x);
}

// The texel (index within the map) whose patch holds map direction m.
INLINE uint env_texel_of(const GLOBAL Light* l, float3 m) {
  float2 uv = l->flags == ENV_EQUIRECT ? env_equirect_uv(m) : env_octahedral_uv(m);
  uint w = env_width(l), h = env_height(l);
  uint i = (uint)fmin(fmax(uv.x * (float)w, 0.0f), (float)(w - 1u));
  uint j = (uint)fmin(fmax(uv.y * (float)h, 0.0f), (float)(h - 1u));
  return j * w + i;
}

// Solid-angle density of a direction given its texel's probability: texel probability times the
// texel count (the density in the unit square) over the projection's Jacobian.
INLINE float env_map_pdf(const GLOBAL Light* l, float pmf, float3 m) {
  float n = (float)env_width(l) * (float)env_height(l);
  if (l->flags == ENV_OCTAHEDRAL) return pmf * n * (0.25f / CANOPY_PI);
  // sin(theta) from x and y: 1 - z^2 would round to 0 within 3e-4 rad of the poles
  float st = sqrt(m.x * m.x + m.y * m.y);
  return st > 0.0f ? pmf * n / (2.0f * CANOPY_PI * CANOPY_PI * st) : 0.0f;
}

// Radiance arriving along -w (w: unit world direction from the scene towards the environment).
INLINE float3 env_radiance(const GLOBAL Light* l, const EnvBuffers* eb, float3 w) {
  float3 L = xyz_of(l->emission);
  if (l->flags == ENV_CONSTANT) return L;
  return L * xyz_of(eb->texels[env_first_texel(l) + env_texel_of(l, env_to_map(l, w))]);
}

// Solid-angle pdf with which env_sample draws w at a point with unit normal N (0: none).
INLINE float env_pdf(const GLOBAL Light* l, const EnvBuffers* eb, float3 N, float3 w) {
  if (l->flags == ENV_CONSTANT) {
    if (!(dot(N, N) > 0.0f)) return 0.25f / CANOPY_PI;
    return fmax(dot(N, w), 0.0f) * (1.0f / CANOPY_PI);
  }
  float3 m = env_to_map(l, w);
  return env_map_pdf(l, eb->pmf[env_first_texel(l) + env_texel_of(l, m)], m);
}

// Draws a direction towards the environment for a point with unit normal N (0: none) from rng:
// returns it, *pdf its solid-angle density (0: nothing to sample) and *L the radiance along it.
INLINE float3 env_sample(const GLOBAL Light* l, const EnvBuffers* eb, float3 N, LtRng* rng,
                         float* pdf, float3* L) {
  float u1 = lt_rng_next(rng), u2 = lt_rng_next(rng);
  float3 w;
  if (l->flags == ENV_CONSTANT) {
    if (dot(N, N) > 0.0f) { // cosine-weighted about N (Malley's method)
      float2 d = concentric_disk(u1, u2);
      float z = sqrt(fmax(0.0f, 1.0f - d.x * d.x - d.y * d.y));
      float3 t, b;
      onb_from(N, &t, &b);
      w = normalize(t * d.x + b * d.y + N * z);
    } else { // uniform on the sphere
      float z = 1.0f - 2.0f * u1, r = sqrt(fmax(0.0f, 1.0f - z * z)), phi = 2.0f * CANOPY_PI * u2;
      w = make_float3(r * cos(phi), r * sin(phi), z);
    }
  } else {
    uint wd = env_width(l), ht = env_height(l), first = env_first_texel(l);
    uint k = (uint)lt_alias_pick(eb->alias_prob + first, eb->alias_index + first, wd * ht, rng);
    float2 uv = make_float2(((float)(k % wd) + u1) / (float)wd, ((float)(k / wd) + u2) / (float)ht);
    float3 m = l->flags == ENV_EQUIRECT ? env_equirect_dir(uv) : env_octahedral_dir(uv);
    // The drawn texel's own density and radiance (a lookup of the rounded direction could land
    // in a neighbour at a patch's edge): exactly the procedure's density.
    *pdf = env_map_pdf(l, eb->pmf[first + k], m);
    *L = xyz_of(l->emission) * xyz_of(eb->texels[first + k]);
    return normalize(env_from_map(l, m));
  }
  *pdf = env_pdf(l, eb, N, w);
  *L = env_radiance(l, eb, w);
  return w;
}

#endif // CANOPY_CL_LIGHTS_ENVIRONMENT_H
