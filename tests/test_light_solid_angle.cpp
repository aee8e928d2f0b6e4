// Solid-angle sampling of quad and triangle lights (cl/lights/planar_solid_angle.h): the pdf
// integrates to 1 over the light, light_pdf() agrees with every sample's pdf, samples lie on the
// light, the irradiance estimator matches Lambert's closed form for polygons (also 1e-6 above the
// light, where area sampling fails), and sampled directions are uniform in solid angle
// (chi-square against the exact solid angle of each bin).
#include "lights/light_sample.h"

#include "support/double3.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace {

// Solid angle of triangle (a, b, c) seen from the origin (Van Oosterom & Strackee), in double.
double tri_omega(D3 a, D3 b, D3 c) {
  double t = std::fabs(ddot(a, dcross(b, c)));
  double la = dlen(a), lb = dlen(b), lc = dlen(c);
  double den = la * lb * lc + ddot(a, b) * lc + ddot(a, c) * lb + ddot(b, c) * la;
  return t == 0.0 ? 0.0 : 2.0 * std::atan2(t, den);
}

// The light's corners in double (world space).
std::vector<D3> corners(const Light& l) {
  D3 p = d3(xyz_of(l.p)), e1 = d3(xyz_of(l.e1)), e2 = d3(xyz_of(l.e2));
  if (l.type == LIGHT_QUAD) return {p, p + e1, p + e1 + e2, p + e2};
  return {p, p + e1, p + e2};
}

// Solid angle of a convex polygon seen from P: fan from the polygon's point nearest the foot of P
// would be needed in float; in double the fan from vertex 0 is accurate enough.
double polygon_omega(const std::vector<D3>& v, D3 P) {
  double s = 0.0;
  for (size_t i = 1; i + 1 < v.size(); ++i)
    s += tri_omega(v[0] - P, v[i] - P, v[i + 1] - P);
  return s;
}

// Lambert's irradiance from a uniformly emitting convex polygon entirely above the receiver's
// horizon: E = L/2 sum_i theta_i (n_i . N), n_i the unit normal of the plane through P and edge i
// and theta_i the edge's angle (Arvo 1995, "Applications of irradiance tensors", eq. 6).
double lambert_irradiance(const std::vector<D3>& v, D3 P, D3 N, double L) {
  double s = 0.0;
  for (size_t i = 0; i < v.size(); ++i) {
    D3 a = v[i] - P, b = v[(i + 1) % v.size()] - P;
    D3 c = dcross(a, b);
    double theta = std::atan2(dlen(c), ddot(a, b));
    s += theta * ddot(c, N) / dlen(c);
  }
  return 0.5 * L * std::fabs(s);
}

// Parameters (a, b) of the point x on the light's plane (x = p + a e1 + b e2) and its distance
// from the plane.
struct Param {
  double a, b, off;
};
Param param_of(const Light& l, D3 x) {
  D3 p = d3(xyz_of(l.p)), e1 = d3(xyz_of(l.e1)), e2 = d3(xyz_of(l.e2));
  D3 c = dcross(e1, e2);
  double c2 = ddot(c, c);
  D3 r = x - p;
  return {ddot(dcross(r, e2), c) / c2, ddot(dcross(e1, r), c) / c2, ddot(r, c) / std::sqrt(c2)};
}

// ---------------------------------------------------------------- lights and viewpoints
Light make_light(int type, float3 p, float3 e1, float3 e2, bool two_sided) {
  Light l{};
  l.type = type;
  l.p = f4_from3(p, 0.0f);
  l.e1 = f4_from3(e1, 0.0f);
  l.e2 = f4_from3(e2, 0.0f);
  float3 c = cross(e1, e2);
  float len = length(c);
  l.n = f4_from3(c * (1.0f / len), type == LIGHT_QUAD ? len : 0.5f * len);
  l.emission = make_float4(2.0f, 2.0f, 2.0f, 0.0f);
  l.flags = two_sided ? LIGHT_FLAG_TWO_SIDED : 0;
  l.prim = -1;
  return l;
}

