// Importance of clusters and emitters for a shading point (Conty Estevez & Kulla 2018, §5.1, Eq. 3;
// theta_u from the bounding sphere, Fig. 7), four lanes at a time: the lanes of a 4-wide node or
// the emitters of a leaf, read from the records of layout.h. Also the orientation ablation
// (LT_TERMS_DISTANCE, the paper's Fig. 15-16). Compiles as OpenCL C and as C++ (cl/compat.h).
#ifndef CANOPY_LIGHT_TREE_IMPORTANCE_H
#define CANOPY_LIGHT_TREE_IMPORTANCE_H

#include "../compat.h"
#include "../simd4.h"
#include "layout.h"
#include "query.h"

// Smallest importance given to a lane that can contribute, so underflow never makes it 0 (the
// importances of the four lanes are normalised by their maximum energy and minimum distance first).
#define LT_IMPORTANCE_FLOOR 1e-30f

// |a x d| lane-wise: with 1/|d| the sine of the angle between a unit vector a and d.
LT_HOT v4f lt_vcross_len(v4f ax, v4f ay, v4f az, v4f dx, v4f dy, v4f dz) {
  v4f kx = v4_sub(v4_mul(ay, dz), v4_mul(az, dy));
  v4f ky = v4_sub(v4_mul(az, dx), v4_mul(ax, dz));
  v4f kz = v4_sub(v4_mul(ax, dy), v4_mul(ay, dx));
  return v4_sqrt(v4_add(v4_add(v4_mul(kx, kx), v4_mul(ky, ky)), v4_mul(kz, kz)));
}

// ---------------------------------------------------------------- cluster importance (Eq. 3)
// The four lanes (clusters or emitters) a node or a leaf ranks, decoded from its records.
typedef struct LtLanes {
  v4f cx, cy, cz, r; // bounding spheres
  v4f ax, ay, az;    // cone axes (0 when every lane's cone is the full sphere)
  v4f cos_o, cos_e;  // cone: normal bound theta_o, emission bound theta_e
  v4f energy;        // 0: unused lane
  v4f plane_h;       // half-space bound offset (LT_PLANE_NONE: none)
} LtLanes;

// The geometry of four clusters seen from P, shared by the importance of Conty Estevez & Kulla
// (Eq. 3) and the BRDF-oriented one of Liu et al. (cl/light_tree/brdf_cut.h): the vector d from P
// to each centre, d^2, 1/d, the half-angle theta_u of the cone from P around each bounding
// sphere as (sin, cos) (theta_u = pi inside the sphere), and the orientation bound cos(theta') =
// cos(max(theta - theta_o - theta_u, 0)), 0 when theta' >= theta_e. `front` is false for a lane
// whose half-space bound puts P behind all its one-sided planar emitters.
typedef struct LtView {
  v4f dx, dy, dz, d2, inv_d, sin_u, cos_u, orient;
  v4m inside, front;
} LtView;

// The orientation bound of Eq. 3 and Eq. 7: cos(theta') = cos(max(theta - theta_o - theta_u, 0)),
// 0 when theta' >= theta_e, from (cos, sin) of theta (the smallest angle between the cone axis and
// the directions from the cluster towards the receiver) and of theta_u. All angle differences use
// cos(a-b) = cos a cos b + sin a sin b (no acos).
LT_HOT v4f lt_orient_v(const LtLanes* l, v4f cos_t, v4f sin_t, v4f cos_u, v4f sin_u) {
  v4f zero = v4_splat(0.0f);
  v4f one = v4_splat(1.0f);
  v4f sin_o = v4_sqrt(v4_max(v4_sub(one, v4_mul(l->cos_o, l->cos_o)), zero));
  // theta - theta_o, clamped at 0
  v4m within_o = v4_ge(cos_t, l->cos_o);
  v4f c1 = v4_sel(v4_add(v4_mul(cos_t, l->cos_o), v4_mul(sin_t, sin_o)), one, within_o);
  v4f s1 = v4_sel(v4_sub(v4_mul(sin_t, l->cos_o), v4_mul(cos_t, sin_o)), zero, within_o);
  // minus theta_u, clamped at 0
  v4f c2 = v4_sel(v4_add(v4_mul(c1, cos_u), v4_mul(s1, sin_u)), one, v4_ge(c1, cos_u));
  return v4_sel(zero, c2, v4_gt(c2, l->cos_e));
}

