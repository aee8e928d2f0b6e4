// Stage 1: camera rays. One work item per path of the wave. A render covers a window of the film
// (window: x0, y0, width, height; the whole film unless cropped), or bands of its rows (bands,
// row_bands.h; window.w is then the number of rows covered), over the sample indices
// [first_pass, first_pass + spp) of each of its pixels. The path's index g = wave_base + i in the
// render selects the covered pixel (g mod #covered pixels) and the pass (first_pass + g /
// #covered pixels). The random numbers of a sample are keyed on (seed, film pixel, pass) alone, so
// the image depends neither on how samples are split into waves nor on the window or sample range a
// render covers: partial renders merge into the full one. path_sampler: PATH_SAMPLER_* (sampler.h).
#include "row_bands.h"
#include "sampler.h"
#include "types.h"

__kernel void generate(__global const CameraParams* cam, uint seed, int4 window, int4 bands,
                       uint first_pass, ulong wave_base, int count, __global float4* ray_o,
                       __global float4* ray_d, __global float4* throughput,
                       __global float4* radiance, __global uint4* rng, __global int* ray_queue,
                       __global int4* path_counts, uint path_sampler) {
  int i = get_global_id(0);
  if (i >= count) return;
  ulong g = wave_base + (ulong)i;
  ulong nwin = (ulong)window.z * (ulong)window.w; // window.w: the rows covered (row_bands.h)
  uint in_win = (uint)(g % nwin);
  uint pass = first_pass + (uint)(g / nwin);
  uint row = covered_row(bands, in_win / (uint)window.z);
  uint pixel = (uint)(window.y + (int)row) * (uint)cam->width +
               (uint)(window.x + (int)(in_win % (uint)window.z));
  float2 jitter;
  uint4 state = path_sampler_start(path_sampler, seed, pixel, pass, &jitter);
  float x = (float)(pixel % (uint)cam->width) + jitter.x;
  float y = (float)(pixel / (uint)cam->width) + jitter.y;
  float3 d = normalize(cam->lower_left.xyz + cam->du.xyz * x + cam->dv.xyz * y);
  ray_o[i] = (float4)(cam->origin.xyz, 0.0f); // w: tmin
  ray_d[i] = (float4)(d, 0.0f);
  throughput[i] = (float4)(1.0f, 1.0f, 1.0f, 0.0f);
  radiance[i] = (float4)(0.0f);
  rng[i] = state;
  ray_queue[i] = i;
  path_counts[i] = (int4)(0); // shadow rays, shading points, camera ray hit an emitter
}
