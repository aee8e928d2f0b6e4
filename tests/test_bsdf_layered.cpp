// The coated materials (cl/bsdf/layered.h) on the host, against closed forms written here:
// - a smooth coat of index eta over a Lambertian base of reflectance rho, no absorption between:
//   light refracts in, bounces between base and coat, refracts out (e.g. Kelemen &
//   Szirmay-Kalos 2001, the "Fresnel-weighted" diffuse under a smooth coat):
//     f(wo, wi) = (1 - F(o)) (1 - F(i)) rho / (pi eta^2 (1 - rho r_i)),
//     albedo(o) = F(o) + (1 - F(o)) rho (1 - r_i) / (1 - rho r_i),
//   with r_e = int_0^1 F(mu) 2 mu dmu the coat's hemispherical reflectance from outside and
//   r_i = 1 - (1 - r_e) / eta^2 from inside (quadrature in double);
// - white furnace: rho = 1, nothing absorbed: albedo 1 at every angle for a smooth coat, also with
//   a scattering medium between coat and base. A rough coat loses what single-scattering
//   microfacets lose (no light scatters twice between microfacets: Heitz et al. 2016); at alpha
//   0.1 that is up to ~10% here, mostly at the coat's inner face, which light inside meets at
//   grazing angles, so there albedo lies in [0.85, 1];
// - eval integrates to what sampling reflects (with a scattering slab, smooth and rough coat), and
//   per bin of directions;
// - a smooth coat over a smooth conductor: two interfaces and every inter-reflection at the
//   refracted angle t, with transmittance T = exp(-thickness / cos t) per crossing:
//     R = F + (1 - F)^2 Rc T^2 / (1 - F Rc T^2)  (F(o) = F inside at t: Fresnel is symmetric);
// - eval and pdf are finite, non-negative and deterministic everywhere; a sample's pdf is
//   bsdf_pdf at its direction; nothing below the horizon.
// Stochastic estimates are compared within 5 standard errors of their own sample variance.
#include "bsdf/bsdf.h"
#include "support/fresnel_reference.h"
#include "support/materials.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>
#include <vector>

using namespace canopy;
using namespace canopy::test;

namespace {

// A conductor of complex relative index n = eta + i k (Born & Wolf §14.2), complex arithmetic.
double ref_fresnel_conductor(double cos_i, double eta, double k) {
  std::complex<double> n(eta, k);
  double sin2 = 1 - cos_i * cos_i;
  std::complex<double> cos_t = std::sqrt(1.0 - sin2 / (n * n));
  std::complex<double> rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
  std::complex<double> rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
  return 0.5 * (std::norm(rs) + std::norm(rp));
}

// r_e = int_0^1 F(mu) 2 mu dmu (midpoint rule; F is smooth, 1e5 points are exact to ~1e-10).
double external_diffuse_reflectance(double eta) {
  const int n = 100000;
  double s = 0;
  for (int i = 0; i < n; ++i) {
    double mu = (i + 0.5) / n;
    s += ref_fresnel(mu, eta) * 2 * mu;
  }
  return s / n;
}

float3 dir_mu(double mu, double phi) {
  double s = std::sqrt(std::max(0.0, 1 - mu * mu));
  return make_float3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(mu));
}

struct Mean {
  double sum = 0, sum2 = 0;
  long n = 0;
  void add(double x) {
    sum += x;
    sum2 += x * x;
    ++n;
  }
  double mean() const { return sum / n; }
  double se() const { return std::sqrt(std::max(0.0, sum2 / n - mean() * mean()) / n); }
};

// Mean sample weight (channel x) at wo.
Mean sample_albedo(const Material& m, float3 wo, int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  Mean a;
  for (int i = 0; i < n; ++i) {
    BsdfSample s = bsdf_sample(&m, wo, make_float3(uni(rng), uni(rng), uni(rng)));
    EXPECT_TRUE(std::isfinite(s.weight.x) && s.weight.x >= 0 && std::isfinite(s.pdf));
    if (max3(s.weight) > 0) {
      EXPECT_GT(s.wi.z, 0.0f);
    }
    a.add(s.weight.x);
  }
  return a;
}

const Layer kClear{0.0f, {0, 0, 0}, 0.0f, 100, 1}; // nothing between coat and base

