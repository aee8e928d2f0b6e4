// The volume sampling math of cl/volume/ on the host: the Henyey-Greenstein phase function and its
// sampling, equiangular sampling (Kulla & Fajardo 2012), free-flight distance sampling with channel
// MIS (pbrt-v3), and the homogeneous medium's box clipping and transmittance.
//
// References are independent of the code under test: closed forms and quadratures in double (or
// long double, where a naive formula would cancel in double), brute-force ray marching for the box.
// Statistical checks use fixed seeds: chi-square tests pass when the p-value is above
// 0.01 / kChi2Tests (Bonferroni over the file); estimators must match their reference within 5
// standard errors computed from the sample variance.
#include "support/double3.h"
#include "support/gamma_q.h"
#include "volume/equiangular.h"
#include "volume/medium.h"
#include "volume/phase.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kChi2Tests = 40; // an upper bound on the chi-square tests in this file
constexpr double kSignificance = 0.01 / kChi2Tests;
constexpr float kInf = std::numeric_limits<float>::infinity();

// Uniform floats in [0, 1) with 24 random bits (std::uniform_real_distribution<float> may return
// 1).
struct Rng {
  std::mt19937_64 gen;
  explicit Rng(uint64_t seed) : gen(seed) {}
  float next() { return float(gen() >> 40) * 0x1p-24f; }
};

Medium make_medium(float3 sigma_t, float3 sigma_s, float g) {
  Medium m;
  m.sigma_t = f4_from3(sigma_t, g);
  m.sigma_s = f4_from3(sigma_s, 0.0f);
  m.bmin = make_float4(0, 0, 0, 0);
  m.bmax = make_float4(0, 0, 0, 0);
  return m;
}
Medium make_box_medium(float3 sigma_t, float3 bmin, float3 bmax) {
  Medium m = make_medium(sigma_t, sigma_t * 0.5f, 0.0f);
  m.sigma_s.w = 1.0f;
  m.bmin = f4_from3(bmin, 0.0f);
  m.bmax = f4_from3(bmax, 0.0f);
  return m;
}
float chan(float3 v, int c) {
  return c == 0 ? v.x : (c == 1 ? v.y : v.z);
}

// ---------------------------------------------------------------- quadrature
// Adaptive Simpson on [a, b] to an absolute tolerance, at most 24 levels deep. A float integrand is
// noisy at its last bits (relative 2^-24), so tolerances stay above that noise times the integral.
double simpson_rec(const std::function<double(double)>& f, double a, double b, double fa, double fm,
                   double fb, double whole, double tol, int depth) {
  double m = 0.5 * (a + b), lm = 0.5 * (a + m), rm = 0.5 * (m + b);
  double flm = f(lm), frm = f(rm);
  double left = (m - a) / 6 * (fa + 4 * flm + fm), right = (b - m) / 6 * (fm + 4 * frm + fb);
  double delta = left + right - whole;
  if (depth <= 0 || std::fabs(delta) <= 15 * tol) return left + right + delta / 15;
  return simpson_rec(f, a, m, fa, flm, fm, left, tol / 2, depth - 1) +
         simpson_rec(f, m, b, fm, frm, fb, right, tol / 2, depth - 1);
}
double simpson(const std::function<double(double)>& f, double a, double b, double tol) {
  if (!(b > a)) return 0;
  double fa = f(a), fm = f(0.5 * (a + b)), fb = f(b);
  return simpson_rec(f, a, b, fa, fm, fb, (b - a) / 6 * (fa + 4 * fm + fb), tol, 24);
}
// Simpson over [a, b] split at the given interior points (where the integrand peaks).
double simpson_split(const std::function<double(double)>& f, double a, double b,
                     std::vector<double> cuts, double tol) {
  cuts.push_back(a);
  cuts.push_back(b);
  std::sort(cuts.begin(), cuts.end());
  double sum = 0;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    double lo = std::clamp(cuts[i], a, b), hi = std::clamp(cuts[i + 1], a, b);
    sum += simpson(f, lo, hi, tol);
  }
  return sum;
}

// ---------------------------------------------------------------- chi-square
using canopy::test::gamma_q;

// Pearson's chi-square of observed counts against expected probabilities (times n); categories
// expected below 5 are pooled. Returns the p-value; `worst` names the largest contribution.
double chi2_p(const std::vector<double>& observed, const std::vector<double>& prob, double n,
              std::string* worst) {
  double chi2 = 0, pool_o = 0, pool_e = 0, worst_c = -1;
  int cats = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    double e = prob[i] * n;
    if (e < 5) {
      pool_o += observed[i];
      pool_e += e;
      continue;
    }
    double c = (observed[i] - e) * (observed[i] - e) / e;
    chi2 += c;
    ++cats;
    if (c > worst_c) {
      worst_c = c;
      *worst = "bin " + std::to_string(i) + ": observed " + std::to_string(observed[i]) +
               " expected " + std::to_string(e);
    }
  }
  if (pool_e > 0) {
    chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
    ++cats;
  } else if (pool_o > 0) {
    *worst = "observations where the density is 0";
    return 0;
  }
  return gamma_q(0.5 * std::max(1, cats - 1), 0.5 * chi2);
}

// Mean and standard error of a sample.
struct Stat {
  double n = 0, sum = 0, sum2 = 0;
  void add(double x) {
    n += 1;
    sum += x;
    sum2 += x * x;
  }
  double mean() const { return sum / n; }
  double se() const {
    double m = mean();
    return std::sqrt(std::max(0.0, sum2 / n - m * m) / (n - 1));
  }
};

