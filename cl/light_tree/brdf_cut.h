// BRDF-oriented light sampling (Liu, Xu & Yan 2019, §4.1): per shading point a light cut chosen by
// the cosine-weighted BRDF integrated over each cluster's bounding cap (S_C, Eq. 5), the cluster
// importance I_C = E_C cos(theta_C) / d^2 * S_C / Omega_C (Eq. 6), a pick of one cluster of the
// cut by importance, a stochastic descent below it by the same importance, and the probability of
// any light under that technique (for MIS), recomputed along the light's bit-trail. Compiles as
// OpenCL C and as C++ (cl/compat.h); the host tests and the kernels run the same code.
#ifndef CANOPY_LIGHT_TREE_BRDF_CUT_H
#define CANOPY_LIGHT_TREE_BRDF_CUT_H

#include "../bsdf/cap_integral.h"
#include "../compat.h"
#include "discrete.h"
#include "importance.h"
#include "layout.h"
#include "pmf.h"

// Capacity of a point's cut. The paper's cuts average 3.4 (delta 0.5) to 51 (delta 0.005) clusters
// (Table 2); a cut that would grow past this stops splitting (it still covers every light, so the
// estimator stays unbiased). 64 = 4^3: three levels of 4-way choices pick an entry.
#define LT_BRDF_MAX_CUT 64
// Importances are absolute (they are compared across the whole cut), so they are kept in
// [LT_IMPORTANCE_FLOOR, LT_BRDF_IMPORTANCE_MAX]: four of them sum without overflow.
#define LT_BRDF_IMPORTANCE_MAX 1.0e30f
#define LT_BRDF_DEFAULT_DELTA 0.5f

// Importance (Eq. 6) of four lanes for the point P with geometric normal Ng (facing wo) and the
// BRDF lobe `lobe`; S_C of each lane in *S and whether P is inside its bounding sphere in
// *inside. A lane is 0 where none of its emitters can reach P's reflecting side: no energy, the
// orientation cone or half-space bound excludes P (lt_view_v), the cap is below the geometric
// horizon, or the BRDF's mean over the cap is 0. Inside the sphere the cap is the whole sphere
// and d^2 is clamped at (r/2)^2 as in lt_importance_v.
LT_HOT float4 lt_brdf_importance4(const LtLanes* l, float3 P, float3 Ng, const CapLobe* lobe,
                                  float4* S, int4* inside) {
  LtView v = lt_view_v(l, P);
  float4 e = v4_to_f4(l->energy), orient = v4_to_f4(v.orient), sin_u = v4_to_f4(v.sin_u),
         cos_u = v4_to_f4(v.cos_u), dx = v4_to_f4(v.dx), dy = v4_to_f4(v.dy), dz = v4_to_f4(v.dz),
         d2 = v4_to_f4(v.d2), inv_d = v4_to_f4(v.inv_d), r = v4_to_f4(l->r);
  float4 front = v4_to_f4(v4_sel(v4_splat(0.0f), v4_splat(1.0f), v.front));
  float imp[4], s[4];
  int in[4];
  for (int k = 0; k < 4; ++k) {
    imp[k] = 0.0f;
    s[k] = 0.0f;
    float dk2 = f4_get(d2, k), rk = f4_get(r, k);
    in[k] = dk2 <= rk * rk;
    if (!(f4_get(e, k) > 0.0f) || !(f4_get(orient, k) > 0.0f) || !(f4_get(front, k) > 0.0f))
      continue;
    float id = f4_get(inv_d, k);
    float3 c = make_float3(f4_get(dx, k) * id, f4_get(dy, k) * id, f4_get(dz, k) * id);
    float su = f4_get(sin_u, k), cu = f4_get(cos_u, k);
    if (in[k]) c = Ng; // the whole sphere: any axis
    // geometric horizon: cos(max(theta_i - theta_u, 0)) > 0, as lt_importance_v's incidence term
    float ci = dot(c, Ng);
    float si = sqrt(fmax(1.0f - ci * ci, 0.0f));
    if (!in[k] && !(ci >= cu || ci * cu + si * su > 0.0f)) continue;
    float mean;
    // The BRDF's mean over the cap decides, not S_C: a point light's cap has no solid angle (S_C
    // = 0) but the BRDF towards it is its mean.
    s[k] = cap_lobe_integral(lobe, c, su, cu, &mean);
    if (!(mean > 0.0f)) {
      s[k] = 0.0f;
      continue;
    }
    float d2c = fmax(fmax(dk2, 0.25f * rk * rk), 1e-36f);
    float x = f4_get(e, k) * f4_get(orient, k) * (mean / d2c);
    imp[k] = fmin(fmax(x, LT_IMPORTANCE_FLOOR), LT_BRDF_IMPORTANCE_MAX); // NaN -> floor
  }
  *S = make_float4(s[0], s[1], s[2], s[3]);
  *inside = make_int4(in[0], in[1], in[2], in[3]);
  return make_float4(imp[0], imp[1], imp[2], imp[3]);
}

