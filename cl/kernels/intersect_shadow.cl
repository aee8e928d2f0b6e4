// Stage 4: occlusion of the shadow queue. An unoccluded item adds its contribution to its path.
// Each path pushes at most one shadow item per bounce, so the add below never races; the
// split-queue renderer (several items per path) replaces it with a per-path reduction.
#include "geometry.h"

__kernel void intersect_shadow(__global const BvhNode* nodes, __global const int* prim_index,
                               __global const Primitive* prims, __global const ShadowItem* items,
                               int count, __global float4* radiance) {
  int i = get_global_id(0);
  if (i >= count) return;
  ShadowItem s = items[i];
  Hit h;
  if (bvh_intersect(nodes, prim_index, prims, s.origin.xyz, s.dir.xyz, 0.0f, s.origin.w, 1, &h) >= 0)
    return;
  int path = as_int(s.dir.w);
  radiance[path] += (float4)(s.contribution.xyz, 0.0f);
}