TEST(LayeredCoatedDiffuse, SmoothCoatEvalMatchesClosedForm) {
  for (double eta : {1.5, 1.33}) {
    const double rho = 0.7;
    const double ri = 1 - (1 - external_diffuse_reflectance(eta)) / (eta * eta);
    Material m = make_coated_diffuse(make_float3(float(rho), float(rho), float(rho)), float(eta),
                                     0.0f, kClear);
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    Mean ratio;
    for (int i = 0; i < 40000; ++i) {
      double mo = 0.05 + 0.95 * uni(rng), mi = 0.05 + 0.95 * uni(rng);
      float3 wo = dir_mu(mo, 6.283185 * uni(rng)), wi = dir_mu(mi, 6.283185 * uni(rng));
      double closed = (1 - ref_fresnel(wo.z, eta)) * (1 - ref_fresnel(wi.z, eta)) * rho /
                      (M_PI * eta * eta * (1 - rho * ri));
      float3 f = bsdf_eval(&m, wo, wi);
      ASSERT_TRUE(std::isfinite(f.x) && f.x >= 0);
      ratio.add(f.x / closed);
    }
    EXPECT_NEAR(ratio.mean(), 1.0, 5 * ratio.se() + 1e-4) << "eta " << eta;
  }
}

TEST(LayeredCoatedDiffuse, SmoothCoatAlbedoMatchesClosedForm) {
  const double eta = 1.5, rho = 0.6;
  const double ri = 1 - (1 - external_diffuse_reflectance(eta)) / (eta * eta);
  Material m = make_coated_diffuse(make_float3(float(rho), 0.3f, 0.1f), float(eta), 0.0f, kClear);
  for (double mu : {1.0, 0.7, 0.3, 0.08}) {
    float3 wo = dir_mu(mu, 0.3);
    double F = ref_fresnel(wo.z, eta);
    double closed = F + (1 - F) * rho * (1 - ri) / (1 - rho * ri);
    Mean a = sample_albedo(m, wo, 200000, 7);
    EXPECT_NEAR(a.mean(), closed, 5 * a.se()) << "cos " << mu;
  }
}

TEST(LayeredCoatedDiffuse, WhiteFurnace) {
  struct C {
    float alpha;
    Layer layer;
    double min_albedo; // single-scattering microfacets lose a little energy (rough coat)
  };
  const C cases[] = {{0.0f, kClear, 1.0},
                     {0.0f, {0.5f, {1, 1, 1}, 0.3f, 200, 1}, 1.0},  // scattering slab
                     {0.0f, {0.5f, {1, 1, 1}, -0.6f, 200, 1}, 1.0}, // backward scattering
                     {0.1f, kClear, 0.85}};
  for (const C& c : cases) {
    Material m = make_coated_diffuse(make_float3(1, 1, 1), 1.5f, c.alpha, c.layer);
    for (double mu : {1.0, 0.5, 0.2}) {
      Mean a = sample_albedo(m, dir_mu(mu, 1.0), 100000, 9);
      std::string what = "alpha " + std::to_string(c.alpha) + " cos " + std::to_string(mu) + " g " +
                         std::to_string(c.layer.g);
      EXPECT_LE(a.mean(), 1.0 + 5 * a.se()) << what;
      if (c.min_albedo == 1.0) {
        EXPECT_NEAR(a.mean(), 1.0, 5 * a.se() + 1e-6) << what; // (float sums of exact 1s)
      } else {
        EXPECT_GE(a.mean(), c.min_albedo) << what;
      }
    }
  }
}

// f integrates (with the coat's mirror reflection F, which eval excludes) to the albedo the
// sampling gives: eval and sample describe the same BSDF (a scattering slab under a smooth and a
// rough coat; a conductor base, rough or smooth, under a rough or smooth coat).
TEST(LayeredEval, IntegratesToSampledAlbedo) {
  const Layer slab{0.3f, {0.8f, 0.8f, 0.8f}, 0.5f, 100, 1};
  const float3 ce = make_float3(0.2f, 0.2f, 0.2f), ck = make_float3(3, 3, 3);
  const Material cases[] = {make_coated_diffuse(make_float3(0.5f, 0.5f, 0.5f), 1.5f, 0.0f, slab),
                            make_coated_diffuse(make_float3(0.5f, 0.5f, 0.5f), 1.5f, 0.3f, slab),
                            make_coated_conductor(1.5f, 0.3f, ce, ck, 0.2f, kClear),
                            make_coated_conductor(1.5f, 0.0f, ce, ck, 0.3f, kClear),
                            make_coated_conductor(1.5f, 0.3f, ce, ck, 0.0f, kClear)};
  for (const Material& m : cases) {
    float3 wo = dir_mu(0.6, 0.2);
    std::mt19937 rng(31);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    Mean integral; // f cos / (cos / pi) over cosine-distributed wi
    for (int i = 0; i < 200000; ++i) {
      float r = std::sqrt(uni(rng)), phi = 6.2831853f * uni(rng);
      float3 wi = make_float3(r * std::cos(phi), r * std::sin(phi), std::sqrt(1 - r * r));
      integral.add(M_PI * bsdf_eval(&m, wo, wi).x);
    }
    double specular = m.alpha == 0.0f ? ref_fresnel(wo.z, 1.5) : 0.0;
    Mean a = sample_albedo(m, wo, 200000, 13);
    double se = std::hypot(integral.se(), a.se());
    EXPECT_NEAR(integral.mean() + specular, a.mean(), 5 * se)
        << "type " << m.type << " alpha " << m.alpha << " base " << m.base_alpha;
  }
}

