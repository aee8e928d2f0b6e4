// Reference values for the tests of glass and coated materials, in double and written from the
// textbook formulas (not from cl/bsdf/): the unpolarised Fresnel reflectance of a smooth
// dielectric interface (Born & Wolf §1.5.2), light arriving from the side of index 1 onto index
// eta (eta < 1: from inside, with total internal reflection).
#pragma once

#include <cmath>

namespace canopy::test {

inline double ref_fresnel(double cos_i, double eta) {
  double sin2_t = (1 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1) return 1; // total internal reflection
  double cos_t = std::sqrt(1 - sin2_t);
  double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

} // namespace canopy::test
