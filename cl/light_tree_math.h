// Light tree math shared by the host reference (C++20) and the OpenCL kernels (OpenCL C 1.2):
// Conty Estevez & Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree Splitting".
// See docs/DESIGN.md sections 2-4. Everything below the helper layer is written once and compiles
// as both languages, so sampling on the host and on the device make the very same decisions.
//
// ---------------------------------------------------------------- device layout of the tree
// The tree is 4-wide. Node `n` owns LT_NODE_F4 (8) consecutive float4 in `nodes` (struct of
// arrays: record k holds one quantity for the node's four children, lane i = child i; 128 bytes)
// and one int4 in `children`:
//   nodes[n*8 + 0..2]  LT_CX, LT_CY, LT_CZ   bounding-sphere centre of each child
//   nodes[n*8 + 3]     LT_R                  bounding-sphere radius (sphere of the child's bbox)
//   nodes[n*8 + 4]     LT_AXIS               orientation cone axis, octahedral, 2 x 16 bits (the
//                                            bits of the float; lt_oct_decode_v)
//   nodes[n*8 + 5]     LT_COS_O              cos(theta_o) (normal bound), widened by the axis
//                                            quantisation error and rounded down; LT_PLANE_FLAG
//                                            (2): a lane of one-sided planar emitters with a
//                                            half-space bound, theta_o = LT_PLANE_SLOPE
//   nodes[n*8 + 6]     LT_ENERGY             sum of emitter energies (luminance of max intensity)
//   nodes[n*8 + 7]     LT_CE_CV2             bits 0-15: cos(theta_e) * 65535 rounded down
//                                            (emission bound, theta_e <= pi/2), or for a
//                                            LT_PLANE_FLAG lane (theta_e = pi/2) the plane offset
//                                            k: h = (k - 32768) r 2^-14; bits 16-31: the
//                                            high half of the float V[e]/E[e]^2 (squared
//                                            coefficient of variation of the energies, splitting)
//   children[n].lane   >= 0: index of a child node (the child nodes of a node are consecutive)
//                      LT_EMPTY: unused lane (its energy is 0)
//                      other < 0: leaf, code = -1 - child = (first << 2) | (count - 1): the
//                      emitters leaf_lights[first .. first+count), count in 1..4
// Node 0 is the root. After the num_nodes * 8 node records, `nodes` holds one emitter record of
// LT_EMITTER_F4 (2) float4 per emitter in leaf order (index first + j), starting at float4 index
// lt_emitter_base() (root_info.z holds its bits plus LT_EMITTER_BASE_BIAS):
//   record[0]  bounding sphere of the emitter (centre, radius), as in the nodes
//   record[1]  x: octahedral axis bits; y: cone q (q <= 1: cos(theta_o), theta_e = pi/2; q > 1.5:
//              theta_o = 0, cos(theta_e) = q - 2; widened by the axis quantisation error;
//              q < -1.5: one-sided planar, theta_o = LT_PLANE_SLOPE, theta_e = pi/2, half-space
//              bound h = (-2 - q) r); z: energy; w: bits of the light index
//              (= leaf_lights[first + j])
// so a leaf is ranked from its records without touching the scene's Light buffer. The tree costs
// 52-61 bytes/emitter. trails[light]: the light's bit-trail, 2 bits per 4-wide level starting with
// the root in the two lowest bits, then 2 bits for its index inside its leaf. root_sphere /
// root_info: bounding sphere of all emitters; (cv2, total energy, emitter record base, importance
// terms: LT_TERMS_FULL or LT_TERMS_DISTANCE).
#ifndef CANOPY_LIGHT_TREE_MATH_H
#define CANOPY_LIGHT_TREE_MATH_H

#include "compat.h"
#include "rng.h"
#include "types.h"

#define LT_NODE_F4 8
#define LT_CX 0
#define LT_CY 1
#define LT_CZ 2
#define LT_R 3
#define LT_AXIS 4
#define LT_COS_O 5
#define LT_ENERGY 6
#define LT_CE_CV2 7

// Emitter records: LT_EMITTER_F4 float4 per emitter, in leaf order, after the node records.
#define LT_EMITTER_F4 2
#define LT_EMITTER_BASE_BIAS 0x40000000u
#define LT_OCT_SCALE 3.0518044e-05f /* 2 / 65535 */
#define LT_U16_SCALE 1.5259022e-05f /* 1 / 65535 */

