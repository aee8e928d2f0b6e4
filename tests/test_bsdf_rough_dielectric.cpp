// Rough glass (cl/bsdf/dielectric.h, dielectric_interface.h) on the host, against properties
// that hold for any correct microfacet BTDF, computed here by quadrature in double:
// - the directional albedo: the mean sample weight equals the integral of f |cos theta_i| over
//   the whole sphere (reflection and refraction, with the radiance scale 1 / eta^2);
// - the sampled directions follow bsdf_pdf: the share of samples in each band of cos theta_i
//   equals the integral of the pdf over it (a chi-square-like check, within 5 binomial standard
//   errors), and each sample's pdf and weight are bsdf_pdf and bsdf_eval |cos| / pdf;
// - reciprocity for radiance transport (Veach 1997, eq. 5.14): f(wo, wi) / eta_o^2 =
//   f(wi, wo) / eta_i^2, and f symmetric for reflection;
// - the smooth limit: at alpha = 1e-4 the reflected share is the Fresnel reflectance and the
//   refracted directions obey Snell's law;
// - there is a smooth lobe, and eval, pdf and sample stay finite at grazing angles.
#include "bsdf/bsdf.h"
#include "support/direction_at.h"
#include "support/fresnel_reference.h"
#include "support/materials.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

using namespace canopy;
using namespace canopy::test;

namespace {

float3 dir_mu(double mu, double phi) {
  double s = std::sqrt(std::max(0.0, 1 - mu * mu));
  return make_float3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(mu));
}

// Integral over the sphere of g(wi) by the midpoint rule in (cos theta, phi), split into bands
// of cos theta: band b of nb covers mu in [-1 + 2b / nb, -1 + 2(b + 1) / nb].
template <class G> std::vector<double> band_integrals(G g, int nb, int n_mu, int n_phi) {
  std::vector<double> out(nb, 0.0);
  const double dmu = 2.0 / n_mu, dphi = 2 * M_PI / n_phi;
  for (int i = 0; i < n_mu; ++i) {
    double mu = -1 + (i + 0.5) * dmu;
    int b = std::min(nb - 1, int((mu + 1) / 2 * nb));
    double sum = 0;
    for (int j = 0; j < n_phi; ++j)
      sum += g(dir_mu(mu, (j + 0.5) * dphi));
    out[b] += sum * dmu * dphi;
  }
  return out;
}

struct Case {
  float eta, alpha, theta;
};

class RoughDielectric : public ::testing::TestWithParam<Case> {};

TEST_P(RoughDielectric, AlbedoAndPdfMatchQuadrature) {
  const Case c = GetParam();
  Material m = make_dielectric(c.eta, false, c.alpha);
  const float3 wo = direction_at(c.theta, 0.4);
  const int nb = 16;
  // Quadrature: fine enough for these lobes (alpha >= 0.2) to ~1e-3 relative.
  std::vector<double> pdf_bands =
      band_integrals([&](float3 wi) { return double(bsdf_pdf(&m, wo, wi)); }, nb, 4000, 720);
  std::vector<double> alb_bands = band_integrals(
      [&](float3 wi) { return double(bsdf_eval(&m, wo, wi).x) * std::fabs(wi.z); }, nb, 4000, 720);
  double albedo_quad = 0, pdf_total = 0;
  for (int b = 0; b < nb; ++b) {
    albedo_quad += alb_bands[b];
    pdf_total += pdf_bands[b];
  }
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const int n = 400000;
  std::vector<int> counts(nb, 0);
  double sum = 0, sum2 = 0;
  int valid = 0;
  for (int i = 0; i < n; ++i) {
    BsdfSample s = bsdf_sample(&m, wo, make_float3(uni(rng), uni(rng), uni(rng)));
    ASSERT_TRUE(std::isfinite(s.weight.x) && std::isfinite(s.pdf));
    ASSERT_EQ(s.is_delta, 0);
    double w = s.weight.x;
    sum += w;
    sum2 += w * w;
    if (!(s.pdf > 0)) {
      ASSERT_EQ(s.weight.x, 0.0f);
      continue;
    }
    ++valid;
    int b = std::min(nb - 1, int((double(s.wi.z) + 1) / 2 * nb));
    ++counts[b];
    if (i % 97 == 0) { // pdf and weight are the functions' values at the sampled direction
      float p = bsdf_pdf(&m, wo, s.wi);
      EXPECT_NEAR(s.pdf, p, 1e-4f * p);
      float f = bsdf_eval(&m, wo, s.wi).x;
      EXPECT_NEAR(s.weight.x, f * std::fabs(s.wi.z) / p, 1e-4f * s.weight.x + 1e-7f);
    }
  }
  // The pdf integrates to the share of samples that are not absorbed (directions on the wrong
  // side of their microfacet, total internal reflection of a refraction pick).
  EXPECT_NEAR(pdf_total, double(valid) / n, 3e-3);
  EXPECT_LE(pdf_total, 1.0 + 2e-3);
  for (int b = 0; b < nb; ++b) {
    double p = pdf_bands[b];
    double se = std::sqrt(std::max(p * (1 - p), 1e-6) / n);
    EXPECT_NEAR(double(counts[b]) / n, p, 5 * se + 2e-3 * p) << "band " << b;
  }
  double mean = sum / n, var = sum2 / n - mean * mean;
  double se = std::sqrt(var / n);
  EXPECT_NEAR(mean, albedo_quad, 5 * se + 2e-3 * albedo_quad)
      << "eta " << c.eta << " alpha " << c.alpha << " theta " << c.theta;
}

