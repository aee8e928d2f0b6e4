// Probability that the light-tree samplers produce a given light, recomputed along its bit-trail
// with the same functions as the sampling: the stochastic descent (Conty Estevez & Kulla 2018,
// §5.3, Alg. 2) and splitting (§5.4, Alg. 3), for MIS when a BSDF ray hits a light (DESIGN §4).
// Compiles as OpenCL C and as C++ (cl/compat.h).
#ifndef CANOPY_LIGHT_TREE_PMF_H
#define CANOPY_LIGHT_TREE_PMF_H

#include "../compat.h"
#include "importance.h"
#include "layout.h"
#include "query.h"
#include "discrete.h"
#include "split.h"

// Probability that lt_pick_below_q(code, q) returns the light whose remaining trail (decision at
// `code` in the lowest two bits) is `trail`: the same importances, the same lane probabilities.
INLINE float lt_pmf_below_q(const LtTree* t, int code, const LtQuery* q, uint trail) {
  float p = 1.0f;
  while (code >= 0) {
    int4 ch = t->children[code];
    int lane = (int)(trail & 3u);
    trail = trail >> 2;
    int next = i4_get(ch, lane);
    if (next >= 0) {
      LT_PREFETCH(t->nodes + next * LT_NODE_F4);
      LT_PREFETCH(t->nodes + next * LT_NODE_F4 + 4);
      LT_PREFETCH(t->nodes + next * LT_NODE_F4 + 7);
      LT_PREFETCH(t->children + next);
    }
    float4 imp = lt_node_importance_q(t, code, q, 1);
    float pk = lt_lane_prob(imp, lane);
    if (!(pk > 0.0f)) return 0.0f;
    p = p * pk;
    code = next;
  }
  if (code == LT_EMPTY) return 0.0f;
  float4 imp = lt_leaf_importance_q(t, code, q, 1);
  return p * lt_lane_prob(imp, (int)(trail & 3u));
}

// pmf of `light` under splitting (DESIGN §4 "MIS with splitting"): 1 above the item where the
// deterministic split stopped, times the lane probabilities below it along the light's bit-trail.
INLINE float lt_pmf_split_q(const LtTree* t, const LtQuery* q, int light, float threshold,
                            uint max_cut) {
  uint trail = t->trails[light];
  float4 sphere = t->root_sphere;
  float cv2 = t->root_info.x;
  int code = 0;
  uint budget = max_cut;
  for (;;) {
    if (!lt_item_splits_q(t, sphere, cv2, code, budget, q, threshold))
      return lt_pmf_below_q(t, code, q, trail);
    int lane = (int)(trail & 3u);
    trail = trail >> 2;
    float4 imp = lt_code_importance_q(t, code, q);
    if (!(f4_get(imp, lane) > 0.0f)) return 0.0f;
    if (code < 0) return 1.0f; // split leaf: every contributing emitter is taken
    budget = (uint)i4_get(lt_child_budgets_q(t, code, imp, budget, q, threshold), lane);
    sphere = lt_lane_sphere(t, code, lane);
    cv2 = lt_lane_cv2(t, code, lane);
    code = i4_get(t->children[code], lane);
  }
}

// The point forms (shading point P, unit normal N or 0).
INLINE float lt_pmf_below(const LtTree* t, int code, float3 P, float3 N, uint trail) {
  LtQuery q = lt_query_point(P, N);
  return lt_pmf_below_q(t, code, &q, trail);
}
INLINE float lt_pmf_split(const LtTree* t, float3 P, float3 N, int light, float threshold,
                          uint max_cut) {
  LtQuery q = lt_query_point(P, N);
  return lt_pmf_split_q(t, &q, light, threshold, max_cut);
}

#endif // CANOPY_LIGHT_TREE_PMF_H
