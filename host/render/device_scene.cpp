#include "render/device_scene.h"

#include <cmath>

namespace canopy {

namespace {

// The lights, then the distant lights, with emission times 2^-k, uploaded in chunks (no second
// host copy of a light set of 10^7 lights). Emission is read on the device only as
// radiance/intensity (sample_light, light_emitted_radiance); pmfs and MIS weights use the
// sampler's own buffers.
cl::Buffer upload_scaled_lights(const cl::Context& ctx, const std::vector<Light>& lights,
                                const std::vector<Light>& distant, int k) {
  if ((k == 0 && distant.empty()) || (lights.empty() && distant.empty()))
    return upload_buffer(ctx, lights);
  const size_t total = lights.size() + distant.size();
  cl::Buffer buf(ctx, CL_MEM_READ_ONLY, total * sizeof(Light));
  cl::CommandQueue q(ctx, ctx.getInfo<CL_CONTEXT_DEVICES>().at(0));
  const size_t chunk = size_t(1) << 16;
  std::vector<Light> part;
  for (size_t first = 0; first < total; first += chunk) {
    size_t n = std::min(chunk, total - first);
    part.resize(n);
    for (size_t i = 0; i < n; ++i) {
      size_t j = first + i;
      part[i] = j < lights.size() ? lights[j] : distant[j - lights.size()];
    }
    for (Light& l : part) {
      l.emission.x = std::ldexp(l.emission.x, -k);
      l.emission.y = std::ldexp(l.emission.y, -k);
      l.emission.z = std::ldexp(l.emission.z, -k);
    }
    q.enqueueWriteBuffer(buf, CL_TRUE, first * sizeof(Light), n * sizeof(Light), part.data());
  }
  return buf;
}

} // namespace

DeviceScene upload_device_scene(const cl::Context& ctx, const SceneGeometry& geometry,
                                const std::vector<Material>& materials,
                                const std::vector<Light>& lights, const LightSamplerData& sampler,
                                int emission_exponent, const Medium& medium,
                                const std::vector<Light>& infinite_lights,
                                const EnvironmentData& environment, const TextureData& textures) {
  DeviceScene d;
  d.nodes = upload_buffer(ctx, geometry.bvh.nodes);
  d.leaf_blocks = upload_buffer(ctx, geometry.bvh.leaf_blocks);
  d.prims = upload_buffer(ctx, geometry.prims);
  d.materials = upload_buffer(ctx, materials);
  d.shading_normals = upload_buffer(ctx, geometry.shading_normals); // one element when empty
  d.medium = upload_buffer(ctx, std::vector<Medium>{medium});
  d.texcoords = upload_buffer(ctx, geometry.texcoords); // one element each without textures
  d.textures = upload_buffer(ctx, textures.textures);
  d.texels = upload_buffer(ctx, textures.texels);
  upload_light_sampler(ctx, lights, sampler, emission_exponent, d, infinite_lights, environment);
  return d;
}

void upload_light_sampler(const cl::Context& ctx, const std::vector<Light>& lights,
                          const LightSamplerData& sampler, int emission_exponent, DeviceScene& d,
                          const std::vector<Light>& infinite_lights,
                          const EnvironmentData& environment) {
  d.env_texels = upload_buffer(ctx, environment.texels);
  d.env_pmf = upload_buffer(ctx, environment.pmf);
  d.env_alias_prob = upload_buffer(ctx, environment.alias_prob);
  d.env_alias_index = upload_buffer(ctx, environment.alias_index);
  d.lights = upload_scaled_lights(ctx, lights, infinite_lights, emission_exponent);
  d.infinite_count = int(infinite_lights.size());
  d.power_pmf = upload_buffer(ctx, sampler.power_pmf);
  d.alias_prob = upload_buffer(ctx, sampler.alias_prob);
  d.alias_index = upload_buffer(ctx, sampler.alias_index);
  d.lt_nodes = upload_buffer(ctx, sampler.tree.nodes);
  d.lt_children = upload_buffer(ctx, sampler.tree.children);
  d.lt_leaf_lights = upload_buffer(ctx, sampler.tree.leaf_lights);
  d.lt_trails = upload_buffer(ctx, sampler.tree.trails);
  d.light_count = int(lights.size());
  d.root_sphere = sampler.tree.root_sphere;
  d.root_info = sampler.tree.root_info;
  d.split_threshold = sampler.threshold;
  d.max_cut = sampler.root_budget();
  d.brdf = sampler.brdf;
}

void DeviceScene::set_args(KernelArgs& args) const {
#define CANOPY_SET_SCENE_ARG(T, name) args.set(#name, name);
  SCENE_BUFFERS(CANOPY_SET_SCENE_ARG)
#undef CANOPY_SET_SCENE_ARG
  args.set("light_count", cl_int(light_count));
  args.set("infinite_count", cl_int(infinite_count));
  args.set("env_texels", env_texels);
  args.set("env_pmf", env_pmf);
  args.set("env_alias_prob", env_alias_prob);
  args.set("env_alias_index", env_alias_index);
  args.set("lights", lights);
  args.set("power_pmf", power_pmf);
  args.set("alias_prob", alias_prob);
  args.set("alias_index", alias_index);
  args.set("lt_nodes", lt_nodes);
  args.set("lt_children", lt_children);
  args.set("lt_leaf_lights", lt_leaf_lights);
  args.set("lt_trails", lt_trails);
  args.set("lt_root_sphere", root_sphere);
  args.set("lt_root_info", root_info);
  args.set("split_threshold", cl_float(split_threshold));
  args.set("max_cut", cl_uint(max_cut));
  args.set("brdf_delta", cl_float(brdf.delta));
  args.set("brdf_lambda", cl_float(brdf.lambda));
  args.set("brdf_nmax", cl_int(brdf.n_max));
  args.set("brdf_adaptive", cl_int(brdf.adaptive ? 1 : 0));
}

} // namespace canopy
