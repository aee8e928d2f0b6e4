// Stage: light_pick, one split-queue item (DESIGN §4). The adaptive splitting of Conty Estevez &
// Kulla 2018 (Alg. 3) runs as passes over a queue instead of recursion: an item whose cluster
// should split stages its children for the next pass (a split leaf takes each of its emitters with
// probability 1); any other item picks one light below it stochastically (Alg. 2), samples a point
// on it and stages a shadow work item carrying the unoccluded, MIS-weighted contribution divided by
// the pick probability. Samplers without splitting (uniform, power, tree) see only the root item.
#ifndef CANOPY_INTEGRATOR_LIGHT_PICK_H
#define CANOPY_INTEGRATOR_LIGHT_PICK_H

#include "../bsdf/bsdf.h"
#include "../light_sample.h"
#include "../shading.h"
#include "light_sampler.h"
#include "path_state.h"

// Samples a point on `light` (chosen with probability pmf) from the path's shading point and, if
// it can contribute, writes the shadow item. Returns 1 if an item was written.
INLINE int light_pick_shadow_item(const LightSamplerCtx* ls, const SceneBuffers* sc,
                                  const PathBuffers* pb, int path, int light, float pmf, LtRng* rng,
                                  GLOBAL ShadowItem* out) {
  float3 P = xyz_of(pb->shade_P[path]);
  float3 N = xyz_of(pb->shade_N[path]);
  float4 f = pb->shade_f[path];
  float u1 = lt_rng_next(rng);
  float u2 = lt_rng_next(rng);
  LightSample s = sample_light(&ls->lights[light], P, u1, u2);
  // Light arriving from below the geometric surface would leak through it (shading normals).
  if (!(s.pdf > 0.0f) || !(dot(N, s.wi) > 0.0f) || !(max3(s.Li) > 0.0f) || !(pmf > 0.0f)) return 0;
  float4 ns_m = pb->shade_Ns[path];
  Material m = sc->materials[(int)float_as_uint_(ns_m.w)];
  float3 Ns = xyz_of(ns_m);
  float cos_s = dot(Ns, s.wi); // = the local frame's wi.z
  if (!(cos_s > 0.0f)) return 0;
  float3 bsdf;
  float bsdf_p;
  if (!HAS_MICROFACET || m.type == MATERIAL_DIFFUSE) {
    // Lambertian needs no frame (the common case, and the only one of a diffuse-only kernel).
    bsdf = diffuse_eval(&m, make_float3(0.0f, 0.0f, 1.0f), make_float3(0.0f, 0.0f, cos_s));
    bsdf_p = diffuse_pdf(make_float3(0.0f, 0.0f, 1.0f), make_float3(0.0f, 0.0f, cos_s));
  } else {
    Frame fr = frame_from(Ns);
    float3 wo = frame_to_local(&fr, xyz_of(pb->shade_wo[path]));
    float3 wi = frame_to_local(&fr, s.wi);
    bsdf = bsdf_eval(&m, wo, wi);
    bsdf_p = bsdf_pdf(&m, wo, wi);
  }
  // MIS against BSDF sampling when the path continues with it (never for delta lights).
  float w = 1.0f;
  if (!s.is_delta && f.w > 0.0f) w = power_heuristic(pmf * s.pdf, bsdf_p);
  float3 c = xyz_of(f) * bsdf * s.Li * (cos_s * w / (s.pdf * pmf));
  // A non-finite contribution is kept, not dropped: it reaches the path's radiance, where
  // accumulate counts the sample as non-finite (reported by --stats) and records it as zero.
  if (is_finite_f(c.x + c.y + c.z) && !(max3(c) > 0.0f)) return 0;
  // P is already off the surface (shade_surface). The ray ends short of the light point by the
  // float error of that point's own coordinates and of the distance, not by a scene-wide margin;
  // an area light's point is already off the light's surface (sample_light).
  float3 to = s.x - P;
  float dist = length(to);
  if (!(dist > 0.0f)) return 0;
  float tmax = dist - fp_gamma(6) * (max_abs3(s.x) + dist);
  ShadowItem item;
  item.origin = f4_from3(P, fmax(tmax, 0.0f));
  item.dir = f4_from3(to / dist, uint_as_float_((uint)path));
  item.contribution = f4_from3(c, 0.0f);
  *out = item;
  return 1;
}

// Processes one split item. Stages up to 4 child items in children[0..3] or up to 4 shadow items
// in shadows[0..3]. Returns (children staged, shadow items staged, lights in the cut, 0).
INLINE int4 light_pick_item(SplitItem it, const LightSamplerCtx* ls, const SceneBuffers* sc,
                            const PathBuffers* pb, GLOBAL SplitItem* children,
                            GLOBAL ShadowItem* shadows) {
  int4 out = make_int4(0, 0, 0, 0);
  int path = it.path;
  float3 P = xyz_of(pb->shade_P[path]);
  float3 N = xyz_of(pb->shade_N[path]);
  uint seed = float_as_uint_(pb->shade_N[path].w);
  const LtTree* t = &ls->tree;

  if (light_sampler_splits(ls) &&
      lt_item_splits(t, it.sphere, it.cv2, it.code, it.budget, P, ls->threshold)) {
    float4 imp = lt_code_importance(t, it.code, P, N);
    if (it.code >= 0) { // interior node: its contributing lanes go to the next pass
      int4 ch = t->children[it.code];
      int4 budgets = lt_child_budgets(t, it.code, imp, it.budget, P, ls->threshold);
      for (int lane = 0; lane < 4; ++lane) {
        int code = i4_get(ch, lane);
        if (code == LT_EMPTY || !(f4_get(imp, lane) > 0.0f)) continue;
        SplitItem c;
        c.sphere = lt_lane_sphere(t, it.code, lane);
        c.path = path;
        c.code = code;
        c.budget = (uint)i4_get(budgets, lane);
        c.cv2 = lt_lane_cv2(t, it.code, lane);
        children[out.x++] = c;
      }
      return out;
    }
    // Leaf: every contributing emitter is in the cut with probability 1.
    int first = lt_leaf_first(it.code);
    for (int j = 0; j < lt_leaf_count(it.code); ++j) {
      if (!(f4_get(imp, j) > 0.0f)) continue;
      int light = t->leaf_lights[first + j];
      LtRng rng = lt_rng_make(seed, 0x80000000u ^ (uint)light);
      out.z += 1;
      out.y += light_pick_shadow_item(ls, sc, pb, path, light, 1.0f, &rng, &shadows[out.y]);
    }
    return out;
  }

  // One stochastic pick below the item (codes are unique within a cut: one stream each).
  LtRng rng = lt_rng_make(seed, (uint)it.code);
  float pmf;
  int light = light_sampler_pick(ls, it.code, P, N, &rng, &pmf);
  out.z = 1;
  if (light >= 0) out.y = light_pick_shadow_item(ls, sc, pb, path, light, pmf, &rng, &shadows[0]);
  return out;
}

#endif // CANOPY_INTEGRATOR_LIGHT_PICK_H
