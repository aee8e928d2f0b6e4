// End-to-end renders of a homogeneous participating medium against exact answers computed here
// by quadrature (issue 13). A diffuse plane z = 0 under point lights, a camera above it looking
// down through the lit medium, max_depth 1: a pixel's radiance is the single scattering along its
// camera ray up to the plane plus the plane's attenuated direct light,
//   L = sum_l [ int sigma_s p(cos theta) I_l T(x(t), l) T(o, x(t)) / r^2 dt
//               + T(o, x_p) albedo/pi I_l cos_l T(x_p, l) / r_p^2 ],
// T the transmittance exp(-sigma_t * length inside the medium), p the Henyey-Greenstein phase
// function with theta between the light's direction of travel before (x - l) and after (-d)
// scattering (docs/scene-format.md, "medium"). Nothing occludes: the lights and the camera are
// above the plane.
//
// The reference is computed in double: for each light the integral along the ray is taken in the
// equiangular variable phi (t = t* + h tan phi, Kulla & Fajardo 2012, which turns dt / r^2 into
// dphi / h and leaves a smooth integrand) by composite Gauss-Legendre, and the pixel's box filter
// by a midpoint rule over a sub-pixel grid. Both quadrature errors are measured (half the panels,
// half the grid) and added to the bound; the renderer's pixel means must match within k standard
// errors of their own sample variance, k from a Bonferroni correction over all the comparisons.
//   a. an unbounded medium (the camera inside it), three lights;
//   b. a bounded box the camera looks into from outside, the plane behind it, one light inside
//      the box and one outside: the reference clips the camera ray and every light leg to the box.
// The lights are just outside the frame (their light fills it): a light in view would make its
// pixel's variance infinite (see lights_outside_the_frame). A 10% error in g or in the light legs'
// transmittance fails both scenes (tried when the test was written).
#include "render/camera.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "support/double3.h"

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

using namespace canopy;

namespace {

// ---------------------------------------------------------------- double vectors
using V3 = D3; // support/double3.h
double dot(V3 a, V3 b) {
  return ddot(a, b);
}
double len(V3 a) {
  return dlen(a);
}
double comp(V3 a, int k) {
  return k == 0 ? a.x : k == 1 ? a.y : a.z;
}
V3 v3(float4 f) {
  return {double(f.x), double(f.y), double(f.z)};
}

using Rgb = std::array<double, 3>;

// ---------------------------------------------------------------- the test scenes
struct PointL {
  V3 p;
  Rgb I;
};

struct FogScene {
  std::string name;
  V3 cam, look_at, up{0, 0, 1};
  double fov;
  int width = 24, height = 16;
  Rgb albedo;
  Rgb sigma_a, sigma_s;
  double g;
  float split_threshold = LT_DEFAULT_SPLIT_THRESHOLD; // tree-split's
  bool bounded = false;
  V3 bmin{0, 0, 0}, bmax{0, 0, 0};
  std::vector<PointL> lights;
};

std::string num(double v) {
  return fmt::format("{:.17g}", v);
}
std::string vec(V3 v) {
  return fmt::format("[{}, {}, {}]", num(v.x), num(v.y), num(v.z));
}
std::string rgb(const Rgb& c) {
  return fmt::format("[{}, {}, {}]", num(c[0]), num(c[1]), num(c[2]));
}

std::string scene_json(const FogScene& s, const std::string& sampler) {
  std::string lights;
  for (const PointL& l : s.lights)
    lights += fmt::format(R"({}{{"type": "point", "position": {}, "intensity": {}}})",
                          lights.empty() ? "" : ", ", vec(l.p), rgb(l.I));
  std::string bounds =
      s.bounded ? fmt::format(R"(, "bounds": {{"min": {}, "max": {}}})", vec(s.bmin), vec(s.bmax))
                : std::string();
  // The plane: 100 x 100 around the origin, facing +z (edge1 x edge2 = +z), larger than every
  // camera ray's footprint so that every ray ends on it.
  return fmt::format(
      R"({{"camera": {{"position": {cam}, "look_at": {at}, "up": {up}, "fov": {fov}}},
          "film": {{"width": {w}, "height": {h}}},
          "integrator": {{"max_depth": 1, "light_sampler": "{sampler}"}},
          "medium": {{"sigma_a": {sa}, "sigma_s": {ss}, "g": {g}{bounds}}},
          "materials": [{{"name": "plane", "albedo": {alb}}}],
          "shapes": [{{"type": "quad", "corner": [-50, -50, 0], "edge1": [100, 0, 0],
                       "edge2": [0, 100, 0], "material": "plane"}}],
          "lights": [{lights}]}})",
      fmt::arg("cam", vec(s.cam)), fmt::arg("at", vec(s.look_at)), fmt::arg("up", vec(s.up)),
      fmt::arg("fov", num(s.fov)), fmt::arg("w", s.width), fmt::arg("h", s.height),
      fmt::arg("sampler", sampler), fmt::arg("sa", rgb(s.sigma_a)), fmt::arg("ss", rgb(s.sigma_s)),
      fmt::arg("g", num(s.g)), fmt::arg("bounds", bounds), fmt::arg("alb", rgb(s.albedo)),
      fmt::arg("lights", lights));
}

