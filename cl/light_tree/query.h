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
