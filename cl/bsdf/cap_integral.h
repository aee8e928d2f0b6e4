// The cosine-weighted BRDF integral over a spherical cap (Liu, Xu & Yan 2019, §4.1, Eq. 5),
//   S(C) = int_C f(wo, wi) max(cos theta_i, 0) dwi      (mean over R, G, B),
// for the cap C of a light cluster's bounding sphere, and its mean S / |C| (the B_C of their
// Eq. 6). docs/cap-integral.md derives the formulas and measures their accuracy and cost.
//
// - Diffuse lobe (diffuse, plastic base): albedo / pi times the exact integral of cos theta over
//   the cap clipped by the horizon (cap_cosine_integral).
// - GGX lobe (conductor, plastic coat with alpha > 0): a Spherical Pivot Transformed Distribution
//   (Dupuy, Heitz & Belcour 2017) fitted per (theta_o, alpha) by tools/fit_sptd.cpp
//   (sptd_table.h): f_ggx(wo, w) cos theta ~= amplitude * D_xi(w) [w above the horizon], with
//   D_xi the uniform distribution pivoted about xi. The integral of D_xi over a region is the
//   solid angle of its pivot image / 4 pi, and the pivot maps caps to caps, so the integral over
//   C clipped by the horizon H is |P(C) n P(H)| / 4 pi: the intersection of two caps, in closed
//   form. Fresnel is applied outside the fit, per cap (see CapLobe).
// Delta lobes (alpha == 0) are excluded, as bsdf_eval excludes them.
#ifndef CANOPY_CL_BSDF_CAP_INTEGRAL_H
#define CANOPY_CL_BSDF_CAP_INTEGRAL_H

#include "../compat.h"
#include "../kernel_features.h"
#include "../shading.h"
#include "../types.h"
#include "fresnel.h"
#include "microfacet.h"

#if HAS_MICROFACET
#include "sptd_table.h"
#endif

// Per shading point. float4s so the layout is the same 96 bytes in OpenCL C (float3 is 16 bytes
// there) and C++. The glossy part of S for a cap C is the SPTD integral
// amp |P(C) n P(H)| fres_lobe (the lobe's mean Fresnel), blended for caps small against the lobe
// with the exact GGX f cos at the centre times |C| (Fresnel from cap_fresnel at its half vector;
// cap_lobe_integral).
typedef struct CapLobe {
  float4 n;  // xyz: shading normal; w: diffuse scale, mean(albedo) / pi (0: no diffuse lobe)
  float4 xi; // xyz: SPTD pivot (|xi| < 1); w: fres_lobe, scale x the lobe's mean Fresnel
  float4 wo; // xyz: direction to the viewer; w: GGX alpha, negative for a dielectric coat
             // (plastic), 0 for no glossy lobe
  float fres0, fres1, fres2; // the Fresnel factor's parameters (cap_fresnel)
  float amp;                 // SPTD amplitude: the lobe's albedo / |P(H)|
  // The pivot image P(H) of the horizon cap: xyz its axis, w its cos; and its sin, m = 1 - |xi|^2.
  // The same for every cap of the point, so computed once (cap_lobe_integral runs per cluster).
  float4 horizon;
  float horizon_sin, m;
  float pad0, pad1;
} CapLobe;

#if HAS_MICROFACET
// The glossy lobe's Fresnel factor at cos c, mean over RGB times the specular scale.
// Plastic: fres0 x the exact dielectric Fresnel of index fres1 (cheap). Conductor: Schlick's
// form with Lazanyi & Szirmay-Kalos's correction (2005, "Fresnel term approximations for
// metals"), F(c) ~= F(1) + (1 - F(1)) (1 - c)^5 - a c (1 - c)^6 with fres0 = F(1) exact,
// fres1 = 1 - F(1), fres2 = a fitted by least squares (within 1.1% of the exact mean for gold,
// copper and aluminium; the exact one costs three square roots and divisions per channel).
INLINE float cap_fresnel(const CapLobe* l, float c) {
  if (l->wo.w < 0.0f) return l->fres0 * fresnel_dielectric(c, l->fres1);
  float x = 1.0f - c, x2 = x * x, x5 = x2 * x2 * x;
  return l->fres0 + l->fres1 * x5 - l->fres2 * (c * x5 * x);
}
#endif

INLINE float cap_mean3(float3 v) {
  return (v.x + v.y + v.z) * (1.0f / 3.0f);
}