// ---------------------------------------------------------------- Henyey-Greenstein reference
double ref_hg(double g, double c) {
  return (1 - g * g) / (4 * kPi * std::pow(1 + g * g - 2 * g * c, 1.5));
}
// P(cos theta <= c): the closed-form integral of 2 pi ref_hg over [-1, c].
double ref_hg_cdf(double g, double c) {
  if (g == 0) return 0.5 * (c + 1);
  return (1 - g * g) / (2 * g) * (1 / std::sqrt(1 + g * g - 2 * g * c) - 1 / (1 + g));
}

const float kG[] = {-0.9f, -0.3f, 0.0f, 0.5f, 0.95f};

TEST(VolumePhase, HgIntegratesToOneWithMeanCosineG) {
  for (float g : kG) {
    auto p = [&](double c) { return 2 * kPi * double(phase_hg(g, float(c))); };
    auto pc = [&](double c) { return c * p(c); };
    // Split near the peak (cos = +-1) where the lobe of g = 0.95 is 0.0025 wide.
    std::vector<double> cuts = {-0.999, -0.99, -0.9, 0.9, 0.99, 0.999};
    double total = simpson_split(p, -1, 1, cuts, 1e-7);
    double mean = simpson_split(pc, -1, 1, cuts, 1e-7);
    EXPECT_NEAR(total, 1.0, 2e-6) << "g " << g;
    EXPECT_NEAR(mean, double(g), 2e-6) << "g " << g; // HG's mean cosine is g
  }
}

TEST(VolumePhase, HgMatchesDoubleFormula) {
  const float gs[] = {-0.999f, -0.9f, -0.3f, -1e-4f, 0.0f, 1e-4f, 0.5f, 0.95f, 0.999f};
  for (float g : gs) {
    for (int i = 0; i <= 2000; ++i) {
      // cosines spread towards both poles, where the peaks of |g| -> 1 are
      double s = -1 + 2.0 * i / 2000;
      float c = float(std::copysign(1 - (1 - std::fabs(s)) * (1 - std::fabs(s)), s));
      double ref = ref_hg(g, c), got = phase_hg(g, c);
      ASSERT_NEAR(got, ref, 3e-6 * ref) << "g " << g << " cos " << c;
      // p(-g, -cos) = p(g, cos): the same lobe mirrored
      ASSERT_EQ(phase_hg(-g, -c), phase_hg(g, c)) << "g " << g << " cos " << c;
    }
  }
  EXPECT_FLOAT_EQ(phase_hg(0.0f, 0.3f), float(1 / (4 * kPi)));
  // |g| >= 1 is clamped to PHASE_HG_G_MAX: finite, and the peak of the clamped lobe.
  for (float g : {-1.0f, 1.0f, 0.99999f, -0.99999f}) {
    for (float c : {-1.0f, -0.5f, 0.0f, 0.99999994f, 1.0f}) {
      float p = phase_hg(g, c);
      EXPECT_TRUE(std::isfinite(p) && p >= 0) << "g " << g << " cos " << c << ": " << p;
      EXPECT_NEAR(p, ref_hg(std::copysign(double(PHASE_HG_G_MAX), g), c), 1e-4 * p + 1e-30);
    }
  }
}

TEST(VolumePhase, HgSamplesFollowDensity) {
  constexpr int kN = 100000, kCos = 32, kPhi = 8;
  const float3 dirs[] = {make_float3(0, 0, 1), make_float3(0, 0, -1),
                         normalize(make_float3(0.3f, -0.7f, 0.2f))};
  Rng rng(13);
  for (float g : kG) {
    // equal-probability bins in cos theta (bisection on the closed-form CDF)
    std::vector<double> edges(kCos + 1);
    edges[0] = -1;
    edges[kCos] = 1;
    for (int k = 1; k < kCos; ++k) {
      double lo = -1, hi = 1;
      for (int it = 0; it < 100; ++it) {
        double mid = 0.5 * (lo + hi);
        (ref_hg_cdf(g, mid) < double(k) / kCos ? lo : hi) = mid;
      }
      edges[k] = 0.5 * (lo + hi);
    }
    std::vector<double> prob(kCos * kPhi);
    for (int k = 0; k < kCos; ++k)
      for (int j = 0; j < kPhi; ++j)
        prob[k * kPhi + j] = (ref_hg_cdf(g, edges[k + 1]) - ref_hg_cdf(g, edges[k])) / kPhi;
    for (float3 d : dirs) {
      // azimuth measured in a frame of the test's own
      D3 dd = d3(d), e1 = dunit(dcross(dd, D3{0.36, 0.48, 0.8})), e2 = dcross(dd, e1);
      std::vector<double> obs(kCos * kPhi, 0);
      Stat cosine;
      for (int i = 0; i < kN; ++i) {
        float pdf = -1;
        float3 wi = phase_hg_sample(g, d, rng.next(), rng.next(), &pdf);
        ASSERT_NEAR(length(wi), 1.0f, 1e-6f);
        ASSERT_EQ(pdf, phase_hg(g, dot(wi, d))) << "g " << g;
        ASSERT_TRUE(std::isfinite(pdf) && pdf > 0);
        D3 w = d3(wi);
        double c = std::clamp(ddot(w, dd), -1.0, 1.0);
        cosine.add(c);
        int k = int(std::upper_bound(edges.begin(), edges.end(), c) - edges.begin()) - 1;
        k = std::clamp(k, 0, kCos - 1);
        double phi = std::atan2(ddot(w, e2), ddot(w, e1)) + kPi;
        int j = std::clamp(int(phi / (2 * kPi) * kPhi), 0, kPhi - 1);
        obs[k * kPhi + j] += 1;
      }
      std::string worst;
      double p = chi2_p(obs, prob, kN, &worst);
      EXPECT_GT(p, kSignificance) << "g " << g << " d " << d.x << "," << d.y << "," << d.z << ": "
                                  << worst;
      // the mean cosine is g (sign convention: g > 0 puts wi around d)
      EXPECT_NEAR(cosine.mean(), double(g), 5 * cosine.se() + 1e-6) << "g " << g;
    }
  }
}

