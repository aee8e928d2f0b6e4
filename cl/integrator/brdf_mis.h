// Stages of BRDF-oriented many-light sampling (Liu, Xu & Yan 2019) at glossy shading points, for
// the brdf-mis and brdf-oriented samplers. Per glossy point:
// - brdf_cut_item (§4.1): the point's light cut by the BRDF cap integral S_C, stored with the
//   cluster importances, and the number N of BRDF-aware samples: N = ceil(N_max I_B), I_B = max
//   S_C over the cut (§5, Eq. 8-9), in [1, N_max]; 2 with equal allocation; 1 for brdf-oriented.
// - tree light sampling with splitting (light_pick.h) runs as for any point, its samples weighted
//   by brdf_weight_tree (brdf-mis only).
// - rounds of brdf_sample_item / brdf_trace_item / brdf_accumulate_item draw the N samples (§5,
//   Alg. 1): each is BRDF-oriented light sampling with probability p = n_nohit / (n_nohit + lambda
//   n_hit) and BSDF sampling otherwise, n_hit / n_nohit counting this point's BSDF samples that
//   found / missed an emitter. Alg. 1 updates p after every sample; on the wavefront round r draws
//   a batch of brdf_round_batch(r) samples (1, 1, 2, 4, ...) with the p of the round's start, so
//   N = 50 takes 7 rounds of kernels instead of 50.
//
// Unbiasedness with adaptive counts (DESIGN "MIS with splitting", extended): the tree estimate
// (one sample, density p_L) gets the power-heuristic weight w_L = p_L^2 / (p_L^2 + (N q)^2) with
// a density q = s p_B' + (1 - s) p_S fixed before any BRDF-aware sample is drawn, and each
// BRDF-aware sample i the weight (1 - w_L) / N divided by its own density q_i = p_i p_B +
// (1 - p_i) p_S, where p_i is known before the sample is drawn. w_L + (1 - w_L) = 1 for every light
// point, and each BRDF-aware sample is unbiased for (1 - w_L) f / N given the samples before it,
// so the sum is unbiased however p_i adapts. (Weights computed from the realised counts, as a
// plain reading of the paper suggests, would depend on the samples they weight and bias the
// estimate.) The share s is the mean of p_i over the N samples if no BSDF sample finds an emitter
// (brdf_expected_share), the case BRDF-oriented sampling is for. w_L only has to be a function of
// the light point, so p_B' is a cheap stand-in for the BRDF-oriented density p_B
// (lt_brdf_pmf_weight: exact to the cut entry, the tree's descent below it): the exact one costs
// four cap integrals per level of the light's trail, for every tree sample at a glossy point
// (docs/performance.md, "BRDF-oriented sampling at tree cost"). Only q_i, a sample's own density,
// needs the exact p_B. Equal allocation (adaptive = false) draws one sample of each technique
// (s = p_i = 1/2, stratified: sample 0 light, sample 1 BSDF; q_i = q), which makes the weights
// the power heuristic over the three techniques with counts 1, 1, 1 up to the grouping of the
// BRDF-aware two and p_B'. brdf-oriented alone: p_i = 1, no tree estimate (w_L = 0).
//
// The BSDF samples replace the path's own bounce for direct lighting: emission found by the
// continuation ray from a glossy point is not counted (shade_surface.h), as the point's direct
// light is complete without it.
#ifndef CANOPY_INTEGRATOR_BRDF_MIS_H
#define CANOPY_INTEGRATOR_BRDF_MIS_H

#include "../bsdf/bsdf.h"
#include "../bsdf/cap_integral.h"
#include "../geometry.h"
#include "../light_tree/brdf_cut.h"
#include "../light_tree/pmf.h"
#include "../lights/light_sample.h"
#include "../shading.h"
#include "light_point.h"
#include "light_sampler.h"
#include "path_state.h"

// Largest batch of a round: the per-point staging of a round holds this many items.
#define BRDF_MAX_BATCH 32
// shade_f.w of a glossy point under a BRDF sampler (0 and 1: see path_state.h).
#define BRDF_POINT_FLAG 2.0f

