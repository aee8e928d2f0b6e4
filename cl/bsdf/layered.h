// Coated materials: pbrt-v4's LayeredBxDF (§14.3) as its coateddiffuse and coatedconductor. A
// dielectric coat (index m->ior, GGX alpha m->alpha, smooth at 0: dielectric_interface.h) lies
// over a base, Lambertian (m->albedo) or a conductor of index (m->specular + i m->k) / m->ior and
// GGX alpha m->base_alpha; between them an optional homogeneous slab of thickness m->thickness,
// extinction 1 and scattering albedo m->medium.xyz with a Henyey-Greenstein phase function
// (g = m->medium.w). Light finds its way out through a random walk between the interfaces, so
//   layered_eval    is pbrt-v4's stochastic estimate of f (m->n_samples walks of at most
//                   m->max_depth bounces, with next-event estimation through the coat),
//   layered_pdf     its estimate of the pdf (the walk's first inner bounce), mixed with the
//                   uniform pdf 1 / 4 pi: 0.1 of it, so it is never 0 where f may not be,
//   layered_sample  a walk that leaves through the coat; its weight is the walk's throughput
//                   and its pdf layered_pdf (pbrt-v4's pdfIsProportional samples).
// Each is driven by a small counter-based generator seeded from a hash of its inputs (wo and wi,
// or wo and u, as pbrt-v4 seeds its RNG), so eval and pdf are pure functions of (wo, wi): light
// samples and BSDF samples of the same direction agree on them, which MIS relies on.
// Opaque, and seen from the top only (the local frame faces wo): wi.z <= 0 gives 0.
#ifndef CANOPY_CL_BSDF_LAYERED_H
#define CANOPY_CL_BSDF_LAYERED_H

#include "../compat.h"
#include "../kernel_features.h"
#include "../types.h"
#include "bsdf_sample.h"
#include "layered_interfaces.h"

#if HAS_MATERIAL_COATED

