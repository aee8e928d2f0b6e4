#include "render/device_scene.h"

namespace canopy {

DeviceScene upload_device_scene(const cl::Context& ctx, const SceneGeometry& geometry,
                                const std::vector<Material>& materials,
                                const std::vector<Light>& lights, const LightSamplerData& sampler) {
  DeviceScene d;
  d.nodes = upload_buffer(ctx, geometry.bvh.nodes);
  d.prim_index = upload_buffer(ctx, geometry.bvh.prim_index);
  d.prims = upload_buffer(ctx, geometry.prims);
  d.materials = upload_buffer(ctx, materials);
  d.lights = upload_buffer(ctx, lights);
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
  return d;
}

int DeviceScene::set_bvh_args(cl::Kernel& k, int i) const {
  k.setArg(i++, nodes);
  k.setArg(i++, prim_index);
  k.setArg(i++, prims);
  return i;
}

int DeviceScene::set_scene_args(cl::Kernel& k, int i) const {
  i = set_bvh_args(k, i);
  k.setArg(i++, materials);
  return i;
}

int DeviceScene::set_light_sampler_args(cl::Kernel& k, int i) const {
  k.setArg(i++, cl_int(light_count));
  k.setArg(i++, lights);
  k.setArg(i++, power_pmf);
  k.setArg(i++, alias_prob);
  k.setArg(i++, alias_index);
  k.setArg(i++, lt_nodes);
  k.setArg(i++, lt_children);
  k.setArg(i++, lt_leaf_lights);
  k.setArg(i++, lt_trails);
  k.setArg(i++, root_sphere);
  k.setArg(i++, root_info);
  k.setArg(i++, cl_float(split_threshold));
  k.setArg(i++, cl_uint(max_cut));
  return i;
}

} // namespace canopy
