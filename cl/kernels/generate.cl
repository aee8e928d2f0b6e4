// Stage 1: camera rays. One work item per path of the wave. The path's global sample index
// g = wave_base + i selects the pixel (g mod #pixels) and the pass (g / #pixels), so the image
// does not depend on how samples are split into waves.
#include "rng.h"
#include "types.h"

__kernel void generate(__global const CameraParams* cam, uint seed, ulong wave_base, int count,
                       __global float4* ray_o, __global float4* ray_d,
                       __global float4* throughput, __global float4* radiance,
                       __global uint* rng, __global int* ray_queue,
                       __global int4* path_counts) {
  int i = get_global_id(0);
  if (i >= count) return;
  ulong g = wave_base + (ulong)i;
  ulong npix = (ulong)cam->width * (ulong)cam->height;
  uint pixel = (uint)(g % npix);
  uint pass = (uint)(g / npix);
  PathRng r = rng_seed(seed, pixel, pass);
  float jx = rng_next_float(&r);
  float jy = rng_next_float(&r);
  float x = (float)(pixel % (uint)cam->width) + jx;
  float y = (float)(pixel / (uint)cam->width) + jy;
  float3 d = normalize(cam->lower_left.xyz + cam->du.xyz * x + cam->dv.xyz * y);
  ray_o[i] = (float4)(cam->origin.xyz, 0.0f); // w: tmin
  ray_d[i] = (float4)(d, 0.0f);
  throughput[i] = (float4)(1.0f, 1.0f, 1.0f, 0.0f);
  radiance[i] = (float4)(0.0f);
  rng[i] = r.state;
  ray_queue[i] = i;
  path_counts[i] = (int4)(0); // shadow rays, shading points, camera ray hit an emitter
}