// 1 - cos r of an angle given as (sin r, cos r), without cancellation near r = 0.
INLINE float cap_one_minus_cos(float s, float c) {
  return c > 0.0f ? s * s / (1.0f + c) : 1.0f - c;
}

// Solid angle 2 pi (1 - cos r) of a cap of half-angle r.
INLINE float cap_solid_angle(float s, float c) {
  return 2.0f * CANOPY_PI * cap_one_minus_cos(s, c);
}

// The integral of cos theta over the part of the cap (half-angle r given as sin_r, cos_r) above
// the horizon, for a cap axis at angle w from the normal (cos_w, sin_w >= 0). Fully above the
// horizon it is pi sin^2 r cos w; straddling it, with q = sqrt(sin^2 r - cos^2 w) and
// y = -cos r cos w / (sin r sin w), the form factor of a sphere cut by the horizon (Snyder 1996,
// "Area light sources for real-time graphics"; Lagarde & de Rousiers 2014, "Moving Frostbite to
// PBR", §4.7.2) is
//   I = sin^2 r cos w acos(y) - q cos r + atan(q / cos r),
// valid for r <= pi/2. For small r the last two terms cancel to O(r^3); with a = q / cos r they
// are rearranged into sin^2 r a + (atan(a) - a), and atan(a) - a is a series for small a. A cap
// larger than a hemisphere is the whole upper hemisphere (integral pi) minus its complement.
INLINE float cap_cosine_integral_small(float cos_w, float sin_w, float sin_r, float cos_r) {
  if (cos_w >= sin_r) return CANOPY_PI * sin_r * sin_r * cos_w;
  if (cos_w <= -sin_r) return 0.0f;
  float acw = fabs(cos_w);
  float q = sqrt(fmax(0.0f, (sin_r - acw) * (sin_r + acw)));
  float den = sin_r * sin_w;
  float y = den > 0.0f ? clamp(-cos_r * cos_w / den, -1.0f, 1.0f) : 0.0f;
  float s2 = sin_r * sin_r;
  float v;
  if (cos_r > 0.5f) {
    float a = q / cos_r;
    float atan_minus_a;
    if (a < 0.1f) {
      float a2 = a * a; // -a^3/3 + a^5/5 - a^7/7 + a^9/9: truncation < a^11/11 < 1e-12 a^3
      atan_minus_a =
          a * a2 * (-1.0f / 3.0f + a2 * (0.2f + a2 * (-1.0f / 7.0f + a2 * (1.0f / 9.0f))));
    } else {
      atan_minus_a = atan2(a, 1.0f) - a;
    }
    v = s2 * (cos_w * acos(y) + a) + atan_minus_a;
  } else {
    v = s2 * cos_w * acos(y) - q * cos_r + atan2(q, cos_r);
  }
  return fmax(v, 0.0f);
}

INLINE float cap_cosine_integral(float cos_w, float sin_w, float sin_r, float cos_r) {
  if (cos_r < 0.0f) // the complement: axis -c, half-angle pi - r
    return fmax(CANOPY_PI - cap_cosine_integral_small(-cos_w, sin_w, sin_r, -cos_r), 0.0f);
  return cap_cosine_integral_small(cos_w, sin_w, sin_r, cos_r);
}

