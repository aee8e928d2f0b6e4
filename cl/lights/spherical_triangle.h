// Uniform sampling of the solid angle of a spherical triangle (Arvo 1995, "Stratified Sampling of
// Spherical Triangles", SIGGRAPH, Fig. 2), and its solid angle to float relative precision (Van
// Oosterom & Strackee 1983). Vertices are given as vectors from the viewpoint (not unit) together
// with the triangle's edge vectors and |a . (b x c)|, which callers compute from the light's own
// edges and plane distance: differences of nearly equal unit vectors would lose the precision a
// small or nearby triangle needs.
#ifndef CANOPY_CL_LIGHTS_SPHERICAL_TRIANGLE_H
#define CANOPY_CL_LIGHTS_SPHERICAL_TRIANGLE_H

#include "../compat.h"

typedef struct SphTri {
  float3 A, B, C;   // unit directions towards the vertices
  float3 t_ac;      // unit tangent of the arc A -> C at A
  float alpha;      // angle at vertex A (between the arcs A->B and A->C)
  float tan_half_c; // tan(c / 2), c the arc A -> B
  float area;       // alpha + beta + gamma - pi
  float omega;      // solid angle for the pdf and the sampler (see sph_tri_setup)
} SphTri;

// a x b, which equals a x d for d = b - a: each component from whichever form has the smaller
// rounding bound (b - a for a distant short edge, b for a vertex near the viewpoint's foot).
INLINE float3 sph_cross(float3 a, float3 b, float3 d) {
  float3 r1 = cross(a, b), r2 = cross(a, d);
  float3 fa = fabs(a), fb = fabs(b), fd = fabs(d);
  float3 e1 =
      make_float3(fa.y * fb.z + fa.z * fb.y, fa.z * fb.x + fa.x * fb.z, fa.x * fb.y + fa.y * fb.x);
  float3 e2 =
      make_float3(fa.y * fd.z + fa.z * fd.y, fa.z * fd.x + fa.x * fd.z, fa.x * fd.y + fa.y * fd.x);
  return make_float3(e1.x < e2.x ? r1.x : r2.x, e1.y < e2.y ? r1.y : r2.y,
                     e1.z < e2.z ? r1.z : r2.z);
}

// a, b, c: vertices relative to the viewpoint; ab = b - a, ac = c - a, bc = c - b computed from
// the light's edges; abs_t = |a . (b x c)| (= plane distance * twice the triangle's area).
INLINE SphTri sph_tri_setup(float3 a, float3 b, float3 c, float3 ab, float3 ac, float3 bc,
                            float abs_t) {
  SphTri t;
  float la = length(a), lb = length(b), lc = length(c);
  t.A = a / la;
  t.B = b / lb;
  t.C = c / lc;
  // Normals of the great circles through the edges, from the accurate edge vectors or the
  // vertices (sph_cross). The angle at a vertex is the angle between the two normals there;
  // |(a x b) x (a x c)| = |a . (b x c)| |a|, so each angle is an atan2 of accurate terms.
  float3 n_ab = sph_cross(a, b, ab);
  float3 n_ac = sph_cross(a, c, ac);
  float3 n_bc = sph_cross(b, c, bc);
  float ca = dot(n_ab, n_ac), sa = abs_t * la;
  float cb = -dot(n_ab, n_bc), sb = abs_t * lb;
  float cc = dot(n_ac, n_bc), sc = abs_t * lc;
  t.alpha = atan2(sa, ca);
  float beta = atan2(sb, cb);
  float gamma = atan2(sc, cc);
  // tan(c/2) = |a x b| / (|a||b| + a.b): no cosine of a short arc
  float tden = la * lb + dot(a, b);
  t.tan_half_c = tden > 0.0f ? length(n_ab) / tden : FLT_INF;
  float3 tac = ac - t.A * dot(ac, t.A);
  float ltac = length(tac);
  t.t_ac = ltac > 0.0f ? tac / ltac : make_float3(0.0f, 0.0f, 0.0f);
  t.area = fmax(0.0f, t.alpha + beta + gamma - CANOPY_PI);
  // The angle sum loses ~1e-6 sr absolute to cancellation against pi, too much for the pdf of a
  // small triangle; Van Oosterom & Strackee's tan(omega/2) = |a.(b x c)| / (|a||b||c| + (a.b)|c|
  // + (a.c)|b| + (b.c)|a|) keeps relative precision there. It is ill-conditioned only near
  // omega = pi with a tiny numerator (a viewpoint almost on the plane above an edge), where the
  // angle sum is accurate: each is used where it is good.
  if (!(abs_t > 0.0f)) {
    t.omega = 0.0f;
  } else if (t.area >= 0.5f) {
    t.omega = t.area;
  } else {
    float den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
    t.omega = 2.0f * atan2(abs_t, den);
  }
  return t;
}

// Unit direction uniformly distributed in the triangle's solid angle for (u1, u2) in [0,1)^2.
// First a point C' on the arc A -> C such that the triangle A B C' has area u1 * area, then a
// point on the arc B -> C' uniform in 1 - cos of its distance to B.
INLINE float3 sph_tri_sample(const SphTri* t, float u1, float u2) {
  // Arvo finds cos(b'), b' = the arc A -> C', from the area; a short arc is then lost in the
  // cosine (sqrt(1 - cos^2) has absolute error ~ sqrt(eps)). Instead, the excess E of a spherical
  // triangle with sides c, b' and included angle alpha satisfies the standard identity
  // tan(E/2) = tan(b'/2) tan(c/2) sin(alpha) / (1 + tan(b'/2) tan(c/2) cos(alpha)), which solved
  // for tan(b'/2) with E = u1 * area is well conditioned:
  //   tan(b'/2) = sin(E/2) / (tan(c/2) sin(alpha - E/2)).
  float e2 = 0.5f * u1 * t->omega; // omega rather than the angle sum: relative precision
  float num = sin(e2), den = t->tan_half_c * sin(t->alpha - e2);
  float cos_b, sin_b;
  if (!(num < den)) {
    // tan(b'/2) >= 1 (b' >= pi/2): the same in 1 / tan(b'/2) (den 0 -> b' = pi)
    float y = num > 0.0f ? fmax(den, 0.0f) / num : 1.0f;
    cos_b = (y * y - 1.0f) / (y * y + 1.0f);
    sin_b = 2.0f * y / (y * y + 1.0f);
  } else {
    float x = num / den;
    cos_b = (1.0f - x * x) / (1.0f + x * x);
    sin_b = 2.0f * x / (1.0f + x * x);
  }
  float3 c1 = t->A * cos_b + t->t_ac * sin_b;
  // 1 - C'.B as |C' - B|^2 / 2, and the tangent at B from C' - B: both keep their precision when
  // C' is close to B.
  float3 dcb = c1 - t->B;
  float k = fmin(2.0f, 0.5f * dot(dcb, dcb));
  float omz = u2 * k; // 1 - cos of the distance to B
  float sz = sqrt(fmax(0.0f, omz * (2.0f - omz)));
  float3 tb = dcb - t->B * dot(dcb, t->B);
  float ltb = length(tb);
  if (!(ltb > 0.0f)) return t->B;
  return normalize(t->B * (1.0f - omz) + tb * (sz / ltb));
}

#endif // CANOPY_CL_LIGHTS_SPHERICAL_TRIANGLE_H
