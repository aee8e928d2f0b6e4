// The BSDFs of cl/bsdf/ on the host: for every material over a grid of roughness and incident
// angle, the sampled directions follow bsdf_pdf (chi-square), the pdf integrates to 1 minus the
// absorbed fraction, every sample's pdf and weight agree with bsdf_pdf and bsdf_eval; reciprocity;
// a white furnace against an independent integral; Fresnel against complex arithmetic; no NaN/Inf.
//
// How the chi-square bins (after pbrt-v4's bsdfs_test.cpp and Mitsuba's chi2 test, adapted to
// lobes narrower than a float can resolve): a reflected direction wi and its half vector
// h = normalize(wo + wi) determine each other, so directions are binned by h in the "stretched"
// polar grid of a GGX distribution of width a_bin: ring u = tan^2(theta_h) / (a_bin^2 +
// tan^2(theta_h)) in 16 equal steps (the CDF of GGX normals, so each ring holds a similar share of
// a lobe of width a_bin), the innermost ring one cap, the others split into 24 azimuth bins of
// phi_h. The expected share of a bin is the integral of pdf(wo, wi(h)) |d wi / d h| = 4 (wo.h) over
// it, computed by adaptive Simpson in theta_h with Gauss-Legendre in phi_h, split exactly where
// wi crosses the horizon. One more category counts absorbed samples (weight 0), expected
// 1 - (integral of the pdf); a delta lobe's samples get their own category, expected p(delta).
//
// Which cases are tested how: a lobe is resolvable when alpha >= 64 eps / cos(theta_o), eps = 2^-24
// (the float spacing of a direction's components, amplified by 1 / (wo.h) when the half vector is
// recovered from wo + wi). Resolvable lobes are binned at a_bin = alpha and compared with the
// float bsdf_pdf. Below that (roughness 0.001 everywhere, 0.01 at 89.9 deg) neither the sampled
// directions nor the float pdf resolve the lobe's shape, so the bins are a_bin = 64 eps / cos and
// the expected counts come from an independent double-precision pdf (ref_* below): the test
// then checks that the sampler puts the right mass inside the lobe's cap and the right tail outside
// it, and the float pdf is checked against the reference where it is resolvable. The same samples
// are also binned at a_bin = 1 for plastic (the diffuse lobe's scale) and, for broad lobes
// (roughness >= 0.3, diffuse), on pbrt-v4's plain (cos theta_i, phi_i) grid, which needs no
// half-vector mapping. Each chi-square test passes when its p-value is above 0.01 / kChi2Tests
// (Bonferroni over all of them). 10^5 samples per case.
#include "bsdf/bsdf.h"
#include "support/gamma_q.h"
#include "support/materials.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

using namespace canopy::test;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kChi2Tests = 320; // an upper bound on the chi-square tests in this file
constexpr double kSignificance = 0.01 / kChi2Tests;
constexpr int kSamples = 100000;
constexpr double kFloatEps = 5.9604645e-8; // 2^-24
constexpr double kQuadratureTol = 1e-4;    // absolute error of a pdf integral over the sphere

const float kRoughness[] = {0.001f, 0.01f, 0.1f, 0.3f, 1.0f};
const float kAnglesDeg[] = {0.0f, 30.0f, 60.0f, 80.0f, 89.9f};

// ---------------------------------------------------------------- materials
// Gold-like (eta, k at ~650/550/450 nm, Johnson & Christy 1972 rounded), and F == 1 (eta = 0).
Material gold(float alpha) {
  return make_conductor(make_float3(0.18f, 0.42f, 1.37f), make_float3(3.42f, 2.35f, 1.77f), alpha);
}
Material white_conductor(float alpha) {
  return make_conductor(make_float3(0, 0, 0), make_float3(1, 1, 1), alpha);
}
struct NamedMaterial {
  std::string name;
  std::function<Material(float)> make; // alpha -> material
};
std::vector<NamedMaterial> glossy_materials() {
  return {
      {"gold", gold},
      {"conductor F=1", white_conductor},
      {"plastic red ior1.5",
       [](float a) {
         return make_plastic(make_float3(0.8f, 0.1f, 0.1f), make_float3(1, 1, 1), 1.5f, a);
       }},
      {"plastic dark ior2.2",
       [](float a) {
         return make_plastic(make_float3(0.05f, 0.05f, 0.05f), make_float3(0.5f, 0.7f, 1.0f), 2.2f,
                             a);
       }},
      {"plastic white ior1.33",
       [](float a) {
         return make_plastic(make_float3(0.9f, 0.9f, 0.9f), make_float3(1, 1, 1), 1.33f, a);
       }},
  };
}

float3 wo_at(float theta_deg) {
  double t = theta_deg * kPi / 180.0, phi = 0.7; // off the x axis: no grid alignment
  return make_float3(float(std::sin(t) * std::cos(phi)), float(std::sin(t) * std::sin(phi)),
                     float(std::cos(t)));
}

// Uniform floats in [0, 1) with 24 random bits.
struct Uniform {
  std::mt19937 rng;
  explicit Uniform(uint32_t seed) : rng(seed) {}
  float operator()() { return float(rng() >> 8) * 5.9604645e-8f; }
  float3 u3() {
    float a = (*this)(), b = (*this)(), c = (*this)();
    return make_float3(a, b, c);
  }
};

