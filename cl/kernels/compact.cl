// Deterministic stream compaction. A producer kernel writes, for each input item i, a count pair
// counts[i] = (a, b) of the outputs it staged; these three kernels turn the counts into output
// positions with an exclusive prefix sum, so queues come out in input order. Atomic counters would
// give the same sets in a scheduling-dependent order, and the float sums downstream would then
// differ from run to run in the last bits; with the scan, images are bit-identical.
//
// scan_blocks:      one work item per block of `block` items: local exclusive scan + block total
// scan_block_sums:  one work item: exclusive scan of the block totals; totals[0..1] = grand total
// The scatter step (position = block_sums[i / block] + offsets[i]) is specific to each queue and
// lives with its producer.
#include "types.h"

__kernel void scan_blocks(__global const int2* counts, int n, int block, __global int2* offsets,
                          __global int2* block_sums) {
  int b = get_global_id(0);
  int start = b * block;
  if (start >= n) return;
  int end = min(n, start + block);
  int2 acc = (int2)(0, 0);
  for (int i = start; i < end; ++i) {
    offsets[i] = acc;
    acc += counts[i];
  }
  block_sums[b] = acc;
}

__kernel void scan_block_sums(__global int2* block_sums, int nblocks, __global int* totals) {
  if (get_global_id(0) != 0) return;
  int2 acc = (int2)(0, 0);
  for (int b = 0; b < nblocks; ++b) {
    int2 s = block_sums[b];
    block_sums[b] = acc;
    acc += s;
  }
  totals[0] = acc.x;
  totals[1] = acc.y;
}