// Lanes below `code` and their importances (for a leaf: its emitters).
INLINE float4 lt_brdf_code_importance(const LtTree* t, int code, float3 P, float3 Ng,
                                      const CapLobe* lobe, float4* S, int4* inside) {
  float3 n = Ng;
  LtLanes l = lt_code_lanes4(t, code, &n);
  // Under the orientation ablation n is cleared: keep the geometric horizon all the same (the
  // BRDF lobe holds the receiver's orientation here, not the emitters').
  return lt_brdf_importance4(&l, P, Ng, lobe, S, inside);
}

// The code of lane `lane` below `code`: a child node or leaf, or for a leaf one emitter (a leaf
// code of count 1).
INLINE int lt_lane_code(const LtTree* t, int code, int lane) {
  if (code >= 0) return i4_get(t->children[code], lane);
  return lt_leaf_code(lt_leaf_first(code) + lane, 1);
}
INLINE int lt_code_splittable(int code) {
  return code >= 0 || (code != LT_EMPTY && lt_leaf_count(code) > 1);
}

// Builds the cut of P (§4.1 "Light cut construction"): from the root, a cluster splits when P is
// inside its bounding sphere or S_C > delta (Eq. 5), depth first, while the cut fits in
// LT_BRDF_MAX_CUT entries. Clusters of importance 0 are left out (none of their lights can reach
// P). Writes entries (code bits, importance) to cut[0..count) and returns count; *I_B = max S_C
// over the cut (Eq. 8).
INLINE int lt_brdf_cut_build(const LtTree* t, float3 P, float3 Ng, const CapLobe* lobe, float delta,
                             GLOBAL float2* cut, float* I_B) {
  int stack_code[LT_BRDF_MAX_CUT];
  float stack_imp[LT_BRDF_MAX_CUT], stack_s[LT_BRDF_MAX_CUT];
  int n = 0, top = 0;
  float ib = 0.0f;
  *I_B = 0.0f;
  // The root: its own cap decides whether it splits (its importance is irrelevant alone).
  float4 rs = t->root_sphere;
  float3 d3 = xyz_of(rs) - P;
  float dd = dot(d3, d3);
  float root_s;
  if (dd <= rs.w * rs.w) {
    root_s = cap_lobe_integral(lobe, Ng, 0.0f, -1.0f, &root_s);
    stack_code[top] = 0, stack_imp[top] = 1.0f, stack_s[top] = 1.0f;
    top = 1;
  } else {
    float id = 1.0f / sqrt(dd);
    float su = fmin(rs.w * id, 1.0f), cu = fmin(sqrt(fmax(dd - rs.w * rs.w, 0.0f)) * id, 1.0f);
    float mean;
    root_s = cap_lobe_integral(lobe, d3 * id, su, cu, &mean);
    stack_code[0] = 0, stack_imp[0] = 1.0f, stack_s[0] = root_s;
    top = 1;
    if (!(root_s > delta)) { // one cluster: the whole tree
      cut[0] = make_float2(uint_as_float_(0u), 1.0f);
      *I_B = root_s;
      return 1;
    }
  }
  while (top > 0) {
    --top;
    int code = stack_code[top];
    float4 S;
    int4 inside;
    float4 imp = lt_brdf_code_importance(t, code, P, Ng, lobe, &S, &inside);
    int lanes = (imp.x > 0.0f) + (imp.y > 0.0f) + (imp.z > 0.0f) + (imp.w > 0.0f);
    if (n + top + lanes > LT_BRDF_MAX_CUT) { // no room to split: the cluster joins the cut
      cut[n++] = make_float2(uint_as_float_((uint)code), stack_imp[top]);
      ib = fmax(ib, stack_s[top]);
      continue;
    }
    for (int k = 3; k >= 0; --k) { // pushed in reverse: lane 0 is expanded first
      float ik = f4_get(imp, k);
      if (!(ik > 0.0f)) continue;
      int child = lt_lane_code(t, code, k);
      float sk = f4_get(S, k);
      if (lt_code_splittable(child) && (i4_get(inside, k) || sk > delta)) {
        stack_code[top] = child, stack_imp[top] = ik, stack_s[top] = sk;
        ++top;
      } else {
        cut[n++] = make_float2(uint_as_float_((uint)child), ik);
        ib = fmax(ib, sk);
      }
    }
  }
  *I_B = ib;
  return n;
}