bool finite3(float3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// ---------------------------------------------------------------- double-precision references
// Written from the textbook formulas independently of cl/bsdf/ (tan-based Lambda, complex Fresnel).
struct D3 {
  double x, y, z;
};
D3 d3(float3 v) {
  return {v.x, v.y, v.z};
}
double ddot(D3 a, D3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
D3 dnormalize(D3 a) {
  double l = std::sqrt(ddot(a, a));
  return {a.x / l, a.y / l, a.z / l};
}
double ref_D(D3 h, double a) {
  if (h.z <= 0) return 0;
  double c2 = h.z * h.z, tan2 = (h.x * h.x + h.y * h.y) / c2;
  double t = 1 + tan2 / (a * a);
  return 1 / (kPi * a * a * c2 * c2 * t * t);
}
double ref_lambda(D3 w, double a) {
  double tan2 = (w.x * w.x + w.y * w.y) / (w.z * w.z);
  return (std::sqrt(1 + a * a * tan2) - 1) / 2;
}
double ref_glossy_pdf(D3 wo, D3 wi, double a) {
  if (wi.z <= 0 || wo.z <= 0) return 0;
  D3 h = dnormalize({wo.x + wi.x, wo.y + wi.y, wo.z + wi.z});
  double woh = ddot(wo, h);
  if (woh <= 0) return 0;
  double g1 = 1 / (1 + ref_lambda(wo, a));
  return g1 * woh * ref_D(h, a) / wo.z / (4 * woh);
}
double ref_fresnel(double cos_i, double eta, double k) {
  std::complex<double> n(eta, k);
  double sin2 = std::max(0.0, 1 - cos_i * cos_i);
  std::complex<double> cos_t = std::sqrt(1.0 - sin2 / (n * n));
  std::complex<double> rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
  std::complex<double> rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
  return 0.5 * (std::norm(rs) + std::norm(rp));
}
// The reference pdf of the whole material (the plastic's lobe probability is the implementation's
// design choice: taken from it).
double ref_pdf(const Material& m, float3 wo_f, D3 wi) {
  D3 wo = d3(wo_f);
  if (wi.z <= 0) return 0;
  if (m.type == MATERIAL_DIFFUSE) return wi.z / kPi;
  if (m.type == MATERIAL_CONDUCTOR) return m.alpha > 0 ? ref_glossy_pdf(wo, wi, m.alpha) : 0.0;
  double ps = plastic_coat_prob(&m, wo_f);
  double p = (1 - ps) * wi.z / kPi;
  if (m.alpha > 0) p += ps * ref_glossy_pdf(wo, wi, m.alpha);
  return p;
}

// ---------------------------------------------------------------- quadrature
// 12-point Gauss-Legendre on [a, b].
double gauss12(const std::function<double(double)>& f, double a, double b) {
  static const double x[6] = {0.1252334085114689, 0.3678314989981802, 0.5873179542866175,
                              0.7699026741943047, 0.9041172563704749, 0.9815606342467192};
  static const double w[6] = {0.2491470458134028, 0.2334925365383548, 0.2031674267230659,
                              0.1600783285433462, 0.1069393259953184, 0.0471753363865118};
  double c = 0.5 * (a + b), r = 0.5 * (b - a), s = 0;
  for (int i = 0; i < 6; ++i)
    s += w[i] * (f(c - r * x[i]) + f(c + r * x[i]));
  return s * r;
}

// The integral over theta in [a, b] by composite 12-point Gauss-Legendre (fixed nodes: the float
// pdf is slightly noisy at the float resolution, which an adaptive rule would chase forever).
// Breakpoints: quarters of [a, b], plus points doubling away from a (a GGX tail decays on the scale
// of a) or, from a = 0 (the cap, where a lobe of width ~`scale` may sit), halving towards 0 down
// to scale / 100.
double integrate_theta(const std::function<double(double)>& f, double a, double b, double scale) {
  std::vector<double> x = {a, b};
  for (int i = 1; i < 4; ++i)
    x.push_back(a + (b - a) * i / 4);
  if (a == 0) {
    for (double t = 0.5 * b; t > std::min(b, scale) * 1e-2; t *= 0.5)
      x.push_back(t);
  } else {
    for (double t = 2 * a; t < b; t *= 2)
      x.push_back(t);
  }
  std::sort(x.begin(), x.end());
  double s = 0;
  for (size_t i = 0; i + 1 < x.size(); ++i)
    s += gauss12(f, x[i], x[i + 1]);
  return s;
}

// Half vector at polar (theta, phi) and the reflected direction wi.
D3 h_at(double theta, double phi) {
  double s = std::sin(theta);
  return {s * std::cos(phi), s * std::sin(phi), std::cos(theta)};
}

// The azimuths phi (in [pa, pb]) where the reflection of wo about h(theta, phi) is above the
// horizon: wi.z = 2 (wo.h) h.z - wo.z > 0 <=> cos(phi - phi_o) > -cos(2 theta) wo.z /
// (sin(2 theta) |wo.xy|); returned as up to 3 disjoint intervals.
std::vector<std::pair<double, double>> valid_phi(D3 wo, double theta, double pa, double pb) {
  std::vector<std::pair<double, double>> out;
  double so = std::sqrt(wo.x * wo.x + wo.y * wo.y), s2 = std::sin(2 * theta),
         c2 = std::cos(2 * theta);
  double den = so * s2;
  if (!(den > 1e-300)) {
    if (c2 > 0) out.push_back({pa, pb});
    return out;
  }
  double kappa = -c2 * wo.z / den;
  if (kappa <= -1) {
    out.push_back({pa, pb});
    return out;
  }
  if (kappa >= 1) return out;
  double d = std::acos(kappa), phio = std::atan2(wo.y, wo.x);
  for (int k = -2; k <= 2; ++k) {
    double lo = std::max(pa, phio - d + 2 * kPi * k), hi = std::min(pb, phio + d + 2 * kPi * k);
    if (hi > lo) out.push_back({lo, hi});
  }
  return out;
}

// ---------------------------------------------------------------- chi-square
using canopy::test::gamma_q;

struct Chi2Result {
  double chi2 = 0, p = 1;
  int dof = 0;
  std::string worst; // the category with the largest contribution
};
// Categories with expected count < 5 are pooled into one (pbrt-v4, Mitsuba); observations where
// the expected count is 0 make the test fail.
// `pool_floor` is the smallest expected count the pool may have: the absorbed share is known only
// as 1 - (integral of the pdf), to the quadrature's accuracy.
Chi2Result chi2_test(const std::vector<double>& observed, const std::vector<double>& expected,
                     double pool_floor) {
  Chi2Result r;
  double pool_o = 0, pool_e = 0, worst = -1;
  int cats = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] < 5) {
      pool_o += observed[i];
      pool_e += expected[i];
      continue;
    }
    double d = observed[i] - expected[i], c = d * d / expected[i];
    r.chi2 += c;
    ++cats;
    if (c > worst) {
      worst = c;
      r.worst = "bin " + std::to_string(i) + ": observed " + std::to_string(observed[i]) +
                " expected " + std::to_string(expected[i]);
    }
  }
  pool_e = std::max(pool_e, pool_floor);
  if (pool_e > 0) {
    double d = pool_o - pool_e, c = d * d / pool_e;
    r.chi2 += c;
    ++cats;
    if (c > worst)
      r.worst =
          "pooled: observed " + std::to_string(pool_o) + " expected " + std::to_string(pool_e);
  } else if (pool_o > 0) {
    r.p = 0;
    r.worst = "observations where the pdf is 0";
    return r;
  }
  r.dof = std::max(1, cats - 1);
  r.p = gamma_q(0.5 * r.dof, 0.5 * r.chi2);
  return r;
}

