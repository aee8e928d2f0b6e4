// The scene's device buffers and the one place that names them as kernel arguments (the names of
// cl/kernels/params.h: SCENE_PARAMS, LIGHT_SAMPLER_PARAMS). Used by the renderer, the kernel tests
// and the benchmarks.
#pragma once

#include "accel/bvh.h"
#include "cl/kernel_args.h"
#include "integrator/path_state.h"
#include "render/environment_map.h"
#include "render/light_sampler_data.h"
#include "render/texture_data.h"

#include <CL/opencl.hpp>

#include <algorithm>
#include <vector>

namespace canopy {

// A device copy of a host vector (never zero-sized: OpenCL forbids empty buffers).
template <class T>
cl::Buffer upload_buffer(const cl::Context& ctx, const std::vector<T>& v,
                         cl_mem_flags access = CL_MEM_READ_ONLY) {
  size_t bytes = std::max<size_t>(1, v.size()) * sizeof(T);
  if (v.empty()) return cl::Buffer(ctx, access, bytes);
  return cl::Buffer(ctx, access | CL_MEM_COPY_HOST_PTR, bytes, const_cast<T*>(v.data()));
}

struct DeviceScene {
#define CANOPY_DEVICE_SCENE_BUFFER(T, name) cl::Buffer name;
  SCENE_BUFFERS(CANOPY_DEVICE_SCENE_BUFFER) // nodes, leaf_blocks, prims, materials, normals, medium
#undef CANOPY_DEVICE_SCENE_BUFFER
  cl::Buffer lights;
  cl::Buffer power_pmf, alias_prob, alias_index, lt_nodes, lt_children, lt_leaf_lights, lt_trails;
  cl::Buffer env_texels, env_pmf, env_alias_prob, env_alias_index; // EnvironmentData
  int light_count = 0;
  int infinite_count = 0; // distant lights, after the light_count others in `lights`
  float4 root_sphere{0, 0, 0, 0}, root_info{0, 0, 0, 0};
  float split_threshold = 0.0f;
  uint32_t max_cut = 1;
  BrdfSettings brdf;

  // Names every buffer and scalar above as the kernels' arguments (SCENE_PARAMS,
  // LIGHT_SAMPLER_PARAMS). Buffers not uploaded (e.g. no geometry) stay without a value, so a
  // kernel that takes one fails to bind.
  void set_args(KernelArgs& args) const;
};

// `emission_exponent` k: the device copy of every light's emission is multiplied by 2^-k (exact for
// results in float's normal range; see emission_scale_exponent in render/renderer.h). The light
// sampler's data (pmfs, tree energies) is uploaded as built: it does not depend on the absolute
// emission, only on ratios.
DeviceScene upload_device_scene(const cl::Context& ctx, const SceneGeometry& geometry,
                                const std::vector<Material>& materials,
                                const std::vector<Light>& lights, const LightSamplerData& sampler,
                                int emission_exponent = 0, const Medium& medium = {},
                                const std::vector<Light>& infinite_lights = {},
                                const EnvironmentData& environment = {},
                                const TextureData& textures = {});

// Uploads only the lights and the light sampler's buffers into `d` (the part of
// upload_device_scene that the pick tests and benchmarks need without any geometry).
void upload_light_sampler(const cl::Context& ctx, const std::vector<Light>& lights,
                          const LightSamplerData& sampler, int emission_exponent, DeviceScene& d,
                          const std::vector<Light>& infinite_lights = {},
                          const EnvironmentData& environment = {});

} // namespace canopy
