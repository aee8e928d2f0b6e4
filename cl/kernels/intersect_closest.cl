// Stage 2: closest hit for every ray in the queue (the BVH built by Embree's rtcBuildBVH).
#include "geometry.h"

__kernel void intersect_closest(__global const BvhNode* nodes, __global const LeafBlock* leaf_blocks,
                                __global const Primitive* prims, __global const int* queue,
                                int count, __global const float4* ray_o,
                                __global const float4* ray_d, __global Hit* hits) {
  int i = get_global_id(0);
  if (i >= count) return;
  int path = queue[i];
  float4 o = ray_o[path];
  Hit h;
  bvh_intersect(nodes, leaf_blocks, prims, o.xyz, ray_d[path].xyz, o.w, INFINITY, 0, &h);
  hits[path] = h;
}