LT_HOT LtView lt_view_v(const LtLanes* l, float3 P) {
  LtView v;
  v4f zero = v4_splat(0.0f);
  v4f one = v4_splat(1.0f);
  v.dx = v4_sub(l->cx, v4_splat(P.x));
  v.dy = v4_sub(l->cy, v4_splat(P.y));
  v.dz = v4_sub(l->cz, v4_splat(P.z));
  v.d2 = v4_add(v4_add(v4_mul(v.dx, v.dx), v4_mul(v.dy, v.dy)), v4_mul(v.dz, v.dz));
  v4f r2 = v4_mul(l->r, l->r);
  v.inside = v4_le(v.d2, r2);
  // Every cosine and sine below is a dot or cross product scaled by 1/d, so the square roots run
  // side by side instead of one after the other (the latency of this function bounds a descent).
  v.inv_d = v4_div(one, v4_sqrt(v4_max(v.d2, v4_splat(1e-36f))));
  // theta_u: half-angle of the cone from P around the bounding sphere
  v4f sin_u = v4_min(v4_mul(l->r, v.inv_d), one);
  v4f cos_u = v4_min(v4_mul(v4_sqrt(v4_max(v4_sub(v.d2, r2), zero)), v.inv_d), one);
  v.sin_u = v4_sel(sin_u, zero, v.inside);
  v.cos_u = v4_sel(cos_u, v4_splat(-1.0f), v.inside);
  // Fast path: four full-sphere cones (theta_o = pi: points, spheres, two-sided emitters and
  // their clusters, every lane under LT_TERMS_DISTANCE) bound every direction, theta' = 0 and
  // cos(theta') = 1; for finite P the general code gives exactly the same (c1 = 1, s1 = 0, c2 = 1)
  // at the cost of the axis (lt_decode_axes: not even decoded) and a third of this function.
  // Full-sphere lanes never carry a half-space bound, so `front` is all true there.
  v4m full = v4_le(l->cos_o, v4_splat(-1.0f));
  v.front = full;
  if (v4_all(full)) {
    v.orient = v4_sel(zero, one, v4_gt(one, l->cos_e));
    return v;
  }
  // theta: angle between the cone axis and the direction from the cluster towards P
  v4f cos_t = v4_mul(
      v4_sub(zero, v4_add(v4_add(v4_mul(l->ax, v.dx), v4_mul(l->ay, v.dy)), v4_mul(l->az, v.dz))),
      v.inv_d);
  // half-space bound: dot(a, P - c) / d > -(h / d + slope), else every emitter faces away from P
  v.front =
      v4_gt(cos_t, v4_sub(zero, v4_add(v4_mul(l->plane_h, v.inv_d), v4_splat(LT_PLANE_SLOPE))));
  v4f sin_t = v4_min(v4_mul(lt_vcross_len(l->ax, l->ay, l->az, v.dx, v.dy, v.dz), v.inv_d), one);
  v.orient = lt_orient_v(l, cos_t, sin_t, v.cos_u, v.sin_u);
  return v;
}

// The importance of four lanes from their falloff denominators `den` (d^2 for a point, d_min for
// a segment), orientation factors `orient` (including the receiver's cosine) and half-space tests
// `front`: E * orient / den, normalised by the largest energy and the smallest denominator among
// the lanes (only ratios matter), at least LT_IMPORTANCE_FLOOR for a lane that can contribute.
// If no lane can contribute but some has energy (bounds of the parent were looser than those of
// its children) and `fallback` is set, lanes with energy are ranked by E / den alone, so a descent
// never dead-ends and the pmf sums to 1 over the lights with energy; such picks contribute 0,
// which keeps them unbiased.
LT_HOT v4f lt_rank_v(const LtLanes* l, v4f den, v4f orient, v4m front, int fallback) {
  v4f zero = v4_splat(0.0f);
  v4m alive = v4_gt(l->energy, zero);
  float emax = v4_hmax(l->energy);
  float dmin = v4_hmin(v4_sel(v4_splat(3.0e38f), den, alive));
  float inv_emax = emax > 0.0f ? 1.0f / emax : 0.0f;
  v4f e = v4_mul(l->energy, v4_splat(inv_emax));
  v4f g = v4_div(v4_splat(dmin), den);
  v4f imp = v4_mul(v4_mul(e, g), orient);
  v4m contributes = v4_and(v4_and(alive, v4_gt(orient, zero)), front);
  v4f res = v4_sel(zero, v4_max(imp, v4_splat(LT_IMPORTANCE_FLOOR)), contributes);
  if (fallback && !(v4_sum(res) > 0.0f) && emax > 0.0f)
    res = v4_sel(zero, v4_max(v4_mul(e, g), v4_splat(LT_IMPORTANCE_FLOOR)), alive);
  return res;
}

