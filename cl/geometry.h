// Ray-primitive and ray-box intersection and BVH traversal, shared by the intersect kernels and
// the host (tests compare the kernel with this code and with Embree).
#ifndef CANOPY_CL_GEOMETRY_H
#define CANOPY_CL_GEOMETRY_H

#include "compat.h"
#include "kernel_features.h"
#include "shading.h"
#include "types.h"

// Each level pushes at most BVH_WIDTH - 1 nodes; the host limits the depth to BVH_MAX_DEPTH.
#define BVH_MAX_DEPTH 30
#define BVH_STACK_SIZE ((BVH_WIDTH - 1) * BVH_MAX_DEPTH + 4)
#define BVH_EMPTY (-2147483647 - 1)
#define BVH_MAX_LEAF 16 // primitives; a leaf has up to 4 blocks of 4

INLINE int bvh_is_leaf(int code) {
  return code < 0 && code != BVH_EMPTY;
}
INLINE int bvh_leaf_first(int code) {
  return (-1 - code) >> 4;
}
INLINE int bvh_leaf_count(int code) {
  return ((-1 - code) & 15) + 1;
}
INLINE int bvh_leaf_code(int first, int count) {
  return -1 - ((first << 4) | (count - 1));
}

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
  // A hit within the rounding error of t is the surface the ray leaves (or geometry closer than
  // float can resolve): reject it, as pbrt-v4's triangle test does (§6.8). The numerator
  // dot(e2, cross(o - v0, e1)) is off by at most about gamma(7) times the same sum of absolute
  // products (o - v0 rounded, the cross product, the dot product; gamma(8) keeps a margin), and
  // det's relative error adds gamma(3) t.
  float3 as = fabs(s), a1 = fabs(e1);
  float3 aq =
      make_float3(as.y * a1.z + as.z * a1.y, as.z * a1.x + as.x * a1.z, as.x * a1.y + as.y * a1.x);
  float t_err = fp_gamma(8) * dot(fabs(e2), aq) * fabs(inv_det) + fp_gamma(4) * t;
  if (t <= t_err) return 0;
  *t_out = t;
  *u_out = u;
  *v_out = v;
  return 1;
}

// ray_triangle on the four lanes of a leaf block at once, with the same arithmetic lane by lane
// (so the same hits and the same t, u, v). Returns -1 in the lanes hit inside (tmin, tmax).
INLINE int4 ray_triangle4(float3 o, float3 d, const GLOBAL LeafBlock* b, float tmin, float tmax,
                          float4* t_out, float4* u_out, float4* v_out) {
  float4 dx = f4_splat(d.x), dy = f4_splat(d.y), dz = f4_splat(d.z);
  float4 e1x = b->e1_x, e1y = b->e1_y, e1z = b->e1_z;
  float4 e2x = b->e2_x, e2y = b->e2_y, e2z = b->e2_z;
  float4 px = dy * e2z - dz * e2y, py = dz * e2x - dx * e2z, pz = dx * e2y - dy * e2x;
  float4 det = e1x * px + e1y * py + e1z * pz;
  float4 inv_det = f4_splat(1.0f) / det;
  float4 sx = f4_splat(o.x) - b->v0_x, sy = f4_splat(o.y) - b->v0_y, sz = f4_splat(o.z) - b->v0_z;
  float4 u = (sx * px + sy * py + sz * pz) * inv_det;
  float4 qx = sy * e1z - sz * e1y, qy = sz * e1x - sx * e1z, qz = sx * e1y - sy * e1x;
  float4 v = (dx * qx + dy * qy + dz * qz) * inv_det;
  float4 t = (e2x * qx + e2y * qy + e2z * qz) * inv_det;
  float4 asx = fabs(sx), asy = fabs(sy), asz = fabs(sz);
  float4 a1x = fabs(e1x), a1y = fabs(e1y), a1z = fabs(e1z);
  float4 aqx = asy * a1z + asz * a1y, aqy = asz * a1x + asx * a1z, aqz = asx * a1y + asy * a1x;
  float4 t_err = f4_splat(fp_gamma(8)) * (fabs(e2x) * aqx + fabs(e2y) * aqy + fabs(e2z) * aqz) *
                     fabs(inv_det) +
                 f4_splat(fp_gamma(4)) * t;
  float4 zero = f4_splat(0.0f), one = f4_splat(1.0f);
  // Written as ray_triangle's rejections, negated, so NaNs fall the same way.
  int4 hit = (det != zero) & ~((u < zero) | (u > one)) & ~((v < zero) | (u + v > one)) &
             (t > f4_splat(tmin)) & (t < f4_splat(tmax)) & ~(t <= t_err);
  *t_out = t;
  *u_out = u;
  *v_out = v;
  return hit;
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
  float ff = dot(f, f);
  float t0 = q == 0.0f ? 0.0f : (ff - r * r) / q;
  float t1 = q / a;
  float tn = fmin(t0, t1), tf = fmax(t0, t1);
  // The near root's numerator ff - r^2 cancels for a ray leaving the surface; a root within its
  // rounding error (f rounded, the dot product, the difference) is the surface the ray leaves.
  float t_err = q == 0.0f ? 0.0f : fp_gamma(8) * (ff + r * r) / fabs(q);
  float t = tn > fmax(tmin, t_err) ? tn : tf;
  if (!(t > tmin && t < tmax) || t <= t_err) return 0;
  *t_out = t;
  return 1;
}