#define LT_EMPTY (-2147483647 - 1)
#define LT_MAX_LEAF 4
// 4-wide node levels below the root (inclusive) so that 2 bits per level + 2 leaf bits fit a uint.
#define LT_MAX_NODE_LEVELS 15
// Smallest importance given to a lane that can contribute, so underflow never makes it 0 (the
// importances of the four lanes are normalised by their maximum energy and minimum distance first).
#define LT_IMPORTANCE_FLOOR 1e-30f
// Uniform floats from the rng carry 24 random bits (lt_rng_next).
#define LT_XI_RES0 5.9604645e-08f /* 2^-24 */
// 2^32 as a float (exact): scales a probability to the units of one 32-bit random word.
#define LT_TWO_POW_32 4294967296.0f
#define LT_TWO_POW_24 16777216.0f
// Cone unions are padded by this angle (radians) so rounding never uncovers an input.
#define LT_CONE_PAD 2e-6f
// Importance terms (root_info.w). LT_TERMS_DISTANCE drops the orientation factors of Eq. 3 (the
// emitter cone cos(theta') and the receiver cos(theta_i')) and keeps E / d^2: the ablation of the
// paper's Fig. 15-16 ("distance" against "distance + orientation"). The tree itself is unchanged.
#define LT_TERMS_FULL 0.0f
#define LT_TERMS_DISTANCE 1.0f
// A cut budget that never binds (the exhaustive sampler: threshold 1 splits down to every light).
#define LT_BUDGET_UNLIMITED 0x7fffffffu
// Default threshold of the adaptive split (see lt_split_measure for its meaning and calibration).
#define LT_DEFAULT_SPLIT_THRESHOLD 0.25f
// Half-space bound of one-sided planar emitters (quads, triangles, mesh triangles): such an emitter
// sends nothing to a point on or behind its plane. A lane with a plane offset h (the emitters of
// the lane all lie on the front side of the plane through c - h a, a = the lane's decoded axis) is
// culled at P when dot(a, P - c) <= -(h + LT_PLANE_SLOPE |P - c|), c = the lane's sphere centre.
// The slope covers the angle between a and every emitter's own normal (octahedral quantisation,
// and for a node the spread of its emitters' normals: nodes qualify when it is below
// LT_PLANE_SLOPE - LT_PLANE_ROUND) plus the float rounding of the test (LT_PLANE_ROUND, relative
// to |P - c|); h absorbs the rest (the emitters' extent below c, the rounding of their sample
// points). Such lanes have the cone theta_o = LT_PLANE_SLOPE, theta_e = pi/2.
#define LT_PLANE_SLOPE 2.4414062e-04f /* 2^-12 */
#define LT_PLANE_ROUND 3.8146973e-06f /* 2^-18 */
#define LT_PLANE_COS_O 0.99999994f    /* cos(2^-12) rounded down */
#define LT_PLANE_NONE 3.0e38f         /* h of a lane without a plane: never culls */
// Node lanes with a plane: LT_COS_O holds LT_PLANE_FLAG (> 1, no cosine) and the low 16 bits of
// LT_CE_CV2 hold k, h = (k - 32768) * (r * LT_PLANE_H_UNIT) (theta_e = pi/2 needs no bits).
#define LT_PLANE_FLAG 2.0f
#define LT_PLANE_H_UNIT 6.1035156e-05f /* 2^-14 */

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
#define LT_HOT static inline __attribute__((always_inline))
// CPU devices (PoCL) have one flat address space: prefetch through an integer round trip (clang's
// builtin takes a private pointer in OpenCL C 1.2).
#if defined(__clang__) && defined(__x86_64__)
#define LT_PREFETCH(addr) __builtin_prefetch((const void*)(ulong)(addr))
#else
#define LT_PREFETCH(addr) ((void)(addr))
#endif
// The low / high 16 bits of the bit patterns of four floats, as floats (exact).
INLINE float4 lt_lo16_4(float4 bits) {
  return convert_float4(as_uint4(bits) & (uint4)(0xffffu));
}
INLINE float4 lt_hi16_4(float4 bits) {
  return convert_float4(as_uint4(bits) >> (uint4)(16u));
}
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
INLINE float4 lt_lo16_4(float4 bits) {
  __m128i i = _mm_and_si128(_mm_castps_si128(lt_ps_(bits)), _mm_set1_epi32(0xffff));
  return lt_f4_(_mm_cvtepi32_ps(i));
}
INLINE float4 lt_hi16_4(float4 bits) {
  __m128i i = _mm_srli_epi32(_mm_castps_si128(lt_ps_(bits)), 16);
  return lt_f4_(_mm_cvtepi32_ps(i));
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
INLINE float4 lt_lo16_4(float4 b) {
  return make_float4((float)(float_as_uint_(b.x) & 0xffffu), (float)(float_as_uint_(b.y) & 0xffffu),
                     (float)(float_as_uint_(b.z) & 0xffffu),
                     (float)(float_as_uint_(b.w) & 0xffffu));
}
INLINE float4 lt_hi16_4(float4 b) {
  return make_float4((float)(float_as_uint_(b.x) >> 16), (float)(float_as_uint_(b.y) >> 16),
                     (float)(float_as_uint_(b.z) >> 16), (float)(float_as_uint_(b.w) >> 16));
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

// ---------------------------------------------------------------- 4-lane vectors for the hot path
// lt_v4 is float4 on the device, an SSE register on the x86-64 host (the float4 struct of
// compat.h would go through memory). Every operation is the same IEEE operation lane by lane, in
// the same order, so host and device compute identical bits.
#ifdef __OPENCL_C_VERSION__
typedef float4 lt_v4;
typedef int4 lt_vm4;
#define lt_vf(a) (a)
#define lt_fv(a) (a)
#define lt_vld(p) (*(p))
#define lt_vs(s) ((float4)(s))
#define lt_vadd(a, b) ((a) + (b))
#define lt_vsub(a, b) ((a) - (b))
#define lt_vmul(a, b) ((a) * (b))
#define lt_vdiv(a, b) ((a) / (b))
#define lt_vsqrt(a) sqrt(a)
#define lt_vmin(a, b) fmin(a, b)
#define lt_vmax(a, b) fmax(a, b)
#define lt_vlt(a, b) ((a) < (b))
#define lt_vle(a, b) ((a) <= (b))
#define lt_vgt(a, b) ((a) > (b))
#define lt_vge(a, b) ((a) >= (b))
#define lt_vand(a, b) ((a) & (b))
#define lt_vsel(a, b, m) select(a, b, m)
#define lt_vlo16(a) convert_float4(as_uint4(a) & (uint4)(0xffffu))
#define lt_vhi16(a) convert_float4(as_uint4(a) >> (uint4)(16u))
INLINE float lt_vhmax(float4 a) {
  return fmax(fmax(a.x, a.y), fmax(a.z, a.w));
}
INLINE float lt_vhmin(float4 a) {
  return fmin(fmin(a.x, a.y), fmin(a.z, a.w));
}
#define lt_vall(m) all(m)
#elif defined(__SSE2__)
typedef __m128 lt_v4;
typedef __m128 lt_vm4;
INLINE lt_v4 lt_vf(float4 a) {
  return _mm_load_ps(&a.x);
}
INLINE float4 lt_fv(lt_v4 v) {
  float4 r;
  _mm_store_ps(&r.x, v);
  return r;
}
INLINE lt_v4 lt_vld(const float4* p) {
  return _mm_load_ps(&p->x);
}
#define lt_vs(s) _mm_set1_ps(s)
#define lt_vadd(a, b) _mm_add_ps(a, b)
#define lt_vsub(a, b) _mm_sub_ps(a, b)
#define lt_vmul(a, b) _mm_mul_ps(a, b)
#define lt_vdiv(a, b) _mm_div_ps(a, b)
#define lt_vsqrt(a) _mm_sqrt_ps(a)
#define lt_vmin(a, b) _mm_min_ps(a, b)
#define lt_vmax(a, b) _mm_max_ps(a, b)
#define lt_vlt(a, b) _mm_cmplt_ps(a, b)
#define lt_vle(a, b) _mm_cmple_ps(a, b)
#define lt_vgt(a, b) _mm_cmpgt_ps(a, b)
#define lt_vge(a, b) _mm_cmpge_ps(a, b)
#define lt_vand(a, b) _mm_and_ps(a, b)
INLINE lt_v4 lt_vsel(lt_v4 a, lt_v4 b, lt_vm4 m) {
  return _mm_or_ps(_mm_and_ps(m, b), _mm_andnot_ps(m, a));
}
INLINE lt_v4 lt_vlo16(lt_v4 a) {
  return _mm_cvtepi32_ps(_mm_and_si128(_mm_castps_si128(a), _mm_set1_epi32(0xffff)));
}
INLINE lt_v4 lt_vhi16(lt_v4 a) {
  return _mm_cvtepi32_ps(_mm_srli_epi32(_mm_castps_si128(a), 16));
}
#define lt_vtranspose(a, b, c, d) _MM_TRANSPOSE4_PS(a, b, c, d)
#define lt_vall(m) (_mm_movemask_ps(m) == 15) /* every lane of a comparison mask is set */
INLINE float lt_vhmax(lt_v4 a) {
  __m128 m = _mm_max_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtss_f32(_mm_max_ss(m, _mm_movehl_ps(m, m)));
}
INLINE float lt_vhmin(lt_v4 a) {
  __m128 m = _mm_min_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtss_f32(_mm_min_ss(m, _mm_movehl_ps(m, m)));
}
INLINE float lt_vsum(lt_v4 a) { // (x + y) + (z + w)
  __m128 t = _mm_add_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtss_f32(_mm_add_ss(t, _mm_movehl_ps(t, t)));
}
#else
typedef float4 lt_v4;
typedef lt_mask4 lt_vm4;
#define lt_vf(a) (a)
#define lt_fv(a) (a)
#define lt_vld(p) (*(p))
#define lt_vs(s) lt_splat4(s)
#define lt_vadd(a, b) ((a) + (b))
#define lt_vsub(a, b) ((a) - (b))
#define lt_vmul(a, b) ((a) * (b))
#define lt_vdiv(a, b) ((a) / (b))
#define lt_vsqrt(a) lt_sqrt4(a)
#define lt_vmin(a, b) lt_min4(a, b)
#define lt_vmax(a, b) lt_max4(a, b)
#define lt_vlt(a, b) lt_lt4(a, b)
#define lt_vle(a, b) lt_le4(a, b)
#define lt_vgt(a, b) lt_gt4(a, b)
#define lt_vge(a, b) lt_ge4(a, b)
#define lt_vand(a, b) lt_and4(a, b)
#define lt_vsel(a, b, m) lt_sel4(a, b, m)
#define lt_vlo16(a) lt_lo16_4(a)
#define lt_vhi16(a) lt_hi16_4(a)
INLINE float lt_vhmax(float4 a) {
  return lt_maxf(lt_maxf(a.x, a.y), lt_maxf(a.z, a.w));
}
INLINE float lt_vhmin(float4 a) {
  return lt_minf(lt_minf(a.x, a.y), lt_minf(a.z, a.w));
}
#define lt_vall(m) ((m).x && (m).y && (m).z && (m).w)
#endif
#if defined(__OPENCL_C_VERSION__) || !defined(__SSE2__)
// float4 lanes (OpenCL C, or C++ without SSE2): the same transpose and horizontal sum.
#define lt_vtranspose(a, b, c, d)                                                                  \
  do {                                                                                             \
    float4 t0_ = make_float4(a.x, b.x, c.x, d.x), t1_ = make_float4(a.y, b.y, c.y, d.y);           \
    float4 t2_ = make_float4(a.z, b.z, c.z, d.z), t3_ = make_float4(a.w, b.w, c.w, d.w);           \
    a = t0_;                                                                                       \
    b = t1_;                                                                                       \
    c = t2_;                                                                                       \
    d = t3_;                                                                                       \
  } while (0)
INLINE float lt_vsum(float4 a) {
  return (a.x + a.y) + (a.z + a.w);
}
#endif

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

// Counter-based stream keyed by hash_u32 (cl/rng.h: the "lowbias32" finaliser).
INLINE LtRng lt_rng_make(uint seed, uint stream) {
  LtRng r;
  r.key = hash_u32(hash_u32(seed ^ 0x3c6ef372u) ^ (stream * 0x9e3779b9u + 0x7f4a7c15u));
  r.ctr = 0u;
  return r;
}
INLINE uint lt_rng_next_u32(LtRng* r) {
  uint x = hash_u32(hash_u32(r->ctr * 0x9e3779b9u + r->key) ^ r->key);
  r->ctr += 1u;
  return x;
}
// Uniform in [0, 1) with 24 random bits.
INLINE float lt_rng_next(LtRng* r) {
  return (float)(lt_rng_next_u32(r) >> 8) * LT_XI_RES0;
}

// ---------------------------------------------------------------- exact discrete choices
// Every discrete choice (uniform index, alias slot and test, tree lane) is made from 32-bit
// random words with exactly the probability the pmf functions report, at any light count and any
// dynamic range (DESIGN §9). A float u in [0, 1) has 24 bits: it cannot index more than 2^24
// items, nor resolve a probability below 2^-24, and a rescaled u loses bits at every decision.

// floor(a * b / 2^32).
INLINE uint lt_mulhi(uint a, uint b) {
#ifdef __OPENCL_C_VERSION__
  return mul_hi(a, b);
#else
  return (uint)(((unsigned long long)a * (unsigned long long)b) >> 32);
#endif
}

// A uniform index in [0, n), n >= 1: floor(W n / 2^64) for a 64-bit random W (two words), with a
// 32 x 32-bit multiply-high per word and no loop (a rejection loop, Lemire 2019, would be exact
// but keeps PoCL from vectorising the kernel across work items: 3x the cost of a uniform pick).
// Every index has floor or ceil of 2^64 / n of the 2^64 values of W: its probability is 1/n to a
// relative n * 2^-64 (< 3e-12 for the format's 5e7 lights, far below the float pmf's own 6e-8).
// A 24-bit float u could not reach more than 2^24 lights, and u32 * n >> 32 alone would be off by
// up to n * 2^-32 (1% at 5e7 lights).
INLINE uint lt_rng_index(LtRng* r, uint n) {
  uint w1 = lt_rng_next_u32(r); // high word of W
  uint w0 = lt_rng_next_u32(r);
  uint mid = w1 * n;                              // low half of w1 * n (weight 2^32)
  uint sum = mid + lt_mulhi(w0, n);               // plus the high half of w0 * n
  return lt_mulhi(w1, n) + (sum < mid ? 1u : 0u); // carry into 2^64
}

// One 32-bit word w of a uniform U = 0.w1 w2 w3 ... (binary) against a boundary whose scaled value
// *x = c * 2^32 (or its remainder after the previous words, all equal to the boundary's) is in
// [0, 2^32). Returns 1 if U >= c, 0 if U < c, 2 if w ties with floor(*x) and the boundary has a
// nonzero fraction: then *x becomes that fraction * 2^32 for the next word. x - floor(x) of a
// float is exact, and so is the scaling, so each word compares 32 more bits of the boundary
// exactly: a float boundary in (0, 1) has no bit below 2^-149, so it is resolved after at most 5
// words (LT_MAX_WORDS), and a tie happens with probability 2^-32 per word.
INLINE int lt_word_vs(uint w, float* x) {
  float f = floor(*x);
  uint fi = (uint)f;
  float rest = *x - f;
  if (w != fi || rest == 0.0f) return w >= fi ? 1 : 0;
  *x = rest * LT_TWO_POW_32;
  return 2;
}

// Words of U that can be needed to compare it with a float boundary: its lowest bit is at
// 2^-149 or above, and 5 words hold 160 bits. A fixed count (no data-dependent loop) keeps kernels
// vectorisable; after LT_MAX_WORDS words a tie cannot remain.
#define LT_MAX_WORDS 5

// P(result = 1) = c exactly, for any float c (denormals included; c <= 0 or NaN: never, c >= 1:
// always). w is U's first word; further words are drawn from r only on a tie.
INLINE int lt_u_below(uint w, float c, LtRng* r) {
  if (!(c > 0.0f)) return 0;
  if (c >= 1.0f) return 1;
  float x = c * LT_TWO_POW_32;
  int o = lt_word_vs(w, &x);
  for (int k = 1; k < LT_MAX_WORDS; ++k)
    if (o == 2) o = lt_word_vs(lt_rng_next_u32(r), &x);
  return o == 0;
}

// Alias method (Walker 1977; table by Vose 1991): slot i in [0, n) uniformly, then i itself when
// U < threshold[i], else alias[i]; the slot and U come from independent words.
INLINE int lt_alias_pick(GLOBAL const float* threshold, GLOBAL const int* alias, uint n, LtRng* r) {
  uint slot = lt_rng_index(r, n);
  uint w = lt_rng_next_u32(r);
  return lt_u_below(w, threshold[slot], r) ? (int)slot : alias[slot];
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
INLINE int lt_should_split(float measure, float threshold) {
  return threshold >= 1.0f || measure < threshold;
}

// ---------------------------------------------------------------- emitter bounds (Table 1)
// Bounds of one light: bbox, cone (as cosines; theta_o is 0 for one-sided flat emitters, pi for
// points/spheres/two-sided; a spot has theta_o = 0, theta_e = aperture, and an aperture beyond pi/2
// becomes theta_o = aperture - pi/2, theta_e = pi/2 so theta_e <= pi/2 always), and energy: the
// luminance of the maximum radiant intensity: I for point/spot, L pi r^2 for a sphere, L A for a
// quad/triangle/disk (Conty & Kulla §5.1). Non-finite or negative energies count as 0.
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
  } else if (L->type == LIGHT_DISK) {
    // Oriented like a quad. Box: the disk's extent along axis i is r sqrt(1 - n_i^2) (the
    // projection of a circle), padded by 2^-20 of r and of |centre| so the box holds the sampled
    // points despite their rounding (cl/light_sample.h).
    float3 n = xyz_of(L->n);
    float r = fabs(L->p.w);
    float nl = length(n);
    if (nl > 0.0f) *axis = n * (1.0f / nl);
    *cos_o = (L->flags & LIGHT_FLAG_TWO_SIDED) ? -1.0f : 1.0f;
    float3 a = *axis;
    float3 ext =
        make_float3(sqrt(lt_maxf(1.0f - a.x * a.x, 0.0f)), sqrt(lt_maxf(1.0f - a.y * a.y, 0.0f)),
                    sqrt(lt_maxf(1.0f - a.z * a.z, 0.0f))) *
            (r * 1.000001f) +
        fabs(p) * 9.5367432e-07f;
    *bmin = p - ext;
    *bmax = p + ext;
    e = lum * M_PI_F * r * r; // L A: the intensity along the normal, as for a quad
  }
  *energy = (e > 0.0f && is_finite_f(e)) ? e : 0.0f;
}
// Bounding sphere of a box, radius rounded up so it contains the box despite rounding.
INLINE float4 lt_sphere_of_box(float3 bmin, float3 bmax) {
  float3 c = (bmin + bmax) * 0.5f;
  float r = 0.5f * length(bmax - bmin);
  return f4_from3(c, r > 0.0f ? r * 1.000001f + 1e-30f : 0.0f);
}

// |a x d| lane-wise: with 1/|d| the sine of the angle between a unit vector a and d.
LT_HOT lt_v4 lt_vcross_len(lt_v4 ax, lt_v4 ay, lt_v4 az, lt_v4 dx, lt_v4 dy, lt_v4 dz) {
  lt_v4 kx = lt_vsub(lt_vmul(ay, dz), lt_vmul(az, dy));
  lt_v4 ky = lt_vsub(lt_vmul(az, dx), lt_vmul(ax, dz));
  lt_v4 kz = lt_vsub(lt_vmul(ax, dy), lt_vmul(ay, dx));
  return lt_vsqrt(lt_vadd(lt_vadd(lt_vmul(kx, kx), lt_vmul(ky, ky)), lt_vmul(kz, kz)));
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
// never 0 for a cluster that can contribute and never overflows. A lane whose half-space bound
// (plane offset h, see LT_PLANE_SLOPE; LT_PLANE_NONE: none) puts P behind all its one-sided planar
// emitters is 0 whatever its sphere, P inside it included. If no lane can contribute and
// `fallback` is set (stochastic descents), lanes with energy get E/d^2 (see below); only lanes
// without energy are ever 0 then. Without `fallback` (splitting) such lanes stay 0.
LT_HOT lt_v4 lt_importance_v(lt_v4 cx, lt_v4 cy, lt_v4 cz, lt_v4 r, lt_v4 ax, lt_v4 ay, lt_v4 az,
                             lt_v4 cos_o, lt_v4 cos_e, lt_v4 energy, lt_v4 plane_h, float3 P,
                             float3 N, int fallback) {
  lt_v4 zero = lt_vs(0.0f);
  lt_v4 one = lt_vs(1.0f);
  lt_v4 dx = lt_vsub(cx, lt_vs(P.x));
  lt_v4 dy = lt_vsub(cy, lt_vs(P.y));
  lt_v4 dz = lt_vsub(cz, lt_vs(P.z));
  lt_v4 d2 = lt_vadd(lt_vadd(lt_vmul(dx, dx), lt_vmul(dy, dy)), lt_vmul(dz, dz));
  lt_v4 r2 = lt_vmul(r, r);
  lt_vm4 inside = lt_vle(d2, r2);
  lt_v4 d2c = lt_vmax(lt_vmax(d2, lt_vmul(r2, lt_vs(0.25f))), lt_vs(1e-36f));
  // Every cosine and sine below is a dot or cross product scaled by 1/d, so the square roots run
  // side by side instead of one after the other (the latency of this function bounds a descent).
  lt_v4 inv_d = lt_vdiv(one, lt_vsqrt(lt_vmax(d2, lt_vs(1e-36f))));
  // theta_u: half-angle of the cone from P around the bounding sphere
  lt_v4 sin_u = lt_vmin(lt_vmul(r, inv_d), one);
  lt_v4 cos_u = lt_vmin(lt_vmul(lt_vsqrt(lt_vmax(lt_vsub(d2, r2), zero)), inv_d), one);
  sin_u = lt_vsel(sin_u, zero, inside);
  cos_u = lt_vsel(cos_u, lt_vs(-1.0f), inside);
  // Fast path: four full-sphere cones (theta_o = pi: points, spheres, two-sided emitters and
  // their clusters, every lane under LT_TERMS_DISTANCE) bound every direction, theta' = 0 and
  // cos(theta') = 1; for finite P the general code gives exactly the same (c1 = 1, s1 = 0, c2 = 1)
  // at the cost of the axis (lt_decode_axes: not even decoded) and a third of this function.
  // Full-sphere lanes never carry a half-space bound, so `front` is all true there.
  lt_v4 orient;
  lt_vm4 full = lt_vle(cos_o, lt_vs(-1.0f));
  lt_vm4 front = full;
  if (lt_vall(full)) {
    orient = lt_vsel(zero, one, lt_vgt(one, cos_e));
  } else {
    // theta: angle between the cone axis and the direction from the cluster towards P
    lt_v4 cos_t = lt_vmul(
        lt_vsub(zero, lt_vadd(lt_vadd(lt_vmul(ax, dx), lt_vmul(ay, dy)), lt_vmul(az, dz))), inv_d);
    // half-space bound: dot(a, P - c) / d > -(h / d + slope), else every emitter faces away from P
    front = lt_vgt(cos_t, lt_vsub(zero, lt_vadd(lt_vmul(plane_h, inv_d), lt_vs(LT_PLANE_SLOPE))));
    lt_v4 sin_t = lt_vmin(lt_vmul(lt_vcross_len(ax, ay, az, dx, dy, dz), inv_d), one);
    lt_v4 sin_o = lt_vsqrt(lt_vmax(lt_vsub(one, lt_vmul(cos_o, cos_o)), zero));
    // theta - theta_o, clamped at 0
    lt_vm4 within_o = lt_vge(cos_t, cos_o);
    lt_v4 c1 = lt_vsel(lt_vadd(lt_vmul(cos_t, cos_o), lt_vmul(sin_t, sin_o)), one, within_o);
    lt_v4 s1 = lt_vsel(lt_vsub(lt_vmul(sin_t, cos_o), lt_vmul(cos_t, sin_o)), zero, within_o);
    // minus theta_u, clamped at 0
    lt_v4 c2 = lt_vsel(lt_vadd(lt_vmul(c1, cos_u), lt_vmul(s1, sin_u)), one, lt_vge(c1, cos_u));
    orient = lt_vsel(zero, c2, lt_vgt(c2, cos_e));
  }
  // incidence at P
  lt_v4 cos_i = one;
  if (N.x != 0.0f || N.y != 0.0f || N.z != 0.0f) {
    lt_v4 nx = lt_vs(N.x), ny = lt_vs(N.y), nz = lt_vs(N.z);
    lt_v4 ci = lt_vmul(lt_vadd(lt_vadd(lt_vmul(dx, nx), lt_vmul(dy, ny)), lt_vmul(dz, nz)), inv_d);
    lt_v4 si = lt_vmin(lt_vmul(lt_vcross_len(nx, ny, nz, dx, dy, dz), inv_d), one);
    cos_i = lt_vsel(lt_vadd(lt_vmul(ci, cos_u), lt_vmul(si, sin_u)), one, lt_vge(ci, cos_u));
    cos_i = lt_vmax(cos_i, zero);
  }
  lt_vm4 alive = lt_vgt(energy, zero);
  float emax = lt_vhmax(energy);
  float dmin2 = lt_vhmin(lt_vsel(lt_vs(3.0e38f), d2c, alive));
  float inv_emax = emax > 0.0f ? 1.0f / emax : 0.0f;
  lt_v4 e = lt_vmul(energy, lt_vs(inv_emax));
  lt_v4 g = lt_vdiv(lt_vs(dmin2), d2c);
  lt_v4 oc = lt_vmul(orient, cos_i);
  lt_v4 imp = lt_vmul(lt_vmul(e, g), oc);
  lt_vm4 contributes = lt_vand(lt_vand(alive, lt_vgt(oc, zero)), front);
  lt_v4 res = lt_vsel(zero, lt_vmax(imp, lt_vs(LT_IMPORTANCE_FLOOR)), contributes);
  // No lane can contribute but some has energy (bounds of the parent were looser than those of
  // its children): rank by energy and distance alone, so a descent never dead-ends and the pmf
  // sums to 1 over the lights with energy. Such picks contribute 0, which keeps them unbiased.
  if (fallback && !(lt_vsum(res) > 0.0f) && emax > 0.0f)
    res = lt_vsel(zero, lt_vmax(lt_vmul(e, g), lt_vs(LT_IMPORTANCE_FLOOR)), alive);
  return res;
}
LT_HOT float4 lt_importance4(float4 cx, float4 cy, float4 cz, float4 r, float4 ax, float4 ay,
                             float4 az, float4 cos_o, float4 cos_e, float4 energy, float3 P,
                             float3 N) {
  return lt_fv(lt_importance_v(lt_vf(cx), lt_vf(cy), lt_vf(cz), lt_vf(r), lt_vf(ax), lt_vf(ay),
                               lt_vf(az), lt_vf(cos_o), lt_vf(cos_e), lt_vf(energy),
                               lt_vs(LT_PLANE_NONE), P, N, 1));
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

// Emitter records (see the top of the file): float4 index of the first one.
INLINE uint lt_emitter_base(const LtTree* t) {
  return float_as_uint_(t->root_info.z) - LT_EMITTER_BASE_BIAS;
}
INLINE GLOBAL const float4* lt_emitter_records(const LtTree* t, int first) {
  return t->nodes + lt_emitter_base(t) + (uint)first * LT_EMITTER_F4;
}
// Octahedral unit vectors from their two 16-bit fixed-point coordinates u, v (as floats,
// 0..65535; stored as the low and high halves of a float's bits), normalised.
LT_HOT void lt_oct_decode_v(lt_v4 u, lt_v4 v, lt_v4* ax, lt_v4* ay, lt_v4* az) {
  lt_v4 one = lt_vs(1.0f);
  lt_v4 zero = lt_vs(0.0f);
  lt_v4 x = lt_vsub(lt_vmul(u, lt_vs(LT_OCT_SCALE)), one);
  lt_v4 y = lt_vsub(lt_vmul(v, lt_vs(LT_OCT_SCALE)), one);
  lt_v4 abs_x = lt_vmax(x, lt_vsub(zero, x));
  lt_v4 abs_y = lt_vmax(y, lt_vsub(zero, y));
  lt_v4 z = lt_vsub(lt_vsub(one, abs_x), abs_y);
  lt_vm4 fold = lt_vlt(z, zero);
  lt_v4 tx = lt_vsel(lt_vsub(abs_y, one), lt_vsub(one, abs_y), lt_vge(x, zero));
  lt_v4 ty = lt_vsel(lt_vsub(abs_x, one), lt_vsub(one, abs_x), lt_vge(y, zero));
  x = lt_vsel(x, tx, fold);
  y = lt_vsel(y, ty, fold);
  lt_v4 inv = lt_vdiv(one, lt_vsqrt(lt_vadd(lt_vadd(lt_vmul(x, x), lt_vmul(y, y)), lt_vmul(z, z))));
  *ax = lt_vmul(x, inv);
  *ay = lt_vmul(y, inv);
  *az = lt_vmul(z, inv);
}
// The same on float4 (the build encodes with it; tests decode with it).
LT_HOT void lt_oct_decode4(float4 u, float4 v, float4* ax, float4* ay, float4* az) {
  lt_v4 x, y, z;
  lt_oct_decode_v(lt_vf(u), lt_vf(v), &x, &y, &z);
  *ax = lt_fv(x);
  *ay = lt_fv(y);
  *az = lt_fv(z);
}

// The orientation ablation (LT_TERMS_DISTANCE): a cone of half-angle pi around any axis bounds
// every direction (cos theta' = 1), N = 0 drops the receiver's incidence term, and no half-space
// bound culls (it is an orientation term too).
INLINE void lt_without_orientation(const LtTree* t, lt_v4* cos_o, lt_v4* cos_e, lt_v4* plane_h,
                                   float3* N) {
  if (t->root_info.w == LT_TERMS_FULL) return;
  *cos_o = lt_vs(-1.0f);
  *cos_e = lt_vs(-1.0f);
  *plane_h = lt_vs(LT_PLANE_NONE);
  *N = make_float3(0.0f, 0.0f, 0.0f);
}

// The cone axes of four lanes from their octahedral bits, decoded only if some lane's cone is not
// the full sphere (cos_o = -1): lt_importance_v ignores the axes of four full-sphere lanes.
LT_HOT void lt_decode_axes(lt_v4 bits, lt_v4 cos_o, lt_v4* ax, lt_v4* ay, lt_v4* az) {
  if (lt_vall(lt_vle(cos_o, lt_vs(-1.0f)))) {
    *ax = lt_vs(0.0f);
    *ay = *ax;
    *az = *ax;
    return;
  }
  lt_oct_decode_v(lt_vlo16(bits), lt_vhi16(bits), ax, ay, az);
}

// Importance of the (up to four) emitters of a leaf, from their emitter records (`fallback`: see
// lt_importance_v).
LT_HOT float4 lt_leaf_importance_f(const LtTree* t, int code, float3 P, float3 N, int fallback) {
  int count = lt_leaf_count(code);
  GLOBAL const float4* e = lt_emitter_records(t, lt_leaf_first(code));
  lt_v4 zero = lt_vs(0.0f);
  lt_v4 a0 = lt_vld(e), b0 = lt_vld(e + 1);
  lt_v4 a1 = zero, b1 = zero, a2 = zero, b2 = zero, a3 = zero, b3 = zero;
  if (count > 1) {
    a1 = lt_vld(e + 2);
    b1 = lt_vld(e + 3);
  }
  if (count > 2) {
    a2 = lt_vld(e + 4);
    b2 = lt_vld(e + 5);
  }
  if (count > 3) {
    a3 = lt_vld(e + 6);
    b3 = lt_vld(e + 7);
  }
  lt_vtranspose(a0, a1, a2, a3); // centre x, y, z, radius
  lt_vtranspose(b0, b1, b2, b3); // axis bits, q, energy, light
  lt_vm4 spot = lt_vgt(b1, lt_vs(1.5f));
  lt_vm4 plane = lt_vlt(b1, lt_vs(-1.5f)); // one-sided planar: q = -2 - h / r
  lt_v4 cos_o = lt_vsel(lt_vsel(b1, lt_vs(1.0f), spot), lt_vs(LT_PLANE_COS_O), plane);
  lt_v4 cos_e = lt_vsel(zero, lt_vsub(b1, lt_vs(2.0f)), spot);
  lt_v4 plane_h = lt_vsel(lt_vs(LT_PLANE_NONE), lt_vmul(lt_vsub(lt_vs(-2.0f), b1), a3), plane);
  lt_without_orientation(t, &cos_o, &cos_e, &plane_h, &N);
  lt_v4 ax, ay, az;
  lt_decode_axes(b0, cos_o, &ax, &ay, &az);
  return lt_fv(
      lt_importance_v(a0, a1, a2, a3, ax, ay, az, cos_o, cos_e, b2, plane_h, P, N, fallback));
}
LT_HOT float4 lt_leaf_importance(const LtTree* t, int code, float3 P, float3 N) {
  return lt_leaf_importance_f(t, code, P, N, 1);
}

LT_HOT float4 lt_node_importance_f(const LtTree* t, int node, float3 P, float3 N, int fallback) {
  GLOBAL const float4* n = t->nodes + node * LT_NODE_F4;
  lt_v4 r = lt_vld(n + LT_R);
  lt_v4 cos_o = lt_vld(n + LT_COS_O);
  lt_v4 k16 = lt_vlo16(lt_vld(n + LT_CE_CV2));
  lt_vm4 plane = lt_vgt(cos_o, lt_vs(1.5f)); // LT_PLANE_FLAG: k16 is the plane offset
  lt_v4 cos_e = lt_vsel(lt_vmul(k16, lt_vs(LT_U16_SCALE)), lt_vs(0.0f), plane);
  lt_v4 plane_h =
      lt_vsel(lt_vs(LT_PLANE_NONE),
              lt_vmul(lt_vsub(k16, lt_vs(32768.0f)), lt_vmul(r, lt_vs(LT_PLANE_H_UNIT))), plane);
  cos_o = lt_vsel(cos_o, lt_vs(LT_PLANE_COS_O), plane);
  lt_without_orientation(t, &cos_o, &cos_e, &plane_h, &N);
  lt_v4 ax, ay, az;
  lt_decode_axes(lt_vld(n + LT_AXIS), cos_o, &ax, &ay, &az);
  return lt_fv(lt_importance_v(lt_vld(n + LT_CX), lt_vld(n + LT_CY), lt_vld(n + LT_CZ), r, ax, ay,
                               az, cos_o, cos_e, lt_vld(n + LT_ENERGY), plane_h, P, N, fallback));
}
LT_HOT float4 lt_node_importance(const LtTree* t, int node, float3 P, float3 N) {
  return lt_node_importance_f(t, node, P, N, 1);
}

// Importances of the four lanes below `code` (a node or a leaf) for the split decisions: without
// the fallback, so a cluster splits into exactly the lanes that can contribute (none where P sees
// no emitter of the cluster: a point behind a ceiling of one-sided lights gets an empty cut).
INLINE float4 lt_code_importance(const LtTree* t, int code, float3 P, float3 N) {
  return code >= 0 ? lt_node_importance_f(t, code, P, N, 0)
                   : lt_leaf_importance_f(t, code, P, N, 0);
}

// Probability of lane k: I_k / (sum of the four). 0 if nothing contributes.
LT_HOT float lt_lane_prob(float4 imp, int k) {
  float s = lt_sum4(imp);
  float ik = f4_get(imp, k);
  return (s > 0.0f && ik > 0.0f) ? ik / s : 0.0f;
}

// Compare-and-swap of a sorting network on (value, lane) pairs, ascending; branch-free (selects),
// since the order of the importances is data dependent and unpredictable.
#define LT_CSWAP(va, ia, vb, ib)                                                                   \
  do {                                                                                             \
    int sw_ = vb < va;                                                                             \
    float lo_ = sw_ ? vb : va, hi_ = sw_ ? va : vb;                                                \
    int il_ = sw_ ? ib : ia, ih_ = sw_ ? ia : ib;                                                  \
    va = lo_;                                                                                      \
    vb = hi_;                                                                                      \
    ia = il_;                                                                                      \
    ib = ih_;                                                                                      \
  } while (0)

// Chooses lane k with probability I_k / sum (what lt_lane_prob reports) from fresh 32-bit words
// of r; -1 if no lane contributes. The lanes are sorted by ascending importance (a 4-input sorting
// network) and U in [0, 1) picks the lane whose interval [c_j, c_j+1) holds it, c_j = (sum of
// the j smallest) / sum: summing from the small end keeps a tiny lane beside a big one, and every
// boundary below a lane is at most 3 times that lane's own probability, so each lane's interval
// has the lane's probability to a few float roundings (relative, < 1e-6) however small it is. The
// comparisons of U with the boundaries are exact (lt_word_vs: one word, more only on a tie), so
// no probability is lost to the resolution of U. A lane of importance 0 has an empty interval.
LT_HOT int lt_choose_lane(float4 imp, LtRng* r) {
  float s = lt_sum4(imp);
  if (!(s > 0.0f) || !is_finite_f(s)) return -1;
  float v0 = imp.x, v1 = imp.y, v2 = imp.z, v3 = imp.w;
  int i0 = 0, i1 = 1, i2 = 2, i3 = 3;
  LT_CSWAP(v0, i0, v1, i1);
  LT_CSWAP(v2, i2, v3, i3);
  LT_CSWAP(v0, i0, v2, i2);
  LT_CSWAP(v1, i1, v3, i3);
  LT_CSWAP(v1, i1, v2, i2);
  float t2 = v0 + v1;
  float t3 = t2 + v2;
  uint w = lt_rng_next_u32(r);
  // Fast path: U's top 24 bits a (exact as a float) against y_j = c_j * 2^24 (exact scaling of
  // the boundary): U >= c_j if a >= y_j, U < c_j if a + 1 <= y_j; only a boundary strictly
  // inside (a, a + 1) needs the exact 32-bit comparison (probability < 3 * 2^-24 per decision).
  float k = LT_TWO_POW_24 / s; // c_3 <= 3/4 < 1: the largest lane has at least a quarter
  float y1 = v0 * k, y2 = t2 * k, y3 = t3 * k;
  float a = (float)(w >> 8);
  float a1 = a + 1.0f;
  int pos = (a >= y1) + (a >= y2) + (a >= y3); // boundaries at or below U
  if ((y1 > a && y1 < a1) || (y2 > a && y2 < a1) || (y3 > a && y3 < a1)) {
    float x1 = y1 * 256.0f, x2 = y2 * 256.0f, x3 = y3 * 256.0f; // c_j * 2^32, exact
    int o1 = lt_word_vs(w, &x1), o2 = lt_word_vs(w, &x2), o3 = lt_word_vs(w, &x3);
    for (int n = 1; n < LT_MAX_WORDS; ++n) { // tied boundaries compare with U's next word
      if (o1 != 2 && o2 != 2 && o3 != 2) break;
      w = lt_rng_next_u32(r);
      if (o1 == 2) o1 = lt_word_vs(w, &x1);
      if (o2 == 2) o2 = lt_word_vs(w, &x2);
      if (o3 == 2) o3 = lt_word_vs(w, &x3);
    }
    pos = (o1 == 1) + (o2 == 1) + (o3 == 1);
  }
  return pos == 0 ? i0 : (pos == 1 ? i1 : (pos == 2 ? i2 : i3));
}

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

// Stochastic descent (Alg. 2) from `code` (a node index or a leaf code) to one light, each
// decision from fresh words of `rng` (lt_choose_lane). Returns the light index, or -1 if nothing
// below `code` contributes; *prob = product of the lane probabilities taken below `code`.
INLINE int lt_pick_below(const LtTree* t, int code, float3 P, float3 N, LtRng* rng, float* prob) {
  float p = 1.0f;
  *prob = 0.0f;
  while (code >= 0) {
    int4 ch = t->children[code];
    lt_prefetch_children(t, ch);
    float4 imp = lt_node_importance(t, code, P, N);
    int lane = lt_choose_lane(imp, rng);
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
  float4 imp = lt_leaf_importance(t, code, P, N);
  int lane = lt_choose_lane(imp, rng);
  if (lane < 0) return -1;
  p = p * lt_lane_prob(imp, lane);
  *prob = p;
  return (int)float_as_uint_(rec[lane * LT_EMITTER_F4 + 1].w); // = leaf_lights[first + lane]
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
      LT_PREFETCH(t->nodes + next * LT_NODE_F4 + 7);
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
INLINE int4 lt_child_budgets(const LtTree* t, int node, float4 imp, uint budget, float3 P,
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
    if (!lt_should_split(lt_split_measure(P, lt_lane_sphere(t, node, j), lt_lane_cv2(t, node, j)),
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
    int lane = (int)(trail & 3u);
    trail = trail >> 2;
    float4 imp = lt_code_importance(t, code, P, N);
    if (!(f4_get(imp, lane) > 0.0f)) return 0.0f;
    if (code < 0) return 1.0f; // split leaf: every contributing emitter is taken
    budget = (uint)i4_get(lt_child_budgets(t, code, imp, budget, P, threshold), lane);
    sphere = lt_lane_sphere(t, code, lane);
    cv2 = lt_lane_cv2(t, code, lane);
    code = i4_get(t->children[code], lane);
  }
}

#endif // CANOPY_LIGHT_TREE_MATH_H