TEST(VolumePhase, HgSignConvention) {
  // A path along d scattering forward (g = 0.9) keeps going along d: most wi within 30 degrees of
  // d.
  const float3 d = normalize(make_float3(1, 2, 3));
  Rng rng(7);
  for (float g : {0.9f, -0.9f}) {
    int near_d = 0;
    for (int i = 0; i < 10000; ++i) {
      float pdf;
      float3 wi = phase_hg_sample(g, d, rng.next(), rng.next(), &pdf);
      near_d += dot(wi, d) > 0.866f;
    }
    // P(cos > cos 30deg) = 1 - F(0.866): 0.86 for g = 0.9, 0.0011 for g = -0.9
    double expect = 1 - ref_hg_cdf(g, 0.866);
    double sd = std::sqrt(10000 * expect * (1 - expect));
    EXPECT_NEAR(near_d, 10000 * expect, 5 * sd + 1) << "g " << g;
  }
}

TEST(VolumePhase, HgExtremeInputsFinite) {
  const float us[] = {0.0f, 1e-7f, 0.5f, 0.99999994f, 1.0f};
  for (float g : {-1.0f, -0.99999f, -0.9999f, -1e-7f, 0.0f, 1e-7f, 0.9999f, 0.99999f, 1.0f}) {
    for (float u1 : us) {
      for (float3 d : {make_float3(0, 0, 1), make_float3(0, 0, -1), make_float3(1, 0, 0)}) {
        float pdf = -1;
        float3 wi = phase_hg_sample(g, d, u1, 0.3f, &pdf);
        EXPECT_TRUE(std::isfinite(pdf) && pdf > 0) << "g " << g << " u1 " << u1;
        EXPECT_NEAR(length(wi), 1.0f, 1e-6f) << "g " << g << " u1 " << u1;
      }
    }
  }
  // u1 -> 1 is the forward direction, u1 = 0 the backward one
  float pdf;
  EXPECT_GT(dot(phase_hg_sample(0.5f, make_float3(0, 0, 1), 0.99999994f, 0.2f, &pdf),
                make_float3(0, 0, 1)),
            0.9999f);
  EXPECT_LT(
      dot(phase_hg_sample(0.5f, make_float3(0, 0, 1), 0.0f, 0.2f, &pdf), make_float3(0, 0, 1)),
      -0.9999f);
}

// ---------------------------------------------------------------- equiangular
struct Segment {
  const char* name;
  float3 o, d;
  float len;
  float3 c;
};
// Geometry references in long double, from the naive formulas (atan of each end, then their
// difference: long double's 64-bit mantissa keeps Theta ~ 1e-12 to 1e-7).
struct RefGeom {
  long double delta, dist, theta_a, theta;
};
RefGeom ref_geom(const Segment& s) {
  long double oc[3] = {(long double)s.c.x - s.o.x, (long double)s.c.y - s.o.y,
                       (long double)s.c.z - s.o.z};
  long double d[3] = {s.d.x, s.d.y, s.d.z};
  RefGeom r;
  r.delta = oc[0] * d[0] + oc[1] * d[1] + oc[2] * d[2];
  long double cr[3] = {oc[1] * d[2] - oc[2] * d[1], oc[2] * d[0] - oc[0] * d[2],
                       oc[0] * d[1] - oc[1] * d[0]};
  r.dist = std::sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
  r.theta_a = std::atan(-r.delta / r.dist);
  r.theta = std::atan((s.len - r.delta) / r.dist) - r.theta_a;
  return r;
}
long double ref_cdf(const RefGeom& r, long double t) {
  return (std::atan((t - r.delta) / r.dist) - r.theta_a) / r.theta;
}

// Geometries where D is resolvable (well above the clamp): the density is the exact one.
const Segment kSegments[] = {
    {"beside", make_float3(0, 0, 0), make_float3(1, 0, 0), 10.0f, make_float3(4, 1, 0)},
    {"behind origin", make_float3(0, 0, 0), make_float3(1, 0, 0), 5.0f,
     make_float3(-3, 0.5f, 0.2f)},
    {"beyond end", make_float3(0, 0, 0), make_float3(1, 0, 0), 10.0f, make_float3(12, 2, 0)},
    {"close to line", make_float3(0, 0, 0), make_float3(1, 0, 0), 10.0f, make_float3(5, 1e-3f, 0)},
    {"oblique", make_float3(1, -2, 3), normalize(make_float3(1, 2, -0.5f)), 7.0f,
     make_float3(2.5f, 1.0f, 2.0f)},
    {"far ahead", make_float3(0, 0, 0), make_float3(1, 0, 0), 1.0f, make_float3(1e6f, 1, 0)},
    {"far behind", make_float3(0, 0, 0), make_float3(1, 0, 0), 1.0f, make_float3(-1e6f, 3, 0)},
    {"far aside", make_float3(0, 0, 0), make_float3(0, 1, 0), 1.0f, make_float3(0.5f, 0.3f, 1e6f)},
    {"long segment", make_float3(0, 0, 0), make_float3(0, 0, 1), 1e6f, make_float3(2, 1, 0)},
    {"long, light behind", make_float3(0, 0, 0), make_float3(0, 0, 1), 1e6f,
     make_float3(0.5f, 0, -2)},
    {"infinite", make_float3(1, 1, 1), normalize(make_float3(1, -1, 2)), kInf,
     make_float3(2, 0.5f, 3)},
    {"infinite, light behind", make_float3(0, 0, 0), make_float3(1, 0, 0), kInf,
     make_float3(-4, 1, 0)},
};

