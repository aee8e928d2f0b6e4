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

// Origin for a ray leaving a surface at p with normal n (facing the side the ray leaves to).
// `eps` is the scene's ray offset: 1e-5 x the scene's extent, computed on the host, so the
// offset scales with the scene and stays hundreds of ulps above the hit point's rounding error.
INLINE float3 offset_ray_origin(float3 p, float3 n, float eps) {
  return p + n * eps;
}

#endif // CANOPY_CL_SHADING_H