// Solid angle of the intersection of caps A (axis a, half-angle ra) and B (axis b, rb), each
// at most a hemisphere and given by its sine and cosine. Disjoint and nested cases are exact; the
// lens (the boundary circles cross at P, P') follows from Gauss-Bonnet: the two circular sectors
// c_a P P' and c_b P P' minus twice the spherical triangle (c_a, c_b, P),
//   |A n B| = 2 phi_a (1 - cos ra) + 2 phi_b (1 - cos rb) - 2 E,
// phi_a, phi_b the triangle's angles at c_a, c_b and E its spherical excess (Mazonka 2012,
// "Solid angle of conical surfaces, polyhedral cones, and intersecting spherical caps", Eq. 52,
// rearranged for float). With d the distance between the axes and
// V = det(c_a, c_b, P) = sin ra sin d sin phi_a:
//   sin ra sin d cos phi_a = cos rb - cos d cos ra,  sin rb sin d cos phi_b = cos ra - cos d cos
//   rb, V^2 = (sin ra sin d)^2 - (cos rb - cos d cos ra)^2, tan(E / 2) = V / (1 + cos d + cos ra +
//   cos rb)   (Van Oosterom & Strackee 1983),
// all angles by atan2 (accurate everywhere, unlike acos). For a cap smaller than 1e-3 rad the
// sector and triangle terms cancel to O(r^2) from O(r) (relative error ~1e-7 / r), so the small
// cap is cut by the chord through P P' instead (relative error O(r cot rb)).
INLINE float cap_lens_area(float3 a, float sa, float ca, float3 b, float sb, float cb) {
  float cd = clamp(dot(a, b), -1.0f, 1.0f);
  float sd = length(cross(a, b));
  float omc_a = cap_one_minus_cos(sa, ca), omc_b = cap_one_minus_cos(sb, cb);
  float area_a = 2.0f * CANOPY_PI * omc_a, area_b = 2.0f * CANOPY_PI * omc_b;
  float x = (cb - cd) + cd * omc_a; // cos rb - cos d cos ra
  float y = (ca - cd) + cd * omc_b; // cos ra - cos d cos rb
  float h = sa * sd;
  float v = sqrt(fmax(0.0f, (h - x) * (h + x)));
  // The circles do not cross (V = 0): x <= 0 puts A's whole circle inside B (A in B, or equal
  // caps), y <= 0 B's inside A, else disjoint (no angles needed: caps are at most hemispheres).
  if (!(v > 0.0f)) return x <= 0.0f ? area_a : (y <= 0.0f ? area_b : 0.0f);
  if (fmin(sa, sb) < 1e-3f) {
    // The segment of the small cap on the other cap's side of the chord: (phi - sin phi cos phi)
    // / pi of its area (phi its half-angle at the centre).
    int a_small = sa <= sb;
    float c = a_small ? x : y;
    float phi = atan2(v, c);
    float sc = v * c / fmax(v * v + c * c, 1e-37f);
    return (a_small ? area_a : area_b) * fmax(phi - sc, 0.0f) * CANOPY_INV_PI;
  }
  float phi_a = atan2(v, x), phi_b = atan2(v, y);
  float e = 2.0f * atan2(v, ((1.0f + cd) + ca) + cb);
  float lens = 2.0f * (phi_a * omc_a + phi_b * omc_b - e);
  return clamp(lens, 0.0f, fmin(area_a, area_b));
}

// Any two caps: a cap larger than a hemisphere is replaced by its complement (the cap of axis -a
// and cos -cos r), so the lens formula only meets caps up to a hemisphere, where its terms are
// at most ~2 pi; a nearly-whole-sphere cap would otherwise cancel terms of 4 pi into a small
// result. |A n B| = |A| - |A n B^c|, and with both complemented
// |A n B| = 4 pi - |A^c| - |B^c| + |A^c n B^c| = -2 pi (cos ra + cos rb) + |A^c n B^c|.
INLINE float cap_intersection_area(float3 a, float sa, float ca, float3 b, float sb, float cb) {
  if (ca < 0.0f && cb < 0.0f)
    return fmax(-2.0f * CANOPY_PI * (ca + cb) + cap_lens_area(-a, sa, -ca, -b, sb, -cb), 0.0f);
  if (cb < 0.0f) return fmax(cap_solid_angle(sa, ca) - cap_lens_area(a, sa, ca, -b, sb, -cb), 0.0f);
  if (ca < 0.0f) return fmax(cap_solid_angle(sb, cb) - cap_lens_area(-a, sa, -ca, b, sb, cb), 0.0f);
  return cap_lens_area(a, sa, ca, b, sb, cb);
}

// Image of the cap {w : w.a >= cos r} under the pivot transform about xi (|xi| < 1, m = 1 -
// |xi|^2): the map w -> xi - m (w - xi) / |w - xi|^2 (the second intersection of the line through
// w and xi with the sphere; Dupuy et al. 2017, §3) is an inversion about xi composed with a point
// reflection, so it maps the cap's plane x.a = cos r to a sphere through xi and the cap's circle
// to a circle. Its plane (the radical plane of that sphere and the unit sphere) is y.N = e with
//   delta = cos r - xi.a,  N = 2 delta xi - m a,  e = delta (1 + |xi|^2) - m xi.a,
// and for y = P(w): y.N - e = m^2 (w.a - cos r) / |w - xi|^2, so the image of the cap is the side
// y.N >= e: the cap of axis N / |N|, cos r' = e / |N|. |N|^2 - e^2 = m^2 sin^2 r, so
// sin r' = m sin r / |N| without cancellation for tiny caps. N != 0 whenever |xi| < 1.
// 1 - |xi|^2.
INLINE float cap_pivot_m(float3 xi) {
  return fmax(1.0f - dot(xi, xi), 1e-12f);
}

