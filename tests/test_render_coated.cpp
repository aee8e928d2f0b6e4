// A coated-diffuse plate in whole renders (PoCL, the full wavefront), direct light only
// (max_depth 1: light samples and BSDF samples MIS-combined at the plate): a sphere light of
// radiance Le over the plate z = 0, seen by a camera with a 2 deg field of view at angle theta_o
// from the normal. A pixel sees
//   L(x) = integral over the light's cone of f(wo, wi) Le cos(theta_i) dwi,
// with, for a smooth coat of index eta over a Lambertian base of reflectance rho and nothing
// absorbed between them (thickness 0), the closed form of the coat's inter-reflections
//   f(wo, wi) = (1 - F(o)) (1 - F(i)) rho / (pi eta^2 (1 - rho r_i)),  r_i = 1 - (1 - r_e) / eta^2,
// r_e = int_0^1 F(mu) 2 mu dmu (Fresnel and quadratures in double, written here; the cone by a
// midpoint rule in (cos, phi) about its axis). The coat's mirror image of the light is outside the
// view. The image's total must match the pixels' references (a 2 x 2 rule over each pixel) within
// 5 standard errors plus the quadrature error (against a 1 x 1 rule), for the tree sampler and
// for brdf-mis (a smooth coat is not glossy: tree-split light sampling there). The BSDF's pdf is
// an estimate (cl/bsdf/layered.h), so this also checks that MIS with it stays unbiased.
// A rough coat has no closed form: brdf-mis (BRDF-oriented light sampling with its cap-integral
// lobe, MIS with the stochastic pdf) must agree with the tree sampler within 5 joint standard
// errors, as two unbiased estimators of the same image.
#include "render/camera.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include "support/double3.h"
#include "support/fresnel_reference.h"

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <string>

using namespace canopy;
using namespace canopy::test;

namespace {

double internal_reflectance(double eta) {
  const int n = 100000;
  double re = 0;
  for (int i = 0; i < n; ++i) {
    double mu = (i + 0.5) / n;
    re += ref_fresnel(mu, eta) * 2 * mu / n;
  }
  return 1 - (1 - re) / (eta * eta);
}

const double kEta = 1.5, kLe = 4.0, kRadius = 0.4;
const D3 kRho{0.7, 0.5, 0.3};
const D3 kLight{1.5, 0.8, 2.4};

Scene plate_scene(double theta_o, double roughness) {
  const double t = theta_o * M_PI / 180;
  std::string json = fmt::format(
      R"({{"camera": {{"position": [0, {y}, {z}], "look_at": [0, 0, 0], "up": [1, 0, 0],
                      "fov": 2}},
          "film": {{"width": 16, "height": 16}},
          "integrator": {{"max_depth": 1}},
          "materials": [{{"name": "coat", "type": "coated_diffuse", "albedo": [{r}, {g}, {b}],
                          "roughness": {rough}, "ior": {eta}, "thickness": 0,
                          "max_depth": 100}}],
          "shapes": [{{"type": "quad", "material": "coat", "corner": [-20, -20, 0],
                       "edge1": [40, 0, 0], "edge2": [0, 40, 0]}}],
          "lights": [{{"type": "sphere", "center": [{lx}, {ly}, {lz}], "radius": {rad},
                       "radiance": {le}}}]}})",
      fmt::arg("y", -5 * std::sin(t)), fmt::arg("z", 5 * std::cos(t)), fmt::arg("r", kRho.x),
      fmt::arg("g", kRho.y), fmt::arg("b", kRho.z), fmt::arg("rough", roughness),
      fmt::arg("eta", kEta), fmt::arg("lx", kLight.x), fmt::arg("ly", kLight.y),
      fmt::arg("lz", kLight.z), fmt::arg("rad", kRadius), fmt::arg("le", kLe));
  return load_scene_from_string(json, "coated.json", ".");
}

// Radiance of the smooth-coated plate at x towards the camera at o: the light's cone by an
// n x 2n midpoint rule in (cos, phi) about its axis.
D3 closed_form(D3 x, D3 o, double ri, int n) {
  D3 wo = dunit(o - x), to = kLight - x;
  double dist = dlen(to);
  D3 axis = to * (1 / dist);
  double cos_max = std::sqrt(1 - kRadius * kRadius / (dist * dist));
  D3 t1 = dunit(dcross(std::fabs(axis.x) < 0.9 ? D3{1, 0, 0} : D3{0, 1, 0}, axis));
  D3 t2 = dcross(axis, t1);
  double fo = 1 - ref_fresnel(wo.z, kEta), sum = 0;
  for (int i = 0; i < n; ++i) {
    double c = cos_max + (1 - cos_max) * (i + 0.5) / n, s = std::sqrt(1 - c * c);
    for (int j = 0; j < 2 * n; ++j) {
      double phi = 2 * M_PI * (j + 0.5) / (2 * n);
      D3 wi = axis * c + t1 * (s * std::cos(phi)) + t2 * (s * std::sin(phi));
      if (wi.z > 0) sum += (1 - ref_fresnel(wi.z, kEta)) * wi.z;
    }
  }
  double solid_angle_per_cell = 2 * M_PI * (1 - cos_max) / (2 * n * n);
  double s = fo * sum * solid_angle_per_cell * kLe / (M_PI * kEta * kEta);
  return {s * kRho.x / (1 - kRho.x * ri), s * kRho.y / (1 - kRho.y * ri),
          s * kRho.z / (1 - kRho.z * ri)};
}