// f(wo, wi): pbrt-v4's LayeredBxDF::f for light entering and leaving through the coat. Each walk
// enters along a refracted wo, bounces between base and coat (reflection only at the coat) and
// scatters in the slab; at every vertex it adds next-event estimates towards a refracted wi drawn
// once per walk (`wis`, importance transport: the adjoint direction), MIS-weighted against the
// walk's own continuation where both techniques can reach wi. The MIS weights compare the two
// techniques' densities of the same inner direction: for the continuation, the density with which
// `wis` would have drawn it, top_pdf(wi, -w) (pbrt-v4 takes top_pdf(-w, wi), the density of the
// opposite event: its weights then do not sum to 1, and under a rough coat its f disagrees with
// what its Sample_f reflects).
INLINE float3 layered_eval(const Material* m, float3 wo, float3 wi) {
  float3 f = make_float3(0.0f, 0.0f, 0.0f);
  if (!(wo.z > 0.0f) || !(wi.z > 0.0f)) return f;
  const float thick = layered_thickness(m);
  const int n = max(m->n_samples, 1);
  const int top_delta = dielectric_is_smooth(m->ior, m->alpha);
  const int base_delta = layered_base_is_delta(m);
  const int medium = layered_has_medium(m);
  const float3 albedo = xyz_of(m->medium);
  const float g = m->medium.w;
  f = make_float3(1.0f, 1.0f, 1.0f) * (layered_top_eval(m, wo, wi) * (float)n);
  LtRng r = layered_rng(wo, wi);
  for (int s = 0; s < n; ++s) {
    BsdfSample wos = layered_top_sample(m, wo, &r, DIELECTRIC_TRANSMIT, 1);
    if (!layered_valid(wos)) continue;
    BsdfSample wis = layered_top_sample(m, wi, &r, DIELECTRIC_TRANSMIT, 0);
    if (!layered_valid(wis)) continue;
    // f / pdf of the exit (its weight without the cosine)
    float3 wis_fp = wis.weight * (1.0f / fabs(wis.wi.z));
    float3 beta = wos.weight;
    float z = thick; // the walk starts just below the coat (z = thickness), base at z = 0
    float3 w = wos.wi;
    for (int depth = 0; depth < m->max_depth; ++depth) {
      if (depth > 3 && max3(beta) < 0.25f) { // Russian roulette
        float q = fmax(0.0f, 1.0f - max3(beta));
        if (layered_u(&r) < q) break;
        beta = beta * (1.0f / (1.0f - q));
      }
      if (!medium) {
        z = z == thick ? 0.0f : thick;
        beta = beta * layered_tr(thick, w);
      } else {
        float dz = -log(1.0f - layered_u(&r)) * fabs(w.z); // extinction 1
        float zp = w.z > 0.0f ? z + dz : z - dz;
        if (zp == z) continue;
        if (0.0f < zp && zp < thick) { // scattering in the slab
          float3 exit_dir = -wis.wi;
          float p_exit = phase_hg(g, dot(w, exit_dir));
          float wt = top_delta ? 1.0f : layered_power(wis.pdf, p_exit);
          f += beta * albedo * wis_fp * (p_exit * wt * layered_tr(zp - thick, wis.wi));
          float ps_pdf;
          float u1 = layered_u(&r), u2 = layered_u(&r);
          float3 wn = phase_hg_sample(g, w, u1, u2, &ps_pdf);
          if (!(ps_pdf > 0.0f) || wn.z == 0.0f) continue;
          beta = beta * albedo; // p / pdf = 1: the phase function is sampled exactly
          w = wn;
          z = zp;
          if (w.z > 0.0f && !top_delta) { // the new direction may leave through a rough coat
            float f_exit = layered_top_eval(m, -w, wi);
            if (f_exit > 0.0f) {
              float exit_pdf = layered_top_pdf(m, wi, -w, DIELECTRIC_TRANSMIT);
              f += beta * (layered_tr(zp - thick, w) * f_exit * layered_power(ps_pdf, exit_pdf));
            }
          }
          continue;
        }
        z = clamp(zp, 0.0f, thick);
      }
      if (z == thick) { // at the coat, from below: internal reflection
        BsdfSample bs = layered_top_sample(m, -w, &r, DIELECTRIC_REFLECT, 1);
        if (!layered_valid(bs)) break;
        beta = beta * bs.weight;
        w = bs.wi;
        continue;
      }
      // At the base: next-event estimate through the coat along wis, then the base's bounce.
      if (!base_delta) {
        float wt = 1.0f;
        if (!top_delta) wt = layered_power(wis.pdf, layered_base_pdf(m, -w, -wis.wi));
        f += beta * layered_base_eval(m, -w, -wis.wi) * wis_fp *
             (fabs(wis.wi.z) * wt * layered_tr(thick, wis.wi));
      }
      float u1 = layered_u(&r), u2 = layered_u(&r);
      BsdfSample bs = layered_base_sample(m, -w, u1, u2);
      if (!layered_valid(bs)) break;
      beta = beta * bs.weight;
      w = bs.wi;
      if (!top_delta) {
        float f_exit = layered_top_eval(m, -w, wi);
        if (f_exit > 0.0f) {
          float wt = 1.0f;
          if (!base_delta)
            wt = layered_power(bs.pdf, layered_top_pdf(m, wi, -w, DIELECTRIC_TRANSMIT));
          f += beta * (layered_tr(thick, bs.wi) * f_exit * wt);
        }
      }
    }
  }
  return f * (1.0f / (float)n);
}

// pbrt-v4's LayeredBxDF::PDF: the coat's reflection plus, per sample, the pdf of one bounce off
// the base between the refracted wo and wi (MIS-combined for a rough coat over a rough base);
// 0.9 of it mixed with the uniform 1 / 4 pi. 0 for a material without a smooth lobe.
INLINE float layered_pdf(const Material* m, float3 wo, float3 wi) {
  if (!(wo.z > 0.0f) || !(wi.z > 0.0f) || !layered_has_smooth_lobe(m)) return 0.0f;
  const int n = max(m->n_samples, 1);
  const int top_delta = dielectric_is_smooth(m->ior, m->alpha);
  float sum = (float)n * layered_top_pdf(m, wo, wi, DIELECTRIC_REFLECT);
  LtRng r = layered_rng(wi, wo);
  for (int s = 0; s < n; ++s) {
    BsdfSample wos = layered_top_sample(m, wo, &r, DIELECTRIC_TRANSMIT, 1);
    BsdfSample wis = layered_top_sample(m, wi, &r, DIELECTRIC_TRANSMIT, 0);
    if (!layered_valid(wos) || !layered_valid(wis)) continue;
    if (top_delta) {
      sum += layered_base_pdf(m, -wos.wi, -wis.wi);
      continue;
    }
    float u1 = layered_u(&r), u2 = layered_u(&r);
    BsdfSample rs = layered_base_sample(m, -wos.wi, u1, u2);
    if (!layered_valid(rs)) continue;
    if (rs.is_delta) {
      sum += layered_top_pdf(m, -rs.wi, wi, DIELECTRIC_ALL);
      continue;
    }
    float r_pdf = layered_base_pdf(m, -wos.wi, -wis.wi);
    sum += layered_power(wis.pdf, r_pdf) * r_pdf;
    float t_pdf = layered_top_pdf(m, -rs.wi, wi, DIELECTRIC_ALL);
    sum += layered_power(rs.pdf, t_pdf) * t_pdf;
  }
  return 0.1f * (0.25f * CANOPY_INV_PI) + 0.9f * (sum / (float)n);
}