// Sums of the cut's importances in groups of 4 (g1[16]) and of 16 (g2), the three levels of the
// pick; computed the same way for sampling and for the pmf.
INLINE void lt_brdf_cut_sums(GLOBAL const float2* cut, int n, float* g1, float4* g2) {
  for (int j = 0; j < 16; ++j) {
    float4 v = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
    if (4 * j < n) v.x = cut[4 * j].y;
    if (4 * j + 1 < n) v.y = cut[4 * j + 1].y;
    if (4 * j + 2 < n) v.z = cut[4 * j + 2].y;
    if (4 * j + 3 < n) v.w = cut[4 * j + 3].y;
    g1[j] = lt_sum4(v);
  }
  *g2 = make_float4(lt_sum4(make_float4(g1[0], g1[1], g1[2], g1[3])),
                    lt_sum4(make_float4(g1[4], g1[5], g1[6], g1[7])),
                    lt_sum4(make_float4(g1[8], g1[9], g1[10], g1[11])),
                    lt_sum4(make_float4(g1[12], g1[13], g1[14], g1[15])));
}
INLINE float4 lt_brdf_cut_quad(GLOBAL const float2* cut, int n, int q) {
  float4 v = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
  if (4 * q < n) v.x = cut[4 * q].y;
  if (4 * q + 1 < n) v.y = cut[4 * q + 1].y;
  if (4 * q + 2 < n) v.z = cut[4 * q + 2].y;
  if (4 * q + 3 < n) v.w = cut[4 * q + 3].y;
  return v;
}

// Probability of entry j of the cut: the product of its three 4-way lane probabilities.
INLINE float lt_brdf_entry_prob(GLOBAL const float2* cut, int n, int j) {
  float g1[16];
  float4 g2;
  lt_brdf_cut_sums(cut, n, g1, &g2);
  int a = j >> 4, b = (j >> 2) & 3;
  return lt_lane_prob(g2, a) *
         lt_lane_prob(make_float4(g1[4 * a], g1[4 * a + 1], g1[4 * a + 2], g1[4 * a + 3]), b) *
         lt_lane_prob(lt_brdf_cut_quad(cut, n, j >> 2), j & 3);
}

// Stochastic descent below `code` by the BRDF-oriented importance (§4.1 "Light cluster sampling":
// sub-clusters are chosen recursively), each choice exact (lt_choose_lane). Returns the light or
// -1; *prob = product of the lane probabilities. Eq. 6 all the way down costs four cap integrals
// per level, but a cut entry can hold thousands of lights around a sharp lobe: descending by
// Conty Estevez & Kulla's importance instead (which ignores the BRDF) was measured 1.5x noisier per
// sample for brdf-mis and 4x for brdf-oriented on the showroom (docs/performance.md).
INLINE int lt_brdf_pick_below(const LtTree* t, int code, float3 P, float3 Ng, const CapLobe* lobe,
                              LtRng* rng, float* prob) {
  float p = 1.0f;
  *prob = 0.0f;
  for (;;) {
    float4 S;
    int4 inside;
    float4 imp = lt_brdf_code_importance(t, code, P, Ng, lobe, &S, &inside);
    int lane = lt_choose_lane(imp, rng);
    if (lane < 0) return -1;
    p = p * lt_lane_prob(imp, lane);
    if (code < 0) {
      *prob = p;
      return t->leaf_lights[lt_leaf_first(code) + lane];
    }
    code = i4_get(t->children[code], lane);
    if (code == LT_EMPTY) return -1;
  }
}

