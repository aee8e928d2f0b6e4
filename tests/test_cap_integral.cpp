// cl/bsdf/cap_integral.h: the cosine-weighted BRDF integral over spherical caps (Liu et al. 2019,
// Eq. 5) against independent double-precision references:
// - the cap-cap intersection area against a 1D quadrature (arc length of each circle about one
//   axis inside the other cap) and exact special cases (lunes, nesting, disjoint, covering);
// - the pivot image of a cap against the pivot map applied to points (boundary to boundary,
//   interior to interior) and its solid angle against the integral of the pivot's Jacobian;
// - the diffuse lobe against a 1D quadrature of cos over the clipped cap (exact up to float);
// - the glossy lobes (conductors, plastic) against a Monte Carlo integral of bsdf_eval times cos
//   over the cap (uniform-in-cap and BSDF samples combined by the balance heuristic, double
//   accumulation, fixed stratified points), reporting the error distribution that
//   docs/cap-integral.md quotes and bounding it there;
// - the small-cap limit of the mean, positivity and finiteness over random and extreme inputs.
#include "bsdf/bsdf.h"
#include "bsdf/cap_integral.h"
#include "shading.h"
#include "support/double3.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace {

constexpr double kPi = 3.14159265358979323846;

double omc(double r) {
  double s = std::sin(0.5 * r);
  return 2.0 * s * s;
}

// Any unit vector orthogonal to unit a, and the third axis.
void basis(D3 a, D3* t, D3* b) {
  D3 h = std::fabs(a.x) < 0.6 ? D3{1, 0, 0} : D3{0, 1, 0};
  *t = dunit(dcross(a, h));
  *b = dcross(a, *t);
}

D3 random_unit(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double z = 2.0 * u(rng) - 1.0, phi = 2.0 * kPi * u(rng), s = std::sqrt(1.0 - z * z);
  return {s * std::cos(phi), s * std::sin(phi), z};
}

float3 f3(D3 v) {
  return make_float3(float(v.x), float(v.y), float(v.z));
}

// Half-angle of the arc of the circle {angle rho from a} inside the cap (b, rb), d = angle(a, b):
// cos psi = (cos rb - cos d cos rho) / (sin d sin rho), clamped (0: outside, pi: inside).
double arc_inside(double rho, double d, double rb) {
  double sd = std::sin(d), sr = std::sin(rho);
  double num = std::cos(rb) - std::cos(d) * std::cos(rho);
  double den = sd * sr;
  if (!(den > 0.0)) return (d + rho <= rb) || (rho + rb >= 2 * kPi - d && rho > 0) ? kPi : 0.0;
  double c = num / den;
  if (c >= 1.0) return 0.0;
  if (c <= -1.0) return kPi;
  return std::acos(c);
}

// |A n B| = int_0^ra sin(rho) 2 psi(rho) drho, Gauss-Legendre on panels split at the kinks
// rho = |d - rb| and d + rb (and 2 pi - d - rb), where psi has square-root ends.
double lens_quadrature(double ra, double rb, double d) {
  static const double x5[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                               0.9061798459386640};
  static const double w5[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                               0.4786286704993665, 0.2369268850561891};
  std::vector<double> cuts = {0.0, ra};
  for (double k : {std::fabs(d - rb), d + rb, 2 * kPi - d - rb})
    if (k > 0.0 && k < ra) cuts.push_back(k);
  std::sort(cuts.begin(), cuts.end());
  double sum = 0.0;
  for (size_t p = 0; p + 1 < cuts.size(); ++p) {
    double lo = cuts[p], hi = cuts[p + 1];
    // Substitution rho = lo + (hi - lo) (1 - (1 - t)^2) ... on both ends: t in [0, 1] mapped by
    // a smooth-step that clusters the nodes at both ends (the square-root kinks).
    const int panels = 200;
    for (int q = 0; q < panels; ++q)
      for (int k = 0; k < 5; ++k) {
        double t = (q + 0.5 + 0.5 * x5[k]) / panels; // in [0, 1]
        double s = t * t * (3.0 - 2.0 * t), ds = 6.0 * t * (1.0 - t);
        double rho = lo + (hi - lo) * s;
        sum += w5[k] * 0.5 / panels * ds * (hi - lo) * std::sin(rho) * 2.0 * arc_inside(rho, d, rb);
      }
  }
  return sum;
}

