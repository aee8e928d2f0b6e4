// Sampling a point on one light as seen from a shading point, and the emitted radiance of an
// area light hit by a ray. Shared by shade_surface and the host reference.
#ifndef CANOPY_CL_LIGHT_SAMPLE_H
#define CANOPY_CL_LIGHT_SAMPLE_H

#include "../compat.h"
#include "../kernel_features.h"
#include "../shading.h"
#include "../types.h"
#if HAS_LIGHT_QUAD || HAS_LIGHT_TRIANGLE
#include "planar_solid_angle.h"
#endif

typedef struct LightSample {
  float3 wi;    // unit direction from the shading point towards the light point
  float dist;   // distance to the light point
  float3 Li;    // radiance arriving along wi (delta lights: intensity / dist^2)
  float pdf;    // solid-angle pdf of wi (1 for delta lights); 0 means "no contribution"
  int is_delta; // point, spot and distant lights
  // Where a shadow ray towards the sample ends: the light point itself for point and spot lights
  // (a distant light's ray has no end: dist is infinite and x is P);
  // for area lights the sampled point moved off the light's surface towards P by its own float
  // error bound, so the light's own primitive cannot occlude it (cl/shading.h).
  float3 x;
} LightSample;

// Smoothstep falloff of a spot light in cos(theta) between the falloff start and the cone edge
// (1 inside the start, 0 outside the edge; a hard edge when they coincide). w_axis_dist2 is
// |w - axis|^2 for the unit direction w from the light to the receiver: 1 - cos(theta) =
// |w - axis|^2 / 2 without the cancellation of 1 - dot(w, axis), which leaves only a few float
// steps across the falloff band of a narrow spot. The host stores 1 - cos of both half-angles
// (e2.x, e2.y, computed in double as 2 sin^2(angle / 2)).
INLINE float spot_falloff(const GLOBAL Light* l, float w_axis_dist2) {
  float omc = 0.5f * w_axis_dist2;
  float omc_edge = l->e2.x, omc_start = l->e2.y;
  if (omc <= omc_start) return omc < omc_edge ? 1.0f : 0.0f;
  if (omc >= omc_edge) return 0.0f;
  // x = (cos(theta) - cos_edge) / (cos_start - cos_edge), in 1 - cos terms
  float x = (omc_edge - omc) / (omc_edge - omc_start);
  return x * x * (3.0f - 2.0f * x);
}

// Whether an area light with normal n emits towards direction w (unit, pointing away from it).
INLINE int light_emits_towards(const GLOBAL Light* l, float3 w) {
  if (l->flags & LIGHT_FLAG_TWO_SIDED) return 1;
  return dot(xyz_of(l->n), w) > 0.0f;
}

// Where a shadow ray towards the point q on a quad or triangle light ends: q moved off the
// light's plane towards P by q's rounding error and that of the light's geometry triangles
// (their vertices are p + e1 etc. rounded): gamma(3) of each term, twice.
INLINE float3 area_light_shadow_end(const GLOBAL Light* l, float3 q, float3 P) {
  float3 q_err = (fabs(xyz_of(l->p)) + fabs(xyz_of(l->e1)) + fabs(xyz_of(l->e2))) * fp_gamma(6);
  float3 ln = xyz_of(l->n);
  return offset_ray_origin(q, q_err, dot(ln, P - q) >= 0.0f ? ln : -ln);
}

// Concentric map of the unit square onto the unit disk (Shirley & Chiu 1997): area-preserving up
// to a constant, so uniform (u1, u2) give a uniform point on the disk, with less distortion than
// the polar map (r = sqrt(u1)).
INLINE float2 concentric_disk(float u1, float u2) {
  float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
  if (a == 0.0f && b == 0.0f) return make_float2(0.0f, 0.0f);
  float rr, phi;
  if (fabs(a) > fabs(b)) {
    rr = a;
    phi = (0.25f * CANOPY_PI) * (b / a);
  } else {
    rr = b;
    phi = 0.5f * CANOPY_PI - (0.25f * CANOPY_PI) * (a / b);
  }
  return make_float2(rr * cos(phi), rr * sin(phi));
}