TEST(VolumeEquiangular, PdfIntegratesToOneAndMatchesClosedForm) {
  for (const Segment& s : kSegments) {
    RefGeom r = ref_geom(s);
    auto pdf = [&](double t) { return double(equiangular_pdf(s.o, s.d, s.len, s.c, float(t))); };
    // cuts at delta and geometrically away from it, where the Cauchy bump of width D is
    std::vector<double> cuts = {double(r.delta)};
    for (double k = 1; k <= 1e6; k *= 10) {
      cuts.push_back(double(r.delta - k * r.dist));
      cuts.push_back(double(r.delta + k * r.dist));
    }
    // an infinite segment: quadrature up to 1e7, the tail beyond in closed form
    double end = std::isinf(s.len) ? 1e7 : double(s.len);
    double tail = std::isinf(s.len)
                      ? double((std::atan2(r.dist, end - r.delta)) / r.theta) // pi/2 - atan
                      : 0.0;
    double total = simpson_split(pdf, 0, end, cuts, 1e-7) + tail;
    EXPECT_NEAR(total, 1.0, 1e-5) << s.name;
    for (int i = 0; i <= 100; ++i) {
      float t = std::isinf(s.len) ? 0.1f * float(i * i) : s.len * float(i) / 100;
      long double x = t - r.delta;
      long double ref = r.dist / (r.theta * (r.dist * r.dist + x * x));
      EXPECT_NEAR(equiangular_pdf(s.o, s.d, s.len, s.c, t), double(ref), 2e-5 * double(ref))
          << s.name << " t " << t;
    }
    EXPECT_EQ(equiangular_pdf(s.o, s.d, s.len, s.c, -1e-3f), 0.0f) << s.name;
    if (!std::isinf(s.len)) {
      EXPECT_EQ(equiangular_pdf(s.o, s.d, s.len, s.c, s.len * 1.001f), 0.0f) << s.name;
    }
  }
}

TEST(VolumeEquiangular, SamplesFollowDensity) {
  constexpr int kN = 100000, kBins = 40;
  Rng rng(21);
  for (const Segment& s : kSegments) {
    RefGeom r = ref_geom(s);
    // equal-probability bins from the long double inverse CDF; the probabilities from the CDF
    std::vector<double> edges(kBins + 1), prob(kBins);
    for (int k = 0; k <= kBins; ++k)
      edges[k] = double(r.delta + r.dist * std::tan(r.theta_a + r.theta * k / kBins));
    edges[0] = 0;
    edges[kBins] = s.len;
    for (int k = 0; k < kBins; ++k)
      prob[k] = double(ref_cdf(r, edges[k + 1]) - ref_cdf(r, edges[k]));
    std::vector<double> obs(kBins, 0);
    for (int i = 0; i < kN; ++i) {
      float pdf = -1;
      float t = equiangular_sample(s.o, s.d, s.len, s.c, rng.next(), &pdf);
      ASSERT_TRUE(t >= 0 && t <= s.len && std::isfinite(t)) << s.name << " t " << t;
      ASSERT_EQ(pdf, equiangular_pdf(s.o, s.d, s.len, s.c, t)) << s.name << " t " << t;
      ASSERT_TRUE(std::isfinite(pdf) && pdf > 0) << s.name << " t " << t;
      int k = int(std::upper_bound(edges.begin(), edges.end(), double(t)) - edges.begin()) - 1;
      obs[std::clamp(k, 0, kBins - 1)] += 1;
    }
    std::string worst;
    EXPECT_GT(chi2_p(obs, prob, kN, &worst), kSignificance) << s.name << ": " << worst;
  }
}

TEST(VolumeEquiangular, LightOnTheLineStaysNormalised) {
  // D = 0: clamped at 2^-21 (max|o| + max|c|) = 1.43e-6 here; a Cauchy bump that narrow is a few
  // float steps of t wide, so its integral is summed over every float t near delta.
  const float3 o = make_float3(0, 0, 0), d = make_float3(1, 0, 0), c = make_float3(3, 0, 0);
  const float len = 10;
  double dmin = double(EQUIANGULAR_D_REL) * 3, w = 1e4 * dmin;
  auto pdf = [&](double t) { return double(equiangular_pdf(o, d, len, c, float(t))); };
  double sum = simpson(pdf, 0, 3 - w, 1e-7) + simpson(pdf, 3 + w, len, 1e-7);
  for (float t = float(3 - w); t < float(3 + w);) {
    float next = std::nextafter(t, kInf);
    sum += double(equiangular_pdf(o, d, len, c, t)) * (double(next) - double(t));
    t = next;
  }
  EXPECT_NEAR(sum, 1.0, 1e-3);
  // the samples sit on the light: P(|t - 3| < 1e-3) = (2/pi) atan(1e-3 / D) ~ 0.999
  Rng rng(5);
  int near_c = 0;
  for (int i = 0; i < 10000; ++i) {
    float p;
    float t = equiangular_sample(o, d, len, c, rng.next(), &p);
    ASSERT_TRUE(std::isfinite(p) && p > 0 && t >= 0 && t <= len);
    near_c += std::fabs(t - 3.0f) < 1e-3f;
  }
  EXPECT_GT(near_c, 9950);
}