// ---------------------------------------------------------------- the exact answer
// The medium as loaded (float values, in double).
struct Med {
  Rgb sigma_s, sigma_t;
  double g;
  bool bounded;
  V3 bmin, bmax;
};

// The part [t0, t1] of the ray o + t d (t0 <= t1) inside the medium, as [a, b] (empty: a >= b).
void clip(const Med& m, V3 o, V3 d, double t0, double t1, double* a, double* b) {
  *a = t0;
  *b = t1;
  if (!m.bounded) return;
  for (int k = 0; k < 3; ++k) {
    double ok = comp(o, k), dk = comp(d, k), lo = comp(m.bmin, k), hi = comp(m.bmax, k);
    if (dk == 0.0) {
      if (ok < lo || ok > hi) *b = *a; // parallel to this slab and outside it
      continue;
    }
    double ta = (lo - ok) / dk, tb = (hi - ok) / dk;
    *a = std::max(*a, std::min(ta, tb));
    *b = std::min(*b, std::max(ta, tb));
  }
}

// Length of the segment from x to y inside the medium.
double inside_length(const Med& m, V3 x, V3 y) {
  V3 e = y - x;
  double L = len(e);
  if (!m.bounded) return L;
  double a, b;
  clip(m, x, e * (1.0 / L), 0.0, L, &a, &b);
  return std::max(0.0, b - a);
}

// The medium of a setup, its coefficients rounded to float as the loader stores them.
Med med_of(const FogScene& s) {
  Med m;
  m.g = double(float(s.g));
  for (int c = 0; c < 3; ++c) {
    m.sigma_s[c] = double(float(s.sigma_s[c]));
    m.sigma_t[c] = double(float(s.sigma_a[c]) + float(s.sigma_s[c]));
  }
  m.bounded = s.bounded;
  auto f = [](V3 v) { return V3{double(float(v.x)), double(float(v.y)), double(float(v.z))}; };
  m.bmin = f(s.bmin);
  m.bmax = f(s.bmax);
  return m;
}

double hg(double cos_t, double g) {
  double den = 1.0 + g * g - 2.0 * g * cos_t;
  return (1.0 - g * g) / (4.0 * M_PI * den * std::sqrt(den));
}

// 8-point Gauss-Legendre nodes and weights on [-1, 1].
constexpr double kGlX[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                            -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                            0.7966664774136267,  0.9602898564975363};
constexpr double kGlW[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                            0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                            0.2223810344533745, 0.1012285362903763};

