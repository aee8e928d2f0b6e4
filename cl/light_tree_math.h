// Light tree math shared by the host reference (C++20) and the OpenCL kernels (OpenCL C 1.2):
// Conty Estevez & Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree Splitting".
// See docs/DESIGN.md sections 2-4. Everything below the helper layer is written once and compiles
// as both languages, so sampling on the host and on the device make the very same decisions.
//
// ---------------------------------------------------------------- device layout of the tree
// The tree is 4-wide. Node `n` owns LT_NODE_F4 consecutive float4 in `nodes` (struct of arrays:
// record k holds one quantity for the node's four children, lane i = child i) and one int4 in
// `children`:
//   nodes[n*11 + 0..2]  LT_CX, LT_CY, LT_CZ   bounding-sphere centre of each child
//   nodes[n*11 + 3]     LT_R                  bounding-sphere radius (sphere of the child's bbox)
//   nodes[n*11 + 4..6]  LT_AX, LT_AY, LT_AZ   orientation cone axis (unit)
//   nodes[n*11 + 7]     LT_COS_O              cos(theta_o)  (normal bound)
//   nodes[n*11 + 8]     LT_COS_E              cos(theta_e)  (emission bound, theta_e <= pi/2)
//   nodes[n*11 + 9]     LT_ENERGY             sum of emitter energies (luminance of max intensity)
//   nodes[n*11 + 10]    LT_CV2                squared coefficient of variation of the emitter
//                                             energies, V[e]/E[e]^2 (dimensionless, for splitting)
//   children[n].lane    >= 0: index of a child node
//                       LT_EMPTY: unused lane (its energy is 0)
//                       other < 0: leaf, code = -1 - child = (first << 2) | (count - 1): the
//                       emitters leaf_lights[first .. first+count), count in 1..4
// Node 0 is the root. Leaf emitters are not stored in the tree: their bounds are recomputed from
// the `Light` records (lt_light_bounds) when a leaf is evaluated, so the tree costs ~40
// bytes/emitter. trails[light]: the light's bit-trail, 2 bits per 4-wide level starting with the
// root in the two lowest bits, then 2 bits for its index inside its leaf. root_sphere / root_info:
// bounding sphere of all emitters; (cv2, total energy, 0, 0).
#ifndef CANOPY_LIGHT_TREE_MATH_H
#define CANOPY_LIGHT_TREE_MATH_H

#include "compat.h"
#include "types.h"

#define LT_NODE_F4 11
#define LT_CX 0
#define LT_CY 1
#define LT_CZ 2
#define LT_R 3
#define LT_AX 4
#define LT_AY 5
#define LT_AZ 6
#define LT_COS_O 7
#define LT_COS_E 8
#define LT_ENERGY 9
#define LT_CV2 10

#define LT_EMPTY (-2147483647 - 1)
#define LT_MAX_LEAF 4
// 4-wide node levels below the root (inclusive) so that 2 bits per level + 2 leaf bits fit a uint.
#define LT_MAX_NODE_LEVELS 15
// Smallest importance given to a lane that can contribute, so underflow never makes it 0 (the
// importances of the four lanes are normalised by their maximum energy and minimum distance first).
#define LT_IMPORTANCE_FLOOR 1e-30f
// xi starts with 24 random bits. After choosing a lane of probability p its resolution is divided
// by p; when fewer than LT_XI_MIN_BITS remain it is replaced by a fresh number from the rng stream.
#define LT_XI_RES0 5.9604645e-08f      /* 2^-24 */
#define LT_XI_RES_LIMIT 1.5258789e-05f /* 2^-16: refresh below 16 bits */
#define LT_ONE_MINUS_EPS 0.99999994f   /* largest float below 1 */
// Cone unions are padded by this angle (radians) so rounding never uncovers an input.
#define LT_CONE_PAD 2e-6f
// Default threshold of the adaptive split (see lt_split_measure for its meaning and calibration).
#define LT_DEFAULT_SPLIT_THRESHOLD 0.85f

