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

inline Material make_dielectric(float ior, bool thin = false) {
  Material m{};
  m.ior = ior;
  m.type = thin ? MATERIAL_THIN_DIELECTRIC : MATERIAL_DIELECTRIC;
  return m;
}

} // namespace canopy::test