// ---------------------------------------------------------------- the binned test
constexpr int kRings = 16, kAzimuths = 24;
constexpr int kBins = 1 + (kRings - 1) * kAzimuths;

// a_bin > 0: the half-vector grid above. a_bin == 0: the plain grid of pbrt-v4's test over the
// reflected directions themselves, kWCos bins in cos(theta_i) over [0, 1] (the lower hemisphere
// holds no non-absorbed sample) by kWPhi bins in phi_i, used where the lobe is broad enough for a
// fixed quadrature (roughness >= 0.3, diffuse): it checks the sampler against the pdf without the
// half-vector mapping.
constexpr int kWCos = 10, kWPhi = 20;
static_assert(kWCos * kWPhi <= kBins);

struct HGrid {
  double a_bin;
  bool wi_space() const { return a_bin == 0; }
  // ring r spans u in [r, r + 1) / kRings; theta edge of u: tan^2 = a^2 u / (1 - u)
  double theta_edge(int r) const {
    if (r >= kRings) return 0.5 * kPi;
    double u = double(r) / kRings;
    return std::atan(a_bin * std::sqrt(u / (1 - u)));
  }
  int bin_of(D3 wi, D3 h) const {
    if (wi_space()) {
      int c = std::min(kWCos - 1, int(std::max(0.0, wi.z) * kWCos));
      double phi = std::atan2(wi.y, wi.x);
      if (phi < 0) phi += 2 * kPi;
      return c * kWPhi + std::min(kWPhi - 1, int(phi / (2 * kPi) * kWPhi));
    }
    double r2 = h.x * h.x + h.y * h.y;
    double u = r2 / (r2 + h.z * h.z * a_bin * a_bin);
    int ring = std::min(kRings - 1, int(u * kRings));
    if (ring == 0) return 0;
    double phi = std::atan2(h.y, h.x);
    if (phi < 0) phi += 2 * kPi;
    int az = std::min(kAzimuths - 1, int(phi / (2 * kPi) * kAzimuths));
    return 1 + (ring - 1) * kAzimuths + az;
  }
};

struct BinnedCase {
  std::string name;
  double chi2_p = 1;
  double integral = 0; // integral of the pdf over all bins
  double absorbed = 0; // fraction of samples with weight 0
  double delta = 0;    // fraction of delta samples
  double delta_expected = 0;
};

using PdfFn =
    std::function<double(float3 wo, D3 wi)>; // wi in double: no rounding noise for ref_pdf

// bsdf_pdf at wi rounded to float.
PdfFn float_pdf(const Material* m) {
  return [m](float3 wo, D3 wi) {
    return double(bsdf_pdf(m, wo, make_float3(float(wi.x), float(wi.y), float(wi.z))));
  };
}

