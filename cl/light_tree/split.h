// Adaptive tree splitting (Conty Estevez & Kulla 2018, §5.4 and Alg. 3): the statistics of the
// geometric term (Eq. 8-9), the split measure (Eq. 10, made dimensionless), split items and the
// cut budgets of the children of a split node. Compiles as OpenCL C and as C++ (cl/compat.h).
#ifndef CANOPY_LIGHT_TREE_SPLIT_H
#define CANOPY_LIGHT_TREE_SPLIT_H

#include "../compat.h"
#include "layout.h"
#include "query.h"

// A cut budget that never binds (the exhaustive sampler: threshold 1 splits down to every light).
#define LT_BUDGET_UNLIMITED 0x7fffffffu
// Default threshold of the adaptive split (see lt_split_measure for its meaning and calibration).
#define LT_DEFAULT_SPLIT_THRESHOLD 0.25f

// ---------------------------------------------------------------- geometric term statistics (§5.4)
// Distance to an emitter uniform in [a, b], g = 1/x^2. Eq. 8-9 in the cancellation-free form:
// E[g] = 1/(ab), V[g] = (b-a)^2 / (3 a^3 b^3) (written to avoid overflowing a^3 b^3).
INLINE float lt_geom_mean(float a, float b) {
  return 1.0f / (a * b);
}
INLINE float lt_geom_var(float a, float b) {
  float q = (b - a) / (a * b);
  return q * q / (3.0f * a * b);
}
// V[g] / E[g]^2 = (b-a)^2 / (3ab): dimensionless.
INLINE float lt_geom_cv2(float a, float b) {
  float d = b - a;
  return d * d / (3.0f * a * b);
}
// The paper's Eq. 10 with units (energy^2 / distance^4), kept for reference and tests.
INLINE float lt_split_sigma2_paper(float var_e, float mean_e, float a, float b) {
  float eg = lt_geom_mean(a, b);
  float vg = lt_geom_var(a, b);
  return var_e * vg + var_e * eg * eg + mean_e * mean_e * vg;
}

// Adaptive-split measure of a cluster (bounding sphere `sphere`, energy CV^2 `cv2_e`) seen from P.
// The paper remaps sigma of Eq. 10 with (1 + sigma)^(-1/4); sigma there has units, so decisions
// would depend on the scene's length unit and brightness. Here sigma is the coefficient of
// variation of e*g: sigma^2 = (1 + V[e]/E[e]^2)(1 + V[g]/E[g]^2) - 1 (Eq. 10 divided by
// E[e]^2 E[g]^2), invariant to scaling sizes or energies, and it cannot overflow.
// Returns (1 + sigma)^(-1/4) in (0, 1], or 0 when P is inside the sphere (a = 0: always split).
//
// Threshold calibration: split while measure < threshold, i.e. sigma > threshold^-4 - 1. The
// default 0.85 (the paper's) means sigma > 1.914: for equal-energy emitters, P closer than 1.17 r
// to the cluster centre; for a distant cluster, energy CV > 1.9. P inside a cluster's sphere always
// splits it (a = 0), so points among the lights get cuts of tens of clusters and distant points a
// single pick, the behaviour of the paper's Fig. 11. Measured mean cut on the spiral scene (10^4
// point lights, shading points on the ground below, bench SplitCut): threshold 0: 1, 0.5: 19,
// 0.85: 38, 0.95: 213, 1: every light (capped by max_cut). The default, 0.25, is the threshold with
// the lowest error at equal render time over the four scenes of docs/results.md (the paper's 0.85
// spends too many shadow rays for this renderer's cost per ray); P inside a cluster's sphere still
// always splits it.
INLINE float lt_split_measure(float3 P, float4 sphere, float cv2_e) {
  float3 d3 = xyz_of(sphere) - P;
  float d2 = dot(d3, d3);
  float r = sphere.w;
  if (d2 <= r * r) return 0.0f;
  float d = sqrt(d2);
  float a = d - r;
  if (!(a > 0.0f)) return 0.0f;
  float b = d + r;
  float cv2_g = lt_geom_cv2(a, b);
  float cv2 = cv2_e + cv2_g + cv2_e * cv2_g;
  float sigma = sqrt(cv2);
  return 1.0f / sqrt(sqrt(1.0f + sigma));
}
// The split measure for a query: a point's lt_split_measure, and for a segment in a medium the
// same measure at the segment's point closest to the sphere's centre. The paper (§5.4, last
// paragraph) found the quadratic-decay heuristic better for media too, although the importance
// decays as 1/d there (Eq. 7): it prevents over-splitting.
INLINE float lt_split_measure_q(const LtQuery* q, float4 sphere, float cv2_e) {
  if (LT_QUERY_IS_SEGMENT(q))
    return lt_split_measure(lt_query_closest(q, xyz_of(sphere)), sphere, cv2_e);
  return lt_split_measure(q->P, sphere, cv2_e);
}
INLINE int lt_should_split(float measure, float threshold) {
  return threshold >= 1.0f || measure < threshold;
}