// ---------------------------------------------------------------- helper layer (4 lanes)
#ifdef __OPENCL_C_VERSION__
typedef int4 lt_mask4;
#define lt_splat4(s) ((float4)(s))
#define lt_sqrt4(a) sqrt(a)
#define lt_min4(a, b) fmin(a, b)
#define lt_max4(a, b) fmax(a, b)
#define lt_lt4(a, b) ((a) < (b))
#define lt_le4(a, b) ((a) <= (b))
#define lt_gt4(a, b) ((a) > (b))
#define lt_ge4(a, b) ((a) >= (b))
#define lt_and4(a, b) ((a) & (b))
#define lt_sel4(a, b, m) select(a, b, m) /* m ? b : a, lane-wise */
#define lt_minf(a, b) fmin(a, b)
#define lt_maxf(a, b) fmax(a, b)
#define LT_HOT INLINE
#define LT_PREFETCH(addr) ((void)(addr))
#else
// C++ (host reference): the same lane-wise operations on SSE registers (x86-64) or scalars.
#if defined(__SSE2__)
#include <emmintrin.h>
typedef __m128 lt_mask4;
INLINE __m128 lt_ps_(float4 a) {
  return _mm_load_ps(&a.x);
}
INLINE float4 lt_f4_(__m128 v) {
  float4 r;
  _mm_store_ps(&r.x, v);
  return r;
}
INLINE float4 lt_splat4(float s) {
  return make_float4(s, s, s, s);
}
INLINE float4 lt_sqrt4(float4 a) {
  return lt_f4_(_mm_sqrt_ps(lt_ps_(a)));
}
INLINE float4 lt_min4(float4 a, float4 b) {
  return lt_f4_(_mm_min_ps(lt_ps_(a), lt_ps_(b)));
}
INLINE float4 lt_max4(float4 a, float4 b) {
  return lt_f4_(_mm_max_ps(lt_ps_(a), lt_ps_(b)));
}
INLINE lt_mask4 lt_lt4(float4 a, float4 b) {
  return _mm_cmplt_ps(lt_ps_(a), lt_ps_(b));
}
INLINE lt_mask4 lt_le4(float4 a, float4 b) {
  return _mm_cmple_ps(lt_ps_(a), lt_ps_(b));
}
INLINE lt_mask4 lt_gt4(float4 a, float4 b) {
  return _mm_cmpgt_ps(lt_ps_(a), lt_ps_(b));
}
INLINE lt_mask4 lt_ge4(float4 a, float4 b) {
  return _mm_cmpge_ps(lt_ps_(a), lt_ps_(b));
}
INLINE lt_mask4 lt_and4(lt_mask4 a, lt_mask4 b) {
  return _mm_and_ps(a, b);
}
INLINE float4 lt_sel4(float4 a, float4 b, lt_mask4 m) {
  return lt_f4_(_mm_or_ps(_mm_and_ps(m, lt_ps_(b)), _mm_andnot_ps(m, lt_ps_(a))));
}
#else
typedef int4 lt_mask4;
INLINE float4 lt_splat4(float s) {
  return make_float4(s, s, s, s);
}
INLINE float4 lt_sqrt4(float4 a) {
  return make_float4(std::sqrt(a.x), std::sqrt(a.y), std::sqrt(a.z), std::sqrt(a.w));
}
INLINE float4 lt_min4(float4 a, float4 b) {
  return make_float4(b.x < a.x ? b.x : a.x, b.y < a.y ? b.y : a.y, b.z < a.z ? b.z : a.z,
                     b.w < a.w ? b.w : a.w);
}
INLINE float4 lt_max4(float4 a, float4 b) {
  return make_float4(a.x < b.x ? b.x : a.x, a.y < b.y ? b.y : a.y, a.z < b.z ? b.z : a.z,
                     a.w < b.w ? b.w : a.w);
}
INLINE lt_mask4 lt_lt4(float4 a, float4 b) {
  return make_int4(-(a.x < b.x), -(a.y < b.y), -(a.z < b.z), -(a.w < b.w));
}
INLINE lt_mask4 lt_le4(float4 a, float4 b) {
  return make_int4(-(a.x <= b.x), -(a.y <= b.y), -(a.z <= b.z), -(a.w <= b.w));
}
INLINE lt_mask4 lt_gt4(float4 a, float4 b) {
  return lt_lt4(b, a);
}
INLINE lt_mask4 lt_ge4(float4 a, float4 b) {
  return lt_le4(b, a);
}
INLINE lt_mask4 lt_and4(lt_mask4 a, lt_mask4 b) {
  return make_int4(a.x & b.x, a.y & b.y, a.z & b.z, a.w & b.w);
}
INLINE float4 lt_sel4(float4 a, float4 b, lt_mask4 m) {
  return make_float4(m.x ? b.x : a.x, m.y ? b.y : a.y, m.z ? b.z : a.z, m.w ? b.w : a.w);
}
#endif
INLINE float lt_minf(float a, float b) {
  return b < a ? b : a;
}
INLINE float lt_maxf(float a, float b) {
  return a < b ? b : a;
}
#if defined(__GNUC__)
#define LT_HOT inline __attribute__((always_inline))
#define LT_PREFETCH(addr) __builtin_prefetch(addr)
#else
#define LT_HOT inline
#define LT_PREFETCH(addr) ((void)(addr))
#endif
#endif // __OPENCL_C_VERSION__

