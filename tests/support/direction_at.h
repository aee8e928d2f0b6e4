// A unit direction of the local shading frame (z = the normal) at polar angle theta_deg (degrees)
// and azimuth phi (radians), for the BSDF tests.
#pragma once

#include "compat.h"

#include <cmath>

namespace canopy::test {

inline float3 direction_at(double theta_deg, double phi) {
  double t = theta_deg * M_PI / 180;
  return make_float3(float(std::sin(t) * std::cos(phi)), float(std::sin(t) * std::sin(phi)),
                     float(std::cos(t)));
}

} // namespace canopy::test
