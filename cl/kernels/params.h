// Kernel parameter lists shared by several stages, and the code that assembles the structs of
// pointers the stage functions take (cl/integrator/path_state.h, light_sampler.h). The host sets
// these arguments in the same order (host/render/kernel_args.h).
#ifndef CANOPY_KERNEL_PARAMS_H
#define CANOPY_KERNEL_PARAMS_H

#include "integrator/light_sampler.h"
#include "integrator/path_state.h"

#ifndef CANOPY_LIGHT_SAMPLER
#define CANOPY_LIGHT_SAMPLER SAMPLER_UNIFORM
#endif

#define PATH_PARAMS                                                                                \
  __global float4 *ray_o, __global float4 *ray_d, __global float4 *throughput,                     \
      __global float4 *radiance, __global uint *rng_state, __global Hit *hits,                     \
      __global float4 *shade_P, __global float4 *shade_N, __global float4 *shade_f,                \
      __global float4 *shade_wo, __global float4 *shade_Ns

#define PATH_ASSEMBLE(pb)                                                                          \
  PathBuffers pb;                                                                                  \
  pb.ray_o = ray_o;                                                                                \
  pb.ray_d = ray_d;                                                                                \
  pb.throughput = throughput;                                                                      \
  pb.radiance = radiance;                                                                          \
  pb.rng = rng_state;                                                                              \
  pb.hits = hits;                                                                                  \
  pb.shade_P = shade_P;                                                                            \
  pb.shade_N = shade_N;                                                                            \
  pb.shade_f = shade_f;                                                                            \
  pb.shade_wo = shade_wo;                                                                          \
  pb.shade_Ns = shade_Ns

#define SCENE_PARAMS                                                                               \
  __global const BvhNode *bvh_nodes, __global const int *prim_index,                               \
      __global const Primitive *prims, __global const Material *materials

#define SCENE_ASSEMBLE(sc)                                                                         \
  SceneBuffers sc;                                                                                 \
  sc.nodes = bvh_nodes;                                                                            \
  sc.prim_index = prim_index;                                                                      \
  sc.prims = prims;                                                                                \
  sc.materials = materials

#define LIGHT_SAMPLER_PARAMS                                                                       \
  int light_count, __global const Light *lights, __global const float *power_pmf,                  \
      __global const float *alias_prob, __global const int *alias_index,                           \
      __global const float4 *lt_nodes, __global const int4 *lt_children,                           \
      __global const int *lt_leaf_lights, __global const uint *lt_trails, float4 lt_root_sphere,   \
      float4 lt_root_info, float split_threshold, uint max_cut

#define LIGHT_SAMPLER_ASSEMBLE(ls)                                                                 \
  LightSamplerCtx ls;                                                                              \
  ls.kind = CANOPY_LIGHT_SAMPLER;                                                                  \
  ls.light_count = light_count;                                                                    \
  ls.lights = lights;                                                                              \
  ls.power_pmf = power_pmf;                                                                        \
  ls.alias_prob = alias_prob;                                                                      \
  ls.alias_index = alias_index;                                                                    \
  ls.tree.nodes = lt_nodes;                                                                        \
  ls.tree.children = lt_children;                                                                  \
  ls.tree.leaf_lights = lt_leaf_lights;                                                            \
  ls.tree.trails = lt_trails;                                                                      \
  ls.tree.lights = lights;                                                                         \
  ls.tree.root_sphere = lt_root_sphere;                                                            \
  ls.tree.root_info = lt_root_info;                                                                \
  ls.threshold = split_threshold;                                                                  \
  ls.max_cut = max_cut

#define SCAN_PARAMS                                                                                \
  __global const int2 *counts, __global const int2 *offsets, __global const int2 *block_sums,      \
      int block

#endif // CANOPY_KERNEL_PARAMS_H