// pbrt-v4's LayeredBxDF::Sample_f: the coat's sample from u; a refracted direction continues as
// a walk (driven by a generator seeded from wo and u) until it leaves through the coat. A path
// of delta bounces only is a delta sample; any other has pdf layered_pdf(wo, wi).
INLINE BsdfSample layered_sample(const Material* m, float3 wo, float3 u) {
  if (!(wo.z > 0.0f)) return bsdf_sample_absorbed(reflect_z(wo));
  BsdfSample bs =
      dielectric_interface_sample(wo, m->ior, m->alpha, u.z, u.x, u.y, DIELECTRIC_ALL, 1);
  if (!layered_valid(bs)) return bsdf_sample_absorbed(bs.wi);
  if (bs.wi.z > 0.0f) { // reflected by the coat
    if (!bs.is_delta) bs.pdf = layered_pdf(m, wo, bs.wi);
    return bs;
  }
  const float thick = layered_thickness(m);
  const int medium = layered_has_medium(m);
  const float3 albedo = xyz_of(m->medium);
  float3 w = bs.wi;
  float3 beta = bs.weight;
  int specular = bs.is_delta;
  float z = thick;
  LtRng r = layered_rng(wo, u);
  for (int depth = 0; depth < m->max_depth; ++depth) {
    if (depth > 3 && max3(beta) < 0.25f) { // Russian roulette
      float q = fmax(0.0f, 1.0f - max3(beta));
      if (layered_u(&r) < q) break;
      beta = beta * (1.0f / (1.0f - q));
    }
    if (w.z == 0.0f) break;
    if (medium) {
      float dz = -log(1.0f - layered_u(&r)) * fabs(w.z);
      float zp = w.z > 0.0f ? z + dz : z - dz;
      if (zp == z) break;
      if (0.0f < zp && zp < thick) { // scattering in the slab
        float ps_pdf;
        float u1 = layered_u(&r), u2 = layered_u(&r);
        float3 wn = phase_hg_sample(m->medium.w, w, u1, u2, &ps_pdf);
        if (!(ps_pdf > 0.0f) || wn.z == 0.0f) break;
        beta = beta * albedo;
        specular = 0;
        w = wn;
        z = zp;
        continue;
      }
      z = clamp(zp, 0.0f, thick);
    } else {
      z = z == thick ? 0.0f : thick;
      beta = beta * layered_tr(thick, w);
    }
    BsdfSample is;
    if (z == 0.0f) {
      float u1 = layered_u(&r), u2 = layered_u(&r);
      is = layered_base_sample(m, -w, u1, u2);
    } else {
      is = layered_top_sample(m, -w, &r, DIELECTRIC_ALL, 1);
    }
    if (!layered_valid(is)) break;
    beta = beta * is.weight;
    specular = specular && is.is_delta;
    w = is.wi;
    if (z != 0.0f && w.z > 0.0f) { // transmitted through the coat: the walk leaves
      BsdfSample out = bsdf_sample_absorbed(w);
      out.weight = beta;
      out.is_delta = specular;
      out.pdf = specular ? 0.0f : layered_pdf(m, wo, w);
      if (!specular && !(out.pdf > 0.0f)) out.weight = make_float3(0.0f, 0.0f, 0.0f);
      return out;
    }
  }
  return bsdf_sample_absorbed(w);
}

#endif // HAS_MATERIAL_COATED
#endif // CANOPY_CL_BSDF_LAYERED_H