// Expected probability of every bin: the integral of pdf(wo, wi(h)) 4 (wo.h) over the bin's
// half vectors.
std::vector<double> bin_probabilities(const HGrid& g, float3 wo_f, const PdfFn& pdf,
                                      double lobe_scale) {
  D3 wo = d3(wo_f);
  std::vector<double> prob(kBins, 0.0);
  if (g.wi_space()) {
    // Panels: quarters of each bin, plus breakpoints closing in on the mirror direction's
    // coordinates (where a lobe peaks) when it lies in the bin, and on the horizon.
    double c_r = wo.z, phi_r = std::atan2(-wo.y, -wo.x);
    if (phi_r < 0) phi_r += 2 * kPi;
    auto breaks = [](double a, double b, double peak) {
      std::vector<double> x = {a, b};
      for (int i = 1; i < 4; ++i)
        x.push_back(a + (b - a) * i / 4);
      if (a == 0) // towards the horizon, where a grazing lobe is squeezed
        for (double d = b / 8; d > b * 1e-5; d *= 0.5)
          x.push_back(d);
      if (peak > a && peak < b)
        for (double d = (b - a) / 8; d > (b - a) * 1e-5; d *= 0.5) {
          x.push_back(peak);
          if (peak - d > a) x.push_back(peak - d);
          if (peak + d < b) x.push_back(peak + d);
        }
      std::sort(x.begin(), x.end());
      x.erase(std::unique(x.begin(), x.end()), x.end());
      return x;
    };
    for (int c = 0; c < kWCos; ++c)
      for (int a = 0; a < kWPhi; ++a) {
        std::vector<double> cs = breaks(double(c) / kWCos, double(c + 1) / kWCos, c_r);
        std::vector<double> ps = breaks(2 * kPi * a / kWPhi, 2 * kPi * (a + 1) / kWPhi, phi_r);
        double sum = 0;
        for (size_t i = 0; i + 1 < cs.size(); ++i)
          sum += gauss12(
              [&](double z) {
                double sz = std::sqrt(std::max(0.0, 1 - z * z)), t = 0;
                for (size_t j = 0; j + 1 < ps.size(); ++j)
                  t += gauss12(
                      [&](double phi) {
                        return pdf(wo_f, {sz * std::cos(phi), sz * std::sin(phi), z});
                      },
                      ps[j], ps[j + 1]);
                return t;
              },
              cs[i], cs[i + 1]);
        prob[c * kWPhi + a] = sum;
      }
    return prob;
  }
  auto density = [&](double theta, double phi) {
    D3 h = h_at(theta, phi);
    double woh = ddot(wo, h);
    if (woh <= 0) return 0.0;
    D3 wi = {2 * woh * h.x - wo.x, 2 * woh * h.y - wo.y, 2 * woh * h.z - wo.z};
    if (wi.z <= 0) return 0.0;
    return pdf(wo_f, wi) * 4 * woh;
  };
  auto cell = [&](double t0, double t1, double p0, double p1) {
    auto over_phi = [&](double theta) {
      double s = 0;
      for (auto [lo, hi] : valid_phi(wo, theta, p0, p1))
        s += gauss12([&](double phi) { return density(theta, phi); }, lo, hi);
      return s * std::sin(theta);
    };
    return integrate_theta(over_phi, t0, t1, lobe_scale);
  };
  prob[0] = cell(0, g.theta_edge(1), 0, 2 * kPi);
  for (int r = 1; r < kRings; ++r)
    for (int a = 0; a < kAzimuths; ++a)
      prob[1 + (r - 1) * kAzimuths + a] =
          cell(g.theta_edge(r), g.theta_edge(r + 1), 2 * kPi * a / kAzimuths,
               2 * kPi * (a + 1) / kAzimuths);
  return prob;
}

// Samples the material from wo, checks every sample (finite, pdf == bsdf_pdf, weight ==
// eval cos / pdf, delta samples = mirror), and runs the chi-square against `pdf` on grid g.
// The same samples are binned on every grid of `grids`: one result per grid.
std::vector<BinnedCase> run_binned(const Material& m, float3 wo, const std::vector<HGrid>& grids,
                                   const PdfFn& pdf, double p_delta, uint32_t seed) {
  double lobe_scale = m.type == MATERIAL_DIFFUSE || !(m.alpha > 0) ? 1.0 : double(m.alpha);
  Uniform u(seed);
  // per grid: bins + absorbed + delta
  std::vector<std::vector<double>> observed(grids.size(), std::vector<double>(kBins + 2, 0.0));
  double absorbed = 0, delta = 0;
  int bad = 0;
  for (int i = 0; i < kSamples; ++i) {
    BsdfSample s = bsdf_sample(&m, wo, u.u3());
    bool ok = finite3(s.wi) && finite3(s.weight) && std::isfinite(s.pdf) && s.pdf >= 0 &&
              s.weight.x >= 0 && s.weight.y >= 0 && s.weight.z >= 0;
    if (s.is_delta) {
      ok = ok && s.pdf == 0 && s.wi.x == -wo.x && s.wi.y == -wo.y && s.wi.z == wo.z;
      delta += 1;
    } else if (s.pdf == 0) {
      ok = ok && s.weight.x == 0 && s.weight.y == 0 && s.weight.z == 0;
      absorbed += 1;
    } else {
      float p = bsdf_pdf(&m, wo, s.wi);
      float3 f = bsdf_eval(&m, wo, s.wi);
      float3 w = f * (s.wi.z / s.pdf);
      auto close = [](float a, float b, float tol) {
        return std::fabs(a - b) <= tol * std::max(std::fabs(a), std::fabs(b));
      };
      ok = ok && s.wi.z > 0 && std::fabs(std::sqrt(dot(s.wi, s.wi)) - 1) < 1e-5f &&
           close(p, s.pdf, 1e-5f) && close(w.x, s.weight.x, 1e-4f) &&
           close(w.y, s.weight.y, 1e-4f) && close(w.z, s.weight.z, 1e-4f);
      D3 h = dnormalize({double(wo.x) + s.wi.x, double(wo.y) + s.wi.y, double(wo.z) + s.wi.z});
      for (size_t g = 0; g < grids.size(); ++g)
        observed[g][grids[g].bin_of(d3(s.wi), h)] += 1;
    }
    if (!ok && ++bad <= 3)
      ADD_FAILURE() << "sample " << i << ": wi (" << s.wi.x << ", " << s.wi.y << ", " << s.wi.z
                    << ") pdf " << s.pdf << " weight (" << s.weight.x << ", " << s.weight.y << ", "
                    << s.weight.z << ") delta " << s.is_delta;
  }
  std::vector<BinnedCase> out;
  for (size_t g = 0; g < grids.size(); ++g) {
    std::vector<double> prob = bin_probabilities(grids[g], wo, pdf, lobe_scale);
    double integral = 0;
    for (double p : prob)
      integral += p;
    std::vector<double> expected(kBins + 2);
    for (int i = 0; i < kBins; ++i)
      expected[i] = prob[i] * kSamples;
    // What the delta lobe and the pdf leave is absorbed.
    expected[kBins] = std::max(0.0, 1 - p_delta - integral) * kSamples;
    expected[kBins + 1] = p_delta * kSamples;
    observed[g][kBins] = absorbed;
    observed[g][kBins + 1] = delta;
    Chi2Result r = chi2_test(observed[g], expected, kQuadratureTol * kSamples);
    BinnedCase c;
    c.chi2_p = r.p;
    c.integral = integral;
    c.absorbed = absorbed / kSamples;
    c.delta = delta / kSamples;
    c.delta_expected = p_delta;
    EXPECT_GT(r.p, kSignificance) << "grid a_bin " << grids[g].a_bin << ": chi2 " << r.chi2
                                  << " dof " << r.dof << "; worst " << r.worst;
    out.push_back(c);
  }
  return out;
}