// The pivot map in double (Dupuy et al. 2017): the second intersection of the line through w and
// xi with the unit sphere.
D3 pivot(D3 w, D3 xi) {
  D3 dv = xi - w;
  double s = 2.0 * (1.0 - ddot(w, xi)) / ddot(dv, dv);
  return w + dv * s;
}

float area_f(D3 a, double ra, D3 b, double rb) {
  return cap_intersection_area(f3(a), float(std::sin(ra)), float(std::cos(ra)), f3(b),
                               float(std::sin(rb)), float(std::cos(rb)));
}

} // namespace

TEST(CapIntegral, IntersectionAreaExactCases) {
  D3 z = {0, 0, 1}, x = {1, 0, 0};
  // Two hemispheres whose axes are d apart meet in a lune of angle pi - d: area 2 (pi - d).
  for (double d : {0.1, 0.5, kPi / 2, 2.0, 3.0}) {
    D3 b = {std::sin(d), 0, std::cos(d)};
    EXPECT_NEAR(area_f(z, kPi / 2, b, kPi / 2), 2.0 * (kPi - d), 2e-5) << d;
  }
  EXPECT_NEAR(area_f(z, kPi / 2, x, kPi / 2), kPi, 2e-6);
  // Nested: the smaller cap (also for caps larger than a hemisphere).
  D3 b = {std::sin(0.2), 0, std::cos(0.2)};
  EXPECT_NEAR(area_f(z, 0.5, b, 0.1), 2 * kPi * omc(0.1), 1e-7);
  EXPECT_NEAR(area_f(z, 2.8, b, 2.5), 2 * kPi * omc(2.5), 1e-5);
  EXPECT_NEAR(area_f(z, 1e-4, z, 2.0), 2 * kPi * omc(1e-4), 1e-15);
  // Disjoint.
  EXPECT_EQ(area_f(z, 0.3, x, 0.3), 0.0f);
  // Together covering the sphere: |A| + |B| - 4 pi.
  EXPECT_NEAR(area_f(z, 2.5, x, 2.5), 2 * (2 * kPi * omc(2.5)) - 4 * kPi, 2e-5);
  // The whole sphere (u = pi) with anything: the other cap.
  EXPECT_NEAR(
      cap_intersection_area(f3(z), 0.0f, -1.0f, f3(x), float(std::sin(0.7)), float(std::cos(0.7))),
      2 * kPi * omc(0.7), 1e-6);
}

// Random caps of every size against the 1D quadrature; tiny caps straddling a large cap's
// boundary (the chord branch below 1e-3 rad) relative to their own area.
TEST(CapIntegral, IntersectionAreaMatchesQuadrature) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst_abs = 0, worst_small = 0;
  for (int i = 0; i < 400; ++i) {
    D3 a = random_unit(rng), b = random_unit(rng);
    double ra = 0.02 + 3.1 * u(rng), rb = 0.02 + 3.1 * u(rng);
    double d = std::atan2(dlen(dcross(a, b)), ddot(a, b));
    double ref = lens_quadrature(ra, rb, d);
    double got = area_f(a, ra, b, rb);
    // float inputs (axes rounded to 6e-8, angles through sin/cos) and float atan2/sqrt: the area
    // moves by at most ~perimeter x 1e-6 < 2e-5 sr.
    EXPECT_NEAR(got, ref, 2e-5) << "ra " << ra << " rb " << rb << " d " << d;
    worst_abs = std::max(worst_abs, std::fabs(got - ref));
  }
  for (double r : {1e-5, 1e-4, 5e-4, 2e-3, 1e-2}) {
    for (double rb : {0.3, 1.2, 2.5}) {
      for (double off : {-0.9, -0.5, -0.1, 0.0, 0.3, 0.8}) {
        // cap A of radius r centred off * r inside the boundary of B (positive: inside).
        double d = rb - off * r;
        D3 a = {0, 0, 1}, b = {std::sin(d), 0, std::cos(d)};
        double ref = lens_quadrature(r, rb, d);
        double got = area_f(a, r, b, rb);
        double rel = std::fabs(got - ref) / (2 * kPi * omc(r));
        // The centre's offset is known to ~1e-7 rad in float (the axis' rounding), which moves
        // the area by ~2 r 1e-7 / (pi r^2 / 2) of the cap; the chord misses the boundary's
        // curvature by O(r cot rb) below 1e-3 rad; the lens formula loses ~1e-7 / r above.
        double bound = 2e-7 / r + 2.0 * r / std::tan(std::min(rb, kPi - rb)) + 1e-4;
        EXPECT_LT(rel, bound) << "r " << r << " rb " << rb << " off " << off;
        worst_small = std::max(worst_small, rel);
      }
    }
  }
  std::printf("intersection area: worst abs error %.3g sr (random caps), worst relative error "
              "%.3g (small caps on a boundary)\n",
              worst_abs, worst_small);
}