// The pixel's box-filtered reference by an n x n midpoint rule over its footprint.
D3 pixel_reference(const CameraParams& cam, int px, int py, int n, double ri, int cone) {
  D3 acc{0, 0, 0};
  D3 o = d3(xyz_of(cam.origin));
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      double x = px + (a + 0.5) / n, y = py + (b + 0.5) / n;
      D3 d = dunit(d3(xyz_of(cam.lower_left)) + d3(xyz_of(cam.du)) * x + d3(xyz_of(cam.dv)) * y);
      acc = acc + closed_form(o + d * (-o.z / d.z), o, ri, cone);
    }
  return acc * (1.0 / (n * n));
}

struct Totals {
  D3 mean{0, 0, 0}, var{0, 0, 0}; // sums over pixels of the pixel means and their variances
};

Totals render_totals(Scene& scene, const std::string& sampler, int spp) {
  ClRuntime rt;
  RendererOptions opt;
  opt.light_sampler = sampler;
  Renderer renderer(rt, scene, opt);
  RenderSettings rs;
  rs.spp = spp;
  rs.seed = 7;
  Film film = renderer.render(rs);
  EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
  Totals t;
  for (size_t p = 0; p < film.sum.size(); ++p) {
    double n = film.sum[p].w;
    const double* sum = &film.sum[p].x;
    const double* sq = &film.sumsq[p].x;
    double* mean = &t.mean.x;
    double* var = &t.var.x;
    for (int ch = 0; ch < 3; ++ch) {
      double m = sum[ch] / n;
      mean[ch] += m;
      var[ch] += std::max(0.0, sq[ch] / n - m * m) / (n - 1.0);
    }
  }
  return t;
}

// The camera in world space, where the references are: the loader put it at 0 (scene.origin).
CameraParams world_camera(const Scene& scene) {
  CameraParams cam = make_camera_params(scene.camera, scene.film.width, scene.film.height);
  cam.origin = make_float4(float(scene.origin.x), float(scene.origin.y), float(scene.origin.z),
                           cam.origin.w);
  return cam;
}

struct SmoothCase {
  double theta_o;
  const char* sampler;
};

class CoatedPlate : public ::testing::TestWithParam<SmoothCase> {};

TEST_P(CoatedPlate, SmoothCoatMatchesClosedForm) {
  const SmoothCase c = GetParam();
  Scene scene = plate_scene(c.theta_o, 0.0);
  const double ri = internal_reflectance(kEta);
  CameraParams cam = world_camera(scene);
  D3 ref{0, 0, 0}, quad{0, 0, 0};
  for (int y = 0; y < scene.film.height; ++y)
    for (int x = 0; x < scene.film.width; ++x) {
      D3 fine = pixel_reference(cam, x, y, 2, ri, 32),
         coarse = pixel_reference(cam, x, y, 1, ri, 16);
      ref = ref + fine;
      D3 diff = fine - coarse;
      quad = quad + D3{std::fabs(diff.x), std::fabs(diff.y), std::fabs(diff.z)};
    }
  Totals t = render_totals(scene, c.sampler, 1024);
  const double* mean = &t.mean.x;
  const double* var = &t.var.x;
  const double* r = &ref.x;
  const double* q = &quad.x;
  for (int ch = 0; ch < 3; ++ch) {
    double bound = 5 * std::sqrt(var[ch]) + q[ch] + 1e-5 * r[ch];
    EXPECT_NEAR(mean[ch], r[ch], bound)
        << "theta_o " << c.theta_o << " " << c.sampler << " channel " << ch;
    std::printf("%s theta_o %g ch %d: %.6g vs %.6g (bound %.2f%%)\n", c.sampler, c.theta_o, ch,
                mean[ch], r[ch], 100 * bound / r[ch]);
  }
}

INSTANTIATE_TEST_SUITE_P(Samplers, CoatedPlate,
                         ::testing::Values(SmoothCase{20, "tree"}, SmoothCase{65, "tree"},
                                           SmoothCase{40, "brdf-mis"}));

// A rough coat is glossy: brdf-mis samples it with BRDF-oriented light sampling and MIS against
// the BSDF's stochastic pdf; the tree sampler with light sampling and BSDF sampling. Both are
// unbiased: their images agree.
TEST(CoatedPlateRough, BrdfMisAgreesWithTree) {
  Scene scene = plate_scene(40, 0.4);
  Totals a = render_totals(scene, "tree", 512), b = render_totals(scene, "brdf-mis", 512);
  const double* ma = &a.mean.x;
  const double* mb = &b.mean.x;
  const double* va = &a.var.x;
  const double* vb = &b.var.x;
  for (int ch = 0; ch < 3; ++ch) {
    EXPECT_GT(ma[ch], 0.0);
    EXPECT_NEAR(ma[ch], mb[ch], 5 * std::sqrt(va[ch] + vb[ch])) << "channel " << ch;
    std::printf("rough: tree %.6g brdf-mis %.6g (5 SE %.2f%%)\n", ma[ch], mb[ch],
                100 * 5 * std::sqrt(va[ch] + vb[ch]) / ma[ch]);
  }
}

} // namespace
