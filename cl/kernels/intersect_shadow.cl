// Stage 5: occlusion of one pass's shadow queue, then the per-path sum. The queue holds each
// path's items contiguously (the split queue stays grouped by path from pass to pass), so the
// first item of each run adds the run's visible contributions in queue order: race-free and
// deterministic, however many shadow rays a path has.
#include "geometry.h"

__kernel void intersect_shadow(__global const BvhNode* nodes, __global const LeafBlock* leaf_blocks,
                               __global const Primitive* prims, __global ShadowItem* shadow_items,
                               int count) {
  int i = get_global_id(0);
  if (i >= count) return;
  ShadowItem s = shadow_items[i];
  Hit h;
  if (bvh_intersect(nodes, leaf_blocks, prims, s.origin.xyz, s.dir.xyz, 0.0f, s.origin.w, 1, &h) >= 0)
    shadow_items[i].contribution = (float4)(0.0f);
}

__kernel void accumulate_shadow(__global const ShadowItem* shadow_items, int count,
                                __global float4* radiance, __global int4* path_counts) {
  int i = get_global_id(0);
  if (i >= count) return;
  int path = as_int(shadow_items[i].dir.w);
  if (i > 0 && as_int(shadow_items[i - 1].dir.w) == path) return; // not the first of its run
  float3 sum = (float3)(0.0f);
  int j = i;
  for (; j < count && as_int(shadow_items[j].dir.w) == path; ++j)
    sum += shadow_items[j].contribution.xyz;
  radiance[path] += (float4)(sum, 0.0f);
  path_counts[path].x += j - i;
}