// Importance of four clusters for a shading point P with unit normal N (N = 0: no orientation,
// e.g. a point in a medium or a two-sided/transmissive surface). Per lane:
//   E * cos(theta') * max(cos(theta_i'), 0) / max(d^2, (r/2)^2)
// (lt_view_v for theta'), theta_i' = max(theta_i - theta_u, 0). Emitters below the horizon of N
// are culled (opaque surfaces).
// Lanes are normalised by the largest energy and the smallest clamped d^2 among the lanes (only
// ratios matter) and a lane that can contribute gets at least LT_IMPORTANCE_FLOOR: the result is
// never 0 for a cluster that can contribute and never overflows. A lane whose half-space bound
// (plane offset h, see LT_PLANE_SLOPE; LT_PLANE_NONE: none) puts P behind all its one-sided planar
// emitters is 0 whatever its sphere, P inside it included. If no lane can contribute and
// `fallback` is set (stochastic descents), lanes with energy get E/d^2 (see below); only lanes
// without energy are ever 0 then. Without `fallback` (splitting) such lanes stay 0.
LT_HOT v4f lt_importance_v(const LtLanes* l, float3 P, float3 N, int fallback) {
  v4f zero = v4_splat(0.0f);
  v4f one = v4_splat(1.0f);
  LtView v = lt_view_v(l, P);
  v4f d2c = v4_max(v4_max(v.d2, v4_mul(v4_mul(l->r, l->r), v4_splat(0.25f))), v4_splat(1e-36f));
  // incidence at P
  v4f cos_i = one;
  if (N.x != 0.0f || N.y != 0.0f || N.z != 0.0f) {
    v4f nx = v4_splat(N.x), ny = v4_splat(N.y), nz = v4_splat(N.z);
    v4f ci = v4_mul(v4_add(v4_add(v4_mul(v.dx, nx), v4_mul(v.dy, ny)), v4_mul(v.dz, nz)), v.inv_d);
    v4f si = v4_min(v4_mul(lt_vcross_len(nx, ny, nz, v.dx, v.dy, v.dz), v.inv_d), one);
    cos_i = v4_sel(v4_add(v4_mul(ci, v.cos_u), v4_mul(si, v.sin_u)), one, v4_ge(ci, v.cos_u));
    cos_i = v4_max(cos_i, zero);
  }
  return lt_rank_v(l, d2c, v4_mul(v.orient, cos_i), v.front, fallback);
}
// ---------------------------------------------------------------- segment importance (§5.2, Eq. 7)
// Importance of four clusters for the ray segment x(t) = a + t d, t in [0, len] (a = q->P, unit
// d = q->N) in a medium, whose direct light is integrated along the segment (equiangular sampling):
// what remains of a light's 1/x^2 after that integral is (theta_b - theta_a) / D (Eq. 4), so the
// falloff is 1/d_min. Per lane (Eq. 7):
//   E * cos(max(theta_min - theta_o - theta_u, 0)) / max(d_min, r/2)
// (0 when that angle >= theta_e), d_min the distance from the centre c to the segment, theta_u the
// sphere's half-angle seen from the closest point, theta_min the smallest angle between the cone
// axis and a direction from c towards a point of the segment (Eq. 5-6). As the paper says, the
// distance and the angle are bounded at different points of the segment: conservative. No receiver
// cosine (a medium point has no normal). Normalisation, floor and `fallback` as lt_importance_v.
//
// theta_min: the directions from c to x(t) sweep the great-circle arc from v0 = (a - c)/|a - c| to
// v1 = (b - c)/|b - c|. Eq. 5-6 maximise v . axis over the arc in the basis o0 = v0, o1 = v1
// orthonormalised against v0, which is ill-conditioned for short segments (v0 ~ v1) and for c near
// the segment's line. The same maximum in the basis (w/D, d), w = the vector from c to the foot of
// the perpendicular on the line, D = |w|: x(s) - c = w + s d, s in [s_a, s_b] = [(a - c).d,
// (a - c).d + len], and (w + s d).axis / |w + s d| is stationary at s* = D^2 (d.axis) / (w.axis),
// the maximum over the whole line iff w.axis > 0, of value sqrt((w.axis)^2 + D^2 (d.axis)^2) / D
// (Eq. 6's second case: phi0 within the arc); if w.axis <= 0 or s* is outside [s_a, s_b] (Eq. 6's
// first case: o1.a < 0 or v0.v1 > cos phi0) the maximum is b_max, the larger endpoint cosine. Where
// c is within D <= 1e-3 sqrt(s_a^2 + s_b^2) of the line with its foot on the segment, the direction
// of w is rounding noise and cos theta_min = 1 (conservative: some plane through the line holds the
// axis). A zero-length segment is a point (s_a = s_b).
//
// Half-space bound (one-sided planar lanes): dot(axis, x - c) + h + LT_PLANE_SLOPE |x - c| is
// convex in x, so it is positive somewhere on the segment iff it is at an end: the lane is culled
// only if both ends are behind.
LT_HOT v4f lt_importance_seg_v(const LtLanes* l, const LtQuery* q, int fallback) {
  v4f zero = v4_splat(0.0f);
  v4f one = v4_splat(1.0f);
  v4f dx = v4_splat(q->N.x), dy = v4_splat(q->N.y), dz = v4_splat(q->N.z);
  v4f len = v4_splat(q->len);
  // e = a - c, s_a = e.d, w = e - s_a d
  v4f ex = v4_sub(v4_splat(q->P.x), l->cx);
  v4f ey = v4_sub(v4_splat(q->P.y), l->cy);
  v4f ez = v4_sub(v4_splat(q->P.z), l->cz);
  v4f sa = v4_add(v4_add(v4_mul(ex, dx), v4_mul(ey, dy)), v4_mul(ez, dz));
  v4f sb = v4_add(sa, len);
  v4f wx = v4_sub(ex, v4_mul(sa, dx));
  v4f wy = v4_sub(ey, v4_mul(sa, dy));
  v4f wz = v4_sub(ez, v4_mul(sa, dz));
  v4f D2 = v4_add(v4_add(v4_mul(wx, wx), v4_mul(wy, wy)), v4_mul(wz, wz));
  // closest point: s = clamp(0, s_a, s_b)
  v4f sc = v4_max(sa, v4_min(sb, zero));
  v4f dist2 = v4_add(D2, v4_mul(sc, sc));
  v4f r2 = v4_mul(l->r, l->r);
  v4m inside = v4_le(dist2, r2);
  v4f dist = v4_sqrt(dist2);
  v4f inv_dist = v4_div(one, v4_max(dist, v4_splat(1e-18f)));
  // theta_u from the closest point (pi inside the sphere)
  v4f sin_u = v4_min(v4_mul(l->r, inv_dist), one);
  v4f cos_u = v4_min(v4_mul(v4_sqrt(v4_max(v4_sub(dist2, r2), zero)), inv_dist), one);
  sin_u = v4_sel(sin_u, zero, inside);
  cos_u = v4_sel(cos_u, v4_splat(-1.0f), inside);
  v4f orient;
  v4m front = v4_le(l->cos_o, v4_splat(-1.0f)); // full-sphere lanes: no half-space bound
  if (v4_all(front)) {
    orient = v4_sel(zero, one, v4_gt(one, l->cos_e)); // theta' = 0, as in lt_view_v
  } else {
    v4f fx = v4_add(ex, v4_mul(len, dx)); // f = b - c
    v4f fy = v4_add(ey, v4_mul(len, dy));
    v4f fz = v4_add(ez, v4_mul(len, dz));
    v4f la = v4_sqrt(v4_add(v4_add(v4_mul(ex, ex), v4_mul(ey, ey)), v4_mul(ez, ez)));
    v4f lb = v4_sqrt(v4_add(v4_add(v4_mul(fx, fx), v4_mul(fy, fy)), v4_mul(fz, fz)));
    v4f ea = v4_add(v4_add(v4_mul(ex, l->ax), v4_mul(ey, l->ay)), v4_mul(ez, l->az));
    v4f fa = v4_add(v4_add(v4_mul(fx, l->ax), v4_mul(fy, l->ay)), v4_mul(fz, l->az));
    v4f da = v4_add(v4_add(v4_mul(dx, l->ax), v4_mul(dy, l->ay)), v4_mul(dz, l->az));
    v4f wa = v4_add(v4_add(v4_mul(wx, l->ax), v4_mul(wy, l->ay)), v4_mul(wz, l->az));
    // half-space bound at either end: the larger margin dot(axis, x - c) + h + slope |x - c|
    v4f slope = v4_splat(LT_PLANE_SLOPE);
    v4f margin_a = v4_add(ea, v4_add(l->plane_h, v4_mul(slope, la)));
    v4f margin_b = v4_add(fa, v4_add(l->plane_h, v4_mul(slope, lb)));
    front = v4_gt(v4_max(margin_a, margin_b), zero);
    // b_max: the endpoint cosines
    v4f tiny = v4_splat(1e-30f);
    v4f ca = v4_div(ea, v4_max(la, tiny));
    v4f cb = v4_div(fa, v4_max(lb, tiny));
    v4f cos_t = v4_max(ca, cb);
    // the interior maximum (Eq. 6, second case) where s* = D^2 da / wa lies in [s_a, s_b]
    v4f D2da = v4_mul(D2, da);
    v4m interior =
        v4_and(v4_gt(wa, zero), v4_and(v4_le(v4_mul(sa, wa), D2da), v4_le(D2da, v4_mul(sb, wa))));
    v4f R = v4_mul(v4_sqrt(v4_add(v4_mul(wa, wa), v4_mul(D2da, da))),
                   v4_div(one, v4_sqrt(v4_max(D2, v4_splat(1e-36f)))));
    cos_t = v4_sel(cos_t, v4_min(R, one), interior);
    // c (numerically) on the line, its foot on the segment: every direction of the plane
    v4m on_line = v4_and(v4_le(D2, v4_mul(v4_splat(1e-6f), v4_add(v4_mul(sa, sa), v4_mul(sb, sb)))),
                         v4_and(v4_le(sa, zero), v4_ge(sb, zero)));
    cos_t = v4_sel(cos_t, one, on_line);
    cos_t = v4_min(v4_max(cos_t, v4_splat(-1.0f)), one);
    v4f sin_t = v4_sqrt(v4_max(v4_sub(one, v4_mul(cos_t, cos_t)), zero));
    orient = lt_orient_v(l, cos_t, sin_t, cos_u, sin_u);
  }
  // falloff 1/d_min, d_min clamped at r/2 like Eq. 3's d; normalised by the largest energy and
  // the smallest d_min among the lanes
  v4f dc = v4_max(v4_max(dist, v4_mul(l->r, v4_splat(0.5f))), v4_splat(1e-18f));
  return lt_rank_v(l, dc, orient, front, fallback);
}

