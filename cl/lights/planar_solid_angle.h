// Solid-angle sampling of quad (parallelogram) and triangle lights, and the choice between it and
// area sampling (docs/design.md, "Sampling area lights"). The choice is a function of the light
// and the shading point only, so light_pdf() (MIS for a BSDF ray that hits the light) returns the
// pdf of the technique sample_light() used.
// - Rectangles (edges orthogonal to 1e-4 relative): Urena et al.'s spherical rectangle.
// - Triangles and other parallelograms: a fan of spherical triangles from the apex F, the point
//   of the light nearest to the foot of the shading point on the light's plane (the foot itself
//   when it lies on the light); one fan triangle is chosen with probability proportional to its
//   solid angle, then sampled by Arvo's method with F as the vertex the second arc starts from. The
//   union is uniform in solid angle, pdf = 1 / omega. The apex makes a viewpoint almost on the
//   plane well conditioned: every arc from F then starts near the nadir, where a whole triangle
//   seen from 1e-6 above would otherwise be a spherical triangle with all three vertices on the
//   horizon.
// - Both samplers take their range from a solid angle accurate to float relative precision (Van
//   Oosterom & Strackee's formula where the angle sum, which loses ~1e-6 sr to cancellation, is
//   small) and map it with formulas that keep that precision (spherical_*.h): perturbing every
//   sin, cos and atan2 by 2 ulps moves the sampled directions by ~1e-6 of the light's angular
//   size on average, ~1e-4 at worst, for solid angles down to 1e-5 sr.
// - Area sampling when omega < LIGHT_SOLID_ANGLE_MIN = 1e-3 sr: the light then spans less than ~2
//   degrees, the area pdf d^2 / (cos A) varies by a fraction of a percent over it unless it is
//   seen edge-on (when its contribution is small), and area sampling costs one square root
//   instead of a dozen trigonometric functions. Also when omega is not finite, or P is on the
//   plane (pdf 0 either way).
#ifndef CANOPY_CL_LIGHTS_PLANAR_SOLID_ANGLE_H
#define CANOPY_CL_LIGHTS_PLANAR_SOLID_ANGLE_H

#include "../compat.h"
#include "../kernel_features.h"
#include "../types.h"
#include "spherical_rectangle.h"
#include "spherical_triangle.h"

#define LIGHT_SOLID_ANGLE_MIN 1e-3f
// |e1 . e2| <= this * |e1| |e2|: the quad is sampled as a rectangle.
#define LIGHT_RECT_TOLERANCE 1e-4f

#define PLANAR_AREA 0 // area sampling (the caller's own code)
#define PLANAR_NONE 1 // the shading point is behind a one-sided light (or on its plane): pdf 0
#define PLANAR_RECT 2 // spherical rectangle
#define PLANAR_FAN 3  // fan of spherical triangles

typedef struct PlanarView {
  int technique; // PLANAR_*
  int corners;   // 4 (quad) or 3 (triangle)
  float omega;   // solid angle (the pdf is 1 / omega)
  float hs;      // signed distance of the shading point from the plane, along n
  float area2;   // |e1 x e2|
  float fa, fb;  // the fan's apex in the light's parameters (point = p + fa e1 + fb e2)
  float fan_omega[4];
  // Fan frame: origin at the shading point, z = the normal turned towards it (the plane is at
  // z = -h), x along e1. In it every vertex has z = -h and every edge z = 0 exactly, so the
  // spherical triangles' great-circle normals keep their small components (a viewpoint near the
  // plane makes the angles at the far vertices nearly pi/2 by amounts of order h).
  float3 fx, fy, fz;
  float h;
  float px, py;       // the light's corner p
  float l1;           // e1 = (l1, 0)
  float e2x, e2y;     // e2
  float cx[4], cy[4]; // the corners
  float bx, by;       // the apex: exactly (0, 0) when the foot is inside the light
#if HAS_LIGHT_QUAD
  SphRect rect;
#endif
} PlanarView;

// Corner i (mod corners) of the light in its parameters: quad (0,0) (1,0) (1,1) (0,1); triangle
// (0,0) (1,0) (0,1).
INLINE float2 planar_corner(int i, int corners) {
  i = i % corners;
  if (i == 0) return make_float2(0.0f, 0.0f);
  if (i == 1) return make_float2(1.0f, 0.0f);
  if (i == 2 && corners == 4) return make_float2(1.0f, 1.0f);
  return make_float2(0.0f, 1.0f);
}