TEST(VolumeEquiangular, ExtremeInputsFinite) {
  const float3 o = make_float3(1, 2, 3), d = normalize(make_float3(0.2f, -1, 0.4f));
  const float lens[] = {0.0f, 1e-30f, 1e-6f, 1.0f, 1e6f, kInf};
  const float offs[] = {0.0f, 1e-30f, 1e-7f, 1.0f, 1e6f};  // distance from the line
  const float alongs[] = {-1e6f, -1.0f, 0.0f, 0.5f, 1e6f}; // delta
  const float us[] = {0.0f, 1e-7f, 0.5f, 0.99999994f};
  float3 side = normalize(cross(d, make_float3(0, 0, 1)));
  int sampled = 0;
  for (float len : lens)
    for (float off : offs)
      for (float along : alongs)
        for (float u : us) {
          float3 c = o + d * along + side * off;
          float pdf = -1;
          float t = equiangular_sample(o, d, len, c, u, &pdf);
          std::string what = "len " + std::to_string(len) + " off " + std::to_string(off) +
                             " along " + std::to_string(along) + " u " + std::to_string(u);
          // an infinite segment may give t = +inf with pdf 0 for u within rounding of 1
          bool inf_end = std::isinf(len) && u > 0.5f;
          ASSERT_TRUE((std::isfinite(t) || inf_end) && t >= 0 && t <= len) << what << ": t " << t;
          ASSERT_TRUE(std::isfinite(pdf) && pdf >= 0) << what << ": pdf " << pdf;
          ASSERT_EQ(pdf, equiangular_pdf(o, d, len, c, t)) << what;
          if (std::isinf(t)) {
            ASSERT_EQ(pdf, 0.0f) << what;
          }
          // every segment of positive length that D len resolves gives a sample
          if (len >= 1e-6f && !inf_end) {
            ASSERT_GT(pdf, 0) << what;
          }
          sampled += pdf > 0;
          for (float tt : {0.0f, std::fmin(0.5f * len, 1e30f), len}) {
            float p = equiangular_pdf(o, d, len, c, tt);
            ASSERT_TRUE(std::isfinite(p) && p >= 0) << what << " t " << tt;
          }
        }
  EXPECT_GT(sampled, 0);
  // light exactly at the ray origin
  float pdf;
  float t = equiangular_sample(o, d, 2.0f, o, 0.5f, &pdf);
  EXPECT_TRUE(std::isfinite(t) && std::isfinite(pdf) && pdf > 0);
}

TEST(VolumeMis, PowerHeuristic) {
  EXPECT_EQ(volume_mis_weight(0.0f, 0.0f), 0.0f);
  EXPECT_EQ(volume_mis_weight(0.0f, 3.0f), 0.0f);
  EXPECT_EQ(volume_mis_weight(2.0f, 0.0f), 1.0f);
  EXPECT_EQ(volume_mis_weight(1.0f, 1.0f), 0.5f);
  EXPECT_NEAR(volume_mis_weight(3.0f, 1.0f), 0.9f, 1e-7f);
  EXPECT_NEAR(volume_mis_weight(1.0f, 3.0f), 0.1f, 1e-7f);
  // huge densities (a peaked equiangular pdf) do not overflow to NaN
  EXPECT_NEAR(volume_mis_weight(1e30f, 1e30f), 0.5f, 1e-7f);
  EXPECT_NEAR(volume_mis_weight(3e30f, 1e30f), 0.9f, 1e-6f);
  EXPECT_EQ(volume_mis_weight(1e-30f, 1e30f), 0.0f);
  EXPECT_EQ(volume_mis_weight(kInf, 1.0f), 1.0f);
  // the two weights of a pair sum to 1
  Rng rng(3);
  for (int i = 0; i < 1000; ++i) {
    float a = std::exp(40 * rng.next() - 20), b = std::exp(40 * rng.next() - 20);
    EXPECT_NEAR(volume_mis_weight(a, b) + volume_mis_weight(b, a), 1.0f, 1e-6f);
  }
}

// Single scattering from an isotropic point light (intensity I at c) along o + t d, t in [0, len],
// in an unbounded medium: L = int sigma_s p(theta) I exp(-sigma_t t) exp(-sigma_t r) / r^2 dt,
// r = |x(t) - c|, cos theta = dot((c - x) / r, d) (light travels c -> x, then x -> o along -d).
struct ScatterCase {
  const char* name;
  float3 sigma_t, sigma_s;
  float g;
  Segment seg;
};