INSTANTIATE_TEST_SUITE_P(Cases, RoughDielectric,
                         ::testing::Values(Case{1.5f, 0.3f, 0.0f}, Case{1.5f, 0.3f, 60.0f},
                                           Case{1.5f, 0.6f, 80.0f}, Case{1.33f, 0.2f, 40.0f},
                                           Case{1 / 1.5f, 0.3f, 20.0f},
                                           Case{1 / 1.5f, 0.4f, 70.0f}));

// Veach's generalised reciprocity for radiance transport: f(wo, wi) / eta_o^2 = f(wi, wo) /
// eta_i^2. Seen from wi's side the frame flips and the index inverts: f(wi, wo) is the material
// of index 1 / eta at (-wi, -wo). Reflection is symmetric.
TEST(RoughDielectricReciprocity, GeneralisedForRadiance) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (float eta : {1.5f, 1.0f / 1.33f}) {
    Material m = make_dielectric(eta, false, 0.25f), inv = make_dielectric(1 / eta, false, 0.25f);
    int compared = 0;
    for (int i = 0; i < 2000; ++i) {
      float3 wo = dir_mu(0.02 + 0.98 * uni(rng), 6.2831853 * uni(rng));
      float3 wi = dir_mu(-1 + 2 * uni(rng), 6.2831853 * uni(rng));
      if (std::fabs(wi.z) < 0.02f) continue;
      // Skip pairs whose microfacet sees a direction within ~3 deg of grazing: 1 - F has an
      // infinite slope at the critical angle, so a float rounding of that cosine dominates f.
      double hx = wo.x + (wi.z < 0 ? eta : 1.0) * wi.x, hy = wo.y + (wi.z < 0 ? eta : 1.0) * wi.y,
             hz = wo.z + (wi.z < 0 ? eta : 1.0) * wi.z, hl = std::sqrt(hx * hx + hy * hy + hz * hz);
      if (std::fabs(hx * wi.x + hy * wi.y + hz * wi.z) < 0.05 * hl ||
          std::fabs(hx * wo.x + hy * wo.y + hz * wo.z) < 0.05 * hl)
        continue;
      float f = bsdf_eval(&m, wo, wi).x;
      float g = wi.z > 0 ? bsdf_eval(&m, wi, wo).x
                         : bsdf_eval(&inv, -wi, -wo).x / (eta * eta); // eta_i^2 / eta_o^2
      EXPECT_NEAR(f, g, 2e-4f * std::max(f, g) + 1e-9f)
          << "eta " << eta << " wo.z " << wo.z << " wi.z " << wi.z;
      compared += f > 0;
    }
    EXPECT_GT(compared, 1000);
  }
}