// Ray-disk (centre c, unit normal n, radius r): the ray-plane distance t = n.(c - o) / n.d, a hit
// when the plane point lies within r of c. Both faces are hit (emission is one-sided, the shape
// is not). A root within the rounding error of t is the surface the ray leaves, rejected as for
// triangles: the numerator's error is about gamma(4) n.|c - o| (the difference rounded, the dot
// product; gamma(8) keeps a margin), divided by |n.d|, plus the division's relative error.
INLINE int ray_disk(float3 o, float3 d, float3 c, float3 n, float r, float tmin, float tmax,
                    float* t_out) {
  float dn = dot(n, d);
  if (dn == 0.0f) return 0;
  float3 co = c - o;
  float t = dot(n, co) / dn;
  if (!(t > tmin && t < tmax)) return 0;
  float t_err = fp_gamma(8) * dot(fabs(n), fabs(co)) / fabs(dn) + fp_gamma(4) * t;
  if (t <= t_err) return 0;
  float3 q = d * t - co; // hit point relative to the centre
  if (!(dot(q, q) <= r * r)) return 0;
  *t_out = t;
  return 1;
}

INLINE int ray_primitive(const GLOBAL Primitive* prim, float3 o, float3 d, float tmin, float tmax,
                         float* t, float* u, float* v) {
  if (IS_PRIM(prim, PRIM_DISK)) {
    *u = 0.0f;
    *v = 0.0f;
    return ray_disk(o, d, xyz_of(prim->v0), xyz_of(prim->e1), prim->v0.w, tmin, tmax, t);
  }
  if (IS_PRIM(prim, PRIM_SPHERE)) {
    *u = 0.0f;
    *v = 0.0f;
    return ray_sphere(o, d, xyz_of(prim->v0), prim->v0.w, tmin, tmax, t);
  }
  return ray_triangle(o, d, xyz_of(prim->v0), xyz_of(prim->e1), xyz_of(prim->e2), tmin, tmax, t, u,
                      v);
}