// Importance of four lanes for a query: a point (lt_importance_v; N as the caller passes it, which
// the orientation ablation may have cleared) or a segment (lt_importance_seg_v).
LT_HOT v4f lt_importance_q_v(const LtLanes* l, const LtQuery* q, float3 N, int fallback) {
  if (LT_QUERY_IS_SEGMENT(q)) return lt_importance_seg_v(l, q, fallback);
  float slack = LT_QUERY_SLACK(q);
  if (slack > 0.0f) { // the midpoint ablation (query.h): spheres and half-spaces grown by slack
    LtLanes w = *l;
    w.r = v4_add(l->r, v4_splat(slack));
    w.plane_h = v4_add(l->plane_h, v4_splat(slack));
    return lt_importance_v(&w, q->P, N, fallback);
  }
  return lt_importance_v(l, q->P, N, fallback);
}

LT_HOT float4 lt_importance4(float4 cx, float4 cy, float4 cz, float4 r, float4 ax, float4 ay,
                             float4 az, float4 cos_o, float4 cos_e, float4 energy, float3 P,
                             float3 N) {
  LtLanes l;
  l.cx = v4_from_f4(cx);
  l.cy = v4_from_f4(cy);
  l.cz = v4_from_f4(cz);
  l.r = v4_from_f4(r);
  l.ax = v4_from_f4(ax);
  l.ay = v4_from_f4(ay);
  l.az = v4_from_f4(az);
  l.cos_o = v4_from_f4(cos_o);
  l.cos_e = v4_from_f4(cos_e);
  l.energy = v4_from_f4(energy);
  l.plane_h = v4_splat(LT_PLANE_NONE);
  return v4_to_f4(lt_importance_v(&l, P, N, 1));
}