INLINE float3 lt_min3(float3 a, float3 b) {
  return make_float3(lt_minf(a.x, b.x), lt_minf(a.y, b.y), lt_minf(a.z, b.z));
}
INLINE float3 lt_max3(float3 a, float3 b) {
  return make_float3(lt_maxf(a.x, b.x), lt_maxf(a.y, b.y), lt_maxf(a.z, b.z));
}
INLINE float lt_clampf(float x, float lo, float hi) {
  return lt_minf(lt_maxf(x, lo), hi);
}

INLINE float4 lt_add4s(float4 a, float s) {
  return a + lt_splat4(s);
}
INLINE float lt_hmin4(float4 a) {
  return lt_minf(lt_minf(a.x, a.y), lt_minf(a.z, a.w));
}
INLINE float lt_hmax4(float4 a) {
  return lt_maxf(lt_maxf(a.x, a.y), lt_maxf(a.z, a.w));
}
// The one summation order used for the four lanes everywhere (sampling and pmf must agree).
INLINE float lt_sum4(float4 a) {
  return (a.x + a.y) + (a.z + a.w);
}

// ---------------------------------------------------------------- random numbers
// A counter-based stream: value i of stream (seed, stream) is a hash of (key, i). Cheap to carry
// in a kernel's private memory; the host sampler interface uses the same struct.
typedef struct LtRng {
  uint key;
  uint ctr;
} LtRng;

// "lowbias32" integer finaliser (C. Wellons): a bijection with good avalanche.
INLINE uint lt_hash_u32(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}
INLINE LtRng lt_rng_make(uint seed, uint stream) {
  LtRng r;
  r.key = lt_hash_u32(lt_hash_u32(seed ^ 0x3c6ef372u) ^ (stream * 0x9e3779b9u + 0x7f4a7c15u));
  r.ctr = 0u;
  return r;
}
INLINE uint lt_rng_next_u32(LtRng* r) {
  uint x = lt_hash_u32(lt_hash_u32(r->ctr * 0x9e3779b9u + r->key) ^ r->key);
  r->ctr += 1u;
  return x;
}
// Uniform in [0, 1) with 24 random bits.
INLINE float lt_rng_next(LtRng* r) {
  return (float)(lt_rng_next_u32(r) >> 8) * LT_XI_RES0;
}

// ---------------------------------------------------------------- orientation cones (Alg. 1)
typedef struct LtCone {
  float3 axis;   // unit
  float theta_o; // normal bound, [0, pi]
  float theta_e; // emission bound, [0, pi/2]
} LtCone;

INLINE LtCone lt_make_cone(float3 axis, float theta_o, float theta_e) {
  LtCone c;
  c.axis = axis;
  c.theta_o = theta_o;
  c.theta_e = theta_e;
  return c;
}
// Angle between unit vectors, accurate near 0 and pi (unlike acos of the dot product).
INLINE float lt_angle_between(float3 a, float3 b) {
  return atan2(length(cross(a, b)), dot(a, b));
}
// Rodrigues rotation of v about the unit axis k.
INLINE float3 lt_rotate(float3 v, float3 k, float angle) {
  float c = cos(angle);
  float s = sin(angle);
  return v * c + cross(k, v) * s + k * (dot(k, v) * (1.0f - c));
}
INLINE float3 lt_any_perpendicular(float3 a) {
  float3 t = fabs(a.x) < 0.9f ? make_float3(1.0f, 0.0f, 0.0f) : make_float3(0.0f, 1.0f, 0.0f);
  return normalize(cross(a, t));
}
// Union of two non-empty cones (paper Alg. 1). The result's theta_o is re-measured against both
// inputs after the rotation and padded by LT_CONE_PAD, so it covers both inputs despite rounding.
INLINE LtCone lt_cone_union(LtCone a, LtCone b) {
  if (b.theta_o > a.theta_o) {
    LtCone t = a;
    a = b;
    b = t;
  }
  float theta_e = lt_maxf(a.theta_e, b.theta_e);
  if (a.theta_o >= M_PI_F) return lt_make_cone(a.axis, M_PI_F, theta_e);
  float theta_d = lt_angle_between(a.axis, b.axis);
  if (lt_minf(theta_d + b.theta_o, M_PI_F) <= a.theta_o)
    return lt_make_cone(a.axis, a.theta_o, theta_e); // a already covers b
  float theta_o = (a.theta_o + theta_d + b.theta_o) * 0.5f;
  if (theta_o >= M_PI_F) return lt_make_cone(a.axis, M_PI_F, theta_e);
  float theta_r = theta_o - a.theta_o;
  float3 k = cross(a.axis, b.axis);
  float kl = length(k);
  float3 axis;
  if (kl > 1e-6f) {
    axis = normalize(lt_rotate(a.axis, k * (1.0f / kl), theta_r));
  } else if (theta_d < 1.0f) {
    axis = a.axis; // (nearly) parallel: keep a's axis, widen below
  } else {
    axis = normalize(lt_rotate(a.axis, lt_any_perpendicular(a.axis), theta_r)); // antiparallel
  }
  float cover = lt_maxf(lt_angle_between(axis, a.axis) + a.theta_o,
                        lt_angle_between(axis, b.axis) + b.theta_o);
  theta_o = lt_minf(lt_maxf(theta_o, cover) + LT_CONE_PAD, M_PI_F);
  return lt_make_cone(axis, theta_o, theta_e);
}

