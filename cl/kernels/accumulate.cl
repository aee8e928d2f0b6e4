// Stage 6: add the wave's path radiance into the film. One work item per pixel the wave touches
// (min(wave_size, npix) of them: path j and its pixel's later paths j + npix, ...), visiting that
// pixel's paths in increasing order, so the sum is race-free and deterministic even when a wave
// holds several samples of the same pixel. film_sum.w counts samples; film_sumsq holds the
// per-channel second moment for variance estimates. A non-finite sample never reaches the film:
// it is counted in nonfinite[0] and recorded as zero. film_counts gathers each pixel's shadow rays
// and shading points (the heat map of Fig. 18).
#include "types.h"

__kernel void accumulate(ulong wave_base, int wave_size, int npix, __global const float4* radiance,
                         __global float4* film_sum, __global float4* film_sumsq,
                         __global int* nonfinite, __global const int2* path_counts,
                         __global float2* film_counts) {
  int first = get_global_id(0);
  if (first >= min(wave_size, npix)) return;
  int p = (int)((wave_base + (ulong)first) % (ulong)npix);
  float4 sum = film_sum[p];
  float4 sumsq = film_sumsq[p];
  float2 counts = film_counts[p];
  for (int i = first; i < wave_size; i += npix) {
    float3 L = radiance[i].xyz;
    if (!(isfinite(L.x) && isfinite(L.y) && isfinite(L.z))) {
      atomic_inc(nonfinite);
      L = (float3)(0.0f);
    }
    sum += (float4)(L, 1.0f);
    sumsq += (float4)(L * L, 0.0f);
    counts += convert_float2(path_counts[i]);
  }
  film_counts[p] = counts;
  film_sum[p] = sum;
  film_sumsq[p] = sumsq;
}