TEST(VolumeEquiangular, SingleScatteringPointLight) {
  constexpr int kN = 100000;
  constexpr double kI = 5.0;
  const Segment near_seg = {"near", make_float3(0.5f, -1, 0.2f),
                            normalize(make_float3(1, 0.2f, -0.1f)), 6.0f,
                            make_float3(3.0f, 0.0f, 0.0f)};
  const Segment far_seg = {"behind, far from the ray", make_float3(0, 0, 0), make_float3(0, 0, 1),
                           8.0f, make_float3(2, 0, -1)};
  const ScatterCase cases[] = {
      {"grey", make_float3(0.6f, 0.6f, 0.6f), make_float3(0.45f, 0.45f, 0.45f), 0.5f, near_seg},
      {"coloured", make_float3(0.1f, 0.9f, 2.0f), make_float3(0.05f, 0.6f, 1.5f), -0.4f, near_seg},
      {"zero channel", make_float3(0.0f, 0.7f, 1.6f), make_float3(0.0f, 0.5f, 1.0f), 0.8f,
       near_seg},
      {"dense, light aside", make_float3(1.2f, 0.3f, 2.5f), make_float3(1.0f, 0.2f, 2.0f), 0.3f,
       far_seg},
  };
  Rng rng(2024);
  for (const ScatterCase& sc : cases) {
    const Segment& s = sc.seg;
    Medium m = make_medium(sc.sigma_t, sc.sigma_s, sc.g);
    // the integrand per channel, in double (reference) ...
    auto f_ref = [&](int ch, double t) {
      D3 x = d3(s.o) + d3(s.d) * t, lc = d3(s.c) - x;
      double r = dlen(lc), cos_t = ddot(lc, d3(s.d)) / r;
      double st = chan(sc.sigma_t, ch), ss = chan(sc.sigma_s, ch);
      return ss * ref_hg(sc.g, cos_t) * kI * std::exp(-st * (t + r)) / (r * r);
    };
    // ... and with the float API, as the integrator computes it
    auto f = [&](float t) {
      float3 x = s.o + s.d * t, lc = s.c - x;
      float r = length(lc);
      float ph = phase_hg(sc.g, dot(lc, s.d) / r);
      float3 tr = medium_tr(&m, t + r);
      return sc.sigma_s * tr * (ph * float(kI) / (r * r));
    };
    RefGeom rg = ref_geom(s);
    double ref[3];
    for (int ch = 0; ch < 3; ++ch)
      ref[ch] = simpson_split([&](double t) { return f_ref(ch, t); }, 0, s.len, {double(rg.delta)},
                              1e-12);
    Stat eq[3], mis[3];
    for (int i = 0; i < kN; ++i) {
      // (a) equiangular alone
      float pe;
      float te = equiangular_sample(s.o, s.d, s.len, s.c, rng.next(), &pe);
      ASSERT_GT(pe, 0);
      float3 fe = f(te);
      // (b) one equiangular and one free-flight sample, power heuristic
      float pf_e = medium_distance_pdf(&m, te);
      float3 est = fe * (volume_mis_weight(pe, pf_e) / pe);
      float tf = medium_sample_distance(&m, rng.next());
      if (tf < s.len) {
        float pf = medium_distance_pdf(&m, tf);
        float pe_f = equiangular_pdf(s.o, s.d, s.len, s.c, tf);
        ASSERT_GT(pf, 0);
        est += f(tf) * (volume_mis_weight(pf, pe_f) / pf);
      }
      for (int ch = 0; ch < 3; ++ch) {
        eq[ch].add(chan(fe, ch) / pe);
        mis[ch].add(chan(est, ch));
      }
    }
    for (int ch = 0; ch < 3; ++ch) {
      double tol_float = 1e-5 * ref[ch]; // float evaluation of the integrand
      std::printf("%s channel %d: reference %.6g, equiangular %.6g +- %.2g, MIS %.6g +- %.2g\n",
                  sc.name, ch, ref[ch], eq[ch].mean(), eq[ch].se(), mis[ch].mean(), mis[ch].se());
      EXPECT_NEAR(eq[ch].mean(), ref[ch], 5 * eq[ch].se() + tol_float)
          << sc.name << " channel " << ch << " (equiangular)";
      EXPECT_NEAR(mis[ch].mean(), ref[ch], 5 * mis[ch].se() + tol_float)
          << sc.name << " channel " << ch << " (MIS)";
      // equiangular sampling cancels the 1 / r^2: a low-variance estimator
      EXPECT_LT(eq[ch].se(), 0.01 * ref[ch] + 1e-30) << sc.name << " channel " << ch;
    }
  }
}

// ---------------------------------------------------------------- distance sampling
const float3 kSigmaT[] = {make_float3(1.3f, 1.3f, 1.3f), make_float3(0.3f, 1.0f, 4.0f),
                          make_float3(0.0f, 0.7f, 2.5f)};

double ref_survival(float3 s, double t) {
  double sum = 0;
  for (int c = 0; c < 3; ++c)
    sum += chan(s, c) > 0 ? std::exp(-chan(s, c) * t) : 1.0;
  return sum / 3;
}

TEST(VolumeDistance, SamplesFollowDensity) {
  constexpr int kN = 200000, kBins = 30;
  constexpr double kT = 3.0;
  Rng rng(99);
  for (float3 st : kSigmaT) {
    Medium m = make_medium(st, st * 0.5f, 0.0f);
    std::vector<double> obs(kBins + 1, 0), prob(kBins + 1);
    for (int k = 0; k < kBins; ++k)
      prob[k] = ref_survival(st, kT * k / kBins) - ref_survival(st, kT * (k + 1) / kBins);
    prob[kBins] = ref_survival(st, kT); // beyond kT, including +inf
    int infinite = 0;
    for (int i = 0; i < kN; ++i) {
      float t = medium_sample_distance(&m, rng.next());
      ASSERT_TRUE(t >= 0) << t;
      infinite += std::isinf(t);
      int k = t >= float(kT) ? kBins : std::min(int(double(t) / kT * kBins), kBins - 1);
      obs[k] += 1;
    }
    std::string worst;
    EXPECT_GT(chi2_p(obs, prob, kN, &worst), kSignificance)
        << st.x << "," << st.y << "," << st.z << ": " << worst;
    // a zero channel never stops the ray: a third of the samples are +inf
    double p_inf = (st.x == 0) / 3.0;
    EXPECT_NEAR(infinite, kN * p_inf, 5 * std::sqrt(kN * p_inf * (1 - p_inf)) + 0.5);
  }
  // the ends of u: u = 0 is t = 0; the last float below 1 is finite on a non-zero channel
  Medium m = make_medium(kSigmaT[1], kSigmaT[1] * 0.5f, 0.0f);
  EXPECT_EQ(medium_sample_distance(&m, 0.0f), 0.0f);
  float t_max = medium_sample_distance(&m, 0.99999994f);
  EXPECT_TRUE(std::isfinite(t_max) && t_max > 0);
}

