// Stage 4: one pass over the split queue (cl/integrator/light_pick.h). Each item stages up to four
// children or shadow items in its own slots; scatter_split then compacts them, in item order, into
// the next pass's split queue and this pass's shadow queue. cut_size counts each path's lights in
// the cut (integer atomics: the totals do not depend on the order).
#include "integrator/light_pick.h"
#include "kernels/params.h"

__kernel void light_pick(__global const SplitItem* split_in, int count, PATH_PARAMS SCENE_PARAMS
                         LIGHT_SAMPLER_PARAMS __global SplitItem* child_stage,
                         __global ShadowItem* shadow_stage, __global int2* counts_pick,
                         __global int* cut_size, __global int* volume_counters) {
  int i = get_global_id(0);
  if (i >= count) return;
  PATH_ASSEMBLE(pb);
  SCENE_ASSEMBLE(sc);
  LIGHT_SAMPLER_ASSEMBLE(ls);
  SplitItem it = split_in[i];
  int4 r = light_pick_item(it, &ls, &sc, &pb, child_stage + 4 * i,
                           shadow_stage + LIGHT_PICK_SHADOW_SLOTS * i);
  counts_pick[i] = (int2)(r.x, r.y);
  int path = it.path & ~SPLIT_SEGMENT;
  // Shadow rays of medium segments, counted apart from those of surface points (--stats).
  if (HAS_MEDIUM && path != it.path && r.y) atomic_add(&volume_counters[1], r.y);
  // Without splitting a path has exactly one item (its root): a plain store. A locked add is a
  // full barrier on x86 (it waits for this item's shadow-item stores to drain); perf put 19% of the
  // stage's samples just after it (the measured gain is within the noise, docs/performance.md).
  // With a medium a path may have two roots (its segment and its surface point).
  if (HAS_MEDIUM ? 0 : !light_sampler_splits(&ls))
    cut_size[path] = r.z;
  else if (r.z)
    atomic_add(&cut_size[path], r.z);
}

__kernel void scatter_split(int count, SCAN_PARAMS __global const SplitItem* child_stage,
                            __global const ShadowItem* shadow_stage, __global SplitItem* split_out,
                            __global ShadowItem* shadow_items) {
  int i = get_global_id(0);
  if (i >= count) return;
  int2 c = counts[i];
  int2 pos = block_sums[i / block] + offsets[i];
  for (int j = 0; j < c.x; ++j) split_out[pos.x + j] = child_stage[4 * i + j];
  for (int j = 0; j < c.y; ++j)
    shadow_items[pos.y + j] = shadow_stage[LIGHT_PICK_SHADOW_SLOTS * i + j];
}

// Histogram of cut sizes over this bounce's shading points (last bin: that many or more).
__kernel void cut_histogram(__global const int* queue, int count, __global const int2* counts_shade,
                            __global const int* cut_size, __global int* histogram, int bins) {
  int i = get_global_id(0);
  if (i >= count || !counts_shade[i].y) return;
  atomic_inc(&histogram[min(cut_size[queue[i]], bins - 1)]);
}
