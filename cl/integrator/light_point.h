// A light point sampled for a path's shading point, with the BRDF and the shadow ray towards it:
// what tree light sampling (light_pick.h) and BRDF-oriented light sampling (brdf_mis.h) both make
// of a chosen light. Compiles as OpenCL C and as C++.
#ifndef CANOPY_INTEGRATOR_LIGHT_POINT_H
#define CANOPY_INTEGRATOR_LIGHT_POINT_H

#include "../bsdf/bsdf.h"
#include "../lights/light_sample.h"
#include "../shading.h"
#include "light_sampler.h"
#include "path_state.h"
#include "volume_light.h"

// A light point sampled for the shading point of `path` from `light` and what it brings: the
// unoccluded radiance times the BRDF and cosine, the BSDF's pdf for the direction, and the shadow
// ray (P is already off the surface; the ray ends short of the light point by the float error of
// that point's own coordinates and of the distance). Returns 0 if the point cannot contribute.
typedef struct LightPoint {
  LightSample s;
  float3 f_cos; // f(wo, wi) cos(theta_s) (local shading frame)
  float bsdf_pdf;
  float4 origin, dir; // the shadow ray (dir.w: path)
} LightPoint;

// What the light sample s (drawn for the shading point of `path`) brings there (see LightPoint).
INLINE int light_point_from(const SceneBuffers* sc, const PathBuffers* pb, int path, LightSample s,
                            LightPoint* lp) {
  float3 P = xyz_of(pb->shade_P[path]);
  float3 N = xyz_of(pb->shade_N[path]);
  // Light arriving from below the geometric surface would leak through it (shading normals),
  // except at a point that transmits: there it arrives from either side, and a direction must be
  // on the same side of the geometric and of the shading surface.
  const int two_sided = shading_point_two_sided(pb, path);
  float side = dot(N, s.wi);
  if (!(s.pdf > 0.0f) || !(two_sided ? side != 0.0f : side > 0.0f) || !(max3(s.Li) > 0.0f))
    return 0;
  Material m = shading_point_material(sc, pb, path);
  float3 Ns = xyz_of(pb->shade_Ns[path]);
  float cos_s = dot(Ns, s.wi); // = the local frame's wi.z
  if (!(two_sided ? cos_s * side > 0.0f : cos_s > 0.0f)) return 0;
  if (two_sided && side < 0.0f) { // leaves from the far side (shade_surface's offset origin)
    P = xyz_of(pb->shade_back[path]);
    cos_s = -cos_s;
  }
#if HAS_GGX || HAS_MATERIAL_DIFFUSE_TRANSMISSION
  const int lambertian = m.type == MATERIAL_DIFFUSE;
#else
  const int lambertian = 1;
#endif
  if (lambertian) {
    // Lambertian needs no frame (the common case, and the only one of a diffuse-only kernel).
    lp->f_cos =
        diffuse_eval(&m, make_float3(0.0f, 0.0f, 1.0f), make_float3(0.0f, 0.0f, cos_s)) * cos_s;
    lp->bsdf_pdf = diffuse_pdf(make_float3(0.0f, 0.0f, 1.0f), make_float3(0.0f, 0.0f, cos_s));
  } else {
    Frame fr = frame_from(Ns);
    float3 wo = frame_to_local(&fr, xyz_of(pb->shade_wo[path]));
    float3 wi = frame_to_local(&fr, s.wi);
    lp->f_cos = bsdf_eval(&m, wo, wi) * cos_s; // (cos_s = |wi.z|)
    lp->bsdf_pdf = bsdf_pdf(&m, wo, wi);
  }
  if (s.is_delta) lp->bsdf_pdf = 0.0f;           // BSDF sampling never finds a point light
  if (HAS_INFINITE_LIGHT && s.dist == FLT_INF) { // a light at infinity: an unbounded shadow ray
    lp->origin = f4_from3(P, FLT_INF);
    lp->dir = f4_from3(s.wi, uint_as_float_((uint)path));
    lp->s = s;
    return 1;
  }
  float3 to = s.x - P;
  float dist = length(to);
  if (!(dist > 0.0f)) return 0;
  float tmax = dist - fp_gamma(6) * (max_abs3(s.x) + dist);
  // Light crossing the medium on its way is attenuated (volume_light.h), unless the point lies
  // inside an object that excludes the medium (a shadow ray cannot leave such an object).
  if (HAS_MEDIUM && pb->shade_wo[path].w == 0.0f)
    s.Li = s.Li * volume_transmittance(sc, P, to / dist, fmax(tmax, 0.0f));
  lp->origin = f4_from3(P, fmax(tmax, 0.0f));
  lp->dir = f4_from3(to / dist, uint_as_float_((uint)path));
  lp->s = s;
  return 1;
}

// A direction towards environment light l for the shading point P with light-query normal N
// (cl/lights/environment.h), as a light sample at infinity.
INLINE LightSample env_light_sample(const LightSamplerCtx* ls, const GLOBAL Light* l, float3 N,
                                    float3 P, LtRng* rng) {
  LightSample s;
  s.dist = FLT_INF;
  s.is_delta = 0;
  s.x = P;
  s.wi = env_sample(l, &ls->env, N, rng, &s.pdf, &s.Li);
  return s;
}

// Samples a point on `light` for the shading point of `path` (sample_light) with (u1, u2).
INLINE int light_point_sample(const LightSamplerCtx* ls, const SceneBuffers* sc,
                              const PathBuffers* pb, int path, int light, float u1, float u2,
                              LightPoint* lp) {
  return light_point_from(sc, pb, path,
                          sample_light(&ls->lights[light], xyz_of(pb->shade_P[path]), u1, u2), lp);
}

#endif // CANOPY_INTEGRATOR_LIGHT_POINT_H
