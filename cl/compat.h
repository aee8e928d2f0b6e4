// Compatibility layer: lets the math headers in cl/ compile both as OpenCL C 1.2 (in the kernels)
// and as C++20 (in the host reference and the tests), so the two cannot drift apart.
// Only what the shared headers use is defined here.
#ifndef CANOPY_CL_COMPAT_H
#define CANOPY_CL_COMPAT_H

#ifdef __OPENCL_C_VERSION__
// ---------------------------------------------------------------- OpenCL C
#define CANOPY_DEVICE 1
#define INLINE static inline
#define GLOBAL __global
#define CONSTANT __constant
#define make_float2(a, b) ((float2)((a), (b)))
#define make_float3(a, b, c) ((float3)((a), (b), (c)))
#define make_float4(a, b, c, d) ((float4)((a), (b), (c), (d)))
#define make_int4(a, b, c, d) ((int4)((a), (b), (c), (d)))
#define make_int2(a, b) ((int2)((a), (b)))
#define make_uint4(a, b, c, d) ((uint4)((a), (b), (c), (d)))
#define xyz_of(v) ((v).xyz)
#define FLT_INF INFINITY
#pragma OPENCL FP_CONTRACT OFF

INLINE float4 f4_from3(float3 v, float w) {
  return (float4)(v, w);
}
INLINE float f4_get(float4 v, int i) {
  return i == 0 ? v.x : (i == 1 ? v.y : (i == 2 ? v.z : v.w));
}
INLINE int i4_get(int4 v, int i) {
  return i == 0 ? v.x : (i == 1 ? v.y : (i == 2 ? v.z : v.w));
}
INLINE float4 f4_splat(float x) {
  return (float4)(x);
}
// Bit i set where lane i's sign bit is (a comparison's -1, or a negative int).
INLINE int sign_bits4(int4 v) {
  return ((v.x >> 31) & 1) | ((v.y >> 31) & 2) | ((v.z >> 31) & 4) | ((v.w >> 31) & 8);
}
// The index of the lowest set bit of x != 0.
INLINE int lowest_bit(int x) {
  return 31 - clz(x & -x);
}
INLINE bool is_finite_f(float x) {
  return isfinite(x);
}
INLINE uint float_as_uint_(float x) {
  return as_uint(x);
}
INLINE float uint_as_float_(uint x) {
  return as_float(x);
}

#else
// ---------------------------------------------------------------- C++
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#define INLINE inline
#define GLOBAL
#define CONSTANT
#define FLT_INF (std::numeric_limits<float>::infinity())

typedef unsigned int uint;
typedef unsigned long ulong_t;

struct float2 {
  float x, y;
};
struct float3 {
  float x, y, z;
};
struct alignas(16) float4 {
  float x, y, z, w;
};
struct alignas(16) int4 {
  int x, y, z, w;
};
struct alignas(8) int2 {
  int x, y;
};
struct alignas(16) uint4 {
  uint x, y, z, w;
};
static_assert(sizeof(float4) == 16 && sizeof(int4) == 16 && sizeof(uint4) == 16);

INLINE float2 make_float2(float a, float b) {
  return {a, b};
}
INLINE float3 make_float3(float a, float b, float c) {
  return {a, b, c};
}
INLINE float4 make_float4(float a, float b, float c, float d) {
  return {a, b, c, d};
}
INLINE int4 make_int4(int a, int b, int c, int d) {
  return {a, b, c, d};
}
INLINE int2 make_int2(int a, int b) {
  return {a, b};
}
INLINE uint4 make_uint4(uint a, uint b, uint c, uint d) {
  return {a, b, c, d};
}
INLINE bool operator==(uint4 a, uint4 b) {
  return a.x == b.x && a.y == b.y && a.z == b.z && a.w == b.w;
}
using std::max;
using std::min;
INLINE float3 xyz_of(float4 v) {
  return {v.x, v.y, v.z};
}
INLINE float4 f4_from3(float3 v, float w) {
  return {v.x, v.y, v.z, w};
}
INLINE float f4_get(float4 v, int i) {
  return i == 0 ? v.x : (i == 1 ? v.y : (i == 2 ? v.z : v.w));
}
INLINE int i4_get(int4 v, int i) {
  return i == 0 ? v.x : (i == 1 ? v.y : (i == 2 ? v.z : v.w));
}
INLINE float4 f4_splat(float x) {
  return {x, x, x, x};
}
INLINE int sign_bits4(int4 v) {
  return ((v.x >> 31) & 1) | ((v.y >> 31) & 2) | ((v.z >> 31) & 4) | ((v.w >> 31) & 8);
}
INLINE int lowest_bit(int x) {
  return std::countr_zero(unsigned(x));
}
INLINE bool is_finite_f(float x) {
  return std::isfinite(x);
}
INLINE uint float_as_uint_(float x) {
  uint u;
  std::memcpy(&u, &x, 4);
  return u;
}
INLINE float uint_as_float_(uint x) {
  float f;
  std::memcpy(&f, &x, 4);
  return f;
}

