// Kernel parameter lists shared by several stages, and the code that assembles the structs of
// pointers the stage functions take (cl/integrator/path_state.h, light_sampler.h). The host binds
// kernel arguments by name (host/cl/kernel_args.h), so these names are also the host's: order
// does not matter, and a name the host does not provide is an error when the kernel is bound.
//
// Each *_PARAMS list ends with a comma and is written before another parameter:
//   __kernel void f(int count, PATH_PARAMS SCENE_PARAMS __global int2* out)
#ifndef CANOPY_KERNEL_PARAMS_H
#define CANOPY_KERNEL_PARAMS_H

#include "integrator/light_sampler.h"
#include "integrator/path_state.h"

#ifndef CANOPY_LIGHT_SAMPLER
#define CANOPY_LIGHT_SAMPLER SAMPLER_UNIFORM
#endif
// The kernels of BRDF-oriented sampling (brdf_mis.cl) exist only for a BRDF sampler on a scene
// with a glossy material.
#define HAS_BRDF_ORIENTED                                                                          \
  (HAS_MICROFACET &&                                                                               \
   (CANOPY_LIGHT_SAMPLER == SAMPLER_BRDF_MIS || CANOPY_LIGHT_SAMPLER == SAMPLER_BRDF_ORIENTED))

// The path state and the scene, generated from PATH_STATE_BUFFERS and SCENE_BUFFERS.
#define CANOPY_PATH_PARAM(T, name) __global T *name,
#define CANOPY_SCENE_PARAM(T, name) __global const T *name,
#define CANOPY_PARAM_NAME(T, name) name,

#define PATH_PARAMS PATH_STATE_BUFFERS(CANOPY_PATH_PARAM)
#define SCENE_PARAMS SCENE_BUFFERS(CANOPY_SCENE_PARAM)

// PATH_ASSEMBLE(pb): a PathBuffers named pb from the PATH_PARAMS (its fields are in the same
// order); SCENE_ASSEMBLE(sc): a SceneBuffers named sc from the SCENE_PARAMS.
#define PATH_ASSEMBLE(pb) PathBuffers pb = {PATH_STATE_BUFFERS(CANOPY_PARAM_NAME)}
#define SCENE_ASSEMBLE(sc) SceneBuffers sc = {SCENE_BUFFERS(CANOPY_PARAM_NAME)}

#define LIGHT_SAMPLER_PARAMS                                                                       \
  int light_count, __global const Light *lights, __global const float *power_pmf,                  \
      __global const float *alias_prob, __global const int *alias_index,                           \
      __global const float4 *lt_nodes, __global const int4 *lt_children,                           \
      __global const int *lt_leaf_lights, __global const uint *lt_trails, float4 lt_root_sphere,   \
      float4 lt_root_info, float split_threshold, uint max_cut, __global float2 *brdf_cut,         \
      float brdf_delta, float brdf_lambda, int brdf_nmax, int brdf_adaptive, int infinite_count,   \
      __global const float4 *env_texels, __global const float *env_pmf,                            \
      __global const float *env_alias_prob, __global const int *env_alias_index,

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
  ls.max_cut = max_cut;                                                                            \
  ls.brdf_cut = brdf_cut;                                                                          \
  ls.brdf_delta = brdf_delta;                                                                      \
  ls.brdf_lambda = brdf_lambda;                                                                    \
  ls.brdf_nmax = brdf_nmax;                                                                        \
  ls.brdf_adaptive = brdf_adaptive;                                                                \
  ls.infinite_count = HAS_INFINITE_LIGHT ? infinite_count : 0;                                    \
  ls.env.texels = env_texels;                                                                      \
  ls.env.pmf = env_pmf;                                                                            \
  ls.env.alias_prob = env_alias_prob;                                                              \
  ls.env.alias_index = env_alias_index

// An exclusive scan's input (counts) and result (block_sums[i / block] + offsets[i]).
#define SCAN_PARAMS                                                                                \
  __global const int2 *counts, __global const int2 *offsets, __global const int2 *block_sums,      \
      int block,

#endif // CANOPY_KERNEL_PARAMS_H