// ---------------------------------------------------------------- orientation measure (Eq. 1)
// M_Omega = 2pi(1 - cos to) + pi/2 (2 tw sin to - cos(to - 2tw) - 2 to sin to + cos to),
// tw = min(to + te, pi). pi for a flat one-sided emitter (to = 0, te = pi/2), 4pi for a sphere.
INLINE float lt_m_omega(float theta_o, float theta_e) {
  if (theta_o >= M_PI_F) return 4.0f * M_PI_F;
  float tw = lt_minf(theta_o + theta_e, M_PI_F);
  float so = sin(theta_o);
  float co = cos(theta_o);
  return 2.0f * M_PI_F * (1.0f - co) +
         0.5f * M_PI_F * (2.0f * tw * so - cos(theta_o - 2.0f * tw) - 2.0f * theta_o * so + co);
}

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
// 0.85: 38, 0.95: 213, 1: every light (capped by max_cut). 0.85 is kept as the default: it splits
// where the importance is least reliable (near and inside clusters) at a moderate cut size.
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
INLINE int lt_should_split(float measure, float threshold) {
  return threshold >= 1.0f || measure < threshold;
}

// ---------------------------------------------------------------- emitter bounds (Table 1)
// Bounds of one light: bbox, cone (as cosines; theta_o is 0 for one-sided flat emitters, pi for
// points/spheres/two-sided; a spot has theta_o = 0, theta_e = aperture, and an aperture beyond pi/2
// becomes theta_o = aperture - pi/2, theta_e = pi/2 so theta_e <= pi/2 always), and energy: the
// luminance of the maximum radiant intensity: I for point/spot, L pi r^2 for a sphere, L A for a
// quad/triangle (Conty & Kulla §5.1). Non-finite or negative energies count as 0.
LT_HOT void lt_light_bounds(GLOBAL const Light* L, float3* bmin, float3* bmax, float3* axis,
                            float* cos_o, float* cos_e, float* energy) {
  float3 p = xyz_of(L->p);
  float lum = luminance3(xyz_of(L->emission));
  *axis = make_float3(0.0f, 0.0f, 1.0f);
  *cos_o = -1.0f;
  *cos_e = 0.0f;
  *bmin = p;
  *bmax = p;
  float e = lum;
  if (L->type == LIGHT_SPOT) {
    float3 a = xyz_of(L->e1);
    float al = length(a);
    if (al > 0.0f) *axis = a * (1.0f / al);
    float c = lt_clampf(L->e1.w, -1.0f, 1.0f);
    if (c >= 0.0f) {
      *cos_o = 1.0f;
      *cos_e = c;
    } else {
      *cos_o = sqrt(lt_maxf(1.0f - c * c, 0.0f)); // cos(aperture - pi/2) = sin(aperture)
      *cos_e = 0.0f;
    }
  } else if (L->type == LIGHT_SPHERE) {
    float r = fabs(L->p.w);
    *bmin = p - make_float3(r, r, r);
    *bmax = p + make_float3(r, r, r);
    e = lum * M_PI_F * r * r;
  } else if (L->type == LIGHT_QUAD || L->type == LIGHT_TRIANGLE) {
    float3 e1 = xyz_of(L->e1);
    float3 e2 = xyz_of(L->e2);
    float3 c = cross(e1, e2);
    float cl = length(c);
    float area = L->type == LIGHT_QUAD ? cl : 0.5f * cl;
    float3 n = xyz_of(L->n);
    float nl = length(n);
    if (nl > 0.0f) {
      *axis = n * (1.0f / nl);
    } else if (cl > 0.0f) {
      *axis = c * (1.0f / cl);
    }
    *cos_o = (L->flags & LIGHT_FLAG_TWO_SIDED) ? -1.0f : 1.0f;
    float3 q1 = p + e1;
    float3 q2 = p + e2;
    *bmin = lt_min3(p, lt_min3(q1, q2));
    *bmax = lt_max3(p, lt_max3(q1, q2));
    if (L->type == LIGHT_QUAD) {
      float3 q3 = q1 + e2;
      *bmin = lt_min3(*bmin, q3);
      *bmax = lt_max3(*bmax, q3);
    }
    e = lum * area;
  }
  *energy = (e > 0.0f && is_finite_f(e)) ? e : 0.0f;
}
// Bounding sphere of a box, radius rounded up so it contains the box despite rounding.
INLINE float4 lt_sphere_of_box(float3 bmin, float3 bmax) {
  float3 c = (bmin + bmax) * 0.5f;
  float r = 0.5f * length(bmax - bmin);
  return f4_from3(c, r > 0.0f ? r * 1.000001f + 1e-30f : 0.0f);
}