// One BRDF-oriented light pick: an entry of the cut by importance (three exact 4-way choices),
// then a descent below it. Returns the light or -1; *pmf its probability.
INLINE int lt_brdf_pick(const LtTree* t, GLOBAL const float2* cut, int n, float3 P, float3 Ng,
                        const CapLobe* lobe, LtRng* rng, float* pmf) {
  *pmf = 0.0f;
  if (n <= 0) return -1;
  float g1[16];
  float4 g2;
  lt_brdf_cut_sums(cut, n, g1, &g2);
  int a = lt_choose_lane(g2, rng);
  if (a < 0) return -1;
  float4 ga = make_float4(g1[4 * a], g1[4 * a + 1], g1[4 * a + 2], g1[4 * a + 3]);
  int b = lt_choose_lane(ga, rng);
  if (b < 0) return -1;
  float4 q = lt_brdf_cut_quad(cut, n, 4 * a + b);
  int c = lt_choose_lane(q, rng);
  if (c < 0) return -1;
  int j = 16 * a + 4 * b + c;
  float p_entry = lt_lane_prob(g2, a) * lt_lane_prob(ga, b) * lt_lane_prob(q, c);
  float p_below;
  int light = lt_brdf_pick_below(t, (int)float_as_uint_(cut[j].x), P, Ng, lobe, rng, &p_below);
  if (light < 0) return -1;
  *pmf = p_entry * p_below;
  return light;
}

// Probability that lt_brdf_pick_below(code) returns the light whose remaining trail is `trail`.
INLINE float lt_brdf_pmf_below(const LtTree* t, int code, uint trail, float3 P, float3 Ng,
                               const CapLobe* lobe) {
  float p = 1.0f;
  for (;;) {
    float4 S;
    int4 inside;
    float4 imp = lt_brdf_code_importance(t, code, P, Ng, lobe, &S, &inside);
    int lane = (int)(trail & 3u);
    trail = trail >> 2;
    float pk = lt_lane_prob(imp, lane);
    if (!(pk > 0.0f)) return 0.0f;
    p = p * pk;
    if (code < 0) return p;
    code = i4_get(t->children[code], lane);
    if (code == LT_EMPTY) return 0.0f;
  }
}

INLINE int lt_brdf_cut_find(GLOBAL const float2* cut, int n, int code) {
  for (int j = 0; j < n; ++j)
    if ((int)float_as_uint_(cut[j].x) == code) return j;
  return -1;
}

// The entry of P's cut that holds `light`, found by following the light's bit-trail from the root:
// its index (-1: the cut has none), and in *code and *trail the entry's code and the trail below
// it; *descends is 0 when the entry is the emitter itself (a split leaf's), with nothing below.
INLINE int lt_brdf_cut_entry(const LtTree* t, GLOBAL const float2* cut, int n, int light, int* code,
                             uint* trail, int* descends) {
  uint tr = t->trails[light];
  int c = 0;
  *descends = 1;
  for (;;) {
    int j = lt_brdf_cut_find(cut, n, c);
    if (j >= 0 || c == LT_EMPTY) {
      *code = c;
      *trail = tr;
      return j;
    }
    int lane = (int)(tr & 3u);
    tr = tr >> 2;
    if (c < 0) { // a split leaf: the emitter's own entry, if P's cut kept it
      *descends = 0;
      return lt_brdf_cut_find(cut, n, lt_leaf_code(lt_leaf_first(c) + lane, 1));
    }
    c = i4_get(t->children[c], lane);
  }
}

// Probability that lt_brdf_pick produces `light` (the cut is P's): the probability of the cut
// entry that holds it, times the descent's lane probabilities below it.
INLINE float lt_brdf_pmf(const LtTree* t, GLOBAL const float2* cut, int n, float3 P, float3 Ng,
                         const CapLobe* lobe, int light) {
  int code, descends;
  uint trail;
  int j = lt_brdf_cut_entry(t, cut, n, light, &code, &trail, &descends);
  if (j < 0) return 0.0f;
  float p = lt_brdf_entry_prob(cut, n, j);
  return descends ? p * lt_brdf_pmf_below(t, code, trail, P, Ng, lobe) : p;
}

// A cheap stand-in for lt_brdf_pmf in MIS weights, which need only be some function of the
// light (brdf_mis.h): the exact probability of the cut entry that holds the light times the
// probability of Conty Estevez & Kulla's descent below it (pmf.h), where the sampler descends by
// Eq. 6. The entries are chosen by the BRDF, so this follows the lobe at the cut's resolution,
// without the four cap integrals per level of the exact pmf.
INLINE float lt_brdf_pmf_weight(const LtTree* t, GLOBAL const float2* cut, int n, float3 P,
                                float3 Nq, int light) {
  int code, descends;
  uint trail;
  int j = lt_brdf_cut_entry(t, cut, n, light, &code, &trail, &descends);
  if (j < 0) return 0.0f;
  float p = lt_brdf_entry_prob(cut, n, j);
  return descends ? p * lt_pmf_below(t, code, P, Nq, trail) : p;
}

#endif // CANOPY_LIGHT_TREE_BRDF_CUT_H