bool resolvable(float alpha, float3 wo) {
  return alpha >= 64 * kFloatEps / wo.z;
}

struct Summary {
  double min_p = 1;
  std::string min_case;
  int tests = 0;
  void add(const std::string& name, double p) {
    ++tests;
    if (p < min_p) {
      min_p = p;
      min_case = name;
    }
  }
  void print(const char* what) const {
    std::printf("%s: %d chi-square tests, smallest p-value %.3g (%s), threshold %.3g\n", what,
                tests, min_p, min_case.c_str(), kSignificance);
  }
};

// The full grid for one glossy material.
void test_glossy_grid(const NamedMaterial& nm, uint32_t seed, Summary* sum) {
  for (float r : kRoughness) {
    for (float deg : kAnglesDeg) {
      float alpha = r * r;
      Material m = nm.make(alpha);
      float3 wo = wo_at(deg);
      bool res = resolvable(alpha, wo);
      std::string name = nm.name + " roughness " + std::to_string(r) + " theta_o " +
                         std::to_string(deg) + (res ? "" : " (unresolvable: reference pdf)");
      SCOPED_TRACE(name);
      PdfFn pdf = res ? float_pdf(&m) : PdfFn([&](float3 a, D3 b) { return ref_pdf(m, a, b); });
      HGrid g{res ? double(alpha) : 64 * kFloatEps / wo.z};
      // Plastic: also at a_bin = 1, the diffuse lobe's scale (the same samples).
      std::vector<HGrid> grids = {g};
      if (m.type == MATERIAL_PLASTIC) grids.push_back(HGrid{1.0});
      if (r >= 0.3f) grids.push_back(HGrid{0.0});
      std::vector<BinnedCase> cs = run_binned(m, wo, grids, pdf, 0.0, seed++);
      const BinnedCase& c = cs[0];
      sum->add(name, c.chi2_p);
      // The pdf integrates to 1 minus the absorbed share: binomial noise of the absorbed count
      // (5 sigma) plus the quadrature tolerance.
      double sigma = std::sqrt(std::max(c.absorbed * (1 - c.absorbed), 1.0 / kSamples) / kSamples);
      EXPECT_NEAR(c.integral + c.absorbed, 1.0, 5 * sigma + kQuadratureTol)
          << "integral " << c.integral << " absorbed " << c.absorbed;
      for (size_t k = 1; k < cs.size(); ++k)
        sum->add(name + (grids[k].wi_space() ? " (wi grid)" : " (a_bin 1)"), cs[k].chi2_p);
    }
  }
}

} // namespace

TEST(Bsdf, DiffuseSamplesFollowPdf) {
  Summary sum;
  Material m = make_diffuse(make_float3(0.9f, 0.5f, 0.1f));
  uint32_t seed = 1;
  for (float deg : kAnglesDeg) {
    float3 wo = wo_at(deg);
    SCOPED_TRACE("theta_o " + std::to_string(deg));
    std::vector<BinnedCase> cs =
        run_binned(m, wo, {HGrid{1.0}, HGrid{0.0}}, float_pdf(&m), 0.0, seed++);
    const BinnedCase& c = cs[0];
    sum.add("diffuse theta_o " + std::to_string(deg), c.chi2_p);
    sum.add("diffuse theta_o " + std::to_string(deg) + " (wi grid)", cs[1].chi2_p);
    EXPECT_EQ(c.absorbed, 0.0);
    EXPECT_NEAR(c.integral, 1.0, 1e-4);
  }
  sum.print("diffuse");
}

TEST(Bsdf, ConductorSamplesFollowPdf) {
  Summary sum;
  auto mats = glossy_materials();
  test_glossy_grid(mats[0], 100, &sum);
  test_glossy_grid(mats[1], 200, &sum);
  sum.print("conductor");
}

TEST(Bsdf, PlasticSamplesFollowPdf) {
  Summary sum;
  auto mats = glossy_materials();
  test_glossy_grid(mats[2], 300, &sum);
  test_glossy_grid(mats[3], 400, &sum);
  test_glossy_grid(mats[4], 500, &sum);
  sum.print("plastic");
}

