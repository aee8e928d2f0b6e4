// Stage 3a (scenes with a medium only): shade_volume over the ray queue, before shade_surface
// (cl/integrator/shade_volume.h). volume_counters[0] counts the segments that get light samples.
#include "integrator/shade_volume.h"
#include "kernels/params.h"

#if HAS_MEDIUM
__kernel void shade_volume(int depth, int max_depth, __global const int* queue, int count,
                           PATH_PARAMS SCENE_PARAMS LIGHT_SAMPLER_PARAMS
                           __global int* volume_counters, __global int4* path_counts) {
  int i = get_global_id(0);
  if (i >= count) return;
  PATH_ASSEMBLE(pb);
  SCENE_ASSEMBLE(sc);
  LIGHT_SAMPLER_ASSEMBLE(ls);
  if (camera_ray_hits_emitter(depth, pb.hits[queue[i]], &sc)) path_counts[queue[i]].z = 1;
  if (shade_volume_item(queue[i], depth, max_depth, &sc, &pb, &ls))
    atomic_inc(&volume_counters[0]);
}
#endif
