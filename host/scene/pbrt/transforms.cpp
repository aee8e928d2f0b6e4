#include "scene/pbrt/transforms.h"

#include <cmath>

namespace canopy::pbrt {

Transform inverse(const Transform& x, bool& ok) {
  double c[3][3];
  double det = x.cofactors(c); // m^-1 = C^T / det
  Transform r;
  ok = det != 0.0 && std::isfinite(det);
  if (!ok) return r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[i][j] = c[j][i] / det;
  double3 t = x.t;
  r.t = {-(r.m[0][0] * t.x + r.m[0][1] * t.y + r.m[0][2] * t.z),
         -(r.m[1][0] * t.x + r.m[1][1] * t.y + r.m[1][2] * t.z),
         -(r.m[2][0] * t.x + r.m[2][1] * t.y + r.m[2][2] * t.z)};
  return r;
}

double3 linear(const Transform& x, double3 v) {
  return {x.m[0][0] * v.x + x.m[0][1] * v.y + x.m[0][2] * v.z,
          x.m[1][0] * v.x + x.m[1][1] * v.y + x.m[1][2] * v.z,
          x.m[2][0] * v.x + x.m[2][1] * v.y + x.m[2][2] * v.z};
}
double dot3(double3 a, double3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
double3 cross3(double3 a, double3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double len3(double3 a) {
  return std::sqrt(dot3(a, a));
}

// The uniform scale of x if its linear part is a similarity (rotation, reflection and uniform
// scale), else 0: spheres and disks stay round only under those.
double similarity_scale(const Transform& x) {
  double3 c[3] = {linear(x, {1, 0, 0}), linear(x, {0, 1, 0}), linear(x, {0, 0, 1})};
  double s2 = dot3(c[0], c[0]);
  if (!(s2 > 0.0) || !std::isfinite(s2)) return 0.0;
  for (int i = 0; i < 3; ++i) {
    if (std::fabs(dot3(c[i], c[i]) / s2 - 1.0) > 1e-6) return 0.0;
    if (std::fabs(dot3(c[i], c[(i + 1) % 3])) / s2 > 1e-6) return 0.0;
  }
  return std::sqrt(s2);
}

// pbrt's 4x4 matrices are written column by column (the format page, "Transformations": the
// translation is elements 12..14); the last row must be 0 0 0 1 for an affine transform.
Transform from_pbrt_matrix(const Loc& loc, const std::vector<double>& v) {
  Transform x;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j)
      x.m[i][j] = v[size_t(4 * j + i)];
  }
  x.t = {v[12], v[13], v[14]};
  if (v[3] != 0.0 || v[7] != 0.0 || v[11] != 0.0 || v[15] != 1.0)
    fail(loc, "projective matrices are not supported (the last row must be 0 0 0 1)");
  return x;
}

} // namespace canopy::pbrt
