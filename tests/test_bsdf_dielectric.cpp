// The smooth dielectrics of cl/bsdf/dielectric.h on the host, against the Fresnel equations in
// double (written here from Born & Wolf §1.5.2, not from the code under test) and Snell's law:
// - the share of reflected samples is R(theta_o) within 5 binomial standard errors, at angles
//   from normal incidence to grazing, from outside and from inside (eta < 1, where beyond the
//   critical angle every sample reflects);
// - a reflected direction is the mirror direction with weight 1; a refracted one lies in the plane
//   of incidence on the far side with sin_t = sin_o / eta, unit length, weight 1 / eta^2;
// - a thin sheet reflects with 2R / (1 + R) (its two faces and the inter-reflections) and passes
//   the rest straight on, unscaled;
// - eval and pdf are 0 and there is no smooth lobe (light sampling skips glass);
// - index 1 passes every sample straight on.
#include "bsdf/bsdf.h"
#include "support/direction_at.h"
#include "support/fresnel_reference.h"
#include "support/materials.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace canopy;
using namespace canopy::test;

namespace {

struct Counts {
  int reflected = 0, transmitted = 0;
};

// n samples at wo, checking each sample's direction and weight; counts the lobes chosen.
Counts sample_and_check(const Material& m, float3 wo, int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const bool thin = m.type == MATERIAL_THIN_DIELECTRIC;
  const double eta = m.ior;
  Counts c;
  for (int i = 0; i < n && !::testing::Test::HasFailure(); ++i) {
    BsdfSample s = bsdf_sample(&m, wo, make_float3(uni(rng), uni(rng), uni(rng)));
    EXPECT_EQ(s.is_delta, 1);
    EXPECT_EQ(s.pdf, 0.0f);
    if (s.wi.z > 0) { // reflection: the mirror direction, weight 1
      ++c.reflected;
      EXPECT_FLOAT_EQ(s.wi.x, -wo.x);
      EXPECT_FLOAT_EQ(s.wi.y, -wo.y);
      EXPECT_FLOAT_EQ(s.wi.z, wo.z);
      EXPECT_FLOAT_EQ(s.weight.x, 1.0f);
      continue;
    }
    ++c.transmitted;
    if (thin) { // straight through, unscaled
      EXPECT_FLOAT_EQ(s.wi.x, -wo.x);
      EXPECT_FLOAT_EQ(s.wi.y, -wo.y);
      EXPECT_FLOAT_EQ(s.wi.z, -wo.z);
      EXPECT_FLOAT_EQ(s.weight.y, 1.0f);
      continue;
    }
    // Snell in the plane of incidence: the tangential part is -wo's divided by eta.
    double sin_o = std::hypot(double(wo.x), double(wo.y));
    double sin_t = std::hypot(double(s.wi.x), double(s.wi.y));
    EXPECT_NEAR(sin_t, sin_o / eta, 2e-6);
    if (sin_o > 1e-3) {
      EXPECT_NEAR(double(s.wi.x) * wo.y - double(s.wi.y) * wo.x, 0.0, 2e-6); // coplanar
      EXPECT_LT(double(s.wi.x) * wo.x + double(s.wi.y) * wo.y, 0.0);         // on the far side
    }
    EXPECT_NEAR(double(s.wi.x) * s.wi.x + double(s.wi.y) * s.wi.y + double(s.wi.z) * s.wi.z, 1.0,
                4e-7);
    EXPECT_NEAR(s.weight.z, 1.0 / (eta * eta), 1e-6 / (eta * eta));
  }
  return c;
}

// The share of reflected samples against the expected reflectance p, within 5 binomial SE.
void expect_share(const Counts& c, double p, const std::string& what) {
  const int n = c.reflected + c.transmitted;
  const double se = std::sqrt(std::max(p * (1 - p), 1e-12) / n);
  EXPECT_NEAR(double(c.reflected) / n, p, 5 * se + 1e-12) << what;
}

} // namespace

TEST(BsdfDielectric, ReflectsWithFresnelAndRefractsBySnell) {
  const int n = 100000;
  uint32_t seed = 1;
  for (double eta : {1.5, 1.0 / 1.5, 2.4, 1.0 / 2.4, 1.01})
    for (double theta : {0.0, 20.0, 40.0, 41.0, 42.5, 60.0, 80.0, 89.0}) {
      Material m = make_dielectric(float(eta));
      float3 wo = direction_at(theta, 0.7 + theta);
      Counts c = sample_and_check(m, wo, n, seed++);
      double r = ref_fresnel(wo.z, eta);
      expect_share(c, r, "eta " + std::to_string(eta) + " theta " + std::to_string(theta));
      if (r == 1.0) {
        EXPECT_EQ(c.transmitted, 0) << "total internal reflection, theta " << theta;
      }
    }
}

TEST(BsdfDielectric, ThinSheetReflectsBothFacesAndPassesStraightOn) {
  const int n = 100000;
  uint32_t seed = 100;
  for (double theta : {0.0, 45.0, 75.0, 89.0}) {
    Material m = make_dielectric(1.5f, true);
    float3 wo = direction_at(theta, 2.0);
    Counts c = sample_and_check(m, wo, n, seed++);
    double r = ref_fresnel(wo.z, 1.5);
    // R + T^2 R (1 + R^2 + R^4 + ...) with T = 1 - R: every path between the two faces.
    expect_share(c, r + (1 - r) * (1 - r) * r / (1 - r * r), "theta " + std::to_string(theta));
  }
}

TEST(BsdfDielectric, HasNoSmoothLobe) {
  for (Material m : {make_dielectric(1.5f), make_dielectric(1.5f, true)}) {
    EXPECT_EQ(bsdf_has_smooth_lobe(&m), 0);
    float3 wo = direction_at(30, 0), wi = make_float3(-wo.x, -wo.y, wo.z);
    float3 f = bsdf_eval(&m, wo, wi);
    EXPECT_EQ(f.x + f.y + f.z, 0.0f);
    EXPECT_EQ(bsdf_pdf(&m, wo, wi), 0.0f);
  }
}

TEST(BsdfDielectric, IndexOnePassesEverythingStraightOn) {
  Material m = make_dielectric(1.0f);
  for (double theta : {0.0, 30.0, 89.0}) {
    float3 wo = direction_at(theta, 1.0);
    Counts c = sample_and_check(m, wo, 1000, 7);
    EXPECT_EQ(c.reflected, 0);
  }
}

TEST(BsdfDielectric, FacingFromInsideInvertsTheIndex) {
  Material m = make_dielectric(1.5f);
  material_face(&m, 0);
  EXPECT_EQ(m.ior, 1.5f);
  material_face(&m, 1);
  EXPECT_FLOAT_EQ(m.ior, 1.0f / 1.5f);
  Material thin = make_dielectric(1.5f, true); // a sheet has no inside
  material_face(&thin, 1);
  EXPECT_EQ(thin.ior, 1.5f);
}
