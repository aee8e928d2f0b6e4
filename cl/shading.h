// Small shading helpers shared by shade_surface and the host reference.
#ifndef CANOPY_CL_SHADING_H
#define CANOPY_CL_SHADING_H

#include "compat.h"

// Orthonormal basis around unit n (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
INLINE void onb_from(float3 n, float3* t, float3* b) {
  float sign = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (sign + n.z);
  float c = n.x * n.y * a;
  *t = make_float3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  *b = make_float3(c, sign + n.y * n.y * a, -n.y);
}

// Cosine-weighted direction around unit n (Malley's method); pdf = cos / pi.
INLINE float3 sample_cosine_hemisphere(float3 n, float u1, float u2) {
  float r = sqrt(u1);
  float phi = 2.0f * CANOPY_PI * u2;
  float3 t, b;
  onb_from(n, &t, &b);
  float z = sqrt(fmax(0.0f, 1.0f - u1));
  return normalize(t * (r * cos(phi)) + b * (r * sin(phi)) + n * z);
}

// An orthonormal shading frame: n is the shading normal, the BSDFs work in (t, b, n) coordinates
// (cl/bsdf/bsdf.h: z up).
typedef struct Frame {
  float3 t, b, n;
} Frame;

INLINE Frame frame_from(float3 n) {
  Frame f;
  f.n = n;
  onb_from(n, &f.t, &f.b);
  return f;
}
INLINE float3 frame_to_local(const Frame* f, float3 w) {
  return make_float3(dot(w, f->t), dot(w, f->b), dot(w, f->n));
}
INLINE float3 frame_to_world(const Frame* f, float3 w) {
  return f->t * w.x + f->b * w.y + f->n * w.z;
}

// A shading normal ns (interpolated vertex normals) usable for the direction wo towards the
// viewer on the side of the geometric normal ng (both unit, dot(ng, wo) > 0). Interpolated normals
// can put wo below ns's horizon or reflect it into the surface, which shows as black fringes on
// smooth meshes; as Cycles does (ensure_valid_reflection), ns is tilted towards ng just enough
// that the mirror direction of wo about it stays above the geometric surface by
// q = min(0.9 dot(ng, wo), 0.01). The tilted normal is the half vector of wo and that direction,
// so dot(ns, wo) > 0 afterwards. A flat surface (ns == ng) is returned unchanged.
INLINE float3 shading_normal_fix(float3 ng, float3 wo, float3 ns) {
  if (dot(ns, ng) < 0.0f) ns = -ns;
  float3 r = ns * (2.0f * dot(ns, wo)) - wo; // mirror direction of wo about ns
  float q = fmin(0.9f * dot(ng, wo), 0.01f);
  float rh = dot(r, ng);
  if (rh >= q) return ns;
  float3 x = r - ng * rh; // the part of r in the surface plane
  float xl = length(x);
  if (!(xl > 0.0f)) return ng;
  float3 r2 = x * (sqrt(fmax(0.0f, 1.0f - q * q)) / xl) + ng * q;
  float3 h = wo + r2;
  float hl = length(h);
  return hl > 0.0f ? h / hl : ng;
}

// Floating-point error bounds (pbrt-v4 §6.8): gamma(n) = n u / (1 - n u) bounds the relative
// error of n successive float operations, u = 2^-24 the unit roundoff.
INLINE float fp_gamma(int n) {
  float nu = (float)n * 5.9604645e-8f;
  return nu / (1.0f - nu);
}

// The neighbouring floats of v (towards +inf / -inf); +-0 step to the smallest denormal.
INLINE float next_float_up(float v) {
  if (v == FLT_INF) return v;
  if (v == 0.0f) v = 0.0f; // -0 -> +0
  uint u = float_as_uint_(v);
  return uint_as_float_(v >= 0.0f ? u + 1u : u - 1u);
}
INLINE float next_float_down(float v) {
  if (v == -FLT_INF) return v;
  if (v == 0.0f) v = -0.0f; // +0 -> -0
  uint u = float_as_uint_(v);
  return uint_as_float_(v > 0.0f ? u - 1u : u + 1u);
}

// Origin for a ray leaving a surface point p, computed with absolute error at most p_err per
// component, on the side of the (unit) normal n. The offset is the projection of the error box
// onto n, so the origin is outside the box that holds the exact surface point, and each moved
// component is rounded one more float away so the addition itself cannot pull it back (pbrt-v4
// §6.8, OffsetRayOrigin). The offset follows the float error of the point's own coordinates:
// a floor far out along x with a small y and z keeps a tiny offset along its normal, whatever the
// size of the scene.
INLINE float3 offset_ray_origin(float3 p, float3 p_err, float3 n) {
  float d = dot(fabs(n), p_err);
  float3 off = n * d;
  float3 po = p + off;
  po.x = off.x > 0.0f ? next_float_up(po.x) : (off.x < 0.0f ? next_float_down(po.x) : po.x);
  po.y = off.y > 0.0f ? next_float_up(po.y) : (off.y < 0.0f ? next_float_down(po.y) : po.y);
  po.z = off.z > 0.0f ? next_float_up(po.z) : (off.z < 0.0f ? next_float_down(po.z) : po.z);
  return po;
}

// Largest absolute component (the magnitude that sets a point's float spacing).
INLINE float max_abs3(float3 v) {
  return fmax(fabs(v.x), fmax(fabs(v.y), fabs(v.z)));
}

// Russian roulette from a path's third vertex on (depth >= 2): it survives with probability
// q = min(max(beta), 0.95) and then carries beta / q. Returns 0 if the path ends.
INLINE int russian_roulette(float3* beta, int depth, float u) {
  if (depth < 2) return 1;
  float q = fmin(max3(*beta), 0.95f);
  if (u >= q) return 0;
  *beta = *beta / q;
  return 1;
}

#endif // CANOPY_CL_SHADING_H
