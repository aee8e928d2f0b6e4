// Lights for render tests built in code: a point light and a distant light (the sun).
#pragma once

#include "compat.h"
#include "types.h"

namespace canopy::test {

// An isotropic point light of intensity I at p.
inline Light point_light(float3 p, float3 I) {
  Light l{};
  l.type = LIGHT_POINT;
  l.p = f4_from3(p, 0.0f);
  l.emission = f4_from3(I, 0.0f);
  l.prim = -1;
  return l;
}

// A distant light whose light travels along `travel`, of irradiance E on a surface facing it.
inline Light distant_light(float3 travel, float3 E) {
  Light l{};
  l.type = LIGHT_DISTANT;
  l.e1 = f4_from3(normalize(travel) * -1.0f, 0.0f);
  l.emission = f4_from3(E, 0.0f);
  l.prim = -1;
  return l;
}

} // namespace canopy::test