// The pivot image: boundary points land on the image circle, interior points inside, and its
// solid angle is the integral of the pivot's Jacobian lambda^2 = ((1 - |xi|^2) / |w - xi|^2)^2
// over the cap (Dupuy et al. 2017, Eq. 3: D_xi = lambda^2 / 4 pi is the pivoted uniform density).
TEST(CapIntegral, PivotMapsCapsToCaps) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 100; ++i) {
    D3 xi = random_unit(rng) * (0.9 * std::cbrt(u(rng))); // lambda^2 <= 361
    double m = 1.0 - ddot(xi, xi);
    D3 a = random_unit(rng);
    double r = i % 4 == 0 ? 1e-4 * (1 + 9 * u(rng)) : 0.01 + 3.1 * u(rng);
    float ps, pc;
    float3 pa =
        cap_pivot(f3(xi), float(m), f3(a), float(std::sin(r)), float(std::cos(r)), &ps, &pc);
    D3 axis = d3(pa);
    double rp = std::atan2(double(ps), double(pc));
    D3 t, b;
    basis(a, &t, &b);
    double jac = 0.0;
    const int n = 64;
    for (int k = 0; k < n; ++k) {
      double phi = 2 * kPi * (k + 0.5) / n;
      D3 dir = t * std::cos(phi) + b * std::sin(phi);
      D3 w = a * std::cos(r) + dir * std::sin(r);
      D3 pw = pivot(w, xi);
      double ang = std::atan2(dlen(dcross(pw, axis)), ddot(pw, axis));
      // Image radius error: the pivot magnifies by up to 2 / (1 - |xi|) ~ 200 for |xi| = 0.99.
      EXPECT_NEAR(ang, rp, 4e-5 + 2e-5 * rp) << i;
      D3 wi = a * std::cos(0.5 * r) + dir * std::sin(0.5 * r); // interior
      D3 pwi = pivot(wi, xi);
      EXPECT_LT(std::atan2(dlen(dcross(pwi, axis)), ddot(pwi, axis)), rp) << i;
    }
    // Solid angle of the image = int_C lambda^2, midpoint rule in (cos rho, phi), over C or, if
    // C holds lambda's peak (the direction of xi), over its complement (|P(C)| = 4 pi - that).
    bool flip = ddot(a, dunit(xi)) > std::cos(r);
    D3 ca = flip ? a * -1.0 : a;
    double cr = flip ? kPi - r : r;
    D3 t2, b2;
    basis(ca, &t2, &b2);
    const int nr = 400, np = 256;
    double o = omc(cr);
    for (int p = 0; p < nr; ++p) {
      double z = 1.0 - o * (p + 0.5) / nr; // cos rho uniform: equal-area rings
      double s = std::sqrt(std::max(0.0, 1.0 - z * z));
      for (int q = 0; q < np; ++q) {
        double phi = 2 * kPi * (q + 0.5) / np;
        D3 w = ca * z + (t2 * std::cos(phi) + b2 * std::sin(phi)) * s;
        D3 dv = w - xi;
        double lam = m / ddot(dv, dv);
        jac += lam * lam;
      }
    }
    jac *= 2 * kPi * o / (double(nr) * np);
    if (flip) jac = 4 * kPi - jac;
    double img = 2 * kPi * omc(rp);
    EXPECT_NEAR(img, jac, 1e-3 * jac + 1e-6) << i << " r " << r;
  }
}

// ---------------------------------------------------------------- diffuse