INLINE float3 cap_pivot(float3 xi, float m, float3 a, float sin_r, float cos_r, float* sin_out,
                        float* cos_out) {
  float xa = dot(xi, a);
  float delta = cos_r - xa;
  float3 nv = xi * (2.0f * delta) - a * m;
  float e = delta * (2.0f - m) - m * xa;
  float len = length(nv);
  float inv = len > 0.0f ? 1.0f / len : 0.0f;
  *sin_out = clamp(m * sin_r * inv, 0.0f, 1.0f);
  *cos_out = clamp(e * inv, -1.0f, 1.0f);
  return len > 0.0f ? nv * inv : a;
}

#if HAS_MICROFACET
// Bilinear lookup of the fit at (cos theta_o, alpha): the pivot as (1 - |xi|) / alpha and its
// signed angle from the normal (negative: towards the mirror direction), the directional albedo
// of the Fresnel-free GGX lobe and the cosine at which to evaluate Fresnel for the whole lobe
// (sptd_table.h documents the grid).
INLINE void cap_sptd_lookup(float cos_o, float alpha, float* gap_over_alpha, float* angle,
                            float* albedo, float* cos_fresnel) {
  float theta = acos(clamp(cos_o, 0.0f, 1.0f));
  float fi =
      clamp(theta * (float)(SPTD_N_THETA - 1) / SPTD_THETA_MAX, 0.0f, (float)(SPTD_N_THETA - 1));
  float rough = sqrt(clamp(alpha, SPTD_ALPHA_MIN, 1.0f));
  float fj = clamp((rough - SPTD_ROUGH_MIN) * (float)(SPTD_N_ALPHA - 1) / (1.0f - SPTD_ROUGH_MIN),
                   0.0f, (float)(SPTD_N_ALPHA - 1));
  int i0 = min((int)fi, SPTD_N_THETA - 2), j0 = min((int)fj, SPTD_N_ALPHA - 2);
  float ti = fi - (float)i0, tj = fj - (float)j0;
  float r[4];
  for (int k = 0; k < 4; ++k) {
    float v00 = sptd_table[((i0 * SPTD_N_ALPHA) + j0) * 4 + k];
    float v01 = sptd_table[((i0 * SPTD_N_ALPHA) + j0 + 1) * 4 + k];
    float v10 = sptd_table[(((i0 + 1) * SPTD_N_ALPHA) + j0) * 4 + k];
    float v11 = sptd_table[(((i0 + 1) * SPTD_N_ALPHA) + j0 + 1) * 4 + k];
    r[k] = (v00 * (1.0f - tj) + v01 * tj) * (1.0f - ti) + (v10 * (1.0f - tj) + v11 * tj) * ti;
  }
  *gap_over_alpha = r[0];
  *angle = r[1];
  *albedo = r[2];
  *cos_fresnel = r[3];
}
#endif

#if HAS_MATERIAL_COATED
// The lobe a coated material (layered.h) gets here: a plastic of the coat's alpha and index over
// the diffuse base, or a conductor of the base's relative index with the wider of the two alphas.
// An approximation: it only steers the light pmf, which the estimators divide by.
INLINE Material cap_coated_proxy(const Material* m) {
  Material p = *m;
  if (m->type == MATERIAL_COATED_DIFFUSE) {
    p.type = MATERIAL_PLASTIC;
    p.specular = make_float4(1.0f, 1.0f, 1.0f, 0.0f);
  } else {
    p.type = MATERIAL_CONDUCTOR;
    p.specular = m->specular * (1.0f / m->ior);
    p.k = m->k * (1.0f / m->ior);
    p.alpha = fmax(m->alpha, m->base_alpha);
  }
  return p;
}
#endif

// A material type test for cap_lobe_make: a coated material's stand-in is a conductor or a
// plastic, so a kernel with coated materials but neither of those keeps their cap code.
#define CAP_IS_MATERIAL(m, T) (HAS_##T || HAS_MATERIAL_COATED ? (m)->type == T : 0)