// Per direction too: in each of 8 x 8 bins of (cos theta_i, phi_i), the sampled weight that lands
// there (E[weight 1{wi in bin}]) equals the integral of f cos over the bin (stratified Monte Carlo
// of eval), within 5 joint standard errors. Rough coats, so nothing is delta.
TEST(LayeredEval, MatchesSamplingPerDirection) {
  const Material cases[] = {make_coated_diffuse(make_float3(0.6f, 0.6f, 0.6f), 1.5f, 0.2f,
                                                {0.2f, {0.7f, 0.7f, 0.7f}, 0.4f, 50, 1}),
                            make_coated_conductor(1.5f, 0.15f, make_float3(0.2f, 0.2f, 0.2f),
                                                  make_float3(3, 3, 3), 0.25f, kClear)};
  const int nb = 8, n_samples = 400000, n_eval = 4000;
  for (const Material& m : cases) {
    const float3 wo = dir_mu(0.5, 0.0);
    std::mt19937 rng(41);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    std::vector<double> sum(nb * nb, 0.0), sum2(nb * nb, 0.0);
    for (int i = 0; i < n_samples; ++i) {
      BsdfSample s = bsdf_sample(&m, wo, make_float3(uni(rng), uni(rng), uni(rng)));
      ASSERT_EQ(s.is_delta, 0);
      if (!(s.weight.x > 0)) continue;
      double phi = std::atan2(double(s.wi.y), double(s.wi.x));
      if (phi < 0) phi += 2 * M_PI;
      int b =
          std::min(nb - 1, int(s.wi.z * nb)) * nb + std::min(nb - 1, int(phi / (2 * M_PI) * nb));
      sum[b] += s.weight.x;
      sum2[b] += double(s.weight.x) * s.weight.x;
    }
    for (int bm = 0; bm < nb; ++bm)
      for (int bp = 0; bp < nb; ++bp) {
        const int b = bm * nb + bp;
        double mean_s = sum[b] / n_samples;
        double var_s = (sum2[b] / n_samples - mean_s * mean_s) / n_samples;
        Mean e; // f cos over the bin, area 2 pi / nb^2 in (mu, phi)
        const double area = 2 * M_PI / (nb * nb);
        for (int k = 0; k < n_eval; ++k) {
          double mu = (bm + uni(rng)) / nb, phi = 2 * M_PI * (bp + uni(rng)) / nb;
          float3 wi = dir_mu(mu, phi);
          e.add(area * bsdf_eval(&m, wo, wi).x * wi.z);
        }
        double se = std::sqrt(std::max(0.0, var_s) + e.se() * e.se());
        EXPECT_NEAR(mean_s, e.mean(), 5 * se + 1e-5)
            << "type " << m.type << " bin mu " << bm << " phi " << bp;
      }
  }
}