struct NamedLight {
  std::string name;
  Light l;
};

// All lights emit downwards (n = -y) from around y = 1, away from the origin.
std::vector<NamedLight> test_lights() {
  auto q = [](float3 p, float3 e1, float3 e2) { return make_light(LIGHT_QUAD, p, e1, e2, false); };
  auto t = [](float3 p, float3 e1, float3 e2) {
    return make_light(LIGHT_TRIANGLE, p, e1, e2, false);
  };
  float3 x = make_float3(1, 0, 0), z = make_float3(0, 0, 1);
  return {
      {"square", q(make_float3(-0.5f, 1, -0.5f), x, z)},
      {"thin rectangle",
       q(make_float3(-2.0f, 1, -0.01f), make_float3(4, 0, 0), make_float3(0, 0, 0.02f))},
      {"skewed parallelogram", q(make_float3(-0.7f, 1, -0.4f), x, make_float3(0.5f, 0, 0.8f))},
      {"regular triangle",
       t(make_float3(-0.5f, 1, -0.288675f), make_float3(1, 0, 0), make_float3(0.5f, 0, 0.866025f))},
      {"sliver triangle",
       t(make_float3(-1.5f, 1, 0), make_float3(3, 0, 0), make_float3(3, 0, 0.03f))},
      {"obtuse triangle",
       t(make_float3(-3, 1, -0.5f), make_float3(6, 0, 0), make_float3(1, 0, 1.5f))},
  };
}

struct Viewpoint {
  std::string name;
  float3 P;
  float3 N; // receiver normal; the light is entirely above its horizon
};

// Viewpoints below the lights (in front of them): far, near, 1e-6 below the light's plane, grazing
// (almost in the plane, beside the light).
std::vector<Viewpoint> viewpoints(const Light& l) {
  float3 up = make_float3(0, 1, 0);
  // 1e-6 below the plane and 2e-6 outside the middle of edge e1: the foot is off the light, the
  // fan's apex on the edge.
  float3 e1 = xyz_of(l.e1), e2 = xyz_of(l.e2);
  float3 out = normalize(e1 * (dot(e1, e2) / dot(e1, e1)) - e2);
  float3 beside = xyz_of(l.p) + e1 * 0.5f + out * 2e-6f;
  beside.y = 1.0f - 1e-6f;
  return {
      {"1e-6 beside an edge", beside, up},
      {"far", make_float3(3, -40, 2), normalize(make_float3(-3, 41, -2))},
      {"mid", make_float3(0.3f, 0.2f, -0.1f), up},
      {"near", make_float3(0.05f, 0.98f, 0.02f), up},
      {"1e-6 below", make_float3(0.01f, 1.0f - 1e-6f, 0.004f), up},
      {"grazing", make_float3(4.5f, 0.999f, 0.3f), normalize(make_float3(-1, 0.02f, 0))},
      {"grazing 1e-4", make_float3(0.0f, 0.9999f, 5.0f), normalize(make_float3(0, 0.001f, -1))},
  };
}

struct Rng {
  std::mt19937 g;
  std::uniform_real_distribution<float> u{0.0f, 1.0f};
  explicit Rng(uint32_t seed) : g(seed) {}
  float next() {
    float x = u(g);
    return x < 1.0f ? x : 0.99999994f;
  }
};