// Samples drawn in round r: 1, 1, 2, 4, ..., BRDF_MAX_BATCH.
INLINE int brdf_round_batch(int round) {
  return round == 0 ? 1 : 1 << (round - 1 < 5 ? round - 1 : 5);
}
// Rounds needed to draw n samples.
INLINE int brdf_rounds_for(int n) {
  int r = 0, drawn = 0;
  while (drawn < n)
    drawn += brdf_round_batch(r++);
  return r;
}

// A material with a glossy (GGX, alpha > 0) lobe: where BRDF-oriented sampling applies. A plastic
// without specular is diffuse. A coated material is glossy with a rough coat (over either base):
// a smooth coat's mirror reflection is a delta lobe, which these estimators do not sample.
INLINE int brdf_material_glossy(const Material* m) {
  if (!(m->alpha > 0.0f)) return 0;
  if (IS_MATERIAL(m, MATERIAL_COATED_DIFFUSE) || IS_MATERIAL(m, MATERIAL_COATED_CONDUCTOR))
    return 1;
  if (IS_MATERIAL(m, MATERIAL_CONDUCTOR)) return 1;
  if (IS_MATERIAL(m, MATERIAL_PLASTIC)) return max3(xyz_of(m->specular)) > 0.0f;
  return 0;
}

// The point's material, shading frame, wo (world and local) and cap lobe (cap_integral.h).
typedef struct BrdfPoint {
  float3 P, N; // shading point (ray origin) and geometric normal facing wo
  float3 Nq;   // the normal of its light-tree queries (light_query_normal: the shading normal)
  Material m;
  Frame fr;
  float3 wo, wo_local;
  CapLobe lobe;
  GLOBAL float2* cut; // the point's cut entries
  int4 state;         // brdf_state: cut size, N, samples drawn, n_hit | n_nohit << 16
} BrdfPoint;

INLINE BrdfPoint brdf_point(const LightSamplerCtx* ls, const SceneBuffers* sc,
                            const PathBuffers* pb, int path) {
  BrdfPoint bp;
  bp.P = xyz_of(pb->shade_P[path]);
  bp.N = xyz_of(pb->shade_N[path]);
  bp.Nq = light_query_normal(pb, path);
  bp.m = shading_point_material(sc, pb, path);
  bp.fr = frame_from(xyz_of(pb->shade_Ns[path]));
  bp.wo = xyz_of(pb->shade_wo[path]);
  bp.wo_local = frame_to_local(&bp.fr, bp.wo);
  bp.lobe = cap_lobe_make(&bp.m, &bp.fr, bp.wo);
  bp.cut = ls->brdf_cut + (size_t)path * LT_BRDF_MAX_CUT;
  bp.state = pb->brdf_state[path];
  return bp;
}

// Probability that BRDF-oriented light sampling picks `light` at the point.
INLINE float brdf_light_pmf(const LightSamplerCtx* ls, const BrdfPoint* bp, int light) {
  return lt_brdf_pmf(&ls->tree, bp->cut, bp->state.x, bp->P, bp->Nq, &bp->lobe, light);
}

// The stand-in p_B' of the MIS weights for `light` at the path's glossy point (see the top): its
// cut and its query, without the material and cap lobe of a BrdfPoint.
INLINE float brdf_light_pmf_weight(const LightSamplerCtx* ls, const PathBuffers* pb, int path,
                                   int light) {
  return lt_brdf_pmf_weight(&ls->tree, ls->brdf_cut + (size_t)path * LT_BRDF_MAX_CUT,
                            pb->brdf_state[path].x, xyz_of(pb->shade_P[path]),
                            light_query_normal(pb, path), light);
}

// Whether the tree estimate of a light at the point is exact: a delta light (point, spot) that the
// tree-split cut takes with probability pmf_split = 1 (an emitter of a split leaf, or alone below
// its cluster). Nothing is sampled for it: its Li is exact and the pick is certain.
INLINE int brdf_tree_exact(float pmf_split, int is_delta) {
  return is_delta && pmf_split >= 1.0f;
}

