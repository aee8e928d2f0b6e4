// The light-selection techniques behind one interface, shared by the light_pick/shade_surface
// kernels and the host reference: uniform, power (alias table), tree (Conty Estevez & Kulla 2018
// Alg. 2), tree with adaptive splitting (Alg. 3), exhaustive (every light; the reference), bsdf
// (no light: BSDF sampling only, nothing to pick, pmf 0), and brdf-mis / brdf-oriented, which are
// tree-split here and add BRDF-oriented sampling at glossy points (brdf_mis.h).
#ifndef CANOPY_INTEGRATOR_LIGHT_SAMPLER_H
#define CANOPY_INTEGRATOR_LIGHT_SAMPLER_H

#include "../light_tree/pmf.h"
#include "../light_tree/query.h"
#include "../light_tree/traverse.h"
#include "../lights/environment.h"
#include "../types.h"

typedef struct LightSamplerCtx {
  int kind; // SAMPLER_*
  int light_count;
  GLOBAL const Light* lights;
  GLOBAL const float* power_pmf;  // power: probability of each light
  GLOBAL const float* alias_prob; // power: alias table (Walker/Vose)
  GLOBAL const int* alias_index;
  LtTree tree;     // tree, tree-split, exhaustive
  float threshold; // tree-split: split while the measure is below it (>= 1: always)
  uint max_cut;    // tree-split: cut size cap per shading point
  // brdf-mis, brdf-oriented (cl/integrator/brdf_mis.h): LT_BRDF_MAX_CUT cut entries per path of
  // the wave, the split threshold delta on S_C (Eq. 5), N_max (Eq. 9), lambda (Eq. 7), and
  // adaptive allocation (0: one sample of each technique).
  GLOBAL float2* brdf_cut;
  float brdf_delta;
  float brdf_lambda;
  int brdf_nmax;
  int brdf_adaptive;
  // Lights at infinity (distant and environment lights): lights[light_count .. light_count +
  // infinite_count), outside every technique above; each shading point samples all of them
  // (light_pick.h). env: the environment maps' buffers (cl/lights/environment.h).
  int infinite_count;
  EnvBuffers env;
} LightSamplerCtx;

// Cut budget of a medium segment's root (Conty Estevez & Kulla 2018, §5.4, last paragraph: the
// surface measure decides the splits of a segment's cut too). A segment that passes through a
// cluster's sphere always splits it (the measure at its closest point is 0 there), so with the
// shading point's budget most segments near a light set split down to max_cut lights (19.7 shadow
// rays per segment on spiral-fog at threshold 0.85, 40.3 on city-fog, against 1.2 without
// splitting). Capping a segment's cut at LT_SEGMENT_MAX_CUT lights: 4 was the best on spiral-fog's
// full paths and 16 on its direct light, within 10% of each other on city-fog; with 16 tree-split
// is at least as efficient as tree on spiral-fog's direct light and on city-fog (with 4 it lost
// spiral-fog's direct light to tree; docs/performance.md, "Splitting in media"). The exhaustive
// sampler's unlimited budget is kept.
#define LT_SEGMENT_MAX_CUT 16u
INLINE uint light_sampler_segment_budget(uint max_cut) {
  return max_cut >= LT_BUDGET_UNLIMITED || max_cut < LT_SEGMENT_MAX_CUT ? max_cut
                                                                        : LT_SEGMENT_MAX_CUT;
}

// The split-queue root item of a shading point.
INLINE SplitItem light_sampler_root(const LightSamplerCtx* ls, int path) {
  SplitItem it;
  it.sphere = ls->tree.root_sphere;
  it.path = path;
  it.code = 0;
  it.budget = ls->max_cut;
  it.cv2 = ls->tree.root_info.x;
  return it;
}

