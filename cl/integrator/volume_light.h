// Direct light in a homogeneous medium along a ray segment, one picked light at a time (Conty
// Estevez & Kulla 2018, §5.2; equiangular sampling, Kulla & Fajardo 2012). The path's segment is
// the part of this bounce's ray inside the medium (shade_volume.h writes it); light_pick ranks
// light clusters for it with the segment importance (Eq. 7) and splits its cut with the surface
// measure (§5.4), and for every light it picks stages one shadow item, at one of two points of
// the segment: the point chosen by equiangular sampling towards the light, or the free-flight
// point of the segment (the distance sample shade_volume drew). The point is chosen per light
// (one-sample MIS, Veach 1997 §9.2.4: equiangular with probability VOLUME_EQ_SHARE when the
// free-flight point falls on the segment) and the sample is weighted by the power heuristic over
// the two techniques' densities in t times their choice probabilities; the light is then sampled
// from that point. Both points for every light cost two shadow rays per light, and with a split
// cut the free-flight point's rays bought little (docs/performance.md, "Splitting in media").
//
// A path that continues from the segment's free-flight point with a phase-function ray is a third
// technique for the same integral (free-flight t, phase direction), which finds area lights: all
// three are combined with the power heuristic over their densities in (t, direction), per light:
//   equiangular:  pmf * pdf_eq(t) * pdf_light(w)      free flight:  pmf * pdf_ff(t) * pdf_light(w)
//   phase:        pdf_ff(t) * p(w)
// (each light technique's density times its choice probability, volume_technique_probs;
// volume_light_item for the light samples, volume_emission_weight for emitters found by phase
// rays). On a path's last vertex no phase ray leaves, and the light samples use two techniques.
//
// Compiles as OpenCL C and as C++.
#ifndef CANOPY_INTEGRATOR_VOLUME_LIGHT_H
#define CANOPY_INTEGRATOR_VOLUME_LIGHT_H

#include "../lights/light_sample.h"
#include "../shading.h"
#include "../volume/equiangular.h"
#include "../volume/medium.h"
#include "../volume/phase.h"
#include "light_sampler.h"
#include "path_state.h"

// SplitItem.path flag: the item picks lights for the path's medium segment, not its surface point.
#define SPLIT_SEGMENT 0x40000000
// shade_f.w of a path whose last vertex is a scattering event in the medium.
#define VOLUME_POINT_FLAG 4.0f
// Hit.prim of a path that scattered in the medium before reaching its closest hit.
#define HIT_SCATTERED (-2)

#ifndef CANOPY_VOLUME_MIDPOINT
#define CANOPY_VOLUME_MIDPOINT 0 // 1: rank clusters by the surface importance at the midpoint
#endif

// The split-queue root item of a path's medium segment, with the segment's cut budget
// (light_sampler_segment_budget, light_sampler.h).
INLINE SplitItem volume_segment_root(const LightSamplerCtx* ls, int path) {
  SplitItem it = light_sampler_root(ls, path | SPLIT_SEGMENT);
  it.budget = light_sampler_segment_budget(ls->max_cut);
  return it;
}

// The light-pick query of a segment (start o.xyz, length o.w, direction d.xyz): the segment itself
// (Eq. 7), or under the ablation its midpoint as a point without a normal (the surface importance,
// Eq. 3, without cos theta_i, with bounds grown by half the segment so that it stays
// conservative: query.h).
INLINE LtQuery volume_query_of(float4 o, float4 d) {
  if (CANOPY_VOLUME_MIDPOINT) return lt_query_midpoint(xyz_of(o), xyz_of(d), o.w);
  return lt_query_segment(xyz_of(o), xyz_of(d), o.w);
}
INLINE LtQuery volume_query(const PathBuffers* pb, int path) {
  return volume_query_of(pb->seg_o[path], pb->seg_d[path]);
}

// Power heuristic of technique a against b and c (densities >= 0, 0 for a technique that cannot
// make the sample), from ratios to the largest so that it neither overflows nor divides 0 by 0.
INLINE float power_heuristic3(float pa, float pb, float pc) {
  if (!(pa > 0.0f)) return 0.0f;
  float m = fmax(pa, fmax(pb, pc));
  float a = pa / m, b = pb / m, c = pc / m;
  return a * a / (a * a + b * b + c * c);
}