// Solid-angle pdf of the direction from P to the point x on disk light l under uniform area
// sampling: d^2 / (|cos_l| A), 0 where the disk does not emit towards P (for the MIS weight of a
// BSDF ray that hit the back of a one-sided disk: it carries no emission). sample_light's disk
// branch and light_pdf both call it with the point they have (the sample's s.x, the BSDF ray's
// hit point), so they agree exactly for the same point.
INLINE float disk_light_pdf(const GLOBAL Light* l, float3 P, float3 x) {
  float3 to = x - P;
  float d2 = dot(to, to);
  if (!(d2 > 0.0f)) return 0.0f;
  float3 w = to / sqrt(d2);
  float3 ln = xyz_of(l->n);
  // A one-sided disk emits towards P when P is in front of its plane: tested against the centre,
  // not x, so the answer does not depend on which side of the plane x was rounded to.
  if (!(l->flags & LIGHT_FLAG_TWO_SIDED) && !(dot(ln, P - xyz_of(l->p)) > 0.0f)) return 0.0f;
  float cos_l = fabs(dot(ln, w));
  float pdf = cos_l > 0.0f ? d2 / (cos_l * l->n.w) : 0.0f;
  return is_finite_f(pdf) ? pdf : 0.0f;
}

INLINE LightSample sample_light(const GLOBAL Light* l, float3 P, float u1, float u2) {
  LightSample s;
  s.wi = make_float3(0.0f, 0.0f, 1.0f);
  s.dist = 0.0f;
  s.Li = make_float3(0.0f, 0.0f, 0.0f);
  s.pdf = 0.0f;
  s.is_delta = 0;
  s.x = P;
  float3 L = xyz_of(l->emission);
  if (IS_LIGHT(l, LIGHT_DISTANT)) {
    // Parallel light: the same direction and irradiance everywhere; the shadow ray is unbounded.
    s.wi = xyz_of(l->e1);
    s.dist = FLT_INF;
    s.Li = L;
    s.pdf = 1.0f;
    s.is_delta = 1;
    return s;
  }
  if (IS_LIGHT(l, LIGHT_POINT) || IS_LIGHT(l, LIGHT_SPOT)) {
    s.x = xyz_of(l->p);
    float3 to = s.x - P;
    float d2 = dot(to, to);
    if (!(d2 > 0.0f)) return s;
    s.dist = sqrt(d2);
    s.wi = to / s.dist;
    float k = 1.0f / d2;
    if (IS_LIGHT(l, LIGHT_SPOT)) {
      float3 w_axis = s.wi + xyz_of(l->e1); // (-wi) - axis, up to the sign
      k *= spot_falloff(l, dot(w_axis, w_axis));
    }
    s.Li = L * k;
    s.pdf = 1.0f;
    s.is_delta = 1;
    return s;
  }
  if (IS_LIGHT(l, LIGHT_SPHERE)) {
    // Uniform sampling of the cone of directions the sphere subtends (pbrt-v4 §6.2.4).
    float3 c = xyz_of(l->p);
    float r = l->p.w;
    float3 to = c - P;
    float d2 = dot(to, to);
    if (!(d2 > r * r)) return s; // inside the sphere: it emits outwards only
    float d = sqrt(d2);
    float3 w = to / d;
    float sin2_max = r * r / d2;
    float cos_max = sqrt(fmax(0.0f, 1.0f - sin2_max));
    // 1 - cos_max without cancellation for small spheres.
    float one_minus_cos_max = sin2_max / (1.0f + cos_max);
    float one_minus_cos = u1 * one_minus_cos_max;
    float cos_t = 1.0f - one_minus_cos;
    float sin2_t = one_minus_cos * (2.0f - one_minus_cos);
    float sin_t = sqrt(fmax(0.0f, sin2_t));
    float phi = 2.0f * CANOPY_PI * u2;
    // Orthonormal basis around w (Duff et al. 2017).
    float sign = w.z >= 0.0f ? 1.0f : -1.0f;
    float a = -1.0f / (sign + w.z);
    float b = w.x * w.y * a;
    float3 t1 = make_float3(1.0f + sign * w.x * w.x * a, sign * b, -sign * w.x);
    float3 t2 = make_float3(b, sign + w.y * w.y * a, -w.y);
    s.wi = normalize(t1 * (sin_t * cos(phi)) + t2 * (sin_t * sin(phi)) + w * cos_t);
    // Distance to the near intersection along wi.
    float dc = d * cos_t;
    s.dist = fmax(0.0f, dc - sqrt(fmax(0.0f, r * r - d2 * sin2_t)));
    s.Li = L;
    s.pdf = 1.0f / (2.0f * CANOPY_PI * one_minus_cos_max);
    // The point projected back onto the sphere (its error then follows the sphere's coordinates,
    // not |P| and the distance), moved outwards: the visible cap faces P.
    float3 lx = (P + s.wi * s.dist) - c;
    float llen = length(lx);
    if (llen > 0.0f) {
      lx = lx * (r / llen);
      float3 x = c + lx;
      s.x = offset_ray_origin(x, fabs(lx) * fp_gamma(6) + fabs(x) * fp_gamma(1), lx * (1.0f / r));
    } else {
      s.x = P + s.wi * s.dist;
    }
    return s;
  }
  if (IS_LIGHT(l, LIGHT_DISK)) {
    // Uniform in area (concentric map), converted to solid angle: pdf = d^2 / (|cos_l| A).
    float3 c = xyz_of(l->p);
    float r = l->p.w;
    float3 t1 = xyz_of(l->e1), t2 = xyz_of(l->e2), ln = xyz_of(l->n);
    float2 uv = concentric_disk(u1, u2);
    float3 q = c + t1 * (r * uv.x) + t2 * (r * uv.y);
    // Off the disk's plane towards P by what can put the shadow ray's plane crossing (cl/geometry.h
    // ray_disk) before its end: q's distance from the plane (the sums, gamma(3) (|c| + r), and the
    // tangent frame's tilt off the plane, a few ulps of 1 times r), the ray-plane numerator
    // n.(c - P) (gamma(4) n.(|c| + |P|)) and the direction's normal component (P - q rounded,
    // normalised, the dot product: gamma(6) n.|q - P| at t ~ dist). All scale with 1/|cos| along
    // the ray, as the offset does; gamma(16) of n.(|c| + |P| + 2r) bounds their sum.
    float3 q_err = (fabs(c) + fabs(P) + make_float3(2.0f * r, 2.0f * r, 2.0f * r)) * fp_gamma(16);
    s.x = offset_ray_origin(q, q_err, dot(ln, P - c) >= 0.0f ? ln : -ln);
    float3 to = s.x - P;
    float d2 = dot(to, to);
    if (!(d2 > 0.0f)) return s;
    s.dist = sqrt(d2);
    s.wi = to / s.dist;
    s.pdf = disk_light_pdf(l, P, s.x);
    if (s.pdf > 0.0f) s.Li = L;
    return s;
  }
  // Quad and triangle: uniform in solid angle where float precision allows, else uniform in area
  // converted to solid angle (cl/lights/planar_solid_angle.h).
  if (!(IS_LIGHT(l, LIGHT_QUAD) || IS_LIGHT(l, LIGHT_TRIANGLE))) return s;
  float3 q;
#if HAS_LIGHT_QUAD || HAS_LIGHT_TRIANGLE
  PlanarView view = planar_view(l, P);
  if (view.technique == PLANAR_NONE) return s;
  if (view.technique != PLANAR_AREA) {
    float2 ab = planar_sample_solid_angle(&view, u1, u2, &s.wi, &s.dist);
    q = xyz_of(l->p) + xyz_of(l->e1) * ab.x + xyz_of(l->e2) * ab.y;
    s.x = area_light_shadow_end(l, q, P);
    if (!(s.dist > 0.0f) || !light_emits_towards(l, -s.wi)) return s;
    s.Li = L;
    s.pdf = 1.0f / view.omega;
    return s;
  }
#endif
  float3 q1, q2;
  if (IS_LIGHT(l, LIGHT_QUAD)) {
    q1 = xyz_of(l->e1) * u1;
    q2 = xyz_of(l->e2) * u2;
  } else {
    float su = sqrt(u1);
    q1 = xyz_of(l->e1) * (1.0f - su);
    q2 = xyz_of(l->e2) * (u2 * su);
  }
  q = xyz_of(l->p) + q1 + q2;
  s.x = area_light_shadow_end(l, q, P);
  float3 to = q - P;
  float d2 = dot(to, to);
  if (!(d2 > 0.0f)) return s;
  s.dist = sqrt(d2);
  s.wi = to / s.dist;
  float cos_l = dot(xyz_of(l->n), -s.wi);
  if (!light_emits_towards(l, -s.wi) || cos_l == 0.0f) return s;
  s.Li = L;
  s.pdf = d2 / (fabs(cos_l) * l->n.w);
  return s;
}