// Weight of the tree light sample (density p_L) against N BRDF-aware samples drawn with share s
// of BRDF-oriented light sampling; p_B' = brdf_light_pmf_weight times the light's density (see
// the top). Where the tree estimate is exact (brdf_tree_exact) it keeps the whole weight: the
// power heuristic compares densities, p_L = 1 against N s p_B', and would hand up to all of the
// light to the BRDF-aware samples, whose estimate of it is noisy (their number of light samples is
// random: each is BRDF-oriented with probability p_i, its contribution scaled by 1 / p_i; under a
// single point light a tree-split estimate without variance became one with it). w_L = 1 is a
// function of the light and the point alone, so the weights still sum to 1 for every light point
// and the estimator stays unbiased (the BRDF-oriented samples of such a light weigh 0).
INLINE float brdf_weight_tree(const LightSamplerCtx* ls, float p_L, float p_Bw, float p_S, int N,
                              float s, int tree_exact) {
  if (ls->kind == SAMPLER_BRDF_ORIENTED) return 0.0f;
  if (tree_exact) return 1.0f;
  return power_heuristic(p_L, (float)N * (s * p_Bw + (1.0f - s) * p_S));
}

// Mean of Alg. 1's p over N samples when every BSDF sample misses, in the fluid limit: after
// sample i the expected misses grow by 1 - p_i (Eq. 7 with n_hit = 1).
INLINE float brdf_expected_share(const LightSamplerCtx* ls, int N) {
  if (ls->kind == SAMPLER_BRDF_ORIENTED) return 1.0f;
  if (!ls->brdf_adaptive) return 0.5f;
  float misses = 1.0f, sum = 0.0f;
  for (int i = 0; i < N; ++i) {
    float p = misses / (misses + ls->brdf_lambda);
    sum += p;
    misses += 1.0f - p;
  }
  return N > 0 ? sum / (float)N : 1.0f;
}

// Probability of choosing BRDF-oriented light sampling for the next samples (Eq. 7), or 1/2 for
// equal allocation, 1 for brdf-oriented.
INLINE float brdf_light_share(const LightSamplerCtx* ls, int4 state) {
  if (ls->kind == SAMPLER_BRDF_ORIENTED) return 1.0f;
  if (!ls->brdf_adaptive) return 0.5f;
  float n_hit = (float)(state.w & 0xffff), n_nohit = (float)((uint)state.w >> 16);
  return n_nohit / (n_nohit + ls->brdf_lambda * n_hit);
}

// Stage brdf_cut, one shading point (pb->brdf_state.y == -1 marks a glossy point of this bounce;
// shade_surface.h). Builds the cut and sets brdf_state. Returns (cut size, N), (0, 0) elsewhere.
INLINE int2 brdf_cut_item(int path, const LightSamplerCtx* ls, const SceneBuffers* sc,
                          const PathBuffers* pb) {
  if (pb->brdf_state[path].y != -1) return make_int2(0, 0);
  BrdfPoint bp = brdf_point(ls, sc, pb, path);
  float I_B;
  int n = lt_brdf_cut_build(&ls->tree, bp.P, bp.Nq, &bp.lobe, ls->brdf_delta, bp.cut, &I_B);
  int N;
  if (ls->kind == SAMPLER_BRDF_ORIENTED)
    N = 1;
  else if (!ls->brdf_adaptive)
    N = 2;
  else // Eq. 9, at least 1: a cut of point lights has I_B = 0 (caps without solid angle)
    N = (int)fmax(fmin(ceil((float)ls->brdf_nmax * I_B), (float)ls->brdf_nmax), 1.0f);
  if (n == 0) N = 0;                                        // no light can reach the point
  pb->brdf_state[path] = make_int4(n, N, 0, 1 | (1 << 16)); // n_hit = n_nohit = 1 (Alg. 1)
  pb->brdf_share[path] = brdf_expected_share(ls, N);
  return make_int2(n, N);
}