// ---------------------------------------------------------------- cluster importance (Eq. 3)
// Importance of four clusters for a shading point P with unit normal N (N = 0: no orientation,
// e.g. a point in a medium or a two-sided/transmissive surface). Per lane:
//   E * cos(theta') * max(cos(theta_i'), 0) / max(d^2, (r/2)^2), 0 when theta' >= theta_e,
// theta' = max(theta - theta_o - theta_u, 0), theta_i' = max(theta_i - theta_u, 0), sin(theta_u) =
// r/d and theta_u = pi inside the sphere. All angle differences use cos(a-b) = cos a cos b +
// sin a sin b (no acos). Emitters below the horizon of N are culled (opaque surfaces).
// Lanes are normalised by the largest energy and the smallest clamped d^2 among the lanes (only
// ratios matter) and a lane that can contribute gets at least LT_IMPORTANCE_FLOOR: the result is
// never 0 for a cluster that can contribute and never overflows. If no lane can contribute, lanes
// with energy get E/d^2 (see below); only lanes without energy are ever 0 then.
LT_HOT float4 lt_importance4(float4 cx, float4 cy, float4 cz, float4 r, float4 ax, float4 ay,
                             float4 az, float4 cos_o, float4 cos_e, float4 energy, float3 P,
                             float3 N) {
  float4 zero = lt_splat4(0.0f);
  float4 one = lt_splat4(1.0f);
  float4 dx = cx - lt_splat4(P.x);
  float4 dy = cy - lt_splat4(P.y);
  float4 dz = cz - lt_splat4(P.z);
  float4 d2 = dx * dx + dy * dy + dz * dz;
  float4 r2 = r * r;
  lt_mask4 inside = lt_le4(d2, r2);
  float4 d2c = lt_max4(lt_max4(d2, r2 * 0.25f), lt_splat4(1e-36f));
  float4 inv_d = one / lt_sqrt4(lt_max4(d2, lt_splat4(1e-36f)));
  float4 ux = dx * inv_d;
  float4 uy = dy * inv_d;
  float4 uz = dz * inv_d;
  // theta_u: half-angle of the cone from P around the bounding sphere
  float4 sin_u = lt_min4(r * inv_d, one);
  float4 cos_u = lt_sqrt4(lt_max4(one - sin_u * sin_u, zero));
  sin_u = lt_sel4(sin_u, zero, inside);
  cos_u = lt_sel4(cos_u, lt_splat4(-1.0f), inside);
  // theta: angle between the cone axis and the direction from the cluster towards P
  float4 cos_t = zero - (ax * ux + ay * uy + az * uz);
  float4 sin_t = lt_sqrt4(lt_max4(one - cos_t * cos_t, zero));
  float4 sin_o = lt_sqrt4(lt_max4(one - cos_o * cos_o, zero));
  // theta - theta_o, clamped at 0
  lt_mask4 within_o = lt_ge4(cos_t, cos_o);
  float4 c1 = lt_sel4(cos_t * cos_o + sin_t * sin_o, one, within_o);
  float4 s1 = lt_sel4(sin_t * cos_o - cos_t * sin_o, zero, within_o);
  // minus theta_u, clamped at 0
  float4 c2 = lt_sel4(c1 * cos_u + s1 * sin_u, one, lt_ge4(c1, cos_u));
  float4 orient = lt_sel4(zero, c2, lt_gt4(c2, cos_e));
  // incidence at P
  float4 cos_i = one;
  if (N.x != 0.0f || N.y != 0.0f || N.z != 0.0f) {
    float4 ci = ux * N.x + uy * N.y + uz * N.z;
    float4 si = lt_sqrt4(lt_max4(one - ci * ci, zero));
    cos_i = lt_sel4(ci * cos_u + si * sin_u, one, lt_ge4(ci, cos_u));
    cos_i = lt_max4(cos_i, zero);
  }
  lt_mask4 alive = lt_gt4(energy, zero);
  float emax = lt_hmax4(energy);
  float dmin2 = lt_hmin4(lt_sel4(lt_splat4(3.0e38f), d2c, alive));
  float inv_emax = emax > 0.0f ? 1.0f / emax : 0.0f;
  float4 e = energy * inv_emax;
  float4 g = lt_splat4(dmin2) / d2c;
  float4 oc = orient * cos_i;
  float4 imp = e * g * oc;
  lt_mask4 contributes = lt_and4(alive, lt_gt4(oc, zero));
  float4 res = lt_sel4(zero, lt_max4(imp, lt_splat4(LT_IMPORTANCE_FLOOR)), contributes);
  // No lane can contribute but some has energy (bounds of the parent were looser than those of
  // its children): rank by energy and distance alone, so a descent never dead-ends and the pmf
  // sums to 1 over the lights with energy. Such picks contribute 0, which keeps them unbiased.
  if (!(lt_sum4(res) > 0.0f) && emax > 0.0f)
    res = lt_sel4(zero, lt_max4(e * g, lt_splat4(LT_IMPORTANCE_FLOOR)), alive);
  return res;
}

