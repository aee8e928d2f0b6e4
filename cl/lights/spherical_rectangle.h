// Uniform sampling of the solid angle of a rectangle (Urena, Fajardo & King 2013, "An
// Area-Preserving Parametrization for Spherical Rectangles", EGSR, Alg. 1 and §3-4). The
// rectangle is described in a local frame centred on the viewpoint: x along one edge, y along the
// other, z the normal turned away from the rectangle so that its plane is at z0 < 0; the
// rectangle is [x0, x1] x [y0, y1] at depth z0.
#ifndef CANOPY_CL_LIGHTS_SPHERICAL_RECTANGLE_H
#define CANOPY_CL_LIGHTS_SPHERICAL_RECTANGLE_H

#include "../compat.h"

typedef struct SphRect {
  float3 x, y, z; // world directions of the local axes
  float x0, y0, x1, y1, z0;
  float b0, b1;       // z components of the normals of the planes through the edges y0, y1
  float b0sq_minus_1; // b0^2 - 1 without cancellation
  float k;            // 2 pi - g2 - g3 (paper: the offset of the first variable)
  float area;         // g0 + g1 + g2 + g3 - 2 pi: the range of the first variable
  float omega;        // solid angle for the pdf (see sph_rect_setup)
} SphRect;

// d: corner - viewpoint; ex, ey: unit edge directions (orthogonal); ez: unit normal; lx, ly: edge
// lengths. The caller guarantees a viewpoint off the plane.
INLINE SphRect sph_rect_setup(float3 d, float3 ex, float3 ey, float3 ez, float lx, float ly) {
  SphRect r;
  r.x = ex;
  r.y = ey;
  r.z = ez;
  r.z0 = dot(d, ez);
  if (r.z0 > 0.0f) {
    r.z = -ez;
    r.z0 = -r.z0;
  }
  r.x0 = dot(d, ex);
  r.y0 = dot(d, ey);
  r.x1 = r.x0 + lx;
  r.y1 = r.y0 + ly;
  float h = -r.z0, z2 = r.z0 * r.z0;
  float l00 = sqrt(r.x0 * r.x0 + r.y0 * r.y0 + z2), l10 = sqrt(r.x1 * r.x1 + r.y0 * r.y0 + z2);
  float l11 = sqrt(r.x1 * r.x1 + r.y1 * r.y1 + z2), l01 = sqrt(r.x0 * r.x0 + r.y1 * r.y1 + z2);
  // The paper's interior angles g_i = acos(-n_i . n_{i+1}) of the normals n0 = (0, z0, -y0),
  // n1 = (-z0, 0, x1), n2 = (0, -z0, y1), n3 = (z0, 0, -x0) (normalised), written as atan2 of
  // |n_i x n_{i+1}| = |z0| |corner| and the dot product: accurate near 0 and pi, where acos is not
  // (a viewpoint almost on the plane makes every angle nearly pi).
  float g0 = atan2(h * l10, r.y0 * r.x1);
  float g1 = atan2(h * l11, -r.x1 * r.y1);
  float g2 = atan2(h * l01, r.x0 * r.y1);
  float g3 = atan2(h * l00, -r.x0 * r.y0);
  r.b0 = -r.y0 / sqrt(z2 + r.y0 * r.y0);
  r.b1 = r.y1 / sqrt(z2 + r.y1 * r.y1);
  r.b0sq_minus_1 = -z2 / (z2 + r.y0 * r.y0);
  r.k = 2.0f * CANOPY_PI - g2 - g3;
  r.area = fmax(0.0f, g0 + g1 - r.k);
  // The angle sum loses ~1e-6 sr absolute to cancellation against 2 pi: for a small rectangle the
  // pdf takes the solid angle of its two halves by Van Oosterom & Strackee's formula instead
  // (cl/lights/spherical_triangle.h), whose triple product is h * lx * ly for either half.
  if (r.area >= 0.5f) {
    r.omega = r.area;
  } else {
    float t = h * lx * ly;
    float d00_10 = r.x0 * r.x1 + r.y0 * r.y0 + z2, d10_11 = r.x1 * r.x1 + r.y0 * r.y1 + z2;
    float d00_11 = r.x0 * r.x1 + r.y0 * r.y1 + z2, d11_01 = r.x1 * r.x0 + r.y1 * r.y1 + z2;
    float d00_01 = r.x0 * r.x0 + r.y0 * r.y1 + z2;
    // halves (v00, v10, v11) and (v00, v11, v01)
    float den1 = l00 * l10 * l11 + d00_10 * l11 + d00_11 * l10 + d10_11 * l00;
    float den2 = l00 * l11 * l01 + d00_11 * l01 + d00_01 * l11 + d11_01 * l00;
    r.omega = 2.0f * (atan2(t, den1) + atan2(t, den2));
  }
  return r;
}

// Local coordinates (xu, yv) in the rectangle of a direction uniformly distributed in its solid
// angle, for (u, v) in [0,1)^2 (the point is (xu, yv, z0) in the local frame).
INLINE float2 sph_rect_sample(const SphRect* r, float u, float v) {
  // x from the area of the sub-rectangle [x0, xu] (paper eq. 8-10).
  float au = u * r->area + r->k;
  float fu = (cos(au) * r->b0 - r->b1) / sin(au);
  // xu = -cu z0 / sqrt(1 - cu^2) with cu = sign(fu) / sqrt(fu^2 + b0^2), simplified so that
  // 1 - cu^2 does not cancel: xu = sign(fu) h / sqrt(fu^2 + b0^2 - 1).
  float h = -r->z0;
  float den = fu * fu + r->b0sq_minus_1;
  float xu;
  if (den > 0.0f && fu * fu < FLT_INF) {
    xu = h / sqrt(den);
    if (fu < 0.0f) xu = -xu;
  } else {
    xu = fu > 0.0f ? r->x1 : r->x0; // at an edge to float precision (also 0/0 at au = 0)
  }
  xu = clamp(xu, r->x0, r->x1);
  // y uniform in the sine of the elevation within the column at xu (paper eq. 11-12).
  float dd = sqrt(xu * xu + r->z0 * r->z0);
  float h0 = r->y0 / sqrt(dd * dd + r->y0 * r->y0);
  float h1 = r->y1 / sqrt(dd * dd + r->y1 * r->y1);
  float hv = h0 + v * (h1 - h0);
  float c2 = (1.0f - hv) * (1.0f + hv);
  float yv = c2 > 0.0f ? hv * dd / sqrt(c2) : (hv > 0.0f ? r->y1 : r->y0);
  yv = clamp(yv, r->y0, r->y1);
  return make_float2(xu, yv);
}

#endif // CANOPY_CL_LIGHTS_SPHERICAL_RECTANGLE_H