// Entry distances of the ray into the four child boxes of group g of a node (INFINITY: missed or
// empty).
INLINE float4 bvh_node_entry(const GLOBAL BvhNode* n, int g, float3 o, float3 inv_d, float tmin,
                             float tmax) {
  float4 tx0 = (n->min_x[g] - o.x) * inv_d.x, tx1 = (n->max_x[g] - o.x) * inv_d.x;
  float4 ty0 = (n->min_y[g] - o.y) * inv_d.y, ty1 = (n->max_y[g] - o.y) * inv_d.y;
  float4 tz0 = (n->min_z[g] - o.z) * inv_d.z, tz1 = (n->max_z[g] - o.z) * inv_d.z;
  float4 t0 = fmax(fmax(fmin(tx0, tx1), fmin(ty0, ty1)),
                   fmax(fmin(tz0, tz1), make_float4(tmin, tmin, tmin, tmin)));
  float4 t1 = fmin(fmin(fmax(tx0, tx1), fmax(ty0, ty1)),
                   fmin(fmax(tz0, tz1), make_float4(tmax, tmax, tmax, tmax)));
  int4 c = n->child[g];
  // 1 + 2*gamma(3) widening keeps the test conservative under rounding (pbrt-v4 §6.1.2).
  float4 one = make_float4(1.0000004f, 1.0000004f, 1.0000004f, 1.0000004f);
  t1 = t1 * one;
  return make_float4(c.x != BVH_EMPTY && t0.x <= t1.x ? t0.x : FLT_INF,
                     c.y != BVH_EMPTY && t0.y <= t1.y ? t0.y : FLT_INF,
                     c.z != BVH_EMPTY && t0.z <= t1.z ? t0.z : FLT_INF,
                     c.w != BVH_EMPTY && t0.w <= t1.w ? t0.w : FLT_INF);
}

// Child code of lane i (= 4 g + k) of a node.
INLINE int bvh_lane_child(const GLOBAL BvhNode* n, int lane) {
  return i4_get(n->child[lane >> 2], lane & 3);
}

// A node's lanes for the traversal: each lane's entry distance (INFINITY: missed or empty) and
// child code into lane_t / lane_c, and as bit masks the lanes entered before tmax (returned) and
// those of them that are leaves (*leaves). On the device an 8-wide node is one float8 per
// coordinate, which PoCL compiles to AVX: against the 4-wide tree, closest hits 1.14-1.16x and
// shadow rays 1.16-1.29x faster, where the same 8-wide tree tested as two float4 groups gained
// nothing (docs/performance.md). The host tests the lanes in groups of four (bvh_node_entry);
// both do the same operations lane by lane, and the tests compare them.
INLINE int bvh_node_lanes(const GLOBAL BvhNode* n, float3 o, float3 inv_d, float tmin,
                          float tmax, float* lane_t, int* lane_c, int* leaves) {
#if defined(__OPENCL_C_VERSION__) && BVH_WIDTH == 8
  const GLOBAL float* nf = (const GLOBAL float*)n; // min_x..max_z: 8 floats each, then child
  float8 tx0 = (vload8(0, nf) - o.x) * inv_d.x, tx1 = (vload8(3, nf) - o.x) * inv_d.x;
  float8 ty0 = (vload8(1, nf) - o.y) * inv_d.y, ty1 = (vload8(4, nf) - o.y) * inv_d.y;
  float8 tz0 = (vload8(2, nf) - o.z) * inv_d.z, tz1 = (vload8(5, nf) - o.z) * inv_d.z;
  float8 t0 = fmax(fmax(fmin(tx0, tx1), fmin(ty0, ty1)), fmax(fmin(tz0, tz1), (float8)(tmin)));
  float8 t1 = fmin(fmin(fmax(tx0, tx1), fmax(ty0, ty1)), fmin(fmax(tz0, tz1), (float8)(tmax)));
  t1 = t1 * (float8)(1.0000004f); // as in bvh_node_entry
  int8 c8 = vload8(0, (const GLOBAL int*)(nf + 48));
  int8 in = (c8 != (int8)(BVH_EMPTY)) & (t0 <= t1) & (t0 != (float8)(FLT_INF)) &
            (t0 <= (float8)(tmax));
  vstore8(select((float8)(FLT_INF), t0, in), 0, lane_t);
  vstore8(c8, 0, lane_c);
  int entered = sign_bits4(in.lo) | (sign_bits4(in.hi) << 4);
  *leaves = entered & (sign_bits4(c8.lo) | (sign_bits4(c8.hi) << 4));
  return entered;
#else
  int entered = 0;
  *leaves = 0;
  for (int g = 0; g < BVH_GROUPS; ++g) {
    float4 t4 = bvh_node_entry(n, g, o, inv_d, tmin, tmax);
    int4 c4 = n->child[g];
    lane_t[4 * g] = t4.x, lane_t[4 * g + 1] = t4.y, lane_t[4 * g + 2] = t4.z;
    lane_t[4 * g + 3] = t4.w;
    lane_c[4 * g] = c4.x, lane_c[4 * g + 1] = c4.y, lane_c[4 * g + 2] = c4.z;
    lane_c[4 * g + 3] = c4.w;
    // lanes entered before tmax (a missed or empty lane has t = INFINITY; tmax may be infinite)
    int e = sign_bits4((t4 != f4_splat(FLT_INF)) & (t4 <= f4_splat(tmax)));
    entered |= e << (4 * g);
    *leaves |= (e & sign_bits4(c4)) << (4 * g);
  }
  return entered;
#endif
}

