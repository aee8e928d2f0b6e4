#include "render/features.h"

#include "types.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace canopy {

int light_sampler_from_name(const std::string& name) {
  int kind = light_sampler_kind(name);
  if (kind < 0)
    throw SceneError(
        fmt::format("light sampler '{}': unknown ({})", name, fmt::join(kLightSamplerNames, ", ")));
  return kind;
}

const char* light_sampler_name(int kind) {
  // The names are string literals: data() is NUL-terminated.
  return kind >= 0 && size_t(kind) < kLightSamplerNames.size() ? kLightSamplerNames[kind].data()
                                                               : "?";
}

KernelFeatures KernelFeatures::all(int light_sampler) {
  KernelFeatures f;
  f.light_point = f.light_spot = f.light_sphere = f.light_quad = f.light_triangle = true;
  f.light_disk = f.light_distant = f.light_environment = true;
  f.prim_sphere = f.prim_disk = true;
  f.material_conductor = f.material_plastic = f.material_dielectric = f.material_coated = true;
  f.material_mix = f.material_diffuse_transmission = true;
  f.medium = true;
  f.textures = true;
  f.light_sampler = light_sampler;
  return f;
}

std::string KernelFeatures::build_options() const {
  return fmt::format(
      "-DCANOPY_FEATURES_SET -DHAS_LIGHT_POINT={} -DHAS_LIGHT_SPOT={} "
      "-DHAS_LIGHT_SPHERE={} -DHAS_LIGHT_QUAD={} -DHAS_LIGHT_TRIANGLE={} "
      "-DHAS_LIGHT_DISK={} -DHAS_LIGHT_DISTANT={} -DHAS_LIGHT_ENVIRONMENT={} "
      "-DHAS_PRIM_SPHERE={} -DHAS_PRIM_DISK={} "
      "-DHAS_MATERIAL_CONDUCTOR={} -DHAS_MATERIAL_PLASTIC={} -DHAS_MATERIAL_DIELECTRIC={} "
      "-DHAS_MATERIAL_COATED={} -DHAS_MATERIAL_MIX={} -DHAS_MATERIAL_DIFFUSE_TRANSMISSION={} "
      "-DHAS_MEDIUM={} -DHAS_TEXTURES={} "
      "-DCANOPY_LIGHT_SAMPLER={} -DCANOPY_MIS={} -DCANOPY_VOLUME_MIDPOINT={}",
      int(light_point), int(light_spot), int(light_sphere), int(light_quad), int(light_triangle),
      int(light_disk), int(light_distant), int(light_environment), int(prim_sphere), int(prim_disk),
      int(material_conductor), int(material_plastic), int(material_dielectric),
      int(material_coated), int(material_mix), int(material_diffuse_transmission), int(medium),
      int(textures), light_sampler, int(mis), int(volume_midpoint));
}

KernelFeatures scene_features(const Scene& scene, int light_sampler) {
  KernelFeatures f;
  f.light_sampler = light_sampler;
  for (const Light& l : scene.lights) {
    switch (l.type) {
    case LIGHT_POINT:
      f.light_point = true;
      break;
    case LIGHT_SPOT:
      f.light_spot = true;
      break;
    case LIGHT_SPHERE:
      f.light_sphere = f.prim_sphere = true;
      break;
    case LIGHT_QUAD:
      f.light_quad = true;
      break;
    case LIGHT_TRIANGLE:
      f.light_triangle = true;
      break;
    case LIGHT_DISK:
      f.light_disk = f.prim_disk = true;
      break;
    default:
      break;
    }
  }
  for (const Light& l : scene.infinite_lights) {
    f.light_distant |= l.type == LIGHT_DISTANT;
    f.light_environment |= l.type == LIGHT_ENVIRONMENT;
  }
  f.medium = scene.has_medium;
  f.volume_midpoint = scene.has_medium && scene.integrator.volume_importance == "midpoint";
  for (const MaterialDesc& m : scene.materials) {
    f.material_conductor |= m.gpu.type == MATERIAL_CONDUCTOR;
    f.material_plastic |= m.gpu.type == MATERIAL_PLASTIC;
    f.material_dielectric |=
        m.gpu.type == MATERIAL_DIELECTRIC || m.gpu.type == MATERIAL_THIN_DIELECTRIC;
    f.material_coated |=
        m.gpu.type == MATERIAL_COATED_DIFFUSE || m.gpu.type == MATERIAL_COATED_CONDUCTOR;
    f.material_mix |= m.gpu.type == MATERIAL_MIX;
    f.material_diffuse_transmission |= m.gpu.type == MATERIAL_DIFFUSE_TRANSMISSION;
    f.textures |= material_textured(m.gpu);
  }
  return f;
}

} // namespace canopy