// Under LT_TERMS_DISTANCE (the orientation ablation) every cone is the full sphere and bounds
// every direction (cos theta' = 1), N = 0 drops the receiver's incidence term, and no half-space
// bound culls (it is an orientation term too).
INLINE void lt_without_orientation(const LtTree* t, LtLanes* l, float3* N) {
  if (t->root_info.w == LT_TERMS_FULL) return;
  l->cos_o = v4_splat(-1.0f);
  l->cos_e = v4_splat(-1.0f);
  l->plane_h = v4_splat(LT_PLANE_NONE);
  *N = make_float3(0.0f, 0.0f, 0.0f);
}

// The cone axes of four lanes from their octahedral bits, decoded only if some lane's cone is not
// the full sphere (cos_o = -1): lt_view_v ignores the axes of four full-sphere lanes.
LT_HOT void lt_decode_axes(v4f bits, LtLanes* l) {
  if (v4_all(v4_le(l->cos_o, v4_splat(-1.0f)))) {
    l->ax = v4_splat(0.0f);
    l->ay = l->ax;
    l->az = l->ax;
    return;
  }
  lt_oct_decode_v(v4_lo16(bits), v4_hi16(bits), &l->ax, &l->ay, &l->az);
}

// The (up to four) emitters of a leaf as lanes, from their emitter records; *N is cleared under
// the orientation ablation.
LT_HOT LtLanes lt_leaf_lanes(const LtTree* t, int code, float3* N) {
  int count = lt_leaf_count(code);
  GLOBAL const float4* e = lt_emitter_records(t, lt_leaf_first(code));
  v4f zero = v4_splat(0.0f);
  v4f a0 = v4_load(e), b0 = v4_load(e + 1);
  v4f a1 = zero, b1 = zero, a2 = zero, b2 = zero, a3 = zero, b3 = zero;
  if (count > 1) {
    a1 = v4_load(e + 2);
    b1 = v4_load(e + 3);
  }
  if (count > 2) {
    a2 = v4_load(e + 4);
    b2 = v4_load(e + 5);
  }
  if (count > 3) {
    a3 = v4_load(e + 6);
    b3 = v4_load(e + 7);
  }
  v4_transpose(a0, a1, a2, a3); // centre x, y, z, radius
  v4_transpose(b0, b1, b2, b3); // axis bits, q, energy, light
  LtLanes l;
  l.cx = a0;
  l.cy = a1;
  l.cz = a2;
  l.r = a3;
  l.energy = b2;
  v4m spot = v4_gt(b1, v4_splat(1.5f));
  v4m plane = v4_lt(b1, v4_splat(-1.5f)); // one-sided planar: q = -2 - h / r
  l.cos_o = v4_sel(v4_sel(b1, v4_splat(1.0f), spot), v4_splat(LT_PLANE_COS_O), plane);
  l.cos_e = v4_sel(zero, v4_sub(b1, v4_splat(2.0f)), spot);
  l.plane_h = v4_sel(v4_splat(LT_PLANE_NONE), v4_mul(v4_sub(v4_splat(-2.0f), b1), a3), plane);
  lt_without_orientation(t, &l, N);
  lt_decode_axes(b0, &l);
  return l;
}

