// Bounds of one emitter for the light tree, per light type (Conty Estevez & Kulla 2018, §4.1
// and Table 1; the energy as in §5.1): bounding box, orientation cone (as cosines) and energy, and
// the bounding sphere of a box. Compiles as OpenCL C and as C++ (cl/compat.h).
#ifndef CANOPY_LIGHT_BOUNDS_H
#define CANOPY_LIGHT_BOUNDS_H

#include "../compat.h"
#include "../simd4.h"
#include "../types.h"

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
    // points despite their rounding (cl/lights/light_sample.h).
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

#endif // CANOPY_LIGHT_BOUNDS_H
