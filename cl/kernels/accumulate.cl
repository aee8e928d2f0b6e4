// Stage 6: add the wave's path radiance into the film. One work item per pixel the wave touches
// (min(wave_size, npix) of them: path j and its pixel's later paths j + npix, ...), visiting that
// pixel's paths in increasing order, so the sum is race-free and deterministic even when a wave
// holds several samples of the same pixel. film_sum.w counts samples; film_sumsq holds the
// per-channel second moment for variance estimates. A non-finite sample never reaches the film:
// it is counted in nonfinite[0] and recorded as zero. film_counts gathers each pixel's shadow rays
// and shading points (the heat map of Fig. 18) and its samples whose camera ray hit an emitter.
//
// The film is summed in double (cl_khr_fp64, checked by the host before the build): a float sum
// stops growing once it is 2^24 times a sample (at 2^22 spp a pixel came out 3-5% low) and
// overflows to Inf when samples near FLT_MAX add up. Each sample is a float; its square and the
// sums are exact or rounded to 53 bits, so 2^24 spp of samples up to FLT_MAX stay finite and
// accurate to ~1e-9. The counts are integers below 2^53, exact in double.
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#include "types.h"

__kernel void accumulate(ulong wave_base, int wave_size, int npix, __global const float4* radiance,
                         __global double4* film_sum, __global double4* film_sumsq,
                         __global int* nonfinite, __global const int4* path_counts,
                         __global double4* film_counts) {
  int first = get_global_id(0);
  if (first >= min(wave_size, npix)) return;
  int p = (int)((wave_base + (ulong)first) % (ulong)npix);
  double4 sum = film_sum[p];
  double4 sumsq = film_sumsq[p];
  double4 counts = film_counts[p];
  for (int i = first; i < wave_size; i += npix) {
    float3 L = radiance[i].xyz;
    if (!(isfinite(L.x) && isfinite(L.y) && isfinite(L.z))) {
      atomic_inc(nonfinite);
      L = (float3)(0.0f);
    }
    double3 Ld = convert_double3(L);
    sum += (double4)(Ld, 1.0);
    sumsq += (double4)(Ld * Ld, 0.0);
    counts += convert_double4(path_counts[i]);
  }
  film_counts[p] = counts;
  film_sum[p] = sum;
  film_sumsq[p] = sumsq;
}