// The four children of a node as lanes; *N is cleared under the orientation ablation.
LT_HOT LtLanes lt_node_lanes(const LtTree* t, int node, float3* N) {
  GLOBAL const float4* n = t->nodes + node * LT_NODE_F4;
  LtLanes l;
  l.cx = v4_load(n + LT_CX);
  l.cy = v4_load(n + LT_CY);
  l.cz = v4_load(n + LT_CZ);
  l.r = v4_load(n + LT_R);
  l.energy = v4_load(n + LT_ENERGY);
  v4f cos_o = v4_load(n + LT_COS_O);
  v4f k16 = v4_lo16(v4_load(n + LT_CE_CV2));
  v4m plane = v4_gt(cos_o, v4_splat(1.5f)); // LT_PLANE_FLAG: k16 is the plane offset
  l.cos_e = v4_sel(v4_mul(k16, v4_splat(LT_U16_SCALE)), v4_splat(0.0f), plane);
  l.plane_h = v4_sel(
      v4_splat(LT_PLANE_NONE),
      v4_mul(v4_sub(k16, v4_splat(32768.0f)), v4_mul(l.r, v4_splat(LT_PLANE_H_UNIT))), plane);
  l.cos_o = v4_sel(cos_o, v4_splat(LT_PLANE_COS_O), plane);
  lt_without_orientation(t, &l, N);
  lt_decode_axes(v4_load(n + LT_AXIS), &l);
  return l;
}
// The lanes below `code`, a node or a leaf.
LT_HOT LtLanes lt_code_lanes4(const LtTree* t, int code, float3* N) {
  return code >= 0 ? lt_node_lanes(t, code, N) : lt_leaf_lanes(t, code, N);
}

