// BRDF-oriented many-light sampling at glossy points (cl/integrator/brdf_mis.h), compiled only for
// the brdf-mis and brdf-oriented samplers on scenes with a glossy material (HAS_BRDF_ORIENTED).
// Per bounce: brdf_cut over the ray queue before the split passes, then rounds of brdf_sample ->
// scan -> scatter_brdf -> brdf_trace -> brdf_accumulate.
#include "integrator/brdf_mis.h"
#include "kernels/params.h"

#if HAS_BRDF_ORIENTED

// The cut of each glossy point of this bounce. brdf_counters: (glossy points, sum of cut sizes,
// sum of N) of the wave, for --stats (integer atomics: the totals do not depend on the order),
// and the largest N of the bounce, which sets its number of rounds.
__kernel void brdf_cut(__global const int* queue, int count, PATH_PARAMS SCENE_PARAMS
                       LIGHT_SAMPLER_PARAMS __global int* brdf_counters) {
  int i = get_global_id(0);
  if (i >= count) return;
  PATH_ASSEMBLE(pb);
  SCENE_ASSEMBLE(sc);
  LIGHT_SAMPLER_ASSEMBLE(ls);
  int path = queue[i];
  if (pb.brdf_state[path].y != -1) return;
  int2 r = brdf_cut_item(path, &ls, &sc, &pb);
  atomic_inc(&brdf_counters[0]);
  atomic_add(&brdf_counters[1], r.x);
  atomic_add(&brdf_counters[2], r.y);
  atomic_max(&brdf_counters[3], r.y);
}

// One round's samples of each point, staged in its own BRDF_MAX_BATCH slots.
__kernel void brdf_sample(__global const int* queue, int count, int brdf_round, PATH_PARAMS SCENE_PARAMS
                          LIGHT_SAMPLER_PARAMS __global BrdfItem* brdf_stage,
                          __global int2* counts_brdf) {
  int i = get_global_id(0);
  if (i >= count) return;
  PATH_ASSEMBLE(pb);
  SCENE_ASSEMBLE(sc);
  LIGHT_SAMPLER_ASSEMBLE(ls);
  int n = brdf_sample_item(queue[i], brdf_round, &ls, &sc, &pb, brdf_stage + BRDF_MAX_BATCH * i);
  counts_brdf[i] = (int2)(n, 0);
}

// Compacts the staged items, in queue order (each path's items stay together).
__kernel void scatter_brdf(int count, SCAN_PARAMS __global const BrdfItem* brdf_stage,
                           __global BrdfItem* brdf_items) {
  int i = get_global_id(0);
  if (i >= count) return;
  int n = counts[i].x;
  int pos = block_sums[i / block].x + offsets[i].x;
  for (int j = 0; j < n; ++j) brdf_items[pos + j] = brdf_stage[BRDF_MAX_BATCH * i + j];
}

__kernel void brdf_trace(PATH_PARAMS SCENE_PARAMS LIGHT_SAMPLER_PARAMS __global BrdfItem* brdf_items,
                         int count) {
  int i = get_global_id(0);
  if (i >= count) return;
  PATH_ASSEMBLE(pb);
  SCENE_ASSEMBLE(sc);
  LIGHT_SAMPLER_ASSEMBLE(ls);
  brdf_trace_item(&brdf_items[i], &ls, &sc, &pb);
}

__kernel void brdf_accumulate(__global const BrdfItem* brdf_items, int count, PATH_PARAMS
                              __global int4* path_counts) {
  int i = get_global_id(0);
  if (i >= count) return;
  PATH_ASSEMBLE(pb);
  int n = brdf_accumulate_item(i, brdf_items, count, &pb);
  if (n > 0) path_counts[as_int(brdf_items[i].dir.w)].x += n;
}

#endif // HAS_BRDF_ORIENTED
