// Stage: light_pick, one split-queue item (DESIGN §4). The adaptive splitting of Conty Estevez &
// Kulla 2018 (Alg. 3) runs as passes over a queue instead of recursion: an item whose cluster
// should split stages its children for the next pass (a split leaf takes each of its emitters with
// probability 1); any other item picks one light below it stochastically (Alg. 2), samples a point
// on it and stages a shadow work item carrying the unoccluded, MIS-weighted contribution divided by
// the pick probability. Samplers without splitting (uniform, power, tree) see only the root item.
#ifndef CANOPY_INTEGRATOR_LIGHT_PICK_H
#define CANOPY_INTEGRATOR_LIGHT_PICK_H

#include "../sampler.h"
#include "brdf_mis.h"
#include "light_point.h"
#include "light_sampler.h"
#include "path_state.h"
#include "volume_light.h"

// Shadow-item slots per split item: a split leaf stages one item per emitter (up to 4), for a
// medium segment too (one of its two points per light, volume_light.h).
#define LIGHT_PICK_SHADOW_SLOTS 4

// Samples a point on `light` (chosen with probability pmf) from the path's shading point and, if
// it can contribute, writes the shadow item. Returns 1 if an item was written. With use_u, the
// point on a light with a surface comes from u (the path sampler's light-point dimensions,
// cl/sampler.h), else from rng.
INLINE int light_pick_shadow_item_u(const LightSamplerCtx* ls, const SceneBuffers* sc,
                                    const PathBuffers* pb, int path, int light, float pmf,
                                    int use_u, float2 u, LtRng* rng, GLOBAL ShadowItem* out) {
  if (!(pmf > 0.0f)) return 0;
  LightPoint lp;
  if (HAS_LIGHT_ENVIRONMENT && IS_LIGHT(&ls->lights[light], LIGHT_ENVIRONMENT)) {
    LightSample s = env_light_sample(ls, &ls->lights[light], env_query_normal(pb, path),
                                     xyz_of(pb->shade_P[path]), rng);
    if (!light_point_from(sc, pb, path, s, &lp)) return 0;
  } else {
    float u1 = use_u ? u.x : lt_rng_next(rng);
    float u2 = use_u ? u.y : lt_rng_next(rng);
    if (!light_point_sample(ls, sc, pb, path, light, u1, u2, &lp)) return 0;
  }
  float f_w = pb->shade_f[path].w;
  float w = 1.0f;
  float p_L = pmf * lp.s.pdf;
  if (HAS_INFINITE_LIGHT && light >= ls->light_count) {
    // A light at infinity is outside the tree: BSDF sampling is its only other technique (a ray
    // that escapes, shade_surface.h; never for a distant light's delta direction: bsdf_pdf 0).
    if (CANOPY_MIS && f_w > 0.0f) w = power_heuristic(p_L, lp.bsdf_pdf);
  } else if (HAS_MICROFACET && light_sampler_brdf(ls) && f_w == BRDF_POINT_FLAG) {
    // A glossy point: against its N BRDF-aware samples (brdf_mis.h).
    w = brdf_weight_tree(ls, p_L, brdf_light_pmf_weight(ls, pb, path, light) * lp.s.pdf,
                         lp.bsdf_pdf, pb->brdf_state[path].y, pb->brdf_share[path],
                         brdf_tree_exact(pmf, lp.s.is_delta));
  } else if (f_w > 0.0f) {
    // MIS against BSDF sampling when the path continues with it (bsdf_pdf 0: delta lights).
    w = power_heuristic(p_L, lp.bsdf_pdf);
  }
  float3 c = xyz_of(pb->shade_f[path]) * lp.f_cos * lp.s.Li * (w / p_L);
  // A non-finite contribution is kept, not dropped: it reaches the path's radiance, where
  // accumulate counts the sample as non-finite (reported by --stats) and records it as zero.
  if (is_finite_f(c.x + c.y + c.z) && !(max3(c) > 0.0f)) return 0;
  ShadowItem item;
  item.origin = lp.origin;
  item.dir = lp.dir;
  item.contribution = f4_from3(c, 0.0f);
  *out = item;
  return 1;
}
INLINE int light_pick_shadow_item(const LightSamplerCtx* ls, const SceneBuffers* sc,
                                  const PathBuffers* pb, int path, int light, float pmf, LtRng* rng,
                                  GLOBAL ShadowItem* out) {
  return light_pick_shadow_item_u(ls, sc, pb, path, light, pmf, 0, make_float2(0.0f, 0.0f), rng,
                                  out);
}

// The shadow item of `light`, picked with probability pmf for the item's context (a shading point
// or a medium segment, volume_light.h); returns 1 if it was written.
// use_u, u: as light_pick_shadow_item_u (shading points only; a segment's streams are its own).
INLINE int light_pick_items(const LightSamplerCtx* ls, const SceneBuffers* sc,
                            const PathBuffers* pb, int path, int segment, int light, float pmf,
                            int use_u, float2 u, LtRng* rng, GLOBAL ShadowItem* out) {
  if (HAS_MEDIUM && segment) return volume_shadow_items(ls, sc, pb, path, light, pmf, rng, out);
  return light_pick_shadow_item_u(ls, sc, pb, path, light, pmf, use_u, u, rng, out);
}