TEST(VolumeDistance, PdfAndSurvivalMatchClosedForms) {
  for (float3 st : kSigmaT) {
    Medium m = make_medium(st, st * 0.5f, 0.0f);
    auto pdf = [&](double t) { return double(medium_distance_pdf(&m, float(t))); };
    for (double t : {0.0, 0.05, 0.3, 1.0, 2.5, 7.0, 20.0}) {
      double ref_pdf = 0;
      for (int c = 0; c < 3; ++c)
        ref_pdf += chan(st, c) * std::exp(-chan(st, c) * t) / 3;
      EXPECT_NEAR(pdf(t), ref_pdf, 1e-6 * ref_pdf + 1e-30) << "t " << t;
      // survival = 1 - the integral of the pdf
      double cdf = simpson(pdf, 0, t, 1e-8);
      EXPECT_NEAR(medium_survival(&m, float(t)), 1 - cdf, 2e-6) << "t " << t;
      EXPECT_NEAR(medium_survival(&m, float(t)), ref_survival(st, t), 1e-6) << "t " << t;
    }
    EXPECT_EQ(medium_survival(&m, 0.0f), 1.0f);
    EXPECT_NEAR(medium_survival(&m, kInf), (st.x == 0) / 3.0f, 1e-7f);
    EXPECT_EQ(medium_distance_pdf(&m, kInf), 0.0f);
  }
}

TEST(VolumeDistance, ChannelWeightsBounded) {
  // Tr(t) sigma_s / pdf(t) <= 3 and Tr(t) / survival(t) <= 3 per channel (sigma_s <= sigma_t).
  Rng rng(11);
  for (float3 st : kSigmaT) {
    Medium m = make_medium(st, st * 0.9f, 0.0f);
    for (int i = 0; i < 10000; ++i) {
      float t = -std::log(1 - rng.next()) * 3;
      float3 tr = medium_tr(&m, t);
      float pdf = medium_distance_pdf(&m, t), surv = medium_survival(&m, t);
      for (int c = 0; c < 3; ++c) {
        if (pdf > 0) {
          ASSERT_LE(chan(tr, c) * chan(xyz_of(m.sigma_s), c) / pdf, 3.0001f) << "t " << t;
        }
        ASSERT_LE(chan(tr, c) / surv, 3.0001f) << "t " << t;
      }
    }
  }
}

// ---------------------------------------------------------------- box clipping, transmittance
TEST(VolumeMedium, TrHandlesZeroAndInfinity) {
  Medium m = make_medium(make_float3(0.0f, 0.5f, 2.0f), make_float3(0, 0.2f, 1), 0.0f);
  float3 inf_tr = medium_tr(&m, kInf);
  EXPECT_EQ(inf_tr.x, 1.0f);
  EXPECT_EQ(inf_tr.y, 0.0f);
  EXPECT_EQ(inf_tr.z, 0.0f);
  float3 zero_tr = medium_tr(&m, 0.0f);
  EXPECT_EQ(zero_tr.x, 1.0f);
  EXPECT_EQ(zero_tr.y, 1.0f);
  EXPECT_EQ(zero_tr.z, 1.0f);
  EXPECT_NEAR(medium_tr(&m, 1.5f).y, std::exp(-0.75), 1e-7);
  EXPECT_NEAR(medium_tr(&m, 1.5f).z, std::exp(-3.0), 1e-7);
  // unbounded: the whole ray
  float t0 = -1, t1 = -1;
  ASSERT_TRUE(medium_clip(&m, make_float3(1, 2, 3), make_float3(0, 1, 0), kInf, &t0, &t1));
  EXPECT_EQ(t0, 0.0f);
  EXPECT_EQ(t1, kInf);
  float3 tr = medium_transmittance(&m, make_float3(1, 2, 3), make_float3(0, 1, 0), kInf);
  EXPECT_EQ(tr.x, 1.0f);
  EXPECT_EQ(tr.y, 0.0f);
  tr = medium_transmittance(&m, make_float3(1, 2, 3), make_float3(0, 1, 0), 2.0f);
  EXPECT_NEAR(tr.z, std::exp(-4.0), 1e-7);
  EXPECT_FALSE(medium_clip(&m, make_float3(1, 2, 3), make_float3(0, 1, 0), 0.0f, &t0, &t1));
}