// int over the cap (axis at angle w from the normal, half-angle r) of max(cos theta, 0):
// rings of radius rho about the axis, each with the closed-form integral over phi of
// max(A + B cos phi, 0), A = cos rho cos w, B = sin rho sin w; Gauss-Legendre panels.
double cosine_quadrature(double w, double r) {
  static const double x5[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                               0.9061798459386640};
  static const double w5[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                               0.4786286704993665, 0.2369268850561891};
  std::vector<double> cuts = {0.0, r};
  for (double k : {std::fabs(kPi / 2 - w), kPi / 2 + w, 1.5 * kPi - w})
    if (k > 0 && k < r) cuts.push_back(k);
  std::sort(cuts.begin(), cuts.end());
  double sum = 0;
  for (size_t p = 0; p + 1 < cuts.size(); ++p) {
    double lo = cuts[p], hi = cuts[p + 1];
    const int panels = 200;
    for (int q = 0; q < panels; ++q)
      for (int k = 0; k < 5; ++k) {
        double t = (q + 0.5 + 0.5 * x5[k]) / panels;
        double s = t * t * (3.0 - 2.0 * t), ds = 6.0 * t * (1.0 - t);
        double rho = lo + (hi - lo) * s;
        double A = std::cos(rho) * std::cos(w), B = std::sin(rho) * std::sin(w);
        double ring;
        if (A >= std::fabs(B))
          ring = 2 * kPi * A;
        else if (A <= -std::fabs(B))
          ring = 0;
        else {
          double psi = std::acos(-A / std::fabs(B));
          ring = 2 * (A * psi + std::fabs(B) * std::sin(psi));
        }
        sum += w5[k] * 0.5 / panels * ds * (hi - lo) * std::sin(rho) * ring;
      }
  }
  return sum;
}

TEST(CapIntegral, DiffuseMatchesQuadrature) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst = 0, worst_abs = 0;
  int straddling = 0;
  for (int i = 0; i < 3000; ++i) {
    double r = i % 3 == 0 ? std::exp(std::log(1e-6) * u(rng)) : kPi * u(rng);
    // Axes spread over the sphere, a third of them within r of the horizon.
    double w = i % 3 == 1 ? kPi / 2 + r * (2 * u(rng) - 1) : kPi * u(rng);
    w = std::clamp(w, 0.0, kPi);
    float cw = float(std::cos(w)), sw = float(std::sin(w)), sr = float(std::sin(r)),
          cr = float(std::cos(r));
    // The reference at the angles the float inputs represent, so only the formula's rounding
    // is measured.
    double ref =
        cosine_quadrature(std::atan2(double(sw), double(cw)), std::atan2(double(sr), double(cr)));
    float got = cap_cosine_integral(cw, sw, sr, cr);
    if (std::fabs(w - kPi / 2) < r && r < kPi / 2) ++straddling;
    // The formula's terms are at most ~pi sin^2 r + 2 sin r (pi + 2 for the complement of a
    // cap larger than a hemisphere). Their rounding is a few ulps, but where the cap's circle
    // nearly coincides with the horizon (r ~ pi/2, axis ~ normal) the terms q cos r and
    // atan(q / cos r) amplify the inputs' own rounding (sin r and cos r are not exactly on the
    // unit circle) by ~1 / cos r: measured worst 4e-6 of the scale; bounded at 1e-5.
    double scale = r < kPi / 2 ? kPi * sr * sr + 2.0 * sr : kPi + 2.0;
    double bound = 1e-5 * ref + 1e-5 * scale;
    EXPECT_NEAR(got, ref, bound) << "w " << w << " r " << r;
    worst_abs = std::max(worst_abs, std::fabs(got - ref) / scale);
    if (ref > 1e-3 * scale) worst = std::max(worst, std::fabs(got - ref) / ref);
  }
  EXPECT_GT(straddling, 500);
  // The whole sphere and the upper hemisphere: pi.
  EXPECT_NEAR(cap_cosine_integral(0.3f, std::sqrt(1 - 0.09f), 0.0f, -1.0f), kPi, 1e-6);
  EXPECT_NEAR(cap_cosine_integral(1.0f, 0.0f, 1.0f, 0.0f), kPi, 1e-6);
  std::printf(
      "diffuse: worst error %.3g of the terms' scale, %.3g relative (results > 1e-3 of it)\n",
      worst_abs, worst);
}

