// Per-path state of the wavefront (struct of arrays, indexed by path id) and the scene buffers, as
// structs of pointers so the per-item stage functions take them in one argument on both the device
// (where the kernels assemble them from their arguments, see cl/kernels/params.h) and the host.
#ifndef CANOPY_INTEGRATOR_PATH_STATE_H
#define CANOPY_INTEGRATOR_PATH_STATE_H

#include "../types.h"

typedef struct PathBuffers {
  GLOBAL float4* ray_o;      // xyz: origin, w: tmin
  GLOBAL float4* ray_d;      // xyz: unit direction
  GLOBAL float4* throughput; // xyz: path throughput beta
  GLOBAL float4* radiance;   // xyz: radiance gathered so far
  GLOBAL uint* rng;          // PCG state (cl/rng.h)
  GLOBAL Hit* hits;          // closest hit of the current ray
  // The last shading point, kept for light picking in this bounce and for MIS at the next hit.
  // xyz: position (the ray origin of rays leaving it, offset from the surface, cl/shading.h),
  // w: solid-angle pdf of the BSDF direction that left it
  GLOBAL float4* shade_P;
  GLOBAL float4* shade_N; // xyz: geometric normal facing wo, w: light-pick seed (uint bits)
  // xyz: path throughput beta at the shading point, w: 1 if light samples are MIS-weighted
  // against BSDF sampling (the path continues with a BSDF sample and MIS is on), else 0
  GLOBAL float4* shade_f;
  GLOBAL float4* shade_wo; // xyz: unit direction towards the viewer, w: material index (int bits)
  GLOBAL float4* shade_Ns; // xyz: shading normal (on wo's side; the geometric one when flat)
} PathBuffers;

typedef struct SceneBuffers {
  GLOBAL const BvhNode* nodes;
  GLOBAL const int* prim_index;
  GLOBAL const Primitive* prims;
  GLOBAL const Material* materials;
} SceneBuffers;

#endif // CANOPY_INTEGRATOR_PATH_STATE_H