// ---------------------------------------------------------------- tree traversal (Alg. 2)
// A view of the tree buffers (kernel: build it from the kernel arguments in private memory).
typedef struct LtTree {
  GLOBAL const float4* nodes;    // LT_NODE_F4 per node
  GLOBAL const int4* children;   // one per node
  GLOBAL const int* leaf_lights; // light indices in leaf order
  GLOBAL const uint* trails;     // per light index
  GLOBAL const Light* lights;    // the scene's lights
  float4 root_sphere;            // bounding sphere of all emitters
  float4 root_info;              // x: energy CV^2, y: total energy
} LtTree;

INLINE int lt_is_leaf(int code) {
  return code < 0 && code != LT_EMPTY;
}
INLINE int lt_leaf_first(int code) {
  return (-1 - code) >> 2;
}
INLINE int lt_leaf_count(int code) {
  return ((-1 - code) & 3) + 1;
}
INLINE int lt_leaf_code(int first, int count) {
  return -1 - ((first << 2) | (count - 1));
}

LT_HOT float4 lt_node_importance(const LtTree* t, int node, float3 P, float3 N) {
  GLOBAL const float4* n = t->nodes + node * LT_NODE_F4;
  return lt_importance4(n[LT_CX], n[LT_CY], n[LT_CZ], n[LT_R], n[LT_AX], n[LT_AY], n[LT_AZ],
                        n[LT_COS_O], n[LT_COS_E], n[LT_ENERGY], P, N);
}

// Importance of the (up to four) emitters of a leaf, from their Light records.
LT_HOT float4 lt_leaf_importance(const LtTree* t, int code, float3 P, float3 N) {
  int first = lt_leaf_first(code);
  int count = lt_leaf_count(code);
  float v[10][4];
  for (int j = 0; j < 4; ++j) {
    for (int k = 0; k < 10; ++k)
      v[k][j] = 0.0f;
    if (j < count) {
      float3 bmin, bmax, axis;
      float co, ce, en;
      lt_light_bounds(t->lights + t->leaf_lights[first + j], &bmin, &bmax, &axis, &co, &ce, &en);
      float4 s = lt_sphere_of_box(bmin, bmax);
      v[0][j] = s.x;
      v[1][j] = s.y;
      v[2][j] = s.z;
      v[3][j] = s.w;
      v[4][j] = axis.x;
      v[5][j] = axis.y;
      v[6][j] = axis.z;
      v[7][j] = co;
      v[8][j] = ce;
      v[9][j] = en;
    }
  }
#define LT_V4(k) make_float4(v[k][0], v[k][1], v[k][2], v[k][3])
  return lt_importance4(LT_V4(0), LT_V4(1), LT_V4(2), LT_V4(3), LT_V4(4), LT_V4(5), LT_V4(6),
                        LT_V4(7), LT_V4(8), LT_V4(9), P, N);
#undef LT_V4
}

