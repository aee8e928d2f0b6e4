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
  float cos_k, sin_k; // k = 2 pi - g2 - g3, the paper's offset of the first variable
  float n0;           // cos(k) b0 - b1
  float area;         // g0 + g1 + g2 + g3 - 2 pi (accurate only when large)
  float omega;        // solid angle: the pdf and the range of the first variable
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
  r.area = fmax(0.0f, g0 + g1 + g2 + g3 - 2.0f * CANOPY_PI);
  // cos and sin of k = (pi - g2) + (pi - g3) from the atan2 arguments of g2 and g3, not from k:
  // the first variable is k + u omega, and k rounded to float would move it by ~1e-7 absolute,
  // a distortion of ~1e-7 / omega of the sampled x.
  float s2 = h * l01, c2 = r.x0 * r.y1, s3 = h * l00, c3 = -r.x0 * r.y0;
  float r2 = sqrt(s2 * s2 + c2 * c2), r3 = sqrt(s3 * s3 + c3 * c3);
  float cg2 = c2 / r2, sg2 = s2 / r2, cg3 = c3 / r3, sg3 = s3 / r3;
  r.cos_k = cg2 * cg3 - sg2 * sg3;
  r.sin_k = -(sg2 * cg3 + cg2 * sg3);
  r.n0 = r.cos_k * r.b0 - r.b1;
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
  // au = k + u omega, by the angle-sum formulas (see cos_k): omega, accurate to float relative
  // precision, is the range of the variable, so the sampled x keeps that precision too.
  // cos(au) b0 - b1 and sin(au) are their values at u = 0 plus the change over du, formed
  // separately: both are O(1) while the change is O(omega).
  float du = u * r->omega;
  float sh = sin(0.5f * du), sdu = sin(du);
  float omc = 2.0f * sh * sh; // 1 - cos(du)
  float sin_au = r->sin_k + (r->cos_k * sdu - r->sin_k * omc);
  float fu = (r->n0 - r->b0 * (r->cos_k * omc + r->sin_k * sdu)) / sin_au;
  // xu = -cu z0 / sqrt(1 - cu^2) with cu = sign(fu) / sqrt(fu^2 + b0^2), simplified so that
  // 1 - cu^2 does not cancel: xu = sign(fu) h / sqrt(fu^2 + b0^2 - 1).
  float h = -r->z0;
  float den = fu * fu + r->b0sq_minus_1;
  float xu;
  if (den > 0.0f && fu * fu < FLT_INF) {
    xu = h / sqrt(den);
    if (fu < 0.0f) xu = -xu;
  } else {
    // Beyond float resolution (also 0/0 at au = 0): directions within ~1e-3 rad of the horizon
    // along x, seen from a viewpoint ~1e-6 from the plane, where fu^2 and 1 - b0^2 agree to the
    // last bits (~4e-4 of the samples 1e-6 beside a 4 m edge). Clamped to the end; such
    // directions carry ~1e-3 of a sample's contribution at most.
    xu = fu > 0.0f ? r->x1 : r->x0;
  }
  xu = clamp(xu, r->x0, r->x1);
  // y uniform in the sine of the elevation within the column at xu (paper eq. 11-12).
  // With 1 -+ h0 and 1 -+ h1 formed without cancellation, 1 - hv^2 = (1 - hv)(1 + hv) keeps its
  // precision when hv is near +-1 (a rectangle seen far off to one side).
  float dd = sqrt(xu * xu + r->z0 * r->z0), d2 = dd * dd;
  float r0 = sqrt(d2 + r->y0 * r->y0), r1 = sqrt(d2 + r->y1 * r->y1);
  float h0 = r->y0 / r0, h1 = r->y1 / r1;
  float om0 = (r->y0 > 0.0f ? d2 / (r0 + r->y0) : r0 - r->y0) / r0; // 1 - h0
  float op0 = (r->y0 < 0.0f ? d2 / (r0 - r->y0) : r0 + r->y0) / r0; // 1 + h0
  float om1 = (r->y1 > 0.0f ? d2 / (r1 + r->y1) : r1 - r->y1) / r1;
  float op1 = (r->y1 < 0.0f ? d2 / (r1 - r->y1) : r1 + r->y1) / r1;
  float hv = h0 + v * (h1 - h0);
  float c2 = ((1.0f - v) * om0 + v * om1) * ((1.0f - v) * op0 + v * op1);
  float yv = c2 > 0.0f ? hv * dd / sqrt(c2) : (hv > 0.0f ? r->y1 : r->y0);
  yv = clamp(yv, r->y0, r->y1);
  return make_float2(xu, yv);
}

#endif // CANOPY_CL_LIGHTS_SPHERICAL_RECTANGLE_H