// Distant lights (cl/types.h LIGHT_DISTANT) are sampled beside the light sampler: the root item of
// every shading point takes each of them with probability 1 (a shadow ray per distant light and
// point). They have no position, so the tree has no place for them; pbrt-v4 instead picks among
// its n infinite lights and the tree with probability n / (n + 1) and 1 / (n + 1). The choice was
// measured (docs/performance.md, "Distant lights"). At most MAX_INFINITE_LIGHTS, so that they and
// the root's own pick fit its LIGHT_PICK_SHADOW_SLOTS.
INLINE int light_pick_infinite(const LightSamplerCtx* ls, const SceneBuffers* sc,
                               const PathBuffers* pb, int path, uint seed, GLOBAL ShadowItem* out) {
  int n = 0;
  for (int j = 0; j < ls->infinite_count; ++j) {
    LtRng rng = lt_rng_make(seed, 0x40000000u ^ (uint)j); // apart from codes and leaf lights
    n += light_pick_shadow_item(ls, sc, pb, path, ls->light_count + j, 1.0f, &rng, &out[n]);
  }
  return n;
}

// Processes one split item: a cluster for a path's shading point or (SPLIT_SEGMENT) for its
// medium segment. Stages up to 4 child items in children[0..3] or up to LIGHT_PICK_SHADOW_SLOTS
// shadow items in shadows[] (a shading point's root item: its distant lights first, then its own
// pick). Returns (children staged, shadow items staged, lights in the cut, 0).
INLINE int4 light_pick_item(SplitItem it, const LightSamplerCtx* ls, const SceneBuffers* sc,
                            const PathBuffers* pb, GLOBAL SplitItem* children,
                            GLOBAL ShadowItem* shadows) {
  int4 out = make_int4(0, 0, 0, 0);
  int segment = HAS_MEDIUM && (it.path & SPLIT_SEGMENT) != 0;
  int path = it.path & ~SPLIT_SEGMENT;
  LtQuery q;
  uint seed;
  if (HAS_MEDIUM && segment) {
    q = volume_query(pb, path);
    seed = float_as_uint_(pb->seg_beta[path].w);
  } else {
    q = lt_query_point(xyz_of(pb->shade_P[path]), light_query_normal(pb, path));
    seed = float_as_uint_(pb->shade_N[path].w);
  }
  // sobol (cl/sampler.h): every light sample of a shading point takes its point from the vertex's
  // light-point dimensions (light_u, drawn once by shade_surface: each light's estimate is
  // stratified over the pixel's samples), and the root's pick its first word from the
  // light-selection dimension. The picks below split children and the deeper levels of a descent
  // draw from their own LtRng streams (a dimension cannot serve choices whose number depends on the
  // cut, nor a rescaled word keep their exact probabilities); medium segments keep theirs entirely.
  int strat = !segment && pb->rng[path].w == PATH_SAMPLER_SOBOL;
  const LtTree* t = &ls->tree;
  if (HAS_INFINITE_LIGHT && !segment && it.code == 0 && ls->infinite_count > 0) {
    out.y = light_pick_infinite(ls, sc, pb, path, seed, shadows);
    out.z = ls->infinite_count;
    // No other light (the tree is empty), or a glossy point of brdf-oriented, whose BRDF-oriented
    // samples (brdf_mis.h) are its only light samples of the others.
    int brdf_only =
        HAS_MICROFACET ? ls->kind == SAMPLER_BRDF_ORIENTED && pb->shade_f[path].w == BRDF_POINT_FLAG
                       : 0;
    if (ls->light_count <= 0 || brdf_only) return out;
  }

  if (light_sampler_splits(ls) &&
      lt_item_splits_q(t, it.sphere, it.cv2, it.code, it.budget, &q, ls->threshold)) {
    float4 imp = lt_code_importance_q(t, it.code, &q);
    if (it.code >= 0) { // interior node: its contributing lanes go to the next pass
      int4 ch = t->children[it.code];
      int4 budgets = lt_child_budgets_q(t, it.code, imp, it.budget, &q, ls->threshold);
      for (int lane = 0; lane < 4; ++lane) {
        int code = i4_get(ch, lane);
        if (code == LT_EMPTY || !(f4_get(imp, lane) > 0.0f)) continue;
        SplitItem c;
        c.sphere = lt_lane_sphere(t, it.code, lane);
        c.path = it.path;
        c.code = code;
        c.budget = (uint)i4_get(budgets, lane);
        c.cv2 = lt_lane_cv2(t, it.code, lane);
        children[out.x++] = c;
      }
      return out;
    }
    // Leaf: every contributing emitter is in the cut with probability 1.
    float2 u_point = strat ? pb->light_u[path] : make_float2(0.0f, 0.0f);
    int first = lt_leaf_first(it.code);
    for (int j = 0; j < lt_leaf_count(it.code); ++j) {
      if (!(f4_get(imp, j) > 0.0f)) continue;
      int light = t->leaf_lights[first + j];
      LtRng rng = lt_rng_make(seed, 0x80000000u ^ (uint)light);
      out.z += 1;
      out.y += light_pick_items(ls, sc, pb, path, segment, light, 1.0f, strat, u_point, &rng,
                                &shadows[out.y]);
    }
    return out;
  }

  // One stochastic pick below the item (codes are unique within a cut: one stream each).
  LtRng rng = lt_rng_make(seed, (uint)it.code);
  int root = strat && it.code == 0;
  uint w = root ? path_sampler_word(pb->rng[path], PATH_DIM_LIGHT_SELECT) : 0u;
  float pmf;
  int light = light_sampler_pick_w(ls, it.code, &q, root, w, &rng, &pmf);
  out.z += 1;
  if (light >= 0) {
    float2 u_point = strat ? pb->light_u[path] : make_float2(0.0f, 0.0f);
    out.y += light_pick_items(ls, sc, pb, path, segment, light, pmf, strat, u_point, &rng,
                              &shadows[out.y]);
  }
  return out;
}

#endif // CANOPY_INTEGRATOR_LIGHT_PICK_H