// Parameters clamped into the light: the unit square (quad) or the triangle a, b >= 0, a + b <= 1.
INLINE float2 planar_clamp(float a, float b, int corners) {
  if (!(a >= 0.0f)) a = 0.0f; // also NaN
  if (!(b >= 0.0f)) b = 0.0f;
  if (corners == 4) return make_float2(fmin(a, 1.0f), fmin(b, 1.0f));
  float s = a + b;
  if (s > 1.0f) {
    a = a / s;
    b = fmin(b / s, 1.0f - a);
  }
  return make_float2(a, b);
}

// Fan triangle i: corner i (Arvo's A), the apex (B), corner i + 1 (C), in the fan frame; edge
// vectors from differences of the parameters.
INLINE SphTri planar_fan_triangle(const PlanarView* v, int i) {
  float2 ca = planar_corner(i, v->corners), cc = planar_corner(i + 1, v->corners);
  int j = (i + 1) % v->corners;
  float mh = -v->h;
  float3 a = make_float3(v->cx[i], v->cy[i], mh);
  float3 b = make_float3(v->bx, v->by, mh);
  float3 c = make_float3(v->cx[j], v->cy[j], mh);
  // Edges at the apex as differences of frame coordinates (an apex at the origin makes a x (b - a)
  // exactly vertical); the light's own edge from its parameters.
  float3 ab = make_float3(v->bx - v->cx[i], v->by - v->cy[i], 0.0f);
  float3 bc = make_float3(v->cx[j] - v->bx, v->cy[j] - v->by, 0.0f);
  float acx = cc.x - ca.x, acy = cc.y - ca.y;
  float3 ac = make_float3(acx * v->l1 + acy * v->e2x, acy * v->e2y, 0.0f);
  float abx = v->fa - ca.x, aby = v->fb - ca.y;
  // |a . (b x c)| = plane distance * twice the triangle's area (exactly 0 when it is degenerate)
  float cr = abx * acy - aby * acx;
  float abs_t = v->h * v->area2 * fabs(cr);
  return sph_tri_setup(a, b, c, ab, ac, bc, abs_t);
}

INLINE PlanarView planar_view(const GLOBAL Light* l, float3 P) {
  PlanarView v;
  v.technique = PLANAR_AREA;
  v.corners = IS_LIGHT(l, LIGHT_QUAD) ? 4 : 3;
  v.omega = 0.0f;
  v.fa = v.fb = v.h = v.px = v.py = v.l1 = v.e2x = v.e2y = v.bx = v.by = 0.0f;
  v.fx = v.fy = v.fz = make_float3(0.0f, 0.0f, 0.0f);
  for (int i = 0; i < 4; ++i)
    v.fan_omega[i] = v.cx[i] = v.cy[i] = 0.0f;
  float3 n = xyz_of(l->n), e1 = xyz_of(l->e1), e2 = xyz_of(l->e2);
  float3 dp = P - xyz_of(l->p);
  v.hs = dot(n, dp);
  v.area2 = v.corners == 4 ? l->n.w : 2.0f * l->n.w;
  if (!(l->flags & LIGHT_FLAG_TWO_SIDED) && !(v.hs > 0.0f)) {
    v.technique = PLANAR_NONE;
    return v;
  }
  if (!(fabs(v.hs) > 0.0f)) return v; // on the plane (or NaN): area sampling reports pdf 0
  // Most lights of a many-light scene are small and far: a bound decides without the spherical
  // set-up. omega = integral of cos / d^2 dA <= A h / d_min^3, d_min >= (distance to the
  // centroid) - (radius about it). Not exactly conservative in float, which only moves a light
  // within rounding of the threshold to area sampling: the choice stays a function of (l, P).
  {
    float3 c, r1, r2, r3;
    if (v.corners == 4) {
      c = (e1 + e2) * 0.5f;
      r1 = c;
      r2 = (e1 - e2) * 0.5f;
      r3 = r2;
    } else {
      c = (e1 + e2) * (1.0f / 3.0f);
      r1 = c;
      r2 = e1 - c;
      r3 = e2 - c;
    }
    float rad = sqrt(fmax(dot(r1, r1), fmax(dot(r2, r2), dot(r3, r3))));
    float dmin = fmax(length(c - dp) - rad, fabs(v.hs));
    float bound = l->n.w * (fabs(v.hs) / dmin) / (dmin * dmin);
    if (bound < LIGHT_SOLID_ANGLE_MIN) return v;
  }
  float omega = 0.0f;
  int technique = PLANAR_FAN;
#if HAS_LIGHT_QUAD
  float l1 = length(e1), l2 = length(e2);
  if (v.corners == 4 && fabs(dot(e1, e2)) <= LIGHT_RECT_TOLERANCE * l1 * l2) {
    float3 ex = e1 / l1;
    float3 ey = cross(n, ex);
    v.rect = sph_rect_setup(-dp, ex, ey, n, l1, dot(e2, ey));
    omega = v.rect.omega;
    technique = PLANAR_RECT;
  }
#endif
  if (technique == PLANAR_FAN) {
    v.h = fabs(v.hs);
    v.fz = v.hs > 0.0f ? n : -n;
    v.l1 = length(e1);
    v.fx = e1 / v.l1;
    v.fy = cross(v.fz, v.fx);
    v.px = -dot(dp, v.fx);
    v.py = -dot(dp, v.fy);
    v.e2x = dot(e2, v.fx);
    v.e2y = dot(e2, v.fy);
    // The foot of P on the plane is the frame's (0, 0): the apex when it lies on the light.
    float fb = -v.py / v.e2y;
    float fa = (-v.px - fb * v.e2x) / v.l1;
    for (int i = 0; i < v.corners; ++i) {
      float2 c = planar_corner(i, v.corners);
      v.cx[i] = v.px + c.x * v.l1 + c.y * v.e2x;
      v.cy[i] = v.py + c.y * v.e2y;
    }
    float2 f = planar_clamp(fa, fb, v.corners);
    v.fa = fa;
    v.fb = fb;
    if (!(f.x == fa && f.y == fb)) {
      // Foot outside: the nearest point of the light's boundary (in the plane, not in the
      // parameters, which a skewed light would move far from the foot, towards the horizon).
      float best = FLT_INF;
      for (int i = 0; i < v.corners; ++i) {
        int j = (i + 1) % v.corners;
        float dx = v.cx[j] - v.cx[i], dy = v.cy[j] - v.cy[i];
        float t = clamp(-(v.cx[i] * dx + v.cy[i] * dy) / (dx * dx + dy * dy), 0.0f, 1.0f);
        float qx = v.cx[i] + t * dx, qy = v.cy[i] + t * dy;
        float q2 = qx * qx + qy * qy;
        if (q2 < best) {
          float2 ci = planar_corner(i, v.corners), cj = planar_corner(j, v.corners);
          best = q2;
          v.bx = qx;
          v.by = qy;
          v.fa = ci.x + t * (cj.x - ci.x);
          v.fb = ci.y + t * (cj.y - ci.y);
        }
      }
    }
    for (int i = 0; i < v.corners; ++i) {
      SphTri t = planar_fan_triangle(&v, i);
      v.fan_omega[i] = t.omega;
      omega += t.omega;
    }
  }
  if (omega >= LIGHT_SOLID_ANGLE_MIN && omega < FLT_INF) {
    v.technique = technique;
    v.omega = omega;
  }
  return v;
}