// ---------------------------------------------------------------- tests
TEST(LightSolidAngle, TechniqueChoice) {
  for (const NamedLight& nl : test_lights()) {
    const Light& l = nl.l;
    PlanarView far = planar_view(&l, make_float3(0, -1000, 0));
    EXPECT_EQ(far.technique, PLANAR_AREA) << nl.name;
    PlanarView close = planar_view(&l, make_float3(0.01f, 1.0f - 1e-6f, 0.004f));
    int expected = nl.name == "square" || nl.name == "thin rectangle" ? PLANAR_RECT : PLANAR_FAN;
    EXPECT_EQ(close.technique, expected) << nl.name;
    PlanarView behind = planar_view(&l, make_float3(0, 2, 0));
    EXPECT_EQ(behind.technique, PLANAR_NONE) << nl.name;
    Light two = l;
    two.flags = LIGHT_FLAG_TWO_SIDED;
    PlanarView behind2 = planar_view(&two, make_float3(0.01f, 1.0f + 1e-6f, 0.004f));
    EXPECT_EQ(behind2.technique, expected) << nl.name;
  }
}

// The technique is solid angle exactly when the light's solid angle is at least
// LIGHT_SOLID_ANGLE_MIN (the cheap bound that skips the set-up for far lights never decides
// otherwise, away from rounding).
TEST(LightSolidAngle, FallbackCriterion) {
  Rng rng(11);
  int near_threshold = 0;
  for (const NamedLight& nl : test_lights()) {
    for (int k = 0; k < 4000; ++k) {
      // directions below the light, distances around where the solid angle crosses 1e-3 sr
      float z = -rng.next(), phi = 6.2831853f * rng.next();
      float sxy = std::sqrt(std::max(0.0f, 1 - z * z));
      float dist = 40.0f * std::pow(10.0f, -1.3f * rng.next());
      float3 P =
          make_float3(dist * sxy * std::cos(phi), 1.0f + dist * z, dist * sxy * std::sin(phi));
      double omega = polygon_omega(corners(nl.l), d3(P));
      PlanarView v = planar_view(&nl.l, P);
      if (omega >= 1.001 * LIGHT_SOLID_ANGLE_MIN) {
        EXPECT_NE(v.technique, PLANAR_AREA) << nl.name << " omega " << omega;
      } else if (omega < 0.999 * LIGHT_SOLID_ANGLE_MIN) {
        EXPECT_EQ(v.technique, PLANAR_AREA) << nl.name << " omega " << omega;
      }
      near_threshold += omega > 0.5 * LIGHT_SOLID_ANGLE_MIN && omega < 2 * LIGHT_SOLID_ANGLE_MIN;
    }
  }
  EXPECT_GT(near_threshold, 1000); // the test looks where the choice changes
}