// Single scattering of light l along the ray o + t d (unit d), t in [ta, tb] inside the medium,
// by composite Gauss-Legendre with `panels` panels in the equiangular variable phi:
// t = t* + h tan(phi), t* the closest approach to the light, h its distance, r = h / cos(phi),
// dt / r^2 = dphi / h and cos(theta) = (l - x) . d / r = -sin(phi).
Rgb single_scatter(const Med& m, V3 o, V3 d, double ta, double tb, const PointL& l, int panels) {
  Rgb out{0, 0, 0};
  if (tb <= ta) return out;
  double ts = dot(l.p - o, d);
  double h = len(l.p - (o + d * ts));
  double pa = std::atan2(ta - ts, h), pb = std::atan2(tb - ts, h);
  double w = (pb - pa) / panels;
  for (int i = 0; i < panels; ++i)
    for (int j = 0; j < 8; ++j) {
      double phi = pa + w * (i + 0.5 + 0.5 * kGlX[j]);
      double t = ts + h * std::tan(phi);
      V3 x = o + d * t;
      // Camera leg: the part of [0, t] inside the medium; light leg: x to the light.
      double ca, cb;
      clip(m, o, d, 0.0, t, &ca, &cb);
      double tau = std::max(0.0, cb - ca), tl = inside_length(m, x, l.p);
      double f = hg(-std::sin(phi), m.g) / h * (0.5 * w * kGlW[j]);
      for (int c = 0; c < 3; ++c)
        out[c] += m.sigma_s[c] * l.I[c] * std::exp(-m.sigma_t[c] * (tau + tl)) * f;
    }
  return out;
}

struct RayRef {
  Rgb L, scatter; // total radiance, and its single-scattering part
};

// The exact radiance along one camera ray (the plane z = 0 ends it), with `panels` panels per
// light.
RayRef ray_radiance(const Med& m, const std::vector<PointL>& lights, const Rgb& albedo, V3 o, V3 d,
                    int panels) {
  RayRef r{{0, 0, 0}, {0, 0, 0}};
  double tp = -o.z / d.z; // every test ray points down
  V3 xp = o + d * tp;
  double a, b;
  clip(m, o, d, 0.0, tp, &a, &b);
  double tau_cam = std::max(0.0, b - a);
  for (const PointL& l : lights) {
    Rgb s = single_scatter(m, o, d, a, b, l, panels);
    V3 to = l.p - xp;
    double r2 = dot(to, to), cos_l = to.z / std::sqrt(r2);
    double tau_leg = inside_length(m, xp, l.p);
    for (int c = 0; c < 3; ++c) {
      double surf = cos_l > 0 ? albedo[c] / M_PI * l.I[c] * cos_l / r2 *
                                    std::exp(-m.sigma_t[c] * (tau_cam + tau_leg))
                              : 0.0;
      r.scatter[c] += s[c];
      r.L[c] += s[c] + surf;
    }
  }
  return r;
}

struct PixelRef {
  Rgb L, scatter, err; // box-filtered radiance, its scattering part, quadrature error bound
};

