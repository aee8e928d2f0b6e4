// Material records for the BSDF and light-sampling tests (cl/types.h Material; alpha = GGX alpha).
#pragma once

#include "compat.h"
#include "types.h"

namespace canopy::test {

inline Material make_diffuse(float3 albedo) {
  Material m{};
  m.albedo = f4_from3(albedo, 0);
  m.type = MATERIAL_DIFFUSE;
  return m;
}
inline Material make_conductor(float3 eta, float3 k, float alpha) {
  Material m{};
  m.specular = f4_from3(eta, 0);
  m.k = f4_from3(k, 0);
  m.alpha = alpha;
  m.type = MATERIAL_CONDUCTOR;
  return m;
}
inline Material make_plastic(float3 albedo, float3 spec, float ior, float alpha) {
  Material m{};
  m.albedo = f4_from3(albedo, 0);
  m.specular = f4_from3(spec, 0);
  m.ior = ior;
  m.alpha = alpha;
  m.type = MATERIAL_PLASTIC;
  return m;
}

inline Material make_dielectric(float ior, bool thin = false, float alpha = 0.0f) {
  Material m{};
  m.ior = ior;
  m.alpha = alpha;
  m.type = thin ? MATERIAL_THIN_DIELECTRIC : MATERIAL_DIELECTRIC;
  return m;
}

// A coated material's walk: slab thickness, medium albedo and g, depth and samples.
struct Layer {
  float thickness = 0.01f;
  float3 albedo = {0, 0, 0};
  float g = 0.0f;
  int max_depth = 10;
  int n_samples = 1;
};
inline void set_layer(Material& m, const Layer& l) {
  m.medium = f4_from3(l.albedo, l.g);
  m.thickness = l.thickness;
  m.max_depth = l.max_depth;
  m.n_samples = l.n_samples;
}
inline Material make_coated_diffuse(float3 albedo, float ior, float alpha, const Layer& l = {}) {
  Material m{};
  m.albedo = f4_from3(albedo, 0);
  m.ior = ior;
  m.alpha = alpha;
  m.type = MATERIAL_COATED_DIFFUSE;
  set_layer(m, l);
  return m;
}
inline Material make_coated_conductor(float ior, float alpha, float3 eta, float3 k,
                                      float base_alpha, const Layer& l = {}) {
  Material m{};
  m.specular = f4_from3(eta, 0);
  m.k = f4_from3(k, 0);
  m.ior = ior;
  m.alpha = alpha;
  m.base_alpha = base_alpha;
  m.type = MATERIAL_COATED_CONDUCTOR;
  set_layer(m, l);
  return m;
}

// pbrt-v4's diffuse transmission: reflectance r, transmittance t.
inline Material make_diffuse_transmission(float3 r, float3 t) {
  Material m{};
  m.type = MATERIAL_DIFFUSE_TRANSMISSION;
  m.albedo = f4_from3(r, 0.0f);
  m.specular = f4_from3(t, 0.0f);
  return m;
}

} // namespace canopy::test
