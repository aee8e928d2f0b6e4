// Double-precision 3-vectors for test references (closed forms and quadratures computed
// independently of the float code under test).
#pragma once

#include "compat.h"

#include <cmath>

struct D3 {
  double x, y, z;
};
inline D3 d3(float3 v) {
  return {double(v.x), double(v.y), double(v.z)};
}
inline D3 operator+(D3 a, D3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline D3 operator-(D3 a, D3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline D3 operator*(D3 a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
inline double ddot(D3 a, D3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline D3 dcross(D3 a, D3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double dlen(D3 a) {
  return std::sqrt(ddot(a, a));
}
inline D3 dunit(D3 a) {
  return a * (1.0 / dlen(a));
}