// Stage brdf_sample, one shading point in round `round`: draws the round's batch of BRDF-aware
// samples into out[0..BRDF_MAX_BATCH) and returns how many items it wrote. Each sample has its
// own random stream (the point's seed, stream 0x60000000 + sample index): results do not depend on
// the batching or the order of work items.
INLINE int brdf_sample_item(int path, int round, const LightSamplerCtx* ls, const SceneBuffers* sc,
                            const PathBuffers* pb, GLOBAL BrdfItem* out) {
  int4 st = pb->brdf_state[path];
  if (st.y <= 0 || st.z >= st.y) return 0;
  int b = min(st.y - st.z, brdf_round_batch(round));
  BrdfPoint bp = brdf_point(ls, sc, pb, path);
  uint seed = float_as_uint_(pb->shade_N[path].w);
  float3 beta = xyz_of(pb->shade_f[path]);
  float p_i = brdf_light_share(ls, st);
  float inv_n = 1.0f / (float)st.y;
  int written = 0;
  for (int j = 0; j < b; ++j) {
    int idx = st.z + j;
    LtRng rng = lt_rng_make(seed, 0x60000000u + (uint)idx);
    int use_light;
    if (ls->kind == SAMPLER_BRDF_ORIENTED)
      use_light = 1;
    else if (!ls->brdf_adaptive)
      use_light = idx == 0; // equal allocation: one sample of each technique
    else
      use_light = lt_u_below(lt_rng_next_u32(&rng), p_i, &rng);
    BrdfItem it;
    if (use_light) {
      float pmf;
      int light = lt_brdf_pick(&ls->tree, bp.cut, bp.state.x, bp.P, bp.Nq, &bp.lobe, &rng, &pmf);
      if (light < 0) continue;
      float u1 = lt_rng_next(&rng), u2 = lt_rng_next(&rng);
      LightPoint lp;
      if (!light_point_sample(ls, sc, pb, path, light, u1, u2, &lp)) continue;
      float p_B = pmf * lp.s.pdf;
      float pmf_L = 0.0f;
      if (ls->kind != SAMPLER_BRDF_ORIENTED)
        pmf_L = lt_pmf_split(&ls->tree, bp.P, bp.Nq, light, ls->threshold, ls->max_cut);
      float p_L = pmf_L * lp.s.pdf;
      float q = p_i * p_B + (1.0f - p_i) * lp.bsdf_pdf;
      float p_Bw = 0.0f;
      if (ls->kind != SAMPLER_BRDF_ORIENTED)
        p_Bw = brdf_light_pmf_weight(ls, pb, path, light) * lp.s.pdf;
      float w = 1.0f - brdf_weight_tree(ls, p_L, p_Bw, lp.bsdf_pdf, st.y, pb->brdf_share[path],
                                        brdf_tree_exact(pmf_L, lp.s.is_delta));
      float3 c = beta * lp.f_cos * lp.s.Li * (w * inv_n / q);
      if (is_finite_f(c.x + c.y + c.z) && !(max3(c) > 0.0f)) continue;
      it.origin = lp.origin;
      it.dir = lp.dir;
      it.value = f4_from3(c, 0.0f);
      it.extra = make_float4(lp.bsdf_pdf, p_i, (float)BRDF_ITEM_LIGHT, 0.0f);
    } else {
      // One declarator each: the order of a call's arguments is unspecified (host and device
      // compilers differ), that of declarators is not.
      float u1 = lt_rng_next(&rng), u2 = lt_rng_next(&rng), u3 = lt_rng_next(&rng);
      float3 u = make_float3(u1, u2, u3);
      BsdfSample bs = bsdf_sample(&bp.m, bp.wo_local, u);
      float3 wi = normalize(frame_to_world(&bp.fr, bs.wi));
      // Absorbed, delta or into the geometric surface: a probe that finds nothing (a miss for
      // Alg. 1's counts, traced no further).
      int alive = !bs.is_delta && bs.pdf > 0.0f && max3(bs.weight) > 0.0f && dot(wi, bp.N) > 0.0f;
      it.origin = f4_from3(bp.P, alive ? FLT_INF : 0.0f);
      it.dir = f4_from3(wi, uint_as_float_((uint)path));
      // f cos = weight pdf
      it.value = f4_from3(
          alive ? beta * bs.weight * (bs.pdf * inv_n) : make_float3(0.0f, 0.0f, 0.0f), 0.0f);
      it.extra = make_float4(alive ? bs.pdf : 0.0f, p_i, (float)BRDF_ITEM_BSDF, 0.0f);
    }
    out[written++] = it;
  }
  pb->brdf_state[path] = make_int4(st.x, st.y, st.z + b, st.w);
  return written;
}

