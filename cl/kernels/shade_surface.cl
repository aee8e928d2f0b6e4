// Stage 3: shade_surface over the ray queue (cl/integrator/shade_surface.h), then the scatter that
// builds, in queue order, the next bounce's ray queue and the split queue's root items.
#include "integrator/shade_surface.h"
#include "integrator/shade_volume.h"
#include "kernels/params.h"

__kernel void shade_surface(int depth, int max_depth, __global const int* queue, int count,
                            PATH_PARAMS SCENE_PARAMS LIGHT_SAMPLER_PARAMS
                            __global int2* counts_shade, __global int4* path_counts) {
  int i = get_global_id(0);
  if (i >= count) return;
  PATH_ASSEMBLE(pb);
  SCENE_ASSEMBLE(sc);
  LIGHT_SAMPLER_ASSEMBLE(ls);
  int path = queue[i];
  // (with a medium, shade_volume has also looked, before it could replace the hit)
  if (camera_ray_hits_emitter(depth, pb.hits[path], &sc)) path_counts[path].z = 1;
  int2 c = shade_surface_item(path, depth, max_depth, &sc, &pb, &ls);
  if (HAS_MEDIUM) c = shade_counts_with_volume(c, path, &pb); // shade_volume ran first
  counts_shade[i] = c;
}

__kernel void scatter_shade(__global const int* queue, int count, SCAN_PARAMS
                            __global int* queue_out, __global SplitItem* split_out,
                            float4 lt_root_sphere, float4 lt_root_info, uint max_cut,
                            __global int4* path_counts, __global const float4* seg_o) {
  int i = get_global_id(0);
  if (i >= count) return;
  int2 c = counts[i];
  int2 pos = block_sums[i / block] + offsets[i];
  int path = queue[i];
  if (c.x) queue_out[pos.x] = path;
  if (c.y) {
    SplitItem it;
    it.sphere = lt_root_sphere;
    it.code = 0;
    it.budget = max_cut;
    it.cv2 = lt_root_info.x; // the root's cv^2
    int roots = c.y;
    // The segment's root first, then the surface point's: a path's items stay together.
    if (HAS_MEDIUM && seg_o[path].w >= 0.0f) {
      it.path = path | SPLIT_SEGMENT;
      it.budget = light_sampler_segment_budget(max_cut);
      split_out[pos.y++] = it;
      it.budget = max_cut;
      roots -= 1;
    }
    if (roots) {
      path_counts[path].y += 1; // one shading point per path and bounce: no race
      it.path = path;
      split_out[pos.y] = it;
    }
  }
}