// The pixel's box-filtered radiance: an n x n midpoint rule over its footprint with `panels`
// panels per light, n doubled from 8 (up to 64) until |Q(n) - Q(n/2)| is below 1e-3 of the
// pixel's value (the medium box's silhouette puts kinks into the image). The error bound is
// |Q(n) - Q(n/2)| (the footprint rule) plus |Q(panels) - Q(panels/2)| on the n/2 grid (the
// equiangular integral).
PixelRef pixel_reference(const Med& m, const std::vector<PointL>& lights, const Rgb& albedo,
                         const CameraParams& cam, int px, int py, int panels) {
  V3 o = v3(cam.origin), ll = v3(cam.lower_left), du = v3(cam.du), dv = v3(cam.dv);
  auto grid = [&](int k, int pan, Rgb* scatter) {
    Rgb acc{0, 0, 0};
    if (scatter) *scatter = {0, 0, 0};
    for (int a = 0; a < k; ++a)
      for (int b = 0; b < k; ++b) {
        V3 d = ll + du * (px + (a + 0.5) / k) + dv * (py + (b + 0.5) / k);
        d = d * (1.0 / len(d));
        RayRef r = ray_radiance(m, lights, albedo, o, d, pan);
        for (int c = 0; c < 3; ++c) {
          acc[c] += r.L[c] / (k * k);
          if (scatter) (*scatter)[c] += r.scatter[c] / (k * k);
        }
      }
    return acc;
  };
  PixelRef p{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
  // The equiangular rule's error is measured once, on a 4 x 4 grid.
  const Rgb g4 = grid(4, panels, nullptr), g4_coarse = grid(4, panels / 2, nullptr);
  Rgb half = g4;
  for (int n = 8;; n *= 2) {
    p.L = grid(n, panels, &p.scatter);
    double diff = 0, top = 0;
    for (int c = 0; c < 3; ++c) {
      diff = std::max(diff, std::fabs(p.L[c] - half[c]));
      top = std::max(top, p.L[c]);
    }
    if (diff <= 1e-3 * top || n == 64) break;
    half = p.L;
  }
  for (int c = 0; c < 3; ++c)
    p.err[c] = std::fabs(p.L[c] - half[c]) + std::fabs(g4[c] - g4_coarse[c]);
  return p;
}

// k such that a two-sided normal deviation beyond k standard errors has probability alpha / m
// (Bonferroni: at most alpha false alarms over m comparisons), by bisection on erfc.
double bonferroni_k(double alpha, double m) {
  double lo = 0.0, hi = 20.0;
  for (int i = 0; i < 100; ++i) {
    double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::sqrt(2.0)) > alpha / m ? lo : hi) = mid;
  }
  return hi;
}

// Every light projects at least `margin` pixels outside the film. A light in view makes the
// single scattering of the rays through its pixel diverge like 1/h (h the ray's distance to it):
// the pixel's variance is then (logarithmically) infinite and its footprint integral converges
// slowly, so neither the pixel's standard error nor its reference would be trustworthy.
bool lights_outside_the_frame(const CameraParams& cam, const std::vector<PointL>& lights,
                              double margin) {
  V3 ll = v3(cam.lower_left), du = v3(cam.du), dv = v3(cam.dv);
  V3 fwd = ll + du * (0.5 * cam.width) + dv * (0.5 * cam.height);
  fwd = fwd * (1.0 / len(fwd));
  for (const PointL& l : lights) {
    V3 d = l.p - v3(cam.origin);
    if (dot(d, fwd) <= 0) continue;      // behind the camera
    V3 q = d * (1.0 / dot(d, fwd)) - ll; // on the image plane at distance 1
    double x = dot(q, du) / dot(du, du), y = dot(q, dv) / dot(dv, dv);
    if (x > -margin && x < cam.width + margin && y > -margin && y < cam.height + margin)
      return false;
  }
  return true;
}

struct Outcome {
  int checked = 0, violations = 0, block_violations = 0;
  double total = 0, total_ref = 0, total_var = 0, total_quad = 0, scatter_ref = 0;
  double mean_rel_bound = 0;
};

