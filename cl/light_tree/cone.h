// Orientation cones of emitters and clusters (Conty Estevez & Kulla 2018, §4.1): the cone
// (axis, theta_o normal bound, theta_e emission bound), the union of two cones (Alg. 1) and the
// orientation measure M_Omega (§4.3, Eq. 1) of the build's SAOH cost (§4.4, Eq. 2). Used by the
// tree build (host); compiles as OpenCL C and as C++ (cl/compat.h).
#ifndef CANOPY_LIGHT_TREE_CONE_H
#define CANOPY_LIGHT_TREE_CONE_H

#include "../compat.h"
#include "../simd4.h"

// Cone unions are padded by this angle (radians) so rounding never uncovers an input.
#define LT_CONE_PAD 2e-6f

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

#endif // CANOPY_LIGHT_TREE_CONE_H