// Closest hit (any_hit == 0) or first hit found (any_hit != 0) along o + t d, t in (tmin, tmax).
// Returns the hit primitive or -1; t/u/v of the hit in *hit. Leaves met in a node are intersected
// at once (shrinking tmax before the interior children are ordered); interior children are visited
// nearest first, the others pushed with their entry distance and skipped on pop if a closer hit
// was found meanwhile.
INLINE int bvh_intersect(const GLOBAL BvhNode* nodes, const GLOBAL LeafBlock* leaf_blocks,
                         const GLOBAL Primitive* prims, float3 o, float3 d, float tmin, float tmax,
                         int any_hit, Hit* hit) {
  float3 inv_d = make_float3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
  int stack[BVH_STACK_SIZE];
  float stack_t[BVH_STACK_SIZE];
  int sp = 0;
  int best = -1;
  float best_u = 0.0f, best_v = 0.0f;
  int node = 0;
  while (node >= 0) {
    const GLOBAL BvhNode* n = &nodes[node];
    float lane_t[BVH_WIDTH];
    int lane_c[BVH_WIDTH];
    int leaves;
    int entered = bvh_node_lanes(n, o, inv_d, tmin, tmax, lane_t, lane_c, &leaves);
    int inner_lanes = entered & ~leaves;
    for (; leaves != 0; leaves &= leaves - 1) {
      int c = lane_c[lowest_bit(leaves)];
      int first = bvh_leaf_first(c), end = first + bvh_leaf_count(c);
      for (int b = first; b < end; ++b) {
        const GLOBAL LeafBlock* blk = &leaf_blocks[b];
        float4 th, u, v;
        int4 lanes = ray_triangle4(o, d, blk, tmin, tmax, &th, &u, &v);
        int4 ids = blk->prim;
        if (any(lanes)) {
          // The nearest lane, the first of equals (as testing the lanes in order would).
          float4 tm = select(f4_splat(FLT_INF), th, lanes);
          tmax = fmin(fmin(tm.x, tm.y), fmin(tm.z, tm.w));
          int k = tm.x == tmax ? 0 : (tm.y == tmax ? 1 : (tm.z == tmax ? 2 : 3));
          best = i4_get(ids, k);
          best_u = f4_get(u, k);
          best_v = f4_get(v, k);
          if (any_hit) break;
        }
        if ((HAS_PRIM_SPHERE || HAS_PRIM_DISK) && min(min(ids.x, ids.y), min(ids.z, ids.w)) < -1) {
          for (int k = 0; k < 4; ++k) {
            int p = -2 - i4_get(ids, k);
            float tp, up, vp;
            if (p >= 0 && ray_primitive(&prims[p], o, d, tmin, tmax, &tp, &up, &vp)) {
              tmax = tp;
              best = p;
              best_u = up;
              best_v = vp;
              if (any_hit) break;
            }
          }
          if (any_hit && best >= 0) break;
        }
      }
      if (any_hit && best >= 0) break;
    }
    if (any_hit && best >= 0) break;
    // Interior children, by insertion nearest first.
    int next[BVH_WIDTH];
    float next_t[BVH_WIDTH];
    int m = 0;
    for (int inner = inner_lanes; inner != 0; inner &= inner - 1) {
      int lane = lowest_bit(inner);
      float t = lane_t[lane];
      int k = m++;
      while (k > 0 && next_t[k - 1] > t) {
        next[k] = next[k - 1];
        next_t[k] = next_t[k - 1];
        --k;
      }
      next[k] = lane_c[lane];
      next_t[k] = t;
    }
    // Visit the nearest child that is still closer than the best hit; push the others, farthest
    // first, so the second nearest is popped next.
    node = -1;
    float node_t = 0.0f;
    for (int k = m - 1; k >= 0; --k) {
      if (!(next_t[k] <= tmax)) continue;
      if (node >= 0) {
        stack[sp] = node;
        stack_t[sp] = node_t;
        ++sp;
      }
      node = next[k];
      node_t = next_t[k];
    }
    while (node < 0 && sp > 0) {
      --sp;
      if (stack_t[sp] <= tmax) node = stack[sp];
    }
  }
  hit->t = best >= 0 ? tmax : FLT_INF;
  hit->prim = best;
  hit->u = best_u;
  hit->v = best_v;
  return best;
}