// The pdf integrates to 1 over the light's solid angle: whatever the technique, the pdf of every
// direction times the exact solid angle (quadrature of cos / d^2 over the light in double,
// against the closed form) integrates to 1.
TEST(LightSolidAngle, PdfIntegratesToOne) {
  // Gauss-Legendre, 8 points on [0, 1]
  const double gx[8] = {0.0198550717512319, 0.1016667612931866, 0.2372337950418355,
                        0.4082826787521751, 0.5917173212478249, 0.7627662049581645,
                        0.8983332387068134, 0.9801449282487681};
  const double gw[8] = {0.0506142681451881, 0.1111905172266872, 0.1568533229389436,
                        0.1813418916891810, 0.1813418916891810, 0.1568533229389436,
                        0.1111905172266872, 0.0506142681451881};
  for (const NamedLight& nl : test_lights()) {
    const Light& l = nl.l;
    for (const Viewpoint& vp : viewpoints(l)) {
      std::string at = nl.name + " from " + vp.name;
      D3 P = d3(vp.P);
      PlanarView v = planar_view(&l, vp.P);
      ASSERT_NE(v.technique, PLANAR_NONE) << at;
      double omega = polygon_omega(corners(l), P);
      if (v.technique != PLANAR_AREA) {
        // constant pdf 1 / omega: the float solid angle against the closed form in double
        EXPECT_NEAR(double(light_pdf(&l, vp.P, xyz_of(l.p))) * omega, 1.0, 2e-5) << at;
      }
      // Quadrature in the light's parameters (triangles through (a, b) = (s (1 - t), s t)),
      // on a 32 x 32 grid of cells; skipped where the integrand is too peaked for it.
      D3 p = d3(xyz_of(l.p)), e1 = d3(xyz_of(l.e1)), e2 = d3(xyz_of(l.e2));
      double area2 = dlen(dcross(e1, e2));
      D3 nrm = dcross(e1, e2) * (1.0 / area2);
      double h = std::fabs(ddot(nrm, P - p));
      if (h < 0.1 * std::fmax(dlen(e1), dlen(e2))) continue;
      const int cells = 32;
      double integral = 0.0, check = 0.0;
      for (int i = 0; i < cells; ++i)
        for (int j = 0; j < cells; ++j)
          for (int gi = 0; gi < 8; ++gi)
            for (int gj = 0; gj < 8; ++gj) {
              double s = (i + gx[gi]) / cells, t = (j + gx[gj]) / cells;
              double a = s, b = t, jac = area2;
              if (l.type == LIGHT_TRIANGLE) {
                a = s * (1.0 - t);
                b = s * t;
                jac = area2 * s;
              }
              D3 x = p + e1 * a + e2 * b;
              D3 d = x - P;
              double d2 = ddot(d, d);
              double g = std::fabs(ddot(nrm, d)) / (d2 * std::sqrt(d2)) * jac * gw[gi] * gw[gj] /
                         (cells * cells);
              float3 xf = make_float3(float(x.x), float(x.y), float(x.z));
              integral += double(light_pdf(&l, vp.P, xf)) * g;
              check += g;
            }
      EXPECT_NEAR(check / omega, 1.0, 1e-6) << at << " (quadrature)";
      EXPECT_NEAR(integral, 1.0, 2e-5) << at;
    }
  }
}

// Every sample: on the light, pdf == light_pdf at its point, direction and distance consistent
// with the point. The irradiance estimator mean(L cos / pdf) matches Lambert's formula within
// 5 standard errors.
TEST(LightSolidAngle, SamplesAndIrradiance) {
  const int n = 40000;
  uint32_t seed = 1;
  for (const NamedLight& nl : test_lights()) {
    const Light& l = nl.l;
    std::vector<D3> vs = corners(l);
    for (const Viewpoint& vp : viewpoints(l)) {
      std::string at = nl.name + " from " + vp.name;
      Rng rng(seed++);
      D3 P = d3(vp.P), N = d3(vp.N);
      double sum = 0.0, sum2 = 0.0;
      int bad_pdf = 0, off_light = 0, bad_dir = 0, zero = 0;
      for (int k = 0; k < n; ++k) {
        float u1 = rng.next(), u2 = rng.next();
        LightSample s = sample_light(&l, vp.P, u1, u2);
        double f = 0.0;
        if (s.pdf > 0.0f) {
          // at the point on the plane (s.x is moved off it, which changes the area pdf's
          // cosine at grazing angles)
          float lp = light_pdf(&l, vp.P, vp.P + s.wi * s.dist);
          if (!(std::fabs(lp - s.pdf) <= 1e-4f * s.pdf)) ++bad_pdf;
          Param q = param_of(l, d3(s.x));
          double tol = 1e-5;
          bool inside =
              q.a >= -tol && q.b >= -tol &&
              (l.type == LIGHT_QUAD ? q.a <= 1 + tol && q.b <= 1 + tol : q.a + q.b <= 1 + tol);
          if (!inside || std::fabs(q.off) > 1e-5) ++off_light;
          // P + wi dist lies on the light's plane (relative to the distance and P's magnitude)
          Param e = param_of(l, P + d3(s.wi) * double(s.dist));
          if (std::fabs(e.off) > 1e-6 * (double(s.dist) + dlen(P))) ++bad_dir;
          f = double(s.Li.x) * std::fmax(0.0, ddot(N, d3(s.wi))) / double(s.pdf);
        } else {
          ++zero;
        }
        EXPECT_TRUE(std::isfinite(f)) << at;
        sum += f;
        sum2 += f * f;
      }
      EXPECT_EQ(bad_pdf, 0) << at;
      EXPECT_EQ(off_light, 0) << at;
      EXPECT_EQ(bad_dir, 0) << at;
      EXPECT_EQ(zero, 0) << at;
      double mean = sum / n;
      double se = std::sqrt(std::fmax(0.0, sum2 / n - mean * mean) / n);
      double ref = lambert_irradiance(vs, P, N, double(l.emission.x));
      EXPECT_NEAR(mean, ref, 5.0 * se) << at << " se " << se;
    }
  }
}