INLINE CapLobe cap_lobe_make(const Material* m, const Frame* fr, float3 wo) {
#if HAS_MATERIAL_COATED
  Material proxy;
  if (IS_MATERIAL(m, MATERIAL_COATED_DIFFUSE) || IS_MATERIAL(m, MATERIAL_COATED_CONDUCTOR)) {
    proxy = cap_coated_proxy(m);
    m = &proxy;
  }
#endif
  CapLobe l;
  float3 n = fr->n;
  float cos_o = dot(wo, n);
  l.n = f4_from3(n, 0.0f);
  l.xi = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
  l.wo = f4_from3(wo, 0.0f);
  l.fres0 = 0.0f;
  l.fres1 = 0.0f;
  l.fres2 = 0.0f;
  l.amp = 0.0f;
  l.horizon = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
  l.horizon_sin = 0.0f;
  l.m = 0.0f;
  l.pad0 = 0.0f;
  l.pad1 = 0.0f;
  int diffuse_base = 1;
#if HAS_MICROFACET
  int glossy_type = CAP_IS_MATERIAL(m, MATERIAL_CONDUCTOR) || CAP_IS_MATERIAL(m, MATERIAL_PLASTIC);
  if (CAP_IS_MATERIAL(m, MATERIAL_CONDUCTOR)) diffuse_base = 0;
  int glossy = glossy_type && !ggx_is_delta(m->alpha);
  // The glossy flag (cap_lobe_is_glossy) describes the material, also for a viewer below the
  // horizon, where the amplitudes stay 0.
  if (glossy)
    l.wo.w = CAP_IS_MATERIAL(m, MATERIAL_PLASTIC) ? -ggx_alpha(m->alpha) : ggx_alpha(m->alpha);
#endif
  if (!(cos_o > 0.0f)) return l; // bsdf_eval is 0 for a viewer below the horizon
#if HAS_MICROFACET
  if (glossy) {
    float gap_a, angle, albedo, cos_f;
    cap_sptd_lookup(cos_o, m->alpha, &gap_a, &angle, &albedo, &cos_f);
    float gap = clamp(gap_a * fmax(m->alpha, SPTD_ALPHA_MIN), 1e-7f, 1.0f); // 1 - |xi|
    float norm = 1.0f - gap;
    // The tangent towards wo; any tangent at normal incidence (the lobe is symmetric there).
    float3 tw = wo - n * cos_o;
    float tl = length(tw);
    float3 t = tl > 1e-7f ? tw * (1.0f / tl) : fr->t;
    float3 xi = (t * sin(angle) + n * cos(angle)) * norm;
    float mm = cap_pivot_m(xi);
    float hs, hc;
    float3 ha = cap_pivot(xi, mm, n, 1.0f, 0.0f, &hs, &hc);
    l.horizon = f4_from3(ha, hc);
    l.horizon_sin = hs;
    l.m = mm;
    // amplitude = albedo / (|P(H)| / 4 pi) and S = amplitude |P(C) n P(H)| / 4 pi.
    float ph = cap_solid_angle(hs, hc);
    l.amp = ph > 0.0f ? albedo / ph : 0.0f;
    // Fresnel, mean over RGB. For the whole lobe (fres_lobe) exact at the lobe's effective
    // cosine (sptd_table.h: the half vectors of a rough lobe seen at grazing angles are far
    // from the normal, so F(cos theta_o) would overestimate it).
    float3 eta = xyz_of(m->specular), k = xyz_of(m->k);
    float f_lobe;
    if (CAP_IS_MATERIAL(m, MATERIAL_CONDUCTOR)) {
      float f1 = cap_mean3(fresnel_conductor(1.0f, eta, k));
      // Lazanyi's a: least squares over 8 cosines.
      float num = 0.0f, den = 0.0f;
      for (int i = 0; i < 8; ++i) {
        float c = ((float)i + 0.5f) * 0.125f;
        float x = 1.0f - c, x2 = x * x, x5 = x2 * x2 * x, b = c * x5 * x;
        num += (f1 + (1.0f - f1) * x5 - cap_mean3(fresnel_conductor(c, eta, k))) * b;
        den += b * b;
      }
      l.fres0 = f1;
      l.fres1 = 1.0f - f1;
      l.fres2 = num / den;
      f_lobe = cap_mean3(fresnel_conductor(cos_f, eta, k));
    } else {
      l.fres0 = fmax(cap_mean3(eta), 0.0f); // plastic: the specular tint
      l.fres1 = m->ior;
      f_lobe = l.fres0 * fresnel_dielectric(cos_f, m->ior);
    }
    l.xi = f4_from3(xi, f_lobe);
  }
#endif
  if (diffuse_base) l.n.w = fmax(cap_mean3(xyz_of(m->albedo)), 0.0f) * CANOPY_INV_PI;
  return l;
}