// A direction uniform in the light's solid angle (v->technique RECT or FAN): the unit direction
// *wi, the distance *dist to the light's plane along it and the point's parameters (a, b) on the
// light (returned). *wi and *dist come from the sampled direction, not from the rounded point,
// which would lose their precision when the shading point is very close to the light.
INLINE float2 planar_sample_solid_angle(const PlanarView* v, float u1, float u2, float3* wi,
                                        float* dist) {
#if HAS_LIGHT_QUAD
  if (v->technique == PLANAR_RECT) {
    const SphRect* r = &v->rect;
    float2 xy = sph_rect_sample(r, u1, u2);
    float3 to = r->x * xy.x + r->y * xy.y + r->z * r->z0;
    *dist = length(to);
    *wi = to / *dist;
    return planar_clamp((xy.x - r->x0) / (r->x1 - r->x0), (xy.y - r->y0) / (r->y1 - r->y0), 4);
  }
#endif
  // Fan triangle by its share of the solid angle; u1 is rescaled to the triangle's interval.
  float target = u1 * v->omega, acc = 0.0f;
  int pick = -1;
  for (int i = 0; i < v->corners; ++i) {
    if (!(v->fan_omega[i] > 0.0f)) continue;
    pick = i;
    if (target < acc + v->fan_omega[i]) break;
    acc += v->fan_omega[i];
  }
  float u = pick >= 0 ? clamp((target - acc) / v->fan_omega[pick], 0.0f, 1.0f) : 0.0f;
  SphTri t = planar_fan_triangle(v, pick >= 0 ? pick : 0);
  float3 w = sph_tri_sample(&t, u, u2);
  float d = w.z < 0.0f ? v->h / -w.z : 0.0f;
  *wi = v->fx * w.x + v->fy * w.y + v->fz * w.z;
  *dist = d;
  // Ray-plane intersection, in the light's parameters.
  float b = (w.y * d - v->py) / v->e2y;
  float a = (w.x * d - v->px - b * v->e2x) / v->l1;
  return planar_clamp(a, b, v->corners);
}

#endif // CANOPY_CL_LIGHTS_PLANAR_SOLID_ANGLE_H