// Importance of the (up to four) emitters of a leaf (`fallback`: see lt_importance_v) and of the
// four children of a node, for a query. The lanes take a copy of q->N, which the orientation
// ablation clears (a point's normal; a segment's direction is kept).
LT_HOT float4 lt_leaf_importance_q(const LtTree* t, int code, const LtQuery* q, int fallback) {
  float3 N = q->N;
  LtLanes l = lt_leaf_lanes(t, code, &N);
  return v4_to_f4(lt_importance_q_v(&l, q, N, fallback));
}
LT_HOT float4 lt_node_importance_q(const LtTree* t, int node, const LtQuery* q, int fallback) {
  float3 N = q->N;
  LtLanes l = lt_node_lanes(t, node, &N);
  return v4_to_f4(lt_importance_q_v(&l, q, N, fallback));
}
// Importances of the four lanes below `code` (a node or a leaf) for the split decisions: without
// the fallback, so a cluster splits into exactly the lanes that can contribute (none where P sees
// no emitter of the cluster: a point behind a ceiling of one-sided lights gets an empty cut).
INLINE float4 lt_code_importance_q(const LtTree* t, int code, const LtQuery* q) {
  return code >= 0 ? lt_node_importance_q(t, code, q, 0) : lt_leaf_importance_q(t, code, q, 0);
}

// The point forms (shading point P, normal N).
LT_HOT float4 lt_leaf_importance_f(const LtTree* t, int code, float3 P, float3 N, int fallback) {
  LtQuery q = lt_query_point(P, N);
  return lt_leaf_importance_q(t, code, &q, fallback);
}
LT_HOT float4 lt_leaf_importance(const LtTree* t, int code, float3 P, float3 N) {
  return lt_leaf_importance_f(t, code, P, N, 1);
}
LT_HOT float4 lt_node_importance_f(const LtTree* t, int node, float3 P, float3 N, int fallback) {
  LtQuery q = lt_query_point(P, N);
  return lt_node_importance_q(t, node, &q, fallback);
}
LT_HOT float4 lt_node_importance(const LtTree* t, int node, float3 P, float3 N) {
  return lt_node_importance_f(t, node, P, N, 1);
}
INLINE float4 lt_code_importance(const LtTree* t, int code, float3 P, float3 N) {
  LtQuery q = lt_query_point(P, N);
  return lt_code_importance_q(t, code, &q);
}

#endif // CANOPY_LIGHT_TREE_IMPORTANCE_H