namespace {

Material diffuse_mat(float r, float g, float b) {
  Material m{};
  m.albedo = make_float4(r, g, b, 0);
  m.type = MATERIAL_DIFFUSE;
  return m;
}

Material conductor_mat(float3 eta, float3 k, float alpha) {
  Material m{};
  m.specular = f4_from3(eta, 0);
  m.k = f4_from3(k, 0);
  m.alpha = alpha;
  m.type = MATERIAL_CONDUCTOR;
  return m;
}

Material plastic_mat(float alpha) {
  Material m{};
  m.albedo = make_float4(0.5f, 0.3f, 0.1f, 0);
  m.specular = make_float4(1.0f, 0.9f, 0.8f, 0);
  m.ior = 1.5f;
  m.alpha = alpha;
  m.type = MATERIAL_PLASTIC;
  return m;
}

// Conductors (eta, k at R, G, B; pbrt's measured data at ~650, 550, 450 nm).
struct Metal {
  const char* name;
  float3 eta, k;
};
const Metal kMetals[] = {
    {"gold", {0.18f, 0.42f, 1.37f}, {3.42f, 2.35f, 1.77f}},
    {"copper", {0.27f, 0.68f, 1.22f}, {3.61f, 2.62f, 2.29f}},
    {"aluminium", {1.66f, 0.88f, 0.52f}, {9.22f, 6.27f, 4.84f}},
};

float mean3(float3 v) {
  return (v.x + v.y + v.z) / 3.0f;
}

// Reference S over the cap (c, r) in the local frame (z = normal): the balance heuristic of
// n uniform-in-cap directions and n bsdf_sample directions (R2 sequence with fixed offsets),
// bsdf_eval in float, sums in double.
double reference_integral(const Material& m, float3 wo, D3 c, double r, int n) {
  D3 t, b;
  basis(c, &t, &b);
  double o = omc(r), area = 2 * kPi * o;
  auto in_cap = [&](D3 w) { return 1.0 - ddot(w, c) <= o; };     // w.c >= cos r, for tiny r too
  const double g1 = 0.7548776662466927, g2 = 0.5698402909980532; // R2 (Roberts 2018)
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    double u1 = std::fmod(0.31 + g1 * (i + 1), 1.0), u2 = std::fmod(0.77 + g2 * (i + 1), 1.0);
    // Uniform in the cap: 1 - cos rho = u1 (1 - cos r).
    double om = u1 * o;
    double z = 1.0 - om, s = std::sqrt(std::max(0.0, om * (2.0 - om)));
    D3 w = c * z + (t * std::cos(2 * kPi * u2) + b * std::sin(2 * kPi * u2)) * s;
    if (w.z > 0) {
      float3 wf = f3(w);
      double f = mean3(bsdf_eval(&m, wo, wf)) * w.z;
      double p_bsdf = bsdf_pdf(&m, wo, wf);
      sum += f / (n / area + n * p_bsdf);
    }
    // A BSDF sample.
    double u3 = std::fmod(0.13 + 0.5 * g1 * (i + 1) + 0.618 * g2 * (i + 1), 1.0);
    BsdfSample bs = bsdf_sample(&m, wo, make_float3(float(u1), float(u2), float(u3)));
    if (bs.pdf > 0 && !bs.is_delta && bs.wi.z > 0) {
      D3 wb = d3(bs.wi);
      if (in_cap(wb)) {
        double f = mean3(bsdf_eval(&m, wo, bs.wi)) * wb.z;
        sum += f / (n / area + n * double(bs.pdf));
      }
    }
  }
  return sum;
}

struct Case {
  std::string what;
  double abs_err; // |S - S_ref| / lobe albedo
  double rel_err; // |S - S_ref| / S_ref
  double share;   // S_ref / lobe albedo
};

void percentiles(std::vector<double> v, const char* name, double* p50, double* p90, double* p99,
                 double* mx) {
  std::sort(v.begin(), v.end());
  auto at = [&](double q) { return v[std::min(v.size() - 1, size_t(q * double(v.size())))]; };
  *p50 = at(0.5);
  *p90 = at(0.9);
  *p99 = at(0.99);
  *mx = v.back();
  std::printf("  %-34s n %6zu  median %.4f  p90 %.4f  p99 %.4f  max %.4f\n", name, v.size(), *p50,
              *p90, *p99, *mx);
}

// The caps of one configuration: sizes from 1e-4 rad to pi, centred on the mirror direction, a
// lobe width or a few away from it, at random, and straddling the horizon.
std::vector<std::pair<D3, double>> test_caps(float3 wo, double alpha, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::pair<D3, double>> caps;
  D3 mirror = {-double(wo.x), -double(wo.y), double(wo.z)};
  const double sizes[] = {1e-4, 1e-3, 0.01, 0.03, 0.1, 0.2, 0.4, 0.7, 1.0, 1.5, 2.2, kPi};
  double width = std::max(2.0 * alpha, 1e-3);
  for (double r : sizes) {
    std::vector<D3> centres;
    centres.push_back(mirror);
    for (double k : {0.5, 1.5, 4.0}) {
      D3 t, b;
      basis(mirror, &t, &b);
      double phi = 2 * kPi * u(rng), a = k * width;
      centres.push_back(
          dunit(mirror * std::cos(a) + (t * std::cos(phi) + b * std::sin(phi)) * std::sin(a)));
    }
    centres.push_back(random_unit(rng));
    D3 up = random_unit(rng);
    up.z = std::fabs(up.z);
    centres.push_back(up);
    // Straddling: the axis within r of the horizon (on either side).
    double e = std::clamp(r * (2 * u(rng) - 1), -kPi / 2, kPi / 2), phi = 2 * kPi * u(rng);
    centres.push_back({std::cos(e) * std::cos(phi), std::cos(e) * std::sin(phi), std::sin(e)});
    for (D3 c : centres)
      caps.push_back({c, r});
  }
  return caps;
}

} // namespace