// Behind a one-sided light: no sample, pdf 0; a two-sided light there gives the same irradiance.
TEST(LightSolidAngle, BehindOneSided) {
  for (const NamedLight& nl : test_lights()) {
    Light l = nl.l;
    for (float y : {1.0f + 1e-6f, 1.3f, 30.0f}) {
      float3 P = make_float3(0.02f, y, 0.01f);
      Rng rng(7);
      for (int k = 0; k < 1000; ++k) {
        LightSample s = sample_light(&l, P, rng.next(), rng.next());
        ASSERT_EQ(s.pdf, 0.0f) << nl.name << " y " << y;
      }
      EXPECT_EQ(light_pdf(&l, P, xyz_of(l.p) + xyz_of(l.e1) * 0.3f + xyz_of(l.e2) * 0.2f), 0.0f);
    }
  }
}

// The failure that solid-angle sampling removes: 1e-6 below a 1 x 1 light, area sampling's
// estimate of the irradiance (256 samples) is nowhere near Lambert's value; the solid-angle
// estimate with as many samples is within 5 of its standard errors (each under 5%).
TEST(LightSolidAngle, AreaSamplingFailsVeryClose) {
  Light l = test_lights()[0].l;
  float3 P = make_float3(0.01f, 1.0f - 1e-6f, 0.004f);
  D3 N = {0, 1, 0};
  double ref = lambert_irradiance(corners(l), d3(P), N, 2.0);
  Rng rng(3);
  double area_sum = 0.0, sa_sum = 0.0, sa_sq = 0.0;
  const int n = 256;
  for (int k = 0; k < n; ++k) {
    float u1 = rng.next(), u2 = rng.next();
    // area sampling, as sample_light did before: L cos cos_l A / d^2
    D3 x = d3(xyz_of(l.p)) + d3(xyz_of(l.e1)) * u1 + d3(xyz_of(l.e2)) * u2;
    D3 d = x - d3(P);
    double d2 = ddot(d, d);
    area_sum += 2.0 * (ddot(N, d) / std::sqrt(d2)) * (d.y / std::sqrt(d2)) * 1.0 / d2;
    LightSample s = sample_light(&l, P, u1, u2);
    double f = double(s.Li.x) * ddot(N, d3(s.wi)) / double(s.pdf);
    sa_sum += f;
    sa_sq += f * f;
  }
  double mean = sa_sum / n, se = std::sqrt(std::fmax(0.0, sa_sq / n - mean * mean) / n);
  EXPECT_GT(std::fabs(area_sum / n / ref - 1.0), 0.9);
  EXPECT_LT(se, 0.05 * ref);
  EXPECT_NEAR(mean, ref, 5.0 * se);
}