// Perfect specular (alpha == 0): the conductor is a pure delta lobe (weight F(cos theta_o), eval
// and pdf 0); the plastic's coat is a delta lobe chosen with p_s, the rest cosine-distributed
// (chi-square with the delta samples as one category).
TEST(Bsdf, PerfectSpecular) {
  Uniform u(7);
  for (float deg : kAnglesDeg) {
    float3 wo = wo_at(deg);
    Material c = gold(0.0f);
    EXPECT_EQ(bsdf_has_smooth_lobe(&c), 0);
    float3 F = fresnel_conductor(wo.z, xyz_of(c.specular), xyz_of(c.k));
    for (int i = 0; i < 100; ++i) {
      BsdfSample s = bsdf_sample(&c, wo, u.u3());
      ASSERT_EQ(s.is_delta, 1);
      EXPECT_EQ(s.pdf, 0.0f);
      EXPECT_TRUE(s.wi.x == -wo.x && s.wi.y == -wo.y && s.wi.z == wo.z);
      EXPECT_TRUE(s.weight.x == F.x && s.weight.y == F.y && s.weight.z == F.z);
      float3 wi = sample_cosine_local(u(), u());
      EXPECT_EQ(bsdf_pdf(&c, wo, wi), 0.0f);
      EXPECT_EQ(bsdf_eval(&c, wo, wi).x, 0.0f);
    }
  }
  Summary sum;
  uint32_t seed = 900;
  for (const NamedMaterial& nm : glossy_materials()) {
    Material m = nm.make(0.0f);
    if (m.type != MATERIAL_PLASTIC) continue;
    EXPECT_EQ(bsdf_has_smooth_lobe(&m), 1);
    for (float deg : kAnglesDeg) {
      float3 wo = wo_at(deg);
      std::string name = nm.name + " roughness 0 theta_o " + std::to_string(deg);
      SCOPED_TRACE(name);
      float ps = plastic_coat_prob(&m, wo);
      ASSERT_GT(ps, 0.0f);
      ASSERT_LT(ps, 1.0f);
      // The delta sample's weight is the coat's reflectance over its probability.
      float Fd = float(ref_fresnel(wo.z, m.ior, 0.0));
      BsdfSample s = bsdf_sample(&m, wo, make_float3(0.5f, 0.5f, 0.0f));
      ASSERT_EQ(s.is_delta, 1);
      EXPECT_NEAR(s.weight.z, m.specular.z * Fd / ps, 1e-5 * s.weight.z);
      BinnedCase c = run_binned(m, wo, {HGrid{1.0}}, float_pdf(&m), ps, seed++)[0];
      sum.add(name, c.chi2_p);
      EXPECT_NEAR(c.integral, 1.0 - ps, 1e-4); // the diffuse lobe only
    }
  }
  sum.print("perfect specular plastic");
}

// Fresnel against complex arithmetic in double (Snell's law with a complex index), at every
// angle, for conductors (including eta = 0: F = 1) and dielectrics; and the closed form at normal
// incidence, F(0) = ((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2).
TEST(Bsdf, FresnelMatchesComplexReference) {
  const float etas[] = {0.0f, 0.18f, 0.42f, 1.0f, 1.37f, 2.9f};
  const float ks[] = {0.0f, 0.5f, 1.77f, 3.42f, 10.0f};
  for (float eta : etas)
    for (float k : ks) {
      if (eta == 0 && k == 0) continue;
      double f0 =
          ((eta - 1.0) * (eta - 1.0) + double(k) * k) / ((eta + 1.0) * (eta + 1.0) + double(k) * k);
      EXPECT_NEAR(fresnel_conductor1(1.0f, eta, k), f0, 1e-6 * std::max(1.0, f0))
          << "eta " << eta << " k " << k;
      for (int i = 0; i <= 1000; ++i) {
        float c = i / 1000.0f;
        if (c == 0 && eta == 1 && k == 0) continue; // no interface: undefined at grazing
        double ref = ref_fresnel(c, eta, k);
        float f = fresnel_conductor1(c, eta, k);
        ASSERT_NEAR(f, ref, 2e-5) << "eta " << eta << " k " << k << " cos " << c;
        if (eta == 0) {
          ASSERT_EQ(f, 1.0f);
        }
      }
    }
  for (float ior : {1.0f, 1.33f, 1.5f, 2.2f, 3.0f})
    for (int i = 0; i <= 1000; ++i) {
      float c = i / 1000.0f;
      if (c == 0 && ior == 1) continue;
      ASSERT_NEAR(fresnel_dielectric(c, ior), ref_fresnel(c, ior, 0.0), 2e-6)
          << "ior " << ior << " cos " << c;
    }
}

// Diffuse: f = albedo / pi exactly, above the horizon only.
TEST(Bsdf, DiffuseEvalIsAlbedoOverPi) {
  Material m = make_diffuse(make_float3(0.9f, 0.5f, 0.1f));
  Uniform u(11);
  for (int i = 0; i < 1000; ++i) {
    float3 wo = sample_cosine_local(u(), u()), wi = sample_cosine_local(u(), u());
    float3 f = bsdf_eval(&m, wo, wi);
    EXPECT_EQ(f.x, 0.9f * CANOPY_INV_PI);
    EXPECT_EQ(f.y, 0.5f * CANOPY_INV_PI);
    EXPECT_EQ(f.z, 0.1f * CANOPY_INV_PI);
    EXPECT_EQ(bsdf_eval(&m, wo, make_float3(wi.x, wi.y, -wi.z)).x, 0.0f);
  }
}