// As alpha -> 0 the microfacets all face the normal: reflected share = Fresnel (alpha = 1e-4),
// and (at alpha = 1e-6, where GGX's heavy tail puts hardly any microfacet normal beyond 1e-3 rad
// of the normal in 1e5 samples) reflection in the mirror direction, refraction by Snell's law,
// weights those of the smooth interface.
TEST(RoughDielectricLimit, NearSmoothIsFresnelAndSnell) {
  for (float alpha : {1e-4f, 1e-6f})
    for (float eta : {1.5f, 1 / 1.5f})
      for (double theta : {0.0, 30.0, 60.0, 85.0}) {
        Material m = make_dielectric(eta, false, alpha);
        float3 wo = direction_at(theta, 1.1);
        std::mt19937 rng(11);
        std::uniform_real_distribution<float> uni(0.0f, 1.0f);
        const int n = 100000;
        int refl = 0, valid = 0;
        double sin_o = std::sin(theta * M_PI / 180);
        const bool geometry = alpha < 1e-5f;
        for (int i = 0; i < n; ++i) {
          BsdfSample s = bsdf_sample(&m, wo, make_float3(uni(rng), uni(rng), uni(rng)));
          if (!(max3(s.weight) > 0)) continue;
          ++valid;
          refl += s.wi.z > 0;
          if (!geometry) continue;
          if (s.wi.z > 0) {
            EXPECT_NEAR(s.wi.z, wo.z, 1e-3f);
            EXPECT_NEAR(s.weight.x, 1.0f, 2e-3f);
          } else {
            EXPECT_NEAR(std::hypot(double(s.wi.x), double(s.wi.y)), sin_o / eta, 1e-3);
            EXPECT_NEAR(s.weight.x, 1 / (eta * eta), 2e-3f / (eta * eta));
          }
        }
        double R = ref_fresnel(std::cos(theta * M_PI / 180), eta);
        double share = double(refl) / valid;
        EXPECT_GT(valid, n * 0.999);
        EXPECT_NEAR(share, R, 5 * std::sqrt(std::max(R * (1 - R), 1e-6) / valid) + 1e-3)
            << "alpha " << alpha << " eta " << eta << " theta " << theta;
      }
}

TEST(RoughDielectricEdges, SmoothLobeAndFiniteEverywhere) {
  const Material rough = make_dielectric(1.5f, false, 0.1f),
                 smooth = make_dielectric(1.5f, false, 0.0f),
                 matched = make_dielectric(1.0f, false, 0.1f); // index 1: passes straight on
  EXPECT_EQ(bsdf_has_smooth_lobe(&rough), 1);
  EXPECT_EQ(bsdf_has_smooth_lobe(&smooth), 0);
  EXPECT_EQ(bsdf_has_smooth_lobe(&matched), 0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (float alpha : {1e-7f, 1e-4f, 0.1f, 1.0f})
    for (float eta : {1.5f, 1 / 1.5f, 1.0001f}) {
      Material m = make_dielectric(eta, false, alpha);
      for (double theta : {0.0, 45.0, 89.9, 89.999, 90.0}) {
        float3 wo = direction_at(theta, 0.7);
        for (int i = 0; i < 2000; ++i) {
          BsdfSample s = bsdf_sample(&m, wo, make_float3(uni(rng), uni(rng), uni(rng)));
          ASSERT_TRUE(std::isfinite(s.weight.x) && std::isfinite(s.pdf) && s.pdf >= 0);
          float3 wi = dir_mu(-1 + 2 * uni(rng), 6.2831853 * uni(rng));
          if (i % 7 == 0) wi = make_float3(wo.y, -wo.x, 0.0f);
          float f = bsdf_eval(&m, wo, wi).x, p = bsdf_pdf(&m, wo, wi);
          ASSERT_TRUE(std::isfinite(f) && f >= 0 && std::isfinite(p) && p >= 0)
              << alpha << " " << eta << " " << theta;
        }
      }
    }
}

} // namespace