// Renders `s` with `sampler` at `spp` and compares every pixel and channel, every 4 x 4 block and
// the image total with the reference.
Outcome render_and_compare(ClRuntime& rt, const FogScene& s, const std::string& sampler, int spp,
                           int panels) {
  Scene scene = load_scene_from_string(scene_json(s, sampler), s.name + ".json", ".");
  // The reference uses the lights as loaded and the coefficients as floats, in double, in world
  // space (the loader stores positions relative to the camera, scene.origin).
  Med m = med_of(s);
  const V3 origin{scene.origin.x, scene.origin.y, scene.origin.z};
  std::vector<PointL> lights;
  for (const Light& l : scene.lights)
    lights.push_back(
        {v3(l.p) + origin, {double(l.emission.x), double(l.emission.y), double(l.emission.z)}});
  EXPECT_EQ(lights.size(), s.lights.size());

  RendererOptions opt;
  opt.light_sampler = sampler;
  opt.split_threshold = s.split_threshold;
  Renderer renderer(rt, scene, opt);
  RenderSettings rs;
  rs.spp = spp;
  rs.seed = 5;
  Film film = renderer.render(rs);
  EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
  CameraParams cam = make_camera_params(scene.camera, scene.film.width, scene.film.height);
  cam.origin = make_float4(float(origin.x), float(origin.y), float(origin.z), cam.origin.w);
  EXPECT_TRUE(lights_outside_the_frame(cam, lights, 2.0));

  const int W = film.width, H = film.height;
  // The reference of a setup is the same for every sampler: computed once per test binary.
  static std::map<std::string, std::vector<PixelRef>> cache;
  std::vector<PixelRef>& ref = cache[s.name];
  if (ref.empty()) {
    ref.resize(size_t(W) * H);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        ref[size_t(y) * W + x] = pixel_reference(m, lights, s.albedo, cam, x, y, panels);
  }

  // Pixel means and the variances of the means (from the film's second moments).
  std::vector<Rgb> mean(ref.size()), var(ref.size());
  for (size_t p = 0; p < ref.size(); ++p) {
    double n = film.sum[p].w;
    EXPECT_EQ(n, double(spp));
    const double* sm = &film.sum[p].x;
    const double* sq = &film.sumsq[p].x;
    for (int c = 0; c < 3; ++c) {
      mean[p][c] = sm[c] / n;
      var[p][c] = std::max(0.0, sq[c] / n - mean[p][c] * mean[p][c]) / (n - 1.0);
    }
  }

  const int BW = W / 4, BH = H / 4;
  const double k_pixel = bonferroni_k(1e-3, 3.0 * W * H);
  const double k_block = bonferroni_k(1e-3, 3.0 * BW * BH);
  Outcome o;
  for (size_t p = 0; p < ref.size(); ++p)
    for (int c = 0; c < 3; ++c) {
      const double r = ref[p].L[c];
      // k standard errors, the measured quadrature error and float arithmetic in the renderer.
      double bound = k_pixel * std::sqrt(var[p][c]) + ref[p].err[c] + 1e-4 * r;
      if (std::fabs(mean[p][c] - r) > bound) {
        if (o.violations < 8)
          ADD_FAILURE() << s.name << " " << sampler << ": pixel (" << p % W << "," << p / W
                        << ") ch " << c << ": mean " << mean[p][c] << " vs exact " << r
                        << " (scattering " << ref[p].scatter[c] << "), bound " << bound;
        ++o.violations;
      }
      ++o.checked;
      o.mean_rel_bound += bound / r;
      o.total += mean[p][c];
      o.total_ref += r;
      o.total_var += var[p][c];
      o.total_quad += ref[p].err[c];
      o.scatter_ref += ref[p].scatter[c];
    }
  o.mean_rel_bound /= o.checked;
  // 4 x 4 blocks: a bias that is small per pixel but spatially coherent (a wrong phase-function
  // convention moves light between the forward and backward parts of the image).
  for (int by = 0; by < BH; ++by)
    for (int bx = 0; bx < BW; ++bx)
      for (int c = 0; c < 3; ++c) {
        double bm = 0, br = 0, bv = 0, bq = 0;
        for (int y = 4 * by; y < 4 * by + 4; ++y)
          for (int x = 4 * bx; x < 4 * bx + 4; ++x) {
            size_t p = size_t(y) * W + x;
            bm += mean[p][c];
            br += ref[p].L[c];
            bv += var[p][c];
            bq += ref[p].err[c];
          }
        double bound = k_block * std::sqrt(bv) + bq + 1e-4 * br;
        if (std::fabs(bm - br) > bound) {
          if (o.block_violations < 4)
            ADD_FAILURE() << s.name << " " << sampler << ": block (" << bx << "," << by << ") ch "
                          << c << ": sum " << bm << " vs exact " << br << ", bound " << bound;
          ++o.block_violations;
        }
      }
  double total_bound = 5.0 * std::sqrt(o.total_var) + o.total_quad + 1e-4 * o.total_ref;
  std::printf("%s, %s, %d spp: %d values (k = %.2f per pixel), mean relative bound %.4f; total "
              "%.6g vs exact %.6g (%+.3f%%, bound %.3f%%, quadrature %.4f%%), scattering %.0f%% "
              "of it\n",
              s.name.c_str(), sampler.c_str(), spp, o.checked, k_pixel, o.mean_rel_bound, o.total,
              o.total_ref, 100.0 * (o.total / o.total_ref - 1.0), 100.0 * total_bound / o.total_ref,
              100.0 * o.total_quad / o.total_ref, 100.0 * o.scatter_ref / o.total_ref);
  EXPECT_NEAR(o.total, o.total_ref, total_bound);
  // The checks mean something: the total is tight, the per-pixel bounds catch gross errors, and
  // the medium's own light is a large part of the image (not a perturbation of the plane's).
  EXPECT_LT(total_bound, 0.01 * o.total_ref);
  EXPECT_LT(o.mean_rel_bound, 0.25);
  EXPECT_GT(o.scatter_ref, 0.2 * o.total_ref);
  EXPECT_EQ(o.violations, 0);
  EXPECT_EQ(o.block_violations, 0);
  return o;
}

