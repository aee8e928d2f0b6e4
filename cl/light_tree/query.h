// What a light is picked for: a shading point on a surface (Conty Estevez & Kulla 2018, §5.1) or
// a ray segment in a participating medium (§5.2), whose direct light is integrated along the
// segment (equiangular sampling). The importance (importance.h), the descent (traverse.h), the
// split decisions (split.h) and the pmfs (pmf.h) take a query; their (P, N) forms are point
// queries. Compiles as OpenCL C and as C++ (cl/compat.h).
#ifndef CANOPY_LIGHT_TREE_QUERY_H
#define CANOPY_LIGHT_TREE_QUERY_H

#include "../compat.h"
#include "../kernel_features.h"

typedef struct LtQuery {
  float3 P;  // point: the shading point; segment: its start a
  float3 N;  // point: unit normal (0: no orientation); segment: its unit direction d
  float len; // point: -1; segment: its length >= 0 (finite), end b = P + len * N
} LtQuery;

INLINE LtQuery lt_query_point(float3 P, float3 N) {
  LtQuery q;
  q.P = P;
  q.N = N;
  q.len = -1.0f;
  return q;
}
INLINE LtQuery lt_query_segment(float3 a, float3 d, float len) {
  LtQuery q;
  q.P = a;
  q.N = d;
  q.len = len;
  return q;
}

// The midpoint ablation (the surface importance, Eq. 3, at the segment's midpoint without a
// normal): a point query that carries the segment's half-length s as len = -1 - s, so the
// importance can grow every bounding sphere by s. Then the cone seen from the midpoint around a
// grown sphere holds every direction from the cluster to any point of the segment, and no lane
// that can light the segment gets importance 0 (the pick stays unbiased).
INLINE LtQuery lt_query_midpoint(float3 a, float3 d, float len) {
  LtQuery q = lt_query_point(a + d * (0.5f * len), make_float3(0.0f, 0.0f, 0.0f));
  q.len = -1.0f - 0.5f * len;
  return q;
}
// The slack of a midpoint query (0 for a point or a segment query).
#define LT_QUERY_SLACK(q) (HAS_MEDIUM && (q)->len < -1.0f ? -1.0f - (q)->len : 0.0f)

// Whether q is a segment. Without HAS_MEDIUM (a kernel for a scene without media) this folds to 0
// and the segment code is not compiled; a point query costs one well-predicted branch.
#define LT_QUERY_IS_SEGMENT(q) (HAS_MEDIUM && (q)->len >= 0.0f)

// The point of the segment closest to x (the segment's start and end included).
INLINE float3 lt_query_closest(const LtQuery* q, float3 x) {
  float t = dot(x - q->P, q->N);
  t = t > q->len ? q->len : t;
  t = t > 0.0f ? t : 0.0f;
  return q->P + q->N * t;
}

#endif // CANOPY_LIGHT_TREE_QUERY_H