// Probability of choosing the equiangular point for a picked light (when the free-flight point
// falls on the segment; always, when it does not). Equiangular sampling is the better technique
// near the light (exact in t for point lights), the free-flight point where transmittance along
// the segment dominates. An even choice at most doubles a sample's weight; 0.9 was 4% better on
// spiral-fog but up to ten times the weight of a free-flight sample made the estimate heavy-tailed
// where transmittance matters (a light outside a box of medium: tests/test_render_medium.cpp).
#define VOLUME_EQ_SHARE 0.5f

// The two light techniques' choice probabilities on a segment of length len: (equiangular, free
// flight). The free-flight point is on the segment with probability 1 - survival(len) and is then
// taken with probability 1 - VOLUME_EQ_SHARE; otherwise the equiangular point is. The effective
// densities (probability times density in t) give each sample's one-sample MIS weight.
INLINE float2 volume_technique_probs(const Medium* m, float len) {
  float c_ff = 1.0f - VOLUME_EQ_SHARE;
  return make_float2(1.0f - c_ff * (1.0f - medium_survival(m, len)), c_ff);
}

// Where equiangular sampling aims for a light: its position (point, spot; exact) or the centre of
// its shape (area lights, whose point is sampled afterwards from the chosen medium point).
INLINE float3 light_center(GLOBAL const Light* l) {
  if (IS_LIGHT(l, LIGHT_QUAD)) return xyz_of(l->p) + (xyz_of(l->e1) + xyz_of(l->e2)) * 0.5f;
  if (IS_LIGHT(l, LIGHT_TRIANGLE))
    return xyz_of(l->p) + (xyz_of(l->e1) + xyz_of(l->e2)) * (1.0f / 3.0f);
  return xyz_of(l->p);
}

// Transmittance of the scene's medium along [0, tmax] of a ray (1 without a medium).
INLINE float3 volume_transmittance(const SceneBuffers* sc, float3 o, float3 d, float tmax) {
  if (!HAS_MEDIUM) return make_float3(1.0f, 1.0f, 1.0f);
  Medium m = sc->medium[0];
  return medium_transmittance(&m, o, d, tmax);
}

// A light sample whose MIS weight w is below VOLUME_ROULETTE_WEIGHT is traced with probability
// w / VOLUME_ROULETTE_WEIGHT and then carries that weight (Russian roulette: unbiased). Near a
// light the free-flight point's weight is tiny next to equiangular sampling's, and the roulette
// saves most of those shadow rays, which would add little; the weight is dimensionless, so the
// rule does not depend on the scene's units or brightness.
#define VOLUME_ROULETTE_WEIGHT 0.1f

// The shadow item of a light sampled from the segment's point at distance t, chosen with
// effective density p_t (choice probability times density in t) by one technique (p_other: the
// other's there): beta Tr(t) sigma_s p(theta) Li Tr(leg) w / (p_t pmf pdf(wi)), w the power
// heuristic against the other technique and, when
// `phase_mis`, against the phase-function technique (then the roulette above, with u_rr).
// Returns 1 if an item was written.
INLINE int volume_light_item(const Medium* m, const LightSamplerCtx* ls, int path, float3 a,
                             float3 d, float t, float p_t, float p_other, int phase_mis,
                             float3 beta, int light, float pmf, float u1, float u2, float u_rr,
                             GLOBAL ShadowItem* out) {
  float3 x = a + d * t;
  LightSample s = sample_light(&ls->lights[light], x, u1, u2);
  if (!(s.pdf > 0.0f) || !(max3(s.Li) > 0.0f)) return 0;
  float3 to = s.x - x;
  float dist = length(to);
  if (!(dist > 0.0f)) return 0;
  float3 dir = to / dist;
  float tmax = fmax(dist - fp_gamma(6) * (max_abs3(s.x) + dist), 0.0f);
  float3 tr = medium_tr(m, t) * medium_transmittance(m, x, dir, tmax);
  float phase = phase_hg(m->sigma_t.w, dot(s.wi, d));
  // The phase technique's density in the same units (divided by pmf pdf(wi)); it never finds a
  // point or spot light.
  float p_phase =
      phase_mis && !s.is_delta ? medium_distance_pdf(m, t) * (phase / (pmf * s.pdf)) : 0.0f;
  float w = power_heuristic3(p_t, p_other, p_phase);
  if (w < VOLUME_ROULETTE_WEIGHT) {
    if (u_rr * VOLUME_ROULETTE_WEIGHT >= w) return 0;
    w = VOLUME_ROULETTE_WEIGHT;
  }
  float3 c = beta * tr * xyz_of(m->sigma_s) * s.Li * (phase * (w / p_t) / (pmf * s.pdf));
  // Non-finite contributions are kept (accumulate counts them), zero ones dropped.
  if (is_finite_f(c.x + c.y + c.z) && !(max3(c) > 0.0f)) return 0;
  ShadowItem item;
  item.origin = f4_from3(x, tmax);
  item.dir = f4_from3(dir, uint_as_float_((uint)path));
  item.contribution = f4_from3(c, 0.0f);
  *out = item;
  return 1;
}