// Picks one light among all of them (uniform, power) or below `code` (tree) for query q (a
// shading point or a ray segment in a medium, cl/light_tree/query.h) with random words from rng,
// each choice with exactly the probability it reports (cl/light_tree/discrete.h, "exact discrete
// choices"). Returns the light or -1; *pmf its probability. uniform and power ignore q. The host
// samplers (host/light_tree/light_sampler.cpp) run the same functions.
// light_sampler_pick_w: with use_w, the pick's first random word is w (the light-selection
// dimension of the path's sampler, cl/sampler.h), the rest from rng.
INLINE int light_sampler_pick_w(const LightSamplerCtx* ls, int code, const LtQuery* q, int use_w,
                                uint w, LtRng* rng, float* pmf) {
  *pmf = 0.0f;
  if (ls->light_count <= 0 || ls->kind == SAMPLER_BSDF) return -1;
  if (ls->kind == SAMPLER_UNIFORM) {
    *pmf = 1.0f / (float)ls->light_count;
    uint w1 = use_w ? w : lt_rng_next_u32(rng);
    return (int)lt_rng_index_w(w1, rng, (uint)ls->light_count);
  }
  if (ls->kind == SAMPLER_POWER) {
    uint w1 = use_w ? w : lt_rng_next_u32(rng);
    int l = lt_alias_pick_w(ls->alias_prob, ls->alias_index, (uint)ls->light_count, w1, rng);
    *pmf = ls->power_pmf[l];
    return *pmf > 0.0f ? l : -1;
  }
  return lt_pick_below_w(&ls->tree, code, q, use_w, w, rng, pmf);
}
INLINE int light_sampler_pick_q(const LightSamplerCtx* ls, int code, const LtQuery* q, LtRng* rng,
                                float* pmf) {
  return light_sampler_pick_w(ls, code, q, 0, 0u, rng, pmf);
}
INLINE int light_sampler_pick(const LightSamplerCtx* ls, int code, float3 P, float3 N, LtRng* rng,
                              float* pmf) {
  LtQuery q = lt_query_point(P, N);
  return light_sampler_pick_q(ls, code, &q, rng, pmf);
}

// Probability that the technique produces `light` for query q: for MIS when a BSDF ray (or, in a
// medium, a phase-function ray) hits it. With splitting it is the product of the lane
// probabilities below the item where splitting stopped (DESIGN §4), recomputed along the light's
// bit-trail with the same functions.
INLINE float light_sampler_pmf_q(const LightSamplerCtx* ls, const LtQuery* q, int light) {
  if (ls->light_count <= 0 || ls->kind == SAMPLER_BSDF) return 0.0f;
  if (ls->kind == SAMPLER_UNIFORM) return 1.0f / (float)ls->light_count;
  if (ls->kind == SAMPLER_POWER) return ls->power_pmf[light];
  if (ls->kind == SAMPLER_TREE) return lt_pmf_below_q(&ls->tree, 0, q, ls->tree.trails[light]);
  uint budget = LT_QUERY_IS_SEGMENT(q) ? light_sampler_segment_budget(ls->max_cut) : ls->max_cut;
  return lt_pmf_split_q(&ls->tree, q, light, ls->threshold, budget);
}
INLINE float light_sampler_pmf(const LightSamplerCtx* ls, float3 P, float3 N, int light) {
  LtQuery q = lt_query_point(P, N);
  return light_sampler_pmf_q(ls, &q, light);
}

// Whether the scene has an environment light among its lights at infinity.
INLINE int light_sampler_has_environment(const LightSamplerCtx* ls) {
  if (!HAS_LIGHT_ENVIRONMENT) return 0;
  for (int j = 0; j < ls->infinite_count; ++j)
    if (ls->lights[ls->light_count + j].type == LIGHT_ENVIRONMENT) return 1;
  return 0;
}

// brdf-mis and brdf-oriented are tree-split at points without a glossy BRDF.
INLINE int light_sampler_splits(const LightSamplerCtx* ls) {
  return ls->kind == SAMPLER_TREE_SPLIT || ls->kind == SAMPLER_EXHAUSTIVE ||
         ls->kind == SAMPLER_BRDF_MIS || ls->kind == SAMPLER_BRDF_ORIENTED;
}
INLINE int light_sampler_brdf(const LightSamplerCtx* ls) {
  return ls->kind == SAMPLER_BRDF_MIS || ls->kind == SAMPLER_BRDF_ORIENTED;
}

#endif // CANOPY_INTEGRATOR_LIGHT_SAMPLER_H
