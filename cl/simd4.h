// The one 4-lane vector abstraction of the kernels and the host reference. v4f holds four floats
// (v4m a lane mask, the result of a comparison): float4 in OpenCL C, an SSE register on an x86-64
// host (the float4 struct of compat.h would go through memory) and the compat.h float4 struct on
// other hosts. Every operation is the same IEEE operation lane by lane, in the same order, on
// every backend, so host and device compute identical bits. The light tree's hot path (four
// children of a 4-wide node at once; the importance of Conty Estevez & Kulla 2018, §5.1, Eq. 3) is
// written with it; values stored or returned to scalar code are float4 (v4_from_f4 / v4_to_f4
// convert). Also here: scalar min/max/clamp, the horizontal sum of a float4 in the lanes' order,
// and the LT_HOT / LT_PREFETCH compiler hints.
#ifndef CANOPY_SIMD4_H
#define CANOPY_SIMD4_H

#include "compat.h"

// Scalar min/max/clamp for the code around the lanes: fmin/fmax on the device; on the host the
// operand order of the SSE lane ops (b < a ? b : a is _mm_min_ps(a, b)), with no std overloads.
#ifdef __OPENCL_C_VERSION__
#define lt_minf(a, b) fmin(a, b)
#define lt_maxf(a, b) fmax(a, b)
#else
INLINE float lt_minf(float a, float b) {
  return b < a ? b : a;
}
INLINE float lt_maxf(float a, float b) {
  return a < b ? b : a;
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

#ifdef __OPENCL_C_VERSION__
typedef float4 v4f;
typedef int4 v4m;
#define v4_from_f4(a) (a)
#define v4_to_f4(a) (a)
#define v4_load(p) (*(p))
#define v4_splat(s) ((float4)(s))
#define v4_add(a, b) ((a) + (b))
#define v4_sub(a, b) ((a) - (b))
#define v4_mul(a, b) ((a) * (b))
#define v4_div(a, b) ((a) / (b))
#define v4_sqrt(a) sqrt(a)
#define v4_min(a, b) fmin(a, b)
#define v4_max(a, b) fmax(a, b)
#define v4_lt(a, b) ((a) < (b))
#define v4_le(a, b) ((a) <= (b))
#define v4_gt(a, b) ((a) > (b))
#define v4_ge(a, b) ((a) >= (b))
#define v4_and(a, b) ((a) & (b))
#define v4_sel(a, b, m) select(a, b, m) /* m ? b : a, lane-wise */
// The low / high 16 bits of the bit patterns of four floats, as floats (exact).
#define v4_lo16(a) convert_float4(as_uint4(a) & (uint4)(0xffffu))
#define v4_hi16(a) convert_float4(as_uint4(a) >> (uint4)(16u))
INLINE float v4_hmax(float4 a) {
  return fmax(fmax(a.x, a.y), fmax(a.z, a.w));
}
INLINE float v4_hmin(float4 a) {
  return fmin(fmin(a.x, a.y), fmin(a.z, a.w));
}
#define v4_all(m) all(m)
#define LT_HOT static inline __attribute__((always_inline))
// CPU devices (PoCL) have one flat address space: prefetch through an integer round trip (clang's
// builtin takes a private pointer in OpenCL C 1.2).
#if defined(__clang__) && defined(__x86_64__)
#define LT_PREFETCH(addr) __builtin_prefetch((const void*)(ulong)(addr))
#else
#define LT_PREFETCH(addr) ((void)(addr))
#endif

#elif defined(__SSE2__)
// C++ (host reference) on x86-64: SSE registers.
#include <emmintrin.h>
typedef __m128 v4f;
typedef __m128 v4m;
INLINE v4f v4_from_f4(float4 a) {
  return _mm_load_ps(&a.x);
}
INLINE float4 v4_to_f4(v4f v) {
  float4 r;
  _mm_store_ps(&r.x, v);
  return r;
}
INLINE v4f v4_load(const float4* p) {
  return _mm_load_ps(&p->x);
}
#define v4_splat(s) _mm_set1_ps(s)
#define v4_add(a, b) _mm_add_ps(a, b)
#define v4_sub(a, b) _mm_sub_ps(a, b)
#define v4_mul(a, b) _mm_mul_ps(a, b)
#define v4_div(a, b) _mm_div_ps(a, b)
#define v4_sqrt(a) _mm_sqrt_ps(a)
#define v4_min(a, b) _mm_min_ps(a, b)
#define v4_max(a, b) _mm_max_ps(a, b)
#define v4_lt(a, b) _mm_cmplt_ps(a, b)
#define v4_le(a, b) _mm_cmple_ps(a, b)
#define v4_gt(a, b) _mm_cmpgt_ps(a, b)
#define v4_ge(a, b) _mm_cmpge_ps(a, b)
#define v4_and(a, b) _mm_and_ps(a, b)
INLINE v4f v4_sel(v4f a, v4f b, v4m m) {
  return _mm_or_ps(_mm_and_ps(m, b), _mm_andnot_ps(m, a));
}
INLINE v4f v4_lo16(v4f a) {
  return _mm_cvtepi32_ps(_mm_and_si128(_mm_castps_si128(a), _mm_set1_epi32(0xffff)));
}
INLINE v4f v4_hi16(v4f a) {
  return _mm_cvtepi32_ps(_mm_srli_epi32(_mm_castps_si128(a), 16));
}
#define v4_transpose(a, b, c, d) _MM_TRANSPOSE4_PS(a, b, c, d)
#define v4_all(m) (_mm_movemask_ps(m) == 15) /* every lane of a comparison mask is set */
INLINE float v4_hmax(v4f a) {
  __m128 m = _mm_max_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtss_f32(_mm_max_ss(m, _mm_movehl_ps(m, m)));
}
INLINE float v4_hmin(v4f a) {
  __m128 m = _mm_min_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtss_f32(_mm_min_ss(m, _mm_movehl_ps(m, m)));
}
INLINE float v4_sum(v4f a) { // (x + y) + (z + w)
  __m128 t = _mm_add_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtss_f32(_mm_add_ss(t, _mm_movehl_ps(t, t)));
}

#else
// C++ without SSE2: the compat.h float4 struct, lane by lane (b < a ? b : a is _mm_min_ps(a, b)).
typedef float4 v4f;
typedef int4 v4m;
#define v4_from_f4(a) (a)
#define v4_to_f4(a) (a)
#define v4_load(p) (*(p))
INLINE float4 v4_splat(float s) {
  return make_float4(s, s, s, s);
}
#define v4_add(a, b) ((a) + (b))
#define v4_sub(a, b) ((a) - (b))
#define v4_mul(a, b) ((a) * (b))
#define v4_div(a, b) ((a) / (b))
INLINE float4 v4_sqrt(float4 a) {
  return make_float4(std::sqrt(a.x), std::sqrt(a.y), std::sqrt(a.z), std::sqrt(a.w));
}
INLINE float4 v4_min(float4 a, float4 b) {
  return make_float4(b.x < a.x ? b.x : a.x, b.y < a.y ? b.y : a.y, b.z < a.z ? b.z : a.z,
                     b.w < a.w ? b.w : a.w);
}
INLINE float4 v4_max(float4 a, float4 b) {
  return make_float4(a.x < b.x ? b.x : a.x, a.y < b.y ? b.y : a.y, a.z < b.z ? b.z : a.z,
                     a.w < b.w ? b.w : a.w);
}
INLINE v4m v4_lt(float4 a, float4 b) {
  return make_int4(-(a.x < b.x), -(a.y < b.y), -(a.z < b.z), -(a.w < b.w));
}
INLINE v4m v4_le(float4 a, float4 b) {
  return make_int4(-(a.x <= b.x), -(a.y <= b.y), -(a.z <= b.z), -(a.w <= b.w));
}
INLINE v4m v4_gt(float4 a, float4 b) {
  return v4_lt(b, a);
}
INLINE v4m v4_ge(float4 a, float4 b) {
  return v4_le(b, a);
}
INLINE v4m v4_and(v4m a, v4m b) {
  return make_int4(a.x & b.x, a.y & b.y, a.z & b.z, a.w & b.w);
}
INLINE float4 v4_sel(float4 a, float4 b, v4m m) {
  return make_float4(m.x ? b.x : a.x, m.y ? b.y : a.y, m.z ? b.z : a.z, m.w ? b.w : a.w);
}
INLINE float4 v4_lo16(float4 b) {
  return make_float4((float)(float_as_uint_(b.x) & 0xffffu), (float)(float_as_uint_(b.y) & 0xffffu),
                     (float)(float_as_uint_(b.z) & 0xffffu),
                     (float)(float_as_uint_(b.w) & 0xffffu));
}
INLINE float4 v4_hi16(float4 b) {
  return make_float4((float)(float_as_uint_(b.x) >> 16), (float)(float_as_uint_(b.y) >> 16),
                     (float)(float_as_uint_(b.z) >> 16), (float)(float_as_uint_(b.w) >> 16));
}
INLINE float v4_hmax(float4 a) {
  return lt_maxf(lt_maxf(a.x, a.y), lt_maxf(a.z, a.w));
}
INLINE float v4_hmin(float4 a) {
  return lt_minf(lt_minf(a.x, a.y), lt_minf(a.z, a.w));
}
#define v4_all(m) ((m).x && (m).y && (m).z && (m).w)
#endif // backends

#if defined(__OPENCL_C_VERSION__) || !defined(__SSE2__)
// float4 lanes (OpenCL C, or C++ without SSE2): the same transpose and horizontal sum.
#define v4_transpose(a, b, c, d)                                                                   \
  do {                                                                                             \
    float4 t0_ = make_float4(a.x, b.x, c.x, d.x), t1_ = make_float4(a.y, b.y, c.y, d.y);           \
    float4 t2_ = make_float4(a.z, b.z, c.z, d.z), t3_ = make_float4(a.w, b.w, c.w, d.w);           \
    a = t0_;                                                                                       \
    b = t1_;                                                                                       \
    c = t2_;                                                                                       \
    d = t3_;                                                                                       \
  } while (0)
INLINE float v4_sum(float4 a) {
  return (a.x + a.y) + (a.z + a.w);
}
#endif

#ifndef __OPENCL_C_VERSION__
#if defined(__GNUC__)
#define LT_HOT inline __attribute__((always_inline))
#define LT_PREFETCH(addr) __builtin_prefetch(addr)
#else
#define LT_HOT inline
#define LT_PREFETCH(addr) ((void)(addr))
#endif
#endif

// The one summation order of four lanes held in a float4, the same as v4_sum (sampling and pmf
// must agree).
INLINE float lt_sum4(float4 a) {
  return (a.x + a.y) + (a.z + a.w);
}

#endif // CANOPY_SIMD4_H