// The glossy materials against the Monte Carlo reference over many caps; docs/cap-integral.md
// quotes the printed distribution. Bounds: see there (they are the measured figures rounded up
// by a margin for the reference's own noise, not tuned per case).
TEST(CapIntegral, GlossyMatchesReference) {
  std::mt19937 rng(2019);
  std::vector<Material> mats;
  for (double rough : {0.05, 0.1, 0.2, 0.4, 0.7, 1.0}) {
    float alpha = float(rough * rough);
    for (const Metal& mt : kMetals)
      mats.push_back(conductor_mat(mt.eta, mt.k, alpha));
    mats.push_back(plastic_mat(alpha));
  }
  // Errors for theta_o <= 60 degrees and for 75, 85 degrees (where the GGX lobe is anisotropic
  // and the SPTD, isotropic about its peak, fits it least well).
  std::vector<double> abs_err[2], rel_big[2];
  const int n = 1024;
  for (const Material& m : mats) {
    for (double theta_deg : {0.0, 30.0, 60.0, 75.0, 85.0}) {
      int g = theta_deg > 60.0;
      double th = theta_deg * kPi / 180;
      float3 wo = make_float3(float(std::sin(th)), 0.0f, float(std::cos(th)));
      // A random world frame: the API works in world space.
      Frame fr = frame_from(f3(random_unit(rng)));
      CapLobe lobe = cap_lobe_make(&m, &fr, frame_to_world(&fr, wo));
      double albedo = reference_integral(m, wo, {0, 0, 1}, kPi, 8 * n);
      for (auto [c, r] : test_caps(wo, m.alpha, rng)) {
        double ref = reference_integral(m, wo, c, r, n);
        float mean;
        float got = cap_lobe_integral(&lobe, frame_to_world(&fr, f3(c)), float(std::sin(r)),
                                      float(std::cos(r)), &mean);
        abs_err[g].push_back(std::fabs(got - ref) / albedo);
        if (ref > 0.1 * albedo) rel_big[g].push_back(std::fabs(got - ref) / ref);
      }
    }
  }
  // Bounds: the figures docs/cap-integral.md quotes (measured with the committed table), with
  // headroom of ~1.5x for a refit; a change that breaks the fit or the geometry moves them by
  // far more.
  const char* group[2] = {"theta_o 0..60", "theta_o 75, 85"};
  const double bound_abs[2][4] = {{0.001, 0.012, 0.05, 0.2}, {0.002, 0.04, 0.15, 0.4}};
  const double bound_rel[2][4] = {{0.005, 0.04, 0.25, 1.0}, {0.015, 0.15, 0.8, 1.2}};
  for (int g = 0; g < 2; ++g) {
    double q[4];
    std::printf("glossy (gold, copper, aluminium, plastic; roughness 0.05..1; %s deg):\n",
                group[g]);
    percentiles(abs_err[g], "|S - S_ref| / albedo, all caps", &q[0], &q[1], &q[2], &q[3]);
    for (int k = 0; k < 4; ++k)
      EXPECT_LT(q[k], bound_abs[g][k]) << group[g] << " abs quantile " << k;
    percentiles(rel_big[g], "|S - S_ref| / S_ref, S_ref > 10%", &q[0], &q[1], &q[2], &q[3]);
    for (int k = 0; k < 4; ++k)
      EXPECT_LT(q[k], bound_rel[g][k]) << group[g] << " rel quantile " << k;
  }
}