// The hit point of ray o + t d on primitive prim (t, u, v from the intersection), computed so its
// rounding error is small and bounded (pbrt-v4 §6.8): *p_err gets the absolute error bound per
// component, for offset_ray_origin. A triangle's point comes from its barycentrics (v0 + u e1 +
// v e2 lies on the triangle's plane for any u, v; only the rounding of that sum is error), not
// from o + t d, whose error grows with t and with |o|. A sphere's point is o + t d projected back
// onto the sphere; a disk's, o + t d projected onto its plane (its error then follows the centre's
// coordinates and the offset within the disk: the projection's dot product and the two sums).
INLINE float3 primitive_hit_point(const GLOBAL Primitive* prim, float3 o, float3 d, Hit h,
                                  float3* p_err) {
  if (IS_PRIM(prim, PRIM_DISK)) {
    float3 c = xyz_of(prim->v0), n = xyz_of(prim->e1);
    float3 q = (o + d * h.t) - c;
    q = q - n * dot(n, q);
    float3 p = c + q;
    *p_err = (fabs(c) + fabs(q)) * fp_gamma(6);
    return p;
  }
  if (IS_PRIM(prim, PRIM_SPHERE)) {
    float3 c = xyz_of(prim->v0);
    float r = prim->v0.w;
    float3 l = (o + d * h.t) - c;
    float len = length(l);
    if (len > 0.0f) l = l * (r / len);
    float3 p = c + l;
    *p_err = fabs(l) * fp_gamma(6) + fabs(p) * fp_gamma(1);
    return p;
  }
  float3 v0 = xyz_of(prim->v0), e1 = xyz_of(prim->e1) * h.u, e2 = xyz_of(prim->e2) * h.v;
  float3 p = v0 + e1 + e2;
  *p_err = (fabs(v0) + fabs(e1) + fabs(e2)) * fp_gamma(3);
  return p;
}

// Geometric normal of a primitive at a hit point (not normalised to face the ray).
INLINE float3 primitive_normal(const GLOBAL Primitive* prim, float3 p) {
  if (IS_PRIM(prim, PRIM_DISK)) return xyz_of(prim->e1);
  if (IS_PRIM(prim, PRIM_SPHERE)) return normalize(p - xyz_of(prim->v0));
  return normalize(cross(xyz_of(prim->e1), xyz_of(prim->e2)));
}

// Shading normal at barycentrics (u, v) of a hit on p (Phong shading: the vertex normals
// interpolated like the hit point, v0 + u e1 + v e2), normalised and turned to the side of the
// geometric normal Ng (vertex normals that disagree with the winding are taken as flipped).
// Flat triangles and spheres (p->normals < 0) give Ng, and so does an interpolant shorter than
// 1e-4 (vertex normals that nearly cancel: its direction would be rounding noise).
INLINE float3 primitive_shading_normal(const GLOBAL Primitive* p, GLOBAL const float4* normals,
                                       float u, float v, float3 Ng) {
  if (p->type != PRIM_TRIANGLE || p->normals < 0) return Ng;
  int i = p->normals;
  float3 n =
      xyz_of(normals[i]) * (1.0f - u - v) + xyz_of(normals[i + 1]) * u + xyz_of(normals[i + 2]) * v;
  float len2 = dot(n, n);
  if (!(len2 > 1e-8f)) return Ng;
  n = n * (1.0f / sqrt(len2));
  return dot(n, Ng) < 0.0f ? n * -1.0f : n;
}

#endif // CANOPY_CL_GEOMETRY_H