// a. Unbounded, the camera inside it looking down at the plane: coloured coefficients (red
// scatters least, blue absorbs least), forward scattering, three lights of different colours and
// intensities just outside the frame (see lights_outside_the_frame).
FogScene unbounded_setup() {
  FogScene s;
  s.name = "unbounded";
  s.cam = {0.1, -0.4, 3.0};
  s.look_at = {0.2, 0.2, 0.0};
  s.up = {0, 1, 0};
  s.fov = 50;
  s.albedo = {0.7, 0.5, 0.35};
  s.sigma_a = {0.06, 0.1, 0.02};
  s.sigma_s = {0.25, 0.35, 0.5};
  s.g = 0.5;
  s.lights = {{{2.0, 0.2, 1.0}, {3.0, 2.0, 1.0}},
              {{-1.0, 1.6, 1.4}, {1.0, 2.5, 1.5}},
              {{0.4, -1.8, 0.6}, {0.4, 0.5, 1.2}}};
  return s;
}

// c. (a) with each light replaced by eight, spread outwards from the frame, and tree-split
// splitting every cluster it may (threshold 1): the segments' cuts hit their cap
// (LT_SEGMENT_MAX_CUT, 16 lights of 24), so the pixel means check the capped cut and the
// one-sample choice of the equiangular or free-flight point per light (volume_light.h) against
// the quadrature.
FogScene many_lights_setup() {
  FogScene s = unbounded_setup();
  s.name = "many-lights";
  s.split_threshold = 1.0f;
  std::vector<PointL> lights;
  for (const PointL& l : s.lights)
    for (int k = 0; k < 8; ++k) {
      V3 out = l.p - V3{0.2, 0.2, l.p.z};
      lights.push_back({l.p + out * (0.08 * k), {0.2 * l.I[0], 0.2 * l.I[1], 0.2 * l.I[2]}});
    }
  s.lights = lights;
  return s;
}

// b. A box of medium the camera looks into from outside: wider than the view (so a light inside
// it can be out of the frame), reaching below the plane (so the plane inside it is in the
// medium); the plane is seen through it and beyond it. One light inside the box, one outside
// (its legs into the box are clipped); backward scattering.
FogScene bounded_setup() {
  FogScene s;
  s.name = "bounded";
  s.cam = {0.3, -3.0, 2.4};
  s.look_at = {0.0, 0.0, 0.35};
  s.fov = 35;
  s.albedo = {0.6, 0.6, 0.45};
  s.sigma_a = {0.1, 0.25, 0.1};
  s.sigma_s = {0.9, 0.6, 0.45};
  s.g = -0.3;
  s.bounded = true;
  s.bmin = {-2.6, -0.7, -0.2};
  s.bmax = {2.6, 0.6, 1.0};
  s.lights = {{{2.0, 0.0, 0.5}, {1.5, 1.2, 1.0}}, {{-1.8, 1.2, 1.6}, {3.0, 3.0, 4.5}}};
  return s;
}

} // namespace