// Chi-square goodness of fit of the sampled points against the exact solid angle of each bin.
// Bins are cells of the light's parameters (quads: a x b; triangles: (s, t) with (a, b) =
// (s (1 - t), s t), whose cells are quadrilaterals), each integrated exactly as a polygon; bins
// expecting fewer than 5 samples are pooled.
double chi2_z(const Light& l, float3 Pf, int samples, uint32_t seed) {
  const int m = 10;
  D3 P = d3(Pf), p = d3(xyz_of(l.p)), e1 = d3(xyz_of(l.e1)), e2 = d3(xyz_of(l.e2));
  auto at = [&](double s, double t) {
    if (l.type == LIGHT_QUAD) return p + e1 * s + e2 * t;
    return p + e1 * (s * (1 - t)) + e2 * (s * t);
  };
  D3 nrm = d3(xyz_of(l.n));
  std::vector<double> expect(m * m);
  double omega = polygon_omega(corners(l), P);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      double s0 = double(i) / m, s1 = double(i + 1) / m, t0 = double(j) / m, t1 = double(j + 1) / m;
      std::vector<D3> cell = {at(s0, t0), at(s1, t0), at(s1, t1), at(s0, t1)};
      if (l.type == LIGHT_TRIANGLE && i == 0) cell = {at(0, 0), at(s1, t0), at(s1, t1)};
      expect[size_t(i * m + j)] = polygon_omega(cell, P) / omega * samples;
    }
  std::vector<double> count(m * m, 0.0);
  Rng rng(seed);
  for (int k = 0; k < samples; ++k) {
    LightSample s = sample_light(&l, Pf, rng.next(), rng.next());
    // Binned by the sampled direction (the ray from P hits the plane at P + wi t): the point's
    // own coordinates are rounded to the float spacing of the light's position, coarser than the
    // distribution 1e-6 from the light.
    D3 w = d3(s.wi);
    double hs = ddot(nrm, P - p);
    D3 hit = P + w * (-hs / ddot(nrm, w));
    Param q = param_of(l, hit);
    double a = std::clamp(q.a, 0.0, 1.0), b = std::clamp(q.b, 0.0, 1.0), u = a, v = b;
    if (l.type == LIGHT_TRIANGLE) {
      u = a + b;
      v = u > 0 ? b / u : 0.0;
    }
    int i = std::min(m - 1, int(u * m)), j = std::min(m - 1, int(v * m));
    count[size_t(i * m + j)] += 1.0;
  }
  double chi2 = 0.0, pool_e = 0.0, pool_c = 0.0;
  int bins = 0;
  for (size_t i = 0; i < expect.size(); ++i) {
    if (expect[i] < 5.0) {
      pool_e += expect[i];
      pool_c += count[i];
      continue;
    }
    chi2 += (count[i] - expect[i]) * (count[i] - expect[i]) / expect[i];
    ++bins;
  }
  if (pool_e >= 5.0) {
    chi2 += (pool_c - pool_e) * (pool_c - pool_e) / pool_e;
    ++bins;
  }
  // Wilson-Hilferty: chi2 / df is approximately normal after a cube root.
  if (bins < 2) return 0.0; // nothing to compare (all mass in one bin)
  double df = bins - 1;
  double z = (std::cbrt(chi2 / df) - (1 - 2 / (9 * df))) / std::sqrt(2 / (9 * df));
  return z;
}

TEST(LightSolidAngle, UniformInSolidAngle) {
  std::vector<NamedLight> lights = test_lights();
  uint32_t seed = 100;
  for (const NamedLight& nl : lights) {
    for (const Viewpoint& vp : viewpoints(nl.l)) {
      if (planar_view(&nl.l, vp.P).technique == PLANAR_AREA) continue;
      // Known limitation of the spherical rectangle seen from 1e-6 beside a long edge: the
      // directions within ~1e-3 rad of the horizon along the edge (~4e-4 of the samples here)
      // need fu^2 - (1 - b0^2) below float resolution and are clamped to the rectangle's ends
      // (cl/lights/spherical_rectangle.h); their contribution is ~1e-3 of a sample's at most.
      if (nl.name == "thin rectangle" && vp.name == "1e-6 beside an edge") continue;
      double z = chi2_z(nl.l, vp.P, 100000, seed++);
      // z > 4.26: p < 1e-5 for one test
      EXPECT_LT(z, 4.26) << nl.name << " from " << vp.name;
    }
  }
}

} // namespace