// Stage brdf_trace, one item: a light sample's shadow ray (zeroed if occluded), or a BSDF probe's
// closest hit: if it is an emitter seen from its emitting side, the probe's contribution is
// Le f cos (1 - w_L) / (N q) with the densities of the three techniques at the hit.
INLINE void brdf_trace_item(GLOBAL BrdfItem* item, const LightSamplerCtx* ls,
                            const SceneBuffers* sc, const PathBuffers* pb) {
  BrdfItem it = *item;
  float3 o = xyz_of(it.origin), d = xyz_of(it.dir);
  Hit h;
  if (it.extra.z == (float)BRDF_ITEM_LIGHT) {
    if (bvh_intersect(sc->nodes, sc->leaf_blocks, sc->prims, o, d, 0.0f, it.origin.w, 1, &h) >= 0)
      item->value = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
    return;
  }
  float4 zero = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
  if (!(it.origin.w > 0.0f) ||
      bvh_intersect(sc->nodes, sc->leaf_blocks, sc->prims, o, d, 0.0f, FLT_INF, 0, &h) < 0 ||
      sc->prims[h.prim].light < 0) {
    item->value = zero;
    return;
  }
  GLOBAL const Primitive* prim = &sc->prims[h.prim];
  int light = prim->light;
  float3 err;
  float3 y = primitive_hit_point(prim, o, d, h, &err);
  float3 Le = light_emitted_radiance(&ls->lights[light], primitive_normal(prim, y), -d);
  int path = (int)float_as_uint_(it.dir.w);
  if (HAS_MEDIUM && pb->shade_wo[path].w == 0.0f) // attenuated on its way (light_point.h)
    Le = Le * volume_transmittance(sc, o, d, h.t);
  if (!(max3(Le) > 0.0f)) {
    item->value = zero;
    return;
  }
  BrdfPoint bp = brdf_point(ls, sc, pb, path);
  float pdf_y = light_pdf(&ls->lights[light], bp.P, y);
  float p_B = brdf_light_pmf(ls, &bp, light) * pdf_y;
  float p_L = 0.0f, p_Bw = 0.0f;
  if (ls->kind != SAMPLER_BRDF_ORIENTED) {
    p_L = lt_pmf_split(&ls->tree, bp.P, bp.Nq, light, ls->threshold, ls->max_cut) * pdf_y;
    p_Bw = brdf_light_pmf_weight(ls, pb, path, light) * pdf_y;
  }
  float p_S = it.extra.x, p_i = it.extra.y;
  float q = p_i * p_B + (1.0f - p_i) * p_S;
  // (a probe finds area lights only: never an exact tree estimate)
  float w = 1.0f - brdf_weight_tree(ls, p_L, p_Bw, p_S, bp.state.y, pb->brdf_share[path], 0);
  item->value = f4_from3(xyz_of(it.value) * Le * (w / q), 0.0f);
  item->extra.w = 1.0f;
}

// Stage brdf_accumulate: the first item of each path's run (the queue keeps a path's items
// together) adds the run's contributions to the path's radiance and the run's BSDF probes to the
// point's n_hit / n_nohit (Alg. 1). Returns the run length (0 for the other items).
INLINE int brdf_accumulate_item(int i, GLOBAL const BrdfItem* items, int count,
                                const PathBuffers* pb) {
  int path = (int)float_as_uint_(items[i].dir.w);
  if (i > 0 && (int)float_as_uint_(items[i - 1].dir.w) == path) return 0;
  float3 sum = make_float3(0.0f, 0.0f, 0.0f);
  int hits = 0, misses = 0, j = i;
  for (; j < count && (int)float_as_uint_(items[j].dir.w) == path; ++j) {
    BrdfItem it = items[j];
    sum += xyz_of(it.value);
    if (it.extra.z == (float)BRDF_ITEM_BSDF) {
      if (it.extra.w > 0.0f)
        ++hits;
      else
        ++misses;
    }
  }
  float4 L = pb->radiance[path];
  pb->radiance[path] = f4_from3(xyz_of(L) + sum, L.w);
  int4 st = pb->brdf_state[path];
  int n_hit = min((st.w & 0xffff) + hits, 0xffff);
  int n_nohit = min((int)((uint)st.w >> 16) + misses, 0x7fff);
  pb->brdf_state[path] = make_int4(st.x, st.y, st.z, n_hit | (n_nohit << 16));
  return j - i;
}

#endif // CANOPY_INTEGRATOR_BRDF_MIS_H