INLINE int cap_lobe_is_glossy(const CapLobe* l) {
  return l->wo.w != 0.0f;
}

// Smallest value returned where the true integral is positive (the light sampler needs S > 0
// there for unbiasedness; the fit can round to 0 at the tails).
#define CAP_INTEGRAL_FLOOR 1e-30f

INLINE float cap_lobe_integral(const CapLobe* l, float3 c, float sin_u, float cos_u, float* mean) {
  float3 n = xyz_of(l->n);
  float diff = l->n.w;
  // > 0: the glossy lobe reflects (the specular tint of a plastic, always for a conductor)
  float spec = l->amp * (l->wo.w < 0.0f ? l->fres0 : l->fres0 + l->fres1);
  float cos_w = dot(c, n);
  // The cap reaches above the horizon iff angle(c, n) < pi/2 + u.
  int above = cos_u < 0.0f || cos_w > -sin_u;
  if (!above || !(diff > 0.0f || spec > 0.0f)) {
    *mean = 0.0f;
    return 0.0f;
  }
  float omega = cap_solid_angle(sin_u, cos_u);
  float s = 0.0f;
  float mean_point = 0.0f; // the u -> 0 limit, for caps whose solid angle underflows
  if (diff > 0.0f) {
    float sin_w = length(cross(c, n));
    s += diff * cap_cosine_integral(cos_w, sin_w, sin_u, cos_u);
    mean_point += diff * fmax(cos_w, 0.0f);
  }
#if HAS_MICROFACET
  if (spec > 0.0f) {
    float3 xi = xyz_of(l->xi), wo = xyz_of(l->wo);
    float alpha = fabs(l->wo.w);
    // A cap much smaller than the lobe sees it as constant: there the exact GGX f cos at the
    // centre (microfacet.h; Fresnel at the half vector of wo and c) times the solid angle is
    // exact, where the fit's pointwise error (tens of percent in places) would dominate. The
    // weight w = 1 / (1 + (u / (0.2 alpha))^4) keeps the point value below ~0.1 alpha (the
    // lobe's width is ~2 alpha) and hands over to the SPTD integral by ~0.4 alpha. Each part is
    // computed only where its weight is not negligible.
    float t = sin_u / (0.2f * alpha), t2 = t * t;
    float w = cos_u > 0.0f ? 1.0f / (1.0f + t2 * t2) : 0.0f;
    float s_g = 0.0f;
    if (w > 1e-4f) {
      float fc_exact = 0.0f;
      float zo = dot(wo, n);
      float3 hv = wo + c;
      float hl2 = dot(hv, hv);
      if (cos_w > 0.0f && hl2 > 0.0f) {
        float hl = sqrt(hl2);
        float3 h = hv * (1.0f / hl);
        float f_c = cap_fresnel(l, 0.5f * hl); // wo.h = cos(angle(wo, c) / 2) = |wo + c| / 2
        float3 ht = cross(h, n);               // tangential part, exact near h = n
        float a2 = alpha * alpha;
        float hz = dot(h, n);
        float sd = dot(ht, ht) / a2 + hz * hz;
        float d = 1.0f / ((CANOPY_PI * a2 * sd) * sd);
        float3 ct = cross(c, n), ot = cross(wo, n);
        float lo = sqrt(zo * zo + a2 * dot(ot, ot)), li = sqrt(cos_w * cos_w + a2 * dot(ct, ct));
        float den = cos_w * lo + zo * li;
        fc_exact = den > 0.0f ? f_c * d * cos_w / (2.0f * den) : 0.0f;
      }
      s_g += w * omega * fc_exact;
      mean_point += fc_exact;
    }
    if (w < 1.0f) {
      // The SPTD integral with the lobe's mean Fresnel (docs/cap-integral.md compares per-cap
      // Fresnel factors: none did better, and they cost up to a quarter more).
      float ps, pc;
      float3 pa = cap_pivot(xi, l->m, c, sin_u, cos_u, &ps, &pc);
      s_g += (1.0f - w) * l->amp * l->xi.w *
             cap_intersection_area(pa, ps, pc, xyz_of(l->horizon), l->horizon_sin, l->horizon.w);
    }
    s += s_g;
  }
#endif
  float mu = omega > 1e-30f ? s / omega : mean_point;
  *mean = fmax(mu, CAP_INTEGRAL_FLOOR);
  return fmax(s, CAP_INTEGRAL_FLOOR);
}

#endif // CANOPY_CL_BSDF_CAP_INTEGRAL_H