// The shadow item (at most one) of `light`, picked with probability pmf for the segment of `path`.
INLINE int volume_shadow_items(const LightSamplerCtx* ls, const SceneBuffers* sc,
                               const PathBuffers* pb, int path, int light, float pmf, LtRng* rng,
                               GLOBAL ShadowItem* out) {
  float u_pick = lt_rng_next(rng), u0 = lt_rng_next(rng);
  float u1 = lt_rng_next(rng), u2 = lt_rng_next(rng), u_rr = lt_rng_next(rng);
  if (!(pmf > 0.0f)) return 0;
  Medium m = sc->medium[0];
  float4 so = pb->seg_o[path];
  float4 sd = pb->seg_d[path];
  float3 beta = xyz_of(pb->seg_beta[path]);
  float3 a = xyz_of(so), d = xyz_of(sd);
  float len = so.w, t_free = sd.w;
  int phase_mis = pb->seg_phase[path] > 0.0f;
  float3 c = light_center(&ls->lights[light]);
  float2 pc = volume_technique_probs(&m, len);
  if (t_free < len && u_pick >= VOLUME_EQ_SHARE) {
    // The free-flight point.
    float p_ff = medium_distance_pdf(&m, t_free);
    if (!(p_ff > 0.0f)) return 0;
    return volume_light_item(&m, ls, path, a, d, t_free, pc.y * p_ff,
                             pc.x * equiangular_pdf(a, d, len, c, t_free), phase_mis, beta, light,
                             pmf, u1, u2, u_rr, out);
  }
  // Equiangular sampling towards the light (exact for point lights: pdf ~ 1 / |x(t) - c|^2).
  float p_eq = 0.0f;
  float t_eq = equiangular_sample(a, d, len, c, u0, &p_eq);
  if (!(p_eq > 0.0f)) return 0;
  return volume_light_item(&m, ls, path, a, d, t_eq, pc.x * p_eq,
                           pc.y * medium_distance_pdf(&m, t_eq), phase_mis, beta, light, pmf, u1,
                           u2, u_rr, out);
}

// MIS weight of the emission that a phase-function ray from the path's last medium vertex (at
// distance t along its segment, shade_P.xyz, phase density shade_P.w) finds at point y of `light`:
// the phase technique against the segment's two light-sampling techniques for that light (their
// densities times their choice probabilities, as in volume_shadow_items).
INLINE float volume_emission_weight(const LightSamplerCtx* ls, const SceneBuffers* sc,
                                    const PathBuffers* pb, int path, int light, float3 y) {
  Medium m = sc->medium[0];
  float4 so = pb->scatter_seg_o[path];
  float4 sd = pb->scatter_seg_d[path];
  float4 x = pb->shade_P[path];
  float t = sd.w;
  LtQuery q = volume_query_of(so, sd);
  float p_ff = medium_distance_pdf(&m, t);
  float p_light = light_sampler_pmf_q(ls, &q, light) * light_pdf(&ls->lights[light], xyz_of(x), y);
  float3 c = light_center(&ls->lights[light]);
  float p_eq = equiangular_pdf(xyz_of(so), xyz_of(sd), so.w, c, t);
  float2 pc = volume_technique_probs(&m, so.w);
  return power_heuristic3(p_ff * x.w, pc.x * p_eq * p_light, pc.y * p_ff * p_light);
}

#endif // CANOPY_INTEGRATOR_VOLUME_LIGHT_H