// The diffuse lobe through the API (world frame, mean over RGB): albedo / pi times the clipped
// cosine integral, the whole sphere gives the albedo, and the mean of a vanishing cap tends to
// albedo / pi cos theta at its centre (exact for a Lambertian lobe, up to float rounding).
TEST(CapIntegral, DiffuseLobeThroughApi) {
  Material m = diffuse_mat(0.8f, 0.5f, 0.2f);
  const double rho = (0.8 + 0.5 + 0.2) / 3.0;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 300; ++i) {
    D3 nw = random_unit(rng);
    Frame fr = frame_from(f3(nw));
    float3 wo = frame_to_world(&fr, make_float3(0.3f, 0.1f, 0.94868f));
    CapLobe l = cap_lobe_make(&m, &fr, wo);
    EXPECT_FALSE(cap_lobe_is_glossy(&l));
    double r = i % 2 ? kPi * u(rng) : std::exp(std::log(1e-6) * u(rng));
    double w = kPi * u(rng), phi = 2 * kPi * u(rng);
    D3 cl = {std::sin(w) * std::cos(phi), std::sin(w) * std::sin(phi), std::cos(w)};
    float mean;
    float s = cap_lobe_integral(&l, frame_to_world(&fr, f3(cl)), float(std::sin(r)),
                                float(std::cos(r)), &mean);
    double ref = rho / kPi * cosine_quadrature(w, r);
    // As DiffuseMatchesQuadrature, plus the frame's rotation of c (a few 1e-7 in cos w, which
    // moves the clipped integral by up to the horizon chord 2 sin r times that).
    double sr = std::sin(std::min(r, kPi / 2));
    double bound = 1e-5 * ref + rho / kPi * (1e-5 * (kPi * sr * sr + 2 * sr) + 2 * sr * 5e-7);
    if (ref > 0) {
      EXPECT_NEAR(s, ref, bound) << "w " << w << " r " << r;
    } else {
      EXPECT_EQ(s, 0.0f) << "w " << w << " r " << r;
    }
    if (r < 1e-4 && std::cos(w) > 1e-3) {
      EXPECT_NEAR(mean, rho / kPi * std::cos(w), 1e-3 * rho / kPi * std::cos(w) + 1e-6);
    }
  }
  Frame fr = frame_from(make_float3(0, 0, 1));
  CapLobe l = cap_lobe_make(&m, &fr, make_float3(0, 0, 1));
  float mean;
  EXPECT_NEAR(cap_lobe_integral(&l, make_float3(1, 0, 0), 0.0f, -1.0f, &mean), rho, 1e-6);
  EXPECT_NEAR(mean, rho / (4 * kPi), 1e-7);
  EXPECT_NEAR(cap_lobe_integral(&l, make_float3(0, 0, 1), 1.0f, 0.0f, &mean), rho, 1e-6);
  // A viewer below the horizon sees nothing (bsdf_eval is 0 there).
  CapLobe below = cap_lobe_make(&m, &fr, make_float3(0, 0.6f, -0.8f));
  EXPECT_EQ(cap_lobe_integral(&below, make_float3(0, 0, 1), 1.0f, 0.0f, &mean), 0.0f);
  EXPECT_EQ(mean, 0.0f);
}

// The small-cap limit: as u -> 0 the mean tends to the model's f cos at the centre, computed
// without cancellation (u = 1e-6 and 1e-3 agree), and that is the fit's pointwise approximation
// of bsdf_eval x cos: its error at directions drawn from the lobe (where lights matter) is
// reported and bounded (docs/cap-integral.md).
TEST(CapIntegral, SmallCapLimit) {
  std::vector<double> rel;
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (double rough : {0.05, 0.1, 0.2, 0.4, 0.7, 1.0}) {
    for (int mt = 0; mt < 4; ++mt) {
      Material m = mt < 3 ? conductor_mat(kMetals[mt].eta, kMetals[mt].k, float(rough * rough))
                          : plastic_mat(float(rough * rough));
      if (mt == 3) m.albedo = make_float4(0, 0, 0, 0); // the coat alone
      for (double theta_deg : {0.0, 30.0, 60.0, 75.0, 85.0}) {
        double th = theta_deg * kPi / 180;
        float3 wo = make_float3(float(std::sin(th)), 0.0f, float(std::cos(th)));
        Frame fr = frame_from(make_float3(0, 0, 1));
        CapLobe l = cap_lobe_make(&m, &fr, wo);
        for (int i = 0; i < 64; ++i) {
          BsdfSample bs = bsdf_sample(&m, wo, make_float3(u(rng), u(rng), u(rng)));
          if (!(bs.pdf > 0) || bs.wi.z < 1e-3f) continue;
          float3 c = bs.wi;
          double fc = mean3(bsdf_eval(&m, wo, c)) * c.z;
          float mean6, mean5;
          cap_lobe_integral(&l, c, 1e-6f, 1.0f, &mean6);
          cap_lobe_integral(&l, c, 1e-5f, 1.0f, &mean5);
          // Caps of 1e-6 and 1e-5 rad are far below every lobe width here (2 alpha >= 5e-3): the
          // lobe's curvature over them is < (1e-5 / 2.5e-3)^2 ~ 2e-5, so the means agree to
          // float rounding unless a 1 - cos cancellation in the cap's solid angle (or S) shows.
          EXPECT_NEAR(mean6, mean5, 1e-3 * mean6) << rough << " " << theta_deg;
          rel.push_back(std::fabs(mean6 - fc) / fc);
        }
      }
    }
  }
  double p50, p90, p99, mx;
  std::printf("small-cap limit (u = 1e-6), directions drawn from the lobe:\n");
  percentiles(rel, "|mean - f cos| / f cos", &p50, &p90, &p99, &mx);
  // The limit is the exact GGX f cos times the per-cap Fresnel: exact for the plastic coat,
  // Lazanyi's approximation for the conductors (within 1.1% of the exact mean-RGB Fresnel for
  // these metals over cos in [0.02, 1]), plus float rounding.
  EXPECT_LT(mx, 0.03);
}