// float3
INLINE float3 operator+(float3 a, float3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
INLINE float3 operator-(float3 a, float3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
INLINE float3 operator*(float3 a, float3 b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
INLINE float3 operator/(float3 a, float3 b) {
  return {a.x / b.x, a.y / b.y, a.z / b.z};
}
INLINE float3 operator*(float3 a, float s) {
  return {a.x * s, a.y * s, a.z * s};
}
INLINE float3 operator*(float s, float3 a) {
  return {a.x * s, a.y * s, a.z * s};
}
INLINE float3 operator/(float3 a, float s) {
  return {a.x / s, a.y / s, a.z / s};
}
INLINE float3 operator-(float3 a) {
  return {-a.x, -a.y, -a.z};
}
INLINE float3& operator+=(float3& a, float3 b) {
  return a = a + b;
}
INLINE float3& operator*=(float3& a, float3 b) {
  return a = a * b;
}
INLINE float3& operator*=(float3& a, float s) {
  return a = a * s;
}
INLINE float dot(float3 a, float3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
INLINE float3 cross(float3 a, float3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
INLINE float length(float3 a) {
  return std::sqrt(dot(a, a));
}
INLINE float3 normalize(float3 a) {
  return a * (1.0f / length(a));
}
INLINE float3 fmin(float3 a, float3 b) {
  return {std::fmin(a.x, b.x), std::fmin(a.y, b.y), std::fmin(a.z, b.z)};
}
INLINE float3 fmax(float3 a, float3 b) {
  return {std::fmax(a.x, b.x), std::fmax(a.y, b.y), std::fmax(a.z, b.z)};
}
INLINE float3 fabs(float3 a) {
  return {std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)};
}

// float4 (the 4-wide lanes of the light tree)
INLINE float4 operator+(float4 a, float4 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w};
}
INLINE float4 operator-(float4 a, float4 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z, a.w - b.w};
}
INLINE float4 operator*(float4 a, float4 b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z, a.w * b.w};
}
INLINE float4 operator/(float4 a, float4 b) {
  return {a.x / b.x, a.y / b.y, a.z / b.z, a.w / b.w};
}
INLINE float4 operator*(float4 a, float s) {
  return {a.x * s, a.y * s, a.z * s, a.w * s};
}
INLINE float4 operator-(float4 a, float s) {
  return {a.x - s, a.y - s, a.z - s, a.w - s};
}
INLINE float4 operator*(float s, float4 a) {
  return {a.x * s, a.y * s, a.z * s, a.w * s};
}
INLINE float4 fmin(float4 a, float4 b) {
  return {std::fmin(a.x, b.x), std::fmin(a.y, b.y), std::fmin(a.z, b.z), std::fmin(a.w, b.w)};
}
INLINE float4 fmax(float4 a, float4 b) {
  return {std::fmax(a.x, b.x), std::fmax(a.y, b.y), std::fmax(a.z, b.z), std::fmax(a.w, b.w)};
}
INLINE float4 sqrt(float4 a) {
  return {std::sqrt(a.x), std::sqrt(a.y), std::sqrt(a.z), std::sqrt(a.w)};
}
INLINE float4 fabs(float4 a) {
  return {std::fabs(a.x), std::fabs(a.y), std::fabs(a.z), std::fabs(a.w)};
}

// Lane-wise comparisons and masks as OpenCL C has them: -1 (all bits) where true, else 0.
INLINE int4 mask4(bool x, bool y, bool z, bool w) {
  return {-int(x), -int(y), -int(z), -int(w)};
}
INLINE int4 operator<(float4 a, float4 b) {
  return mask4(a.x < b.x, a.y < b.y, a.z < b.z, a.w < b.w);
}
INLINE int4 operator>(float4 a, float4 b) {
  return mask4(a.x > b.x, a.y > b.y, a.z > b.z, a.w > b.w);
}
INLINE int4 operator<=(float4 a, float4 b) {
  return mask4(a.x <= b.x, a.y <= b.y, a.z <= b.z, a.w <= b.w);
}
INLINE int4 operator==(float4 a, float4 b) {
  return mask4(a.x == b.x, a.y == b.y, a.z == b.z, a.w == b.w);
}
INLINE int4 operator!=(float4 a, float4 b) {
  return mask4(a.x != b.x, a.y != b.y, a.z != b.z, a.w != b.w);
}
INLINE int4 operator&(int4 a, int4 b) {
  return {a.x & b.x, a.y & b.y, a.z & b.z, a.w & b.w};
}
INLINE int4 operator|(int4 a, int4 b) {
  return {a.x | b.x, a.y | b.y, a.z | b.z, a.w | b.w};
}
INLINE int4 operator~(int4 a) {
  return {~a.x, ~a.y, ~a.z, ~a.w};
}
INLINE int any(int4 m) {
  return (m.x | m.y | m.z | m.w) < 0;
}
// select(a, b, m): b where m's sign bit is set, else a.
INLINE float4 select(float4 a, float4 b, int4 m) {
  return {m.x < 0 ? b.x : a.x, m.y < 0 ? b.y : a.y, m.z < 0 ? b.z : a.z, m.w < 0 ? b.w : a.w};
}

// scalar built-ins with their OpenCL names
using std::acos;
using std::atan2;
using std::cos;
using std::fabs;
using std::floor;
using std::fmax;
using std::fmin;
using std::sin;
using std::sqrt;
INLINE float clamp(float x, float lo, float hi) {
  return std::fmin(std::fmax(x, lo), hi);
}
INLINE float mix(float a, float b, float t) {
  return a + (b - a) * t;
}
INLINE float3 mix(float3 a, float3 b, float t) {
  return a + (b - a) * t;
}
#ifndef M_PI_F
#define M_PI_F 3.14159265358979323846f
#endif
#endif // __OPENCL_C_VERSION__

#define CANOPY_PI M_PI_F
#define CANOPY_INV_PI (1.0f / M_PI_F)

// max component and luminance (Rec. 709), used as the scalar "energy" of RGB emission.
INLINE float luminance3(float3 c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}
INLINE float max3(float3 c) {
  return fmax(c.x, fmax(c.y, c.z));
}

#endif // CANOPY_CL_COMPAT_H