// The reference itself: the equiangular Gauss-Legendre rule against a plain midpoint rule in t
// with 2^18 steps, on rays of both scenes (near and far from the lights).
TEST(MediumReference, EquiangularQuadratureMatchesABruteForceRule) {
  for (const FogScene& s : {unbounded_setup(), bounded_setup()}) {
    Med m = med_of(s);
    for (const PointL& l : s.lights)
      for (V3 target : {l.p + V3{0.05, 0.0, 0.0}, l.p + V3{0.4, -0.3, 0.1}, V3{0.0, 0.0, 0.3}}) {
        V3 d = target - s.cam;
        d = d * (1.0 / len(d));
        double tp = -s.cam.z / d.z, a, b;
        clip(m, s.cam, d, 0.0, tp, &a, &b);
        Rgb q = single_scatter(m, s.cam, d, a, b, l, 64);
        const int N = 1 << 18;
        Rgb brute{0, 0, 0};
        for (int i = 0; i < N && b > a; ++i) {
          double t = a + (b - a) * (i + 0.5) / N;
          V3 x = s.cam + d * t;
          V3 to = l.p - x;
          double r2 = dot(to, to), r = std::sqrt(r2);
          double ca, cb;
          clip(m, s.cam, d, 0.0, t, &ca, &cb);
          double tau = std::max(0.0, cb - ca) + inside_length(m, x, l.p);
          double f = hg(dot(to, d) / r, m.g) / r2 * (b - a) / N;
          for (int c = 0; c < 3; ++c)
            brute[c] += m.sigma_s[c] * l.I[c] * std::exp(-m.sigma_t[c] * tau) * f;
        }
        for (int c = 0; c < 3; ++c)
          EXPECT_NEAR(q[c], brute[c], 1e-6 * brute[c] + 1e-12) << s.name << " ch " << c;
        if (!s.bounded) {
          EXPECT_GT(q[0], 0.0);
        }
      }
  }
}

class MediumImage : public ::testing::TestWithParam<std::tuple<int, std::string>> {};

TEST_P(MediumImage, PixelMeansMatchTheQuadrature) {
  const int which = std::get<0>(GetParam());
  const std::string sampler = std::get<1>(GetParam());
  ClRuntime rt;
  // The bounded box's light legs bend the integrand where they cross the box's faces: more panels.
  if (which == 0)
    render_and_compare(rt, unbounded_setup(), sampler, 512, 8);
  else if (which == 1)
    render_and_compare(rt, bounded_setup(), sampler, 512, 32);
  else
    render_and_compare(rt, many_lights_setup(), sampler, 512, 8);
}

INSTANTIATE_TEST_SUITE_P(UnboundedAndBounded, MediumImage,
                         ::testing::Values(std::make_tuple(0, std::string("tree-split")),
                                           std::make_tuple(0, std::string("power")),
                                           std::make_tuple(0, std::string("tree")),
                                           std::make_tuple(1, std::string("tree-split")),
                                           std::make_tuple(1, std::string("power")),
                                           std::make_tuple(2, std::string("tree-split"))),
                         [](const auto& p) {
                           int which = std::get<0>(p.param);
                           std::string name = std::string(which == 0   ? "unbounded_"
                                                          : which == 1 ? "bounded_"
                                                                       : "many_lights_") +
                                              std::get<1>(p.param);
                           for (char& c : name)
                             if (c == '-') c = '_';
                           return name;
                         });