// Positivity (the light sampler's unbiasedness): S > 0 and mean > 0 wherever the cap reaches
// above the horizon and the material reflects, exactly 0 where it lies entirely below or the
// viewer is below the horizon; the glossy flag follows the material; finite
// everywhere, including grazing viewers (wo.z down to 1e-3), alpha from 1e-4 to 1, caps from
// 1e-6 rad to the whole sphere.
TEST(CapIntegral, PositiveAboveHorizonZeroBelowFinite) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int above = 0, below = 0;
  for (int i = 0; i < 20000; ++i) {
    Material m;
    float alpha = float(std::exp(std::log(1e-4) * u(rng)));
    int type = i % 3;
    if (type == 0)
      m = diffuse_mat(0.5f, 0.2f, 0.1f);
    else if (type == 1)
      m = conductor_mat(kMetals[i % 3].eta, kMetals[i % 3].k, alpha);
    else
      m = plastic_mat(alpha);
    D3 nw = random_unit(rng);
    Frame fr = frame_from(f3(nw));
    // Grazing viewers, and some below the horizon (bsdf_eval is 0 there: so is S).
    double zo = i % 4 == 0 ? 1e-3 : (i % 11 == 1 ? -u(rng) : u(rng)), phi = 2 * kPi * u(rng);
    double so = std::sqrt(1 - zo * zo);
    float3 wo = frame_to_world(
        &fr, make_float3(float(so * std::cos(phi)), float(so * std::sin(phi)), float(zo)));
    CapLobe l = cap_lobe_make(&m, &fr, wo);
    EXPECT_EQ(cap_lobe_is_glossy(&l), type != 0) << i; // alpha >= 1e-4 > 0
    // Log-uniform in [1e-6, pi], the whole sphere and the smallest cap.
    double r =
        i % 5 == 0 ? kPi : std::exp(std::log(1e-6) + (std::log(kPi) - std::log(1e-6)) * u(rng));
    if (i % 7 == 0) r = 1e-6;
    // Centres: random, and near the horizon within a few cap radii.
    D3 cl = random_unit(rng);
    if (i % 2 == 1) {
      double e = std::clamp((2 * u(rng) - 1) * 3 * r, -kPi / 2, kPi / 2), ph = 2 * kPi * u(rng);
      cl = {std::cos(e) * std::cos(ph), std::cos(e) * std::sin(ph), std::sin(e)};
    }
    float3 c = normalize(frame_to_world(&fr, f3(cl)));
    float su = float(std::sin(r)), cu = float(std::cos(r));
    if (r == kPi) su = 0.0f, cu = -1.0f;
    float mean = -1;
    float s = cap_lobe_integral(&l, c, su, cu, &mean);
    ASSERT_TRUE(std::isfinite(s) && std::isfinite(mean)) << i;
    // The float centre's own angle to the normal decides (as the function sees it).
    float cw = dot(c, fr.n);
    bool reaches = (cu < 0 || cw > -su) && zo > 0;
    if (reaches) {
      EXPECT_GT(s, 0.0f) << i << " r " << r << " cos_w " << cw;
      EXPECT_GT(mean, 0.0f) << i;
      ++above;
    } else {
      EXPECT_EQ(s, 0.0f) << i;
      EXPECT_EQ(mean, 0.0f) << i;
      ++below;
    }
  }
  EXPECT_GT(above, 5000);
  EXPECT_GT(below, 2000);
}