// Importances of the four lanes below `code` (a node or a leaf).
INLINE float4 lt_code_importance(const LtTree* t, int code, float3 P, float3 N) {
  return code >= 0 ? lt_node_importance(t, code, P, N) : lt_leaf_importance(t, code, P, N);
}

// Probability of lane k: I_k / (sum of the four). 0 if nothing contributes.
LT_HOT float lt_lane_prob(float4 imp, int k) {
  float s = lt_sum4(imp);
  float ik = f4_get(imp, k);
  return (s > 0.0f && ik > 0.0f) ? ik / s : 0.0f;
}

// Chooses lane k with probability I_k / sum using *xi in [0,1) and rescales *xi to [0,1) for the
// next decision. Returns -1 if no lane contributes. Lane k is chosen when c_{k-1} <= xi * sum < c_k
// (prefix sums), so a lane of importance 0 is never chosen.
LT_HOT int lt_choose_lane(float4 imp, float* xi) {
  float s = lt_sum4(imp);
  if (!(s > 0.0f) || !is_finite_f(s)) return -1;
  float target = *xi * s;
  float c0 = imp.x;
  float c1 = c0 + imp.y;
  float c2 = c1 + imp.z;
  int k = (target >= c0) + (target >= c1) + (target >= c2);
  while (k > 0 && !(f4_get(imp, k) > 0.0f))
    --k; // target rounded past the last lane
  float lo = k == 0 ? 0.0f : (k == 1 ? c0 : (k == 2 ? c1 : c2));
  if (!(f4_get(imp, k) > 0.0f)) { // only reachable when lane 0 is empty and target < c0 = 0
    while (k < 3 && !(f4_get(imp, k) > 0.0f))
      ++k;
    lo = 0.0f;
  }
  *xi = lt_clampf((target - lo) / f4_get(imp, k), 0.0f, LT_ONE_MINUS_EPS);
  return k;
}

// Prefetches (host) the records of the children of `node` that the next step will read.
LT_HOT void lt_prefetch_children(const LtTree* t, int4 ch) {
  for (int k = 0; k < 4; ++k) {
    int c = i4_get(ch, k);
    if (c >= 0) {
      GLOBAL const float4* n = t->nodes + c * LT_NODE_F4;
      LT_PREFETCH(n);
      LT_PREFETCH(n + 4);
      LT_PREFETCH(n + 8);
      LT_PREFETCH(n + 10);
      LT_PREFETCH(t->children + c);
    } else if (c != LT_EMPTY) {
      LT_PREFETCH(t->leaf_lights + lt_leaf_first(c));
    }
  }
}

// Stochastic descent (Alg. 2) from `code` (a node index or a leaf code) to one light. `xi` is the
// first random number, `rng` the stream xi is refreshed from once fewer than log2(1/res_limit)
// bits of it remain (pass LT_XI_RES_LIMIT). Returns the light index, or -1 if nothing below `code`
// contributes; *prob = product of the lane probabilities taken below `code`.
INLINE int lt_pick_below(const LtTree* t, int code, float3 P, float3 N, float xi, LtRng* rng,
                         float res_limit, float* prob) {
  float p = 1.0f;
  // xi's resolution is LT_XI_RES0 / q, q = product of the probabilities since the last refresh
  float q_min = LT_XI_RES0 / res_limit;
  float q = 1.0f;
  *prob = 0.0f;
  while (code >= 0) {
    int4 ch = t->children[code];
    lt_prefetch_children(t, ch);
    float4 imp = lt_node_importance(t, code, P, N);
    int lane = lt_choose_lane(imp, &xi);
    if (lane < 0) return -1;
    float pk = lt_lane_prob(imp, lane);
    p = p * pk;
    q = q * pk;
    if (q < q_min) {
      xi = lt_rng_next(rng);
      q = 1.0f;
    }
    code = i4_get(ch, lane);
  }
  if (code == LT_EMPTY) return -1;
  float4 imp = lt_leaf_importance(t, code, P, N);
  int lane = lt_choose_lane(imp, &xi);
  if (lane < 0) return -1;
  p = p * lt_lane_prob(imp, lane);
  *prob = p;
  return t->leaf_lights[lt_leaf_first(code) + lane];
}