// f(wo, wi) == f(wi, wo) for the conductor and the plastic, exactly: every term is a symmetric
// expression of the pair (the half vector from wo + wi, G2's |zi| Lo + |zo| Li, and the Fresnel
// cosine (wo.h + wi.h) / 2), and float addition and multiplication commute.
TEST(Bsdf, Reciprocity) {
  Uniform u(13);
  auto mats = glossy_materials();
  for (const NamedMaterial& nm : mats)
    for (float r : kRoughness) {
      Material m = nm.make(r * r);
      for (int i = 0; i < 2000; ++i) {
        float3 wo = sample_cosine_local(u(), u()), wi = sample_cosine_local(u(), u());
        if (i % 4 == 0)
          wi = normalize(make_float3(-wo.x + 1e-3f * u(), -wo.y, wo.z)); // near mirror
        float3 a = bsdf_eval(&m, wo, wi), b = bsdf_eval(&m, wi, wo);
        for (int c = 0; c < 3; ++c) {
          float x = c == 0 ? a.x : (c == 1 ? a.y : a.z), y = c == 0 ? b.x : (c == 1 ? b.y : b.z);
          ASSERT_EQ(x, y) << nm.name << " roughness " << r << " wo (" << wo.x << ", " << wo.y
                          << ", " << wo.z << ") wi (" << wi.x << ", " << wi.y << ", " << wi.z
                          << ")";
        }
      }
    }
}

// The float pdf and eval against the independent double formulas, where the lobe is resolvable.
TEST(Bsdf, PdfAndEvalMatchReference) {
  Uniform u(17);
  for (const NamedMaterial& nm : glossy_materials())
    for (float r : kRoughness) {
      float alpha = r * r;
      Material m = nm.make(alpha);
      int checked = 0;
      for (int i = 0; i < 4000; ++i) {
        float3 wo = sample_cosine_local(u(), u());
        // wi from the sampler (in the lobe) or cosine-distributed (in the tails)
        float3 wi = i % 2 ? bsdf_sample(&m, wo, u.u3()).wi : sample_cosine_local(u(), u());
        if (!(wi.z > 0) || !resolvable(alpha, wo)) continue;
        D3 h = dnormalize({double(wo.x) + wi.x, double(wo.y) + wi.y, double(wo.z) + wi.z});
        double woh = ddot(d3(wo), h);
        double g2 = 1 / (1 + ref_lambda(d3(wo), alpha) + ref_lambda(d3(wi), alpha));
        double micro = ref_D(h, alpha) * g2 / (4 * double(wo.z) * wi.z);
        double f_ref;
        if (m.type == MATERIAL_CONDUCTOR)
          f_ref = ref_fresnel(woh, m.specular.y, m.k.y) * micro;
        else
          f_ref = m.albedo.y / kPi + m.specular.y * ref_fresnel(woh, m.ior, 0) * micro;
        double p_ref = ref_pdf(m, wo, d3(wi));
        float f = bsdf_eval(&m, wo, wi).y, p = bsdf_pdf(&m, wo, wi);
        // 1e-3: float rounding of the half vector moves D by up to ~2 (h error / alpha) ~
        // 1e-4..1e-3
        ASSERT_NEAR(f, f_ref, 1e-3 * f_ref + 1e-30) << nm.name << " roughness " << r;
        ASSERT_NEAR(p, p_ref, 1e-3 * p_ref + 1e-30) << nm.name << " roughness " << r;
        ++checked;
      }
      if (alpha >= 1e-4f) { // roughness 0.001 is never resolvable
        EXPECT_GT(checked, 1000);
      }
    }
}

// White furnace: a conductor with F == 1 (eta = 0) reflects at most what reaches it; its
// directional albedo is the single-scattering GGX albedo, which loses energy to masking. Three
// estimates must agree: an independent double-precision integral of D G2 / (4 cos_o) over half
// vectors (ref_*), the same integral of the float bsdf_eval, and the mean sample weight.
TEST(Bsdf, WhiteFurnaceConductor) {
  uint32_t seed = 31;
  for (float r : kRoughness) {
    float alpha = r * r;
    Material m = white_conductor(alpha);
    for (float deg : kAnglesDeg) {
      float3 wo_f = wo_at(deg);
      D3 wo = d3(wo_f);
      SCOPED_TRACE("roughness " + std::to_string(r) + " theta_o " + std::to_string(deg));
      // albedo = integral over wi of f cos = integral over h of f cos 4 (wo.h)
      auto albedo = [&](bool reference) {
        HGrid g{std::max(double(alpha), 64 * kFloatEps / wo.z)};
        double sum = 0;
        auto density = [&](double theta, double phi) {
          D3 h = h_at(theta, phi);
          double woh = ddot(wo, h);
          D3 wi = {2 * woh * h.x - wo.x, 2 * woh * h.y - wo.y, 2 * woh * h.z - wo.z};
          if (woh <= 0 || wi.z <= 0) return 0.0;
          if (reference) {
            double g2 = 1 / (1 + ref_lambda(wo, alpha) + ref_lambda(wi, alpha));
            return ref_D(h, alpha) * g2 / (4 * wo.z * wi.z) * wi.z * 4 * woh;
          }
          float3 wif = make_float3(float(wi.x), float(wi.y), float(wi.z));
          return double(bsdf_eval(&m, wo_f, wif).x) * wi.z * 4 * woh;
        };
        for (int ring = 0; ring < kRings; ++ring) {
          auto over_phi = [&](double theta) {
            double s = 0;
            for (auto [lo, hi] : valid_phi(wo, theta, 0, 2 * kPi))
              for (int k = 0; k < 8; ++k) {
                double a = lo + (hi - lo) * k / 8, b = lo + (hi - lo) * (k + 1) / 8;
                s += gauss12([&](double phi) { return density(theta, phi); }, a, b);
              }
            return s * std::sin(theta);
          };
          sum += integrate_theta(over_phi, g.theta_edge(ring), g.theta_edge(ring + 1), alpha);
        }
        return sum;
      };
      double ref = albedo(true);
      Uniform u(seed++);
      double mean = 0, m2 = 0;
      for (int i = 0; i < kSamples; ++i) {
        double w = bsdf_sample(&m, wo_f, u.u3()).weight.x;
        mean += w;
        m2 += w * w;
      }
      mean /= kSamples;
      double sigma = std::sqrt(std::max(0.0, m2 / kSamples - mean * mean) / kSamples);
      EXPECT_LE(ref, 1.0 + 1e-6);
      EXPECT_NEAR(mean, ref, 5 * sigma + 1e-6) << "sampled albedo " << mean << " reference " << ref;
      if (resolvable(alpha, wo_f)) {
        double quad = albedo(false);
        EXPECT_NEAR(quad, ref, 1e-4) << "integral of bsdf_eval " << quad << " reference " << ref;
      }
      // The known masking loss: ~0 for a smooth surface seen from above, tens of percent for
      // alpha = 1 (Kulla & Conty 2017, "Revisiting Physically Based Shading at Imageworks").
      if (alpha <= 1e-4f && deg <= 60) {
        EXPECT_GT(ref, 0.99);
      }
      // (At the horizon itself the loss vanishes again: G2 / G1(wo) -> 1 as Lambda(wo) -> inf,
      // so the albedo tends to the share of visible-normal reflections that leave upwards.)
      if (alpha == 1.0f && deg <= 80) {
        EXPECT_LT(ref, 0.9);
      }
      std::printf("white furnace roughness %g theta_o %g: albedo %.6f (sampled %.6f +- %.1e)\n", r,
                  deg, ref, mean, sigma);
    }
  }
}

