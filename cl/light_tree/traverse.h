// Stochastic descent of the light tree to one light (Conty Estevez & Kulla 2018, §5.3, Alg. 2): at
// each node one child lane with probability proportional to its importance (importance.h, Eq. 3),
// chosen exactly (rng.h). Its pmf is lt_pmf_below (pmf.h). Compiles as OpenCL C and as C++.
#ifndef CANOPY_LIGHT_TREE_TRAVERSE_H
#define CANOPY_LIGHT_TREE_TRAVERSE_H

#include "../compat.h"
#include "discrete.h"
#include "importance.h"
#include "layout.h"
#include "query.h"

// Prefetches the records of the children of a node that the next step may read: node records
// and child codes of its child nodes, emitter records of its leaves.
LT_HOT void lt_prefetch_children(const LtTree* t, int4 ch) {
  for (int k = 0; k < 4; ++k) {
    int c = i4_get(ch, k);
    if (c >= 0) {
      GLOBAL const float4* n = t->nodes + c * LT_NODE_F4;
      LT_PREFETCH(n);
      LT_PREFETCH(n + 4);
      LT_PREFETCH(n + 7);
      LT_PREFETCH(t->children + c);
    } else if (c != LT_EMPTY) {
      GLOBAL const float4* e = lt_emitter_records(t, lt_leaf_first(c));
      LT_PREFETCH(e);
      LT_PREFETCH(e + LT_EMITTER_F4 * lt_leaf_count(c) - 1);
    }
  }
}

// Stochastic descent (Alg. 2) from `code` (a node index or a leaf code) to one light for query q
// (a shading point, §5.1, or a ray segment in a medium, §5.2), each decision from fresh words of
// `rng` (lt_choose_lane). Returns the light index, or -1 if nothing below `code` contributes;
// *prob = product of the lane probabilities taken below `code`.
// With use_w, the first decision's first word is w (a word of the path's sampler, cl/sampler.h:
// the decision among the root's lanes is then stratified over a pixel's samples); the rest of the
// descent draws fresh words, since a rescaled word would not keep every choice's exact
// probability (discrete.h).
INLINE int lt_pick_below_w(const LtTree* t, int code, const LtQuery* q, int use_w, uint w,
                           LtRng* rng, float* prob) {
  float p = 1.0f;
  *prob = 0.0f;
  while (code >= 0) {
    int4 ch = t->children[code];
    lt_prefetch_children(t, ch);
    float4 imp = lt_node_importance_q(t, code, q, 1);
    int lane = lt_choose_lane_w(imp, use_w, w, rng);
    use_w = 0;
    if (lane < 0) return -1;
    p = p * lt_lane_prob(imp, lane);
    code = i4_get(ch, lane);
  }
  if (code == LT_EMPTY) return -1;
  // The caller samples the chosen light next: start fetching the leaf's Light records now.
  GLOBAL const float4* rec = lt_emitter_records(t, lt_leaf_first(code));
  int count = lt_leaf_count(code);
  for (int j = 0; j < count; ++j) {
    GLOBAL const Light* L = t->lights + float_as_uint_(rec[j * LT_EMITTER_F4 + 1].w);
    LT_PREFETCH(L);
    LT_PREFETCH((GLOBAL const float4*)L + 5);
  }
  float4 imp = lt_leaf_importance_q(t, code, q, 1);
  int lane = lt_choose_lane_w(imp, use_w, w, rng);
  if (lane < 0) return -1;
  p = p * lt_lane_prob(imp, lane);
  *prob = p;
  return (int)float_as_uint_(rec[lane * LT_EMITTER_F4 + 1].w); // = leaf_lights[first + lane]
}
INLINE int lt_pick_below_q(const LtTree* t, int code, const LtQuery* q, LtRng* rng, float* prob) {
  return lt_pick_below_w(t, code, q, 0, 0u, rng, prob);
}

// The descent for a shading point P with unit normal N (0: none).
INLINE int lt_pick_below(const LtTree* t, int code, float3 P, float3 N, LtRng* rng, float* prob) {
  LtQuery q = lt_query_point(P, N);
  return lt_pick_below_q(t, code, &q, rng, prob);
}

#endif // CANOPY_LIGHT_TREE_TRAVERSE_H