// Brute force: march the ray in double in steps of h, a step inside when its midpoint is in the
// closed box. The clipped interval's ends and length agree with it to within a step.
TEST(VolumeMedium, ClipAndTransmittanceMatchBruteForce) {
  Rng rng(77);
  auto r = [&](float lo, float hi) { return lo + (hi - lo) * rng.next(); };
  constexpr int kSteps = 20000;
  int nonempty = 0, inside_origin = 0, axis_rays = 0;
  for (int i = 0; i < 600; ++i) {
    float3 bmin = make_float3(r(-2, 2), r(-2, 2), r(-2, 2));
    float3 bmax = bmin + make_float3(r(0.1f, 3), r(0.1f, 3), r(0.1f, 3));
    Medium m = make_box_medium(make_float3(0.4f, 1.1f, 0.0f), bmin, bmax);
    float3 o = i % 3 == 0 ? bmin + (bmax - bmin) * make_float3(rng.next(), rng.next(), rng.next())
                          : make_float3(r(-5, 5), r(-5, 5), r(-5, 5));
    float3 d;
    if (i % 4 == 0) { // axis-parallel, either sign (and -0 components)
      int axis = i / 4 % 3;
      float sgn = rng.next() < 0.5f ? -1.0f : 1.0f;
      d = make_float3(-0.0f, 0.0f, -0.0f);
      if (axis == 0) d.x = sgn;
      if (axis == 1) d.y = sgn;
      if (axis == 2) d.z = sgn;
      // aim the origin at the box on the other axes half of the time
      if (rng.next() < 0.5f) {
        if (axis != 0) o.x = r(bmin.x, bmax.x);
        if (axis != 1) o.y = r(bmin.y, bmax.y);
        if (axis != 2) o.z = r(bmin.z, bmax.z);
      }
      ++axis_rays;
    } else if (i % 4 == 1) { // one zero component
      d = normalize(make_float3(r(-1, 1), r(-1, 1), 0.0f));
    } else {
      // towards a point of the box, so most rays hit it
      float3 target = bmin + (bmax - bmin) * make_float3(rng.next(), rng.next(), rng.next());
      d = normalize(target - o + make_float3(r(-1, 1), r(-1, 1), r(-1, 1)));
    }
    float tmax = i % 5 == 0 ? kInf : r(0.5f, 12.0f);
    // brute force
    double span = std::min(double(tmax), 25.0), h = span / kSteps;
    int first = -1, last = -1, count = 0;
    for (int k = 0; k < kSteps; ++k) {
      double t = (k + 0.5) * h;
      D3 p = d3(o) + d3(d) * t;
      bool in = p.x >= bmin.x && p.x <= bmax.x && p.y >= bmin.y && p.y <= bmax.y && p.z >= bmin.z &&
                p.z <= bmax.z;
      if (in) {
        if (first < 0) first = k;
        last = k;
        ++count;
      }
    }
    float t0 = -1, t1 = -1;
    int hit = medium_clip(&m, o, d, tmax, &t0, &t1);
    std::string what = "case " + std::to_string(i);
    if (count == 0) {
      if (hit) {
        EXPECT_LT(t1 - t0, 2 * h) << what;
      }
    } else {
      ASSERT_TRUE(hit) << what;
      ++nonempty;
      inside_origin += first == 0;
      EXPECT_NEAR(t0, first * h, 1.01 * h) << what;
      EXPECT_NEAR(t1, (last + 1) * h, 1.01 * h) << what;
      EXPECT_LE(t1, tmax) << what;
    }
    double len_bf = count * h;
    float3 tr = medium_transmittance(&m, o, d, tmax);
    EXPECT_NEAR(tr.x, std::exp(-0.4 * len_bf), 0.4 * 2 * h + 1e-6) << what;
    EXPECT_NEAR(tr.y, std::exp(-1.1 * len_bf), 1.1 * 2 * h + 1e-6) << what;
    EXPECT_EQ(tr.z, 1.0f) << what;
  }
  // the random cases cover what they should
  EXPECT_GT(nonempty, 300);
  EXPECT_GT(inside_origin, 150);
  EXPECT_GT(axis_rays, 100);

  // a ray in a face's plane, parallel to it, is inside (closed box); just outside it is not
  Medium box = make_box_medium(make_float3(1, 1, 1), make_float3(0, 0, 0), make_float3(1, 2, 3));
  float t0, t1;
  ASSERT_TRUE(medium_clip(&box, make_float3(0, -1, 1), make_float3(0, 1, 0), kInf, &t0, &t1));
  EXPECT_FLOAT_EQ(t0, 1.0f);
  EXPECT_FLOAT_EQ(t1, 3.0f);
  EXPECT_FALSE(medium_clip(&box, make_float3(-1e-6f, -1, 1), make_float3(0, 1, 0), kInf, &t0, &t1));
  // the same with a denormal component into the box: no 0 * inf = NaN
  ASSERT_TRUE(medium_clip(&box, make_float3(0, -1, 1), make_float3(1e-40f, 1, 0), kInf, &t0, &t1));
  EXPECT_FLOAT_EQ(t0, 1.0f);
  EXPECT_FLOAT_EQ(t1, 3.0f);
  // tmax inside the box, origin inside
  ASSERT_TRUE(
      medium_clip(&box, make_float3(0.5f, 0.5f, 0.5f), make_float3(0, 0, 1), 1.0f, &t0, &t1));
  EXPECT_EQ(t0, 0.0f);
  EXPECT_EQ(t1, 1.0f);
  // pointing away, and an empty (inverted) box
  EXPECT_FALSE(medium_clip(&box, make_float3(0.5f, 0.5f, 4), make_float3(0, 0, 1), kInf, &t0, &t1));
  Medium inverted =
      make_box_medium(make_float3(1, 1, 1), make_float3(1, 1, 1), make_float3(0, 0, 0));
  EXPECT_FALSE(
      medium_clip(&inverted, make_float3(0.5f, 0.5f, -1), make_float3(0, 0, 1), kInf, &t0, &t1));
  float3 tr =
      medium_transmittance(&inverted, make_float3(0.5f, 0.5f, -1), make_float3(0, 0, 1), kInf);
  EXPECT_EQ(tr.x, 1.0f);
}

} // namespace
