// Which kernel features a scene needs (DESIGN §7): light types, sphere and disk primitives, the
// light sampler. They become -D options so a kernel holds only the code the scene uses.
#pragma once

#include "scene/scene.h"

#include <string>

namespace canopy {

struct KernelFeatures {
  bool light_point = false, light_spot = false, light_sphere = false, light_quad = false,
       light_triangle = false, light_disk = false, light_distant = false, light_environment = false;
  bool prim_sphere = false, prim_disk = false;
  bool material_conductor = false, material_plastic = false, material_dielectric = false;
  bool material_coated = false; // coated diffuse and coated conductor (cl/bsdf/layered.h)
  bool material_mix = false;    // a mix of two materials (cl/material_mix.h)
  bool material_diffuse_transmission = false; // cl/bsdf/diffuse_transmission.h
  bool medium = false;                        // a participating medium (cl/volume/, shade_volume)
  bool textures = false;                      // a material with a texture (cl/texture.h)
  bool volume_midpoint = false;               // medium segments ranked at their midpoint (ablation)
  int light_sampler = 0;                      // SAMPLER_* (cl/types.h)
  bool mis = true;                            // RendererOptions::mis

  // Everything on (for the test that checks specialisation changes nothing).
  static KernelFeatures all(int light_sampler);
  std::string build_options() const;
};

// Throws SceneError for an unknown sampler name.
int light_sampler_from_name(const std::string& name);
const char* light_sampler_name(int kind);

KernelFeatures scene_features(const Scene& scene, int light_sampler);

} // namespace canopy