// ---------------------------------------------------------------- splitting (Alg. 3)
// A split item is a cluster: its bounding sphere, energy CV^2, code (node or leaf) and the cut
// budget it may still spend. The root item is (root_sphere, root_info.x, 0, max_cut). An item
// splits when lt_item_splits() says so: it then becomes one item per contributing lane (node: the
// children with importance > 0, budgets from lt_child_budgets; leaf: each contributing emitter
// taken with probability 1). Otherwise it yields lt_pick_below(code) with its probability.
// The budget rule bounds the cut by max_cut and, being a function of the path only, lets the pmf
// of one light be recomputed (lt_pmf_split) without knowing the rest of the cut.
INLINE int lt_code_lanes(const LtTree* t, int code) {
  if (code == LT_EMPTY) return 0;
  if (code < 0) return lt_leaf_count(code);
  int4 c = t->children[code];
  return (c.x != LT_EMPTY) + (c.y != LT_EMPTY) + (c.z != LT_EMPTY) + (c.w != LT_EMPTY);
}
INLINE int lt_item_splits_q(const LtTree* t, float4 sphere, float cv2, int code, uint budget,
                            const LtQuery* q, float threshold) {
  int m = lt_code_lanes(t, code);
  if (m < 1 || (uint)m > budget) return 0;
  return lt_should_split(lt_split_measure_q(q, sphere, cv2), threshold);
}
INLINE int lt_item_splits(const LtTree* t, float4 sphere, float cv2, int code, uint budget,
                          float3 P, float threshold) {
  LtQuery q = lt_query_point(P, make_float3(0.0f, 0.0f, 0.0f));
  return lt_item_splits_q(t, sphere, cv2, code, budget, &q, threshold);
}
// The child item of node `node` in lane `lane` (sphere and CV^2 from the node's lanes).
INLINE float4 lt_lane_sphere(const LtTree* t, int node, int lane) {
  GLOBAL const float4* n = t->nodes + node * LT_NODE_F4;
  return make_float4(f4_get(n[LT_CX], lane), f4_get(n[LT_CY], lane), f4_get(n[LT_CZ], lane),
                     f4_get(n[LT_R], lane));
}
INLINE float lt_lane_cv2(const LtTree* t, int node, int lane) {
  return uint_as_float_(float_as_uint_(f4_get(t->nodes[node * LT_NODE_F4 + LT_CE_CV2], lane)) &
                        0xffff0000u);
}

// Cut budgets of the children of `node` (lanes with importance `imp` > 0; 0 for the others) when
// an item with `budget` splits: every contributing child keeps 1 for its own pick; the rest goes
// to the children that will split in turn (their split measure at P is below the threshold), in
// proportion to importance (largest remainders get the units left by rounding down; ties go to
// the lower lane), and a leaf child gets no more than its emitter count. The budget so flows to
// the clusters that matter (near the shading point), and splitting can isolate single lights
// there; an even share (budget / lanes) stops every branch log4(max_cut) levels down, at clusters
// of N / max_cut lights however near. The budgets sum to at most `budget` (lt_item_splits ensures
// budget >= lanes) and depend on the node's lanes only, so lt_pmf_split recomputes them along one
// trail.
INLINE int4 lt_child_budgets_q(const LtTree* t, int node, float4 imp, uint budget, const LtQuery* q,
                               float threshold) {
  if (budget >= LT_BUDGET_UNLIMITED) { // the exhaustive sampler: every child keeps it
    int u = (int)LT_BUDGET_UNLIMITED;
    return make_int4(imp.x > 0.0f ? u : 0, imp.y > 0.0f ? u : 0, imp.z > 0.0f ? u : 0,
                     imp.w > 0.0f ? u : 0);
  }
  int4 ch = t->children[node];
  float w[4], share[4], frac[4];
  uint cap[4];
  float wsum = 0.0f;
  uint k = 0u;
  for (int j = 0; j < 4; ++j) {
    w[j] = 0.0f;
    cap[j] = 1u;
    if (!(f4_get(imp, j) > 0.0f)) continue;
    k += 1u;
    if (!lt_should_split(lt_split_measure_q(q, lt_lane_sphere(t, node, j), lt_lane_cv2(t, node, j)),
                         threshold))
      continue;
    int c = i4_get(ch, j);
    w[j] = f4_get(imp, j);
    cap[j] = c < 0 ? (uint)lt_leaf_count(c) : 0xffffffffu;
    wsum += w[j];
  }
  float spare = (float)(budget > k ? budget - k : 0u);
  uint whole = 0u;
  for (int j = 0; j < 4; ++j) {
    float x = wsum > 0.0f ? spare * (w[j] / wsum) : 0.0f; // w_j <= wsum: x <= spare
    share[j] = floor(x);
    frac[j] = x - share[j];
    whole += (uint)share[j];
  }
  uint left = (uint)spare > whole ? (uint)spare - whole : 0u;
  uint b[4];
  for (int j = 0; j < 4; ++j) {
    uint rank = 0u; // of this lane's remainder among the lanes that share
    for (int i = 0; i < 4; ++i)
      rank += (uint)(w[i] > 0.0f && (frac[i] > frac[j] || (frac[i] == frac[j] && i < j)));
    uint extra = (uint)share[j] + (uint)(w[j] > 0.0f && rank < left);
    b[j] = f4_get(imp, j) > 0.0f ? 1u + (extra < cap[j] - 1u ? extra : cap[j] - 1u) : 0u;
  }
  return make_int4((int)b[0], (int)b[1], (int)b[2], (int)b[3]);
}

INLINE int4 lt_child_budgets(const LtTree* t, int node, float4 imp, uint budget, float3 P,
                             float threshold) {
  LtQuery q = lt_query_point(P, make_float3(0.0f, 0.0f, 0.0f));
  return lt_child_budgets_q(t, node, imp, budget, &q, threshold);
}

#endif // CANOPY_LIGHT_TREE_SPLIT_H