// Probability that lt_pick_below(code) returns the light whose remaining trail (decision at `code`
// in the lowest two bits) is `trail`: the same importances, the same lane probabilities.
INLINE float lt_pmf_below(const LtTree* t, int code, float3 P, float3 N, uint trail) {
  float p = 1.0f;
  while (code >= 0) {
    int4 ch = t->children[code];
    int lane = (int)(trail & 3u);
    trail = trail >> 2;
    int next = i4_get(ch, lane);
    if (next >= 0) {
      LT_PREFETCH(t->nodes + next * LT_NODE_F4);
      LT_PREFETCH(t->nodes + next * LT_NODE_F4 + 4);
      LT_PREFETCH(t->nodes + next * LT_NODE_F4 + 8);
      LT_PREFETCH(t->nodes + next * LT_NODE_F4 + 10);
      LT_PREFETCH(t->children + next);
    }
    float4 imp = lt_node_importance(t, code, P, N);
    float pk = lt_lane_prob(imp, lane);
    if (!(pk > 0.0f)) return 0.0f;
    p = p * pk;
    code = next;
  }
  if (code == LT_EMPTY) return 0.0f;
  float4 imp = lt_leaf_importance(t, code, P, N);
  return p * lt_lane_prob(imp, (int)(trail & 3u));
}

// ---------------------------------------------------------------- splitting (Alg. 3)
// A split item is a cluster: its bounding sphere, energy CV^2, code (node or leaf) and the cut
// budget it may still spend. The root item is (root_sphere, root_info.x, 0, max_cut). An item
// splits when lt_item_splits() says so: it then becomes one item per contributing lane (node: the
// children with importance > 0, budget / number of non-empty lanes; leaf: each contributing
// emitter taken with probability 1). Otherwise it yields lt_pick_below(code) with its probability.
// The budget rule bounds the cut by max_cut and, being a function of the path only, lets the pmf
// of one light be recomputed (lt_pmf_split) without knowing the rest of the cut.
INLINE int lt_code_lanes(const LtTree* t, int code) {
  if (code == LT_EMPTY) return 0;
  if (code < 0) return lt_leaf_count(code);
  int4 c = t->children[code];
  return (c.x != LT_EMPTY) + (c.y != LT_EMPTY) + (c.z != LT_EMPTY) + (c.w != LT_EMPTY);
}
INLINE int lt_item_splits(const LtTree* t, float4 sphere, float cv2, int code, uint budget,
                          float3 P, float threshold) {
  int m = lt_code_lanes(t, code);
  if (m < 1 || (uint)m > budget) return 0;
  return lt_should_split(lt_split_measure(P, sphere, cv2), threshold);
}
// The child item of node `node` in lane `lane` (sphere and CV^2 from the node's lanes).
INLINE float4 lt_lane_sphere(const LtTree* t, int node, int lane) {
  GLOBAL const float4* n = t->nodes + node * LT_NODE_F4;
  return make_float4(f4_get(n[LT_CX], lane), f4_get(n[LT_CY], lane), f4_get(n[LT_CZ], lane),
                     f4_get(n[LT_R], lane));
}
INLINE float lt_lane_cv2(const LtTree* t, int node, int lane) {
  return f4_get(t->nodes[node * LT_NODE_F4 + LT_CV2], lane);
}

// pmf of `light` under splitting (DESIGN §4 "MIS with splitting"): 1 above the item where the
// deterministic split stopped, times the lane probabilities below it along the light's bit-trail.
INLINE float lt_pmf_split(const LtTree* t, float3 P, float3 N, int light, float threshold,
                          uint max_cut) {
  uint trail = t->trails[light];
  float4 sphere = t->root_sphere;
  float cv2 = t->root_info.x;
  int code = 0;
  uint budget = max_cut;
  for (;;) {
    if (!lt_item_splits(t, sphere, cv2, code, budget, P, threshold))
      return lt_pmf_below(t, code, P, N, trail);
    budget = budget / (uint)lt_code_lanes(t, code);
    int lane = (int)(trail & 3u);
    trail = trail >> 2;
    float4 imp = lt_code_importance(t, code, P, N);
    if (!(f4_get(imp, lane) > 0.0f)) return 0.0f;
    if (code < 0) return 1.0f; // split leaf: every contributing emitter is taken
    sphere = lt_lane_sphere(t, code, lane);
    cv2 = lt_lane_cv2(t, code, lane);
    code = i4_get(t->children[code], lane);
  }
}

#endif // CANOPY_LIGHT_TREE_MATH_H
