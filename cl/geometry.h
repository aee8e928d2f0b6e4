// Ray-primitive and ray-box intersection and BVH traversal, shared by the intersect kernels and
// the host (tests compare the kernel with this code and with Embree).
#ifndef CANOPY_CL_GEOMETRY_H
#define CANOPY_CL_GEOMETRY_H

#include "compat.h"
#include "kernel_features.h"
#include "types.h"

#define BVH_STACK_SIZE 64

// BvhNode packing (see types.h): interior nodes keep the left/right child indices in the w lanes
// (right > 0); leaves keep the first primitive slot in bmin.w and -count in bmax.w.
INLINE int bvh_node_a(BvhNode n) { return (int)float_as_uint_(n.bmin.w); }
INLINE int bvh_node_b(BvhNode n) { return (int)float_as_uint_(n.bmax.w); }

// Slab test. Returns the entry distance, or INFINITY when the ray misses [tmin, tmax].
INLINE float ray_box(float3 o, float3 inv_d, float4 bmin, float4 bmax, float tmin, float tmax) {
  float tx0 = (bmin.x - o.x) * inv_d.x, tx1 = (bmax.x - o.x) * inv_d.x;
  float ty0 = (bmin.y - o.y) * inv_d.y, ty1 = (bmax.y - o.y) * inv_d.y;
  float tz0 = (bmin.z - o.z) * inv_d.z, tz1 = (bmax.z - o.z) * inv_d.z;
  float t0 = fmax(fmax(fmin(tx0, tx1), fmin(ty0, ty1)), fmax(fmin(tz0, tz1), tmin));
  float t1 = fmin(fmin(fmax(tx0, tx1), fmax(ty0, ty1)), fmin(fmax(tz0, tz1), tmax));
  // 1 + 2*gamma(3) widening keeps the test conservative under rounding (pbrt-v4 §6.1.2).
  return t0 <= t1 * 1.0000004f ? t0 : FLT_INF;
}

// Möller-Trumbore. Writes t, u, v and returns 1 on a hit inside (tmin, tmax).
INLINE int ray_triangle(float3 o, float3 d, float3 v0, float3 e1, float3 e2, float tmin, float tmax,
                        float* t_out, float* u_out, float* v_out) {
  float3 p = cross(d, e2);
  float det = dot(e1, p);
  if (det == 0.0f) return 0;
  float inv_det = 1.0f / det;
  float3 s = o - v0;
  float u = dot(s, p) * inv_det;
  if (u < 0.0f || u > 1.0f) return 0;
  float3 q = cross(s, e1);
  float v = dot(d, q) * inv_det;
  if (v < 0.0f || u + v > 1.0f) return 0;
  float t = dot(e2, q) * inv_det;
  if (!(t > tmin && t < tmax)) return 0;
  *t_out = t;
  *u_out = u;
  *v_out = v;
  return 1;
}

// Ray-sphere, with the discriminant computed from the perpendicular offset to avoid the
// cancellation of b^2 - c for distant spheres (Ray Tracing Gems ch. 7).
INLINE int ray_sphere(float3 o, float3 d, float3 c, float r, float tmin, float tmax, float* t_out) {
  float3 f = o - c;
  float a = dot(d, d);
  float b = -dot(f, d);
  float3 l = f + d * (b / a);
  float disc = r * r - dot(l, l);
  if (disc < 0.0f) return 0;
  float sq = sqrt(a * disc);
  float q = b + (b >= 0.0f ? sq : -sq);
  float t0 = q == 0.0f ? 0.0f : (dot(f, f) - r * r) / q;
  float t1 = q / a;
  float tn = fmin(t0, t1), tf = fmax(t0, t1);
  float t = tn > tmin ? tn : tf;
  if (!(t > tmin && t < tmax)) return 0;
  *t_out = t;
  return 1;
}

INLINE int ray_primitive(const GLOBAL Primitive* prim, float3 o, float3 d, float tmin, float tmax,
                         float* t, float* u, float* v) {
  if (HAS_PRIM_SPHERE && prim->type == PRIM_SPHERE) {
    *u = 0.0f;
    *v = 0.0f;
    return ray_sphere(o, d, xyz_of(prim->v0), prim->v0.w, tmin, tmax, t);
  }
  return ray_triangle(o, d, xyz_of(prim->v0), xyz_of(prim->e1), xyz_of(prim->e2), tmin, tmax, t,
                      u, v);
}

// Closest hit (any_hit == 0) or first hit found (any_hit != 0) along o + t d, t in (tmin, tmax).
// Returns the hit primitive or -1; t/u/v of the hit in *hit.
INLINE int bvh_intersect(const GLOBAL BvhNode* nodes, const GLOBAL int* prim_index,
                         const GLOBAL Primitive* prims, float3 o, float3 d, float tmin, float tmax,
                         int any_hit, Hit* hit) {
  float3 inv_d = make_float3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
  int stack[BVH_STACK_SIZE];
  int sp = 0;
  int best = -1;
  float best_u = 0.0f, best_v = 0.0f;
  int node = 0;
  if (ray_box(o, inv_d, nodes[0].bmin, nodes[0].bmax, tmin, tmax) == FLT_INF) node = -1;
  while (node >= 0) {
    BvhNode n = nodes[node];
    int a = bvh_node_a(n), b = bvh_node_b(n);
    if (b < 0) { // leaf
      for (int i = 0; i < -b; ++i) {
        int p = prim_index[a + i];
        float t, u, v;
        if (ray_primitive(&prims[p], o, d, tmin, tmax, &t, &u, &v)) {
          tmax = t;
          best = p;
          best_u = u;
          best_v = v;
          if (any_hit) {
            sp = 0;
            break;
          }
        }
      }
      if (any_hit && best >= 0) break;
      node = sp > 0 ? stack[--sp] : -1;
      continue;
    }
    float ta = ray_box(o, inv_d, nodes[a].bmin, nodes[a].bmax, tmin, tmax);
    float tb = ray_box(o, inv_d, nodes[b].bmin, nodes[b].bmax, tmin, tmax);
    if (ta == FLT_INF && tb == FLT_INF) {
      node = sp > 0 ? stack[--sp] : -1;
    } else if (ta == FLT_INF || tb == FLT_INF) {
      node = ta == FLT_INF ? b : a;
    } else { // both: visit the nearer first
      int near_c = ta <= tb ? a : b;
      int far_c = ta <= tb ? b : a;
      if (sp < BVH_STACK_SIZE) stack[sp++] = far_c;
      node = near_c;
    }
  }
  hit->t = best >= 0 ? tmax : FLT_INF;
  hit->prim = best;
  hit->u = best_u;
  hit->v = best_v;
  return best;
}

// Geometric normal of a primitive at a hit point (not normalised to face the ray).
INLINE float3 primitive_normal(const GLOBAL Primitive* prim, float3 p) {
  if (HAS_PRIM_SPHERE && prim->type == PRIM_SPHERE) return normalize(p - xyz_of(prim->v0));
  return normalize(cross(xyz_of(prim->e1), xyz_of(prim->e2)));
}

#endif // CANOPY_CL_GEOMETRY_H