// Radiance leaving light l towards direction w_out (unit, pointing away from the light), for a
// ray that hit the light's surface.
INLINE float3 light_emitted_radiance(const GLOBAL Light* l, float3 surface_normal, float3 w_out) {
  if (IS_LIGHT(l, LIGHT_SPHERE)) {
    return dot(surface_normal, w_out) > 0.0f ? xyz_of(l->emission) : make_float3(0.0f, 0.0f, 0.0f);
  }
  if (IS_LIGHT(l, LIGHT_QUAD) || IS_LIGHT(l, LIGHT_TRIANGLE)) {
    return light_emits_towards(l, w_out) ? xyz_of(l->emission) : make_float3(0.0f, 0.0f, 0.0f);
  }
  if (IS_LIGHT(l, LIGHT_DISK)) {
    return light_emits_towards(l, w_out) ? xyz_of(l->emission) : make_float3(0.0f, 0.0f, 0.0f);
  }
  return make_float3(0.0f, 0.0f, 0.0f);
}

// Solid-angle pdf with which sample_light() would produce the direction from P to the point x on
// light l (for MIS when a BSDF ray hits an area light). Must mirror sample_light exactly.
INLINE float light_pdf(const GLOBAL Light* l, float3 P, float3 x) {
  if (IS_LIGHT(l, LIGHT_SPHERE)) {
    float3 to = xyz_of(l->p) - P;
    float d2 = dot(to, to);
    float r = l->p.w;
    if (!(d2 > r * r)) return 0.0f;
    float sin2_max = r * r / d2;
    float cos_max = sqrt(fmax(0.0f, 1.0f - sin2_max));
    return 1.0f / (2.0f * CANOPY_PI * (sin2_max / (1.0f + cos_max)));
  }
  if (IS_LIGHT(l, LIGHT_QUAD) || IS_LIGHT(l, LIGHT_TRIANGLE)) {
#if HAS_LIGHT_QUAD || HAS_LIGHT_TRIANGLE
    PlanarView view = planar_view(l, P);
    if (view.technique == PLANAR_NONE) return 0.0f;
    if (view.technique != PLANAR_AREA) return 1.0f / view.omega;
#endif
    float3 to = x - P;
    float d2 = dot(to, to);
    if (!(d2 > 0.0f)) return 0.0f;
    float3 w = to / sqrt(d2);
    if (!light_emits_towards(l, -w)) return 0.0f;
    float cos_l = fabs(dot(xyz_of(l->n), w));
    return cos_l > 0.0f ? d2 / (cos_l * l->n.w) : 0.0f;
  }
  if (IS_LIGHT(l, LIGHT_DISK)) return disk_light_pdf(l, P, x);
  return 0.0f; // delta lights cannot be hit
}

// Power heuristic (beta = 2) weight of technique a against b, from their pdfs. Written with the
// ratio of the pdfs so it neither overflows (pdfs of tiny lights reach 1e20) nor divides 0 by 0.
INLINE float power_heuristic(float pa, float pb) {
  if (!(pa > 0.0f)) return 0.0f;
  if (!(pb > 0.0f)) return 1.0f;
  if (pa >= pb) {
    float r = pb / pa;
    return 1.0f / (1.0f + r * r);
  }
  float r = pa / pb;
  return r * r / (1.0f + r * r);
}

#endif // CANOPY_CL_LIGHT_SAMPLE_H