TEST(LayeredCoatedConductor, SmoothOverSmoothMatchesTwoInterfaces) {
  const double eta = 1.5;
  const double ce = 0.2, ck = 3.0; // conductor index in vacuum; relative: divided by eta
  for (float thickness : {0.0f, 0.2f}) {
    Layer l = kClear;
    l.thickness = thickness;
    Material m = make_coated_conductor(float(eta), 0.0f, make_float3(float(ce), 1, 1),
                                       make_float3(float(ck), 1, 1), 0.0f, l);
    EXPECT_EQ(bsdf_has_smooth_lobe(&m), 0);
    for (double mu : {1.0, 0.6, 0.2}) {
      float3 wo = dir_mu(mu, 0.5);
      double F = ref_fresnel(mu, eta);
      double cos_t = std::sqrt(1 - (1 - mu * mu) / (eta * eta));
      double Rc = ref_fresnel_conductor(cos_t, ce / eta, ck / eta);
      double T2 = thickness > 0 ? std::exp(-2 * thickness / cos_t) : 1.0;
      double closed = F + (1 - F) * (1 - F) * Rc * T2 / (1 - F * Rc * T2);
      std::mt19937 rng(3);
      std::uniform_real_distribution<float> uni(0.0f, 1.0f);
      Mean a;
      for (int i = 0; i < 100000; ++i) {
        BsdfSample s = bsdf_sample(&m, wo, make_float3(uni(rng), uni(rng), uni(rng)));
        if (max3(s.weight) > 0) { // every path is specular: the mirror direction
          ASSERT_EQ(s.is_delta, 1);
          ASSERT_NEAR(s.wi.z, wo.z, 1e-5f);
          ASSERT_NEAR(s.wi.x, -wo.x, 1e-5f);
        }
        a.add(s.weight.x);
      }
      EXPECT_NEAR(a.mean(), closed, 5 * a.se() + 1e-5)
          << "cos " << mu << " thickness " << thickness;
    }
  }
}

// A rough conductor base under a rough coat: a glossy lobe; energy bounded by the furnace.
TEST(LayeredCoatedConductor, RoughIsGlossyAndBounded) {
  Material m = make_coated_conductor(1.5f, 0.2f, make_float3(0.2f, 0.2f, 0.2f),
                                     make_float3(3, 3, 3), 0.3f, kClear);
  EXPECT_EQ(bsdf_has_smooth_lobe(&m), 1);
  Mean a = sample_albedo(m, dir_mu(0.7, 0.1), 100000, 5);
  EXPECT_LE(a.mean(), 1.0 + 5 * a.se());
  EXPECT_GT(a.mean(), 0.5);
}

std::vector<Material> edge_materials() {
  std::vector<Material> v;
  for (float alpha : {0.0f, 1e-4f, 0.3f, 1.0f}) {
    v.push_back(make_coated_diffuse(make_float3(0, 0, 0), 1.5f, alpha));
    v.push_back(
        make_coated_diffuse(make_float3(1, 1, 1), 1.5f, alpha, {0.0f, {1, 1, 1}, 0.9f, 10, 2}));
    v.push_back(make_coated_diffuse(make_float3(0.5f, 0.5f, 0.5f), 1.0f, alpha,
                                    {2.0f, {0.5f, 0.5f, 0.5f}, -0.99f, 10, 1}));
    for (float base : {0.0f, 0.05f, 1.0f})
      v.push_back(make_coated_conductor(1.5f, alpha, make_float3(0.2f, 1, 1.5f),
                                        make_float3(3, 2, 0), base));
  }
  return v;
}

TEST(LayeredEdges, FiniteDeterministicAndAboveTheHorizon) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  for (const Material& m : edge_materials())
    for (double mu : {1.0, 0.5, 1e-3, 1e-6, 0.0}) {
      float3 wo = dir_mu(mu, 0.9);
      for (int i = 0; i < 300; ++i) {
        float3 wi = dir_mu(-1 + 2 * uni(rng), 6.2831853 * uni(rng));
        if (i % 5 == 0) wi = make_float3(-wo.x, -wo.y, wo.z);
        if (i % 5 == 1) wi = make_float3(wo.y, -wo.x, 0.0f);
        float3 f = bsdf_eval(&m, wo, wi);
        float p = bsdf_pdf(&m, wo, wi);
        ASSERT_TRUE(std::isfinite(f.x + f.y + f.z) && std::isfinite(p)) << m.type << " " << mu;
        ASSERT_TRUE(f.x >= 0 && f.y >= 0 && f.z >= 0 && p >= 0);
        if (!(wi.z > 0) || !(wo.z > 0)) {
          ASSERT_TRUE(f.x == 0 && p == 0);
        }
        float3 f2 = bsdf_eval(&m, wo, wi);
        ASSERT_EQ(f.x, f2.x); // a pure function of (wo, wi)
        ASSERT_EQ(p, bsdf_pdf(&m, wo, wi));
        BsdfSample s = bsdf_sample(&m, wo, make_float3(uni(rng), uni(rng), uni(rng)));
        ASSERT_TRUE(std::isfinite(s.weight.x + s.weight.y + s.weight.z) && std::isfinite(s.pdf));
        if (max3(s.weight) > 0) {
          ASSERT_GT(s.wi.z, 0.0f);
          if (!s.is_delta) {
            ASSERT_EQ(s.pdf, bsdf_pdf(&m, wo, s.wi));
          }
        }
      }
    }
}

} // namespace