// No NaN or Inf, and non-negative values, for random and adversarial inputs: grazing wo
// (89.999 deg and 1e-8), alpha 1e-10 .. 1, wi == wo, wi == -wo, wi on the horizon, u at 0 and
// 1 - 2^-24.
TEST(Bsdf, FiniteEverywhere) {
  Uniform u(19);
  const float alphas[] = {0.0f, 1e-10f, 1e-7f, 1e-6f, 1e-4f, 1e-2f, 0.3f, 1.0f};
  const float umax = 1.0f - 5.9604645e-8f;
  std::vector<Material> mats;
  for (float a : alphas) {
    mats.push_back(gold(a));
    mats.push_back(white_conductor(a));
    mats.push_back(
        make_conductor(make_float3(1, 1, 1), make_float3(0, 0, 0), a)); // F = 0 index match
    mats.push_back(make_plastic(make_float3(0.5f, 0.5f, 0.5f), make_float3(1, 1, 1), 1.5f, a));
    mats.push_back(make_plastic(make_float3(0, 0, 0), make_float3(1, 1, 1), 1.0f, a));
    mats.push_back(make_plastic(make_float3(1, 1, 1), make_float3(0, 0, 0), 3.0f, a));
  }
  mats.push_back(make_diffuse(make_float3(1, 1, 1)));
  std::vector<float3> wos = {make_float3(0, 0, 1), wo_at(89.999f), wo_at(89.9f),
                             normalize(make_float3(1, 0, 1e-8f)),
                             normalize(make_float3(0, 1, 1e-30f))};
  for (int i = 0; i < 50; ++i)
    wos.push_back(sample_cosine_local(u(), u()));
  const float corners[] = {0.0f, 0.5f, umax};
  int count = 0;
  for (const Material& m : mats)
    for (float3 wo : wos) {
      std::vector<float3> wis = {wo,
                                 -wo,
                                 reflect_z(wo),
                                 make_float3(wo.x, wo.y, 0),
                                 normalize(make_float3(-wo.y, wo.x, 0)),
                                 make_float3(0, 0, 1)};
      for (int i = 0; i < 20; ++i) {
        float z = 2 * u() - 1, phi = 6.2831853f * u(), s = std::sqrt(std::max(0.0f, 1 - z * z));
        wis.push_back(make_float3(s * std::cos(phi), s * std::sin(phi), z));
      }
      for (float3 wi : wis) {
        float3 f = bsdf_eval(&m, wo, wi);
        float p = bsdf_pdf(&m, wo, wi);
        ASSERT_TRUE(finite3(f) && std::isfinite(p) && f.x >= 0 && f.y >= 0 && f.z >= 0 && p >= 0)
            << "type " << m.type << " alpha " << m.alpha << " wo.z " << wo.z << " wi.z " << wi.z;
        ++count;
      }
      std::vector<float3> us;
      for (float a : corners)
        for (float b : corners)
          for (float c : corners)
            us.push_back(make_float3(a, b, c));
      for (int i = 0; i < 50; ++i)
        us.push_back(u.u3());
      for (float3 uu : us) {
        BsdfSample s = bsdf_sample(&m, wo, uu);
        ASSERT_TRUE(finite3(s.wi) && finite3(s.weight) && std::isfinite(s.pdf) && s.pdf >= 0 &&
                    s.weight.x >= 0 && s.weight.y >= 0 && s.weight.z >= 0)
            << "type " << m.type << " alpha " << m.alpha << " wo.z " << wo.z << " u (" << uu.x
            << ", " << uu.y << ", " << uu.z << ")";
        ++count;
      }
    }
  EXPECT_GT(count, 100000);
}
