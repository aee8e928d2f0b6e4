// End-to-end render against an analytic answer: a diffuse plane under point lights with no
// occluders. Each pixel's expected value is the box-filtered radiance
//   L(x) = albedo/pi * sum_l I_l cos(theta_l) / d_l^2
// integrated over the pixel footprint; the renderer's per-pixel mean must match it within a bound
// derived from that pixel's own sample variance.
#include "render/camera.h"
#include "render/renderer.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace canopy;

namespace {

struct PointLight {
  float3 p, I;
};

Scene make_plane_scene(float scale, const std::vector<PointLight>& lights, float3 albedo) {
  Scene s;
  s.path = "analytic-plane";
  s.camera.position = make_float3(0.3f, -0.2f, 5.0f) * scale;
  s.camera.look_at = make_float3(0.0f, 0.0f, 0.0f);
  s.camera.up = make_float3(0.0f, 1.0f, 0.0f);
  s.camera.fov_y_deg = 50.0f;
  s.film.width = 24;
  s.film.height = 20;
  s.integrator.max_depth = 2; // a bounce off the plane escapes: it must add nothing
  MaterialDesc m;
  m.name = "plane";
  m.gpu.albedo = f4_from3(albedo, 0.0f);
  m.gpu.type = MATERIAL_DIFFUSE;
  s.materials.push_back(m);
  float e = 20.0f * scale;
  s.vertices = {make_float3(-e, -e, 0), make_float3(e, -e, 0), make_float3(e, e, 0), make_float3(-e, e, 0)};
  s.indices = {0, 1, 2, 0, 2, 3};
  s.triangle_material = {0, 0};
  s.triangle_light = {-1, -1};
  for (const PointLight& pl : lights) {
    Light l{};
    l.type = LIGHT_POINT;
    l.p = f4_from3(pl.p * scale, 0.0f);
    l.emission = f4_from3(pl.I * (scale * scale), 0.0f); // same irradiance at every scale
    l.prim = -1;
    s.lights.push_back(l);
  }
  return s;
}

// Exact radiance leaving the plane point x towards the camera.
float3 plane_radiance(const Scene& s, float3 x, float3 albedo) {
  float3 sum = make_float3(0, 0, 0);
  for (const Light& l : s.lights) {
    float3 to = xyz_of(l.p) - x;
    float d2 = dot(to, to);
    float cos_t = to.z / std::sqrt(d2);
    if (cos_t > 0.0f) sum += xyz_of(l.emission) * (cos_t / d2);
  }
  return sum * albedo * (1.0f / float(M_PI));
}

// The pixel's box-filtered radiance by an n x n midpoint rule over the footprint.
float3 pixel_reference(const Scene& s, const CameraParams& cam, int px, int py, int n, float3 albedo) {
  float3 acc = make_float3(0, 0, 0);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      float x = float(px) + (float(a) + 0.5f) / float(n), y = float(py) + (float(b) + 0.5f) / float(n);
      float3 d = normalize(xyz_of(cam.lower_left) + xyz_of(cam.du) * x + xyz_of(cam.dv) * y);
      float3 o = xyz_of(cam.origin);
      float t = -o.z / d.z;
      acc += plane_radiance(s, o + d * t, albedo);
    }
  return acc * (1.0f / float(n * n));
}

struct Check {
  int violations = 0;
  double mean_rel_bound = 0.0;
  int checked = 0;
  // Image-wide: sum of pixel means against the sum of references, with its own 5-sigma bound.
  double total_mean = 0.0, total_ref = 0.0, total_var = 0.0, total_quad = 0.0;
};

Check compare_with_analytic(const Scene& scene, const Film& film, float3 albedo) {
  CameraParams cam = make_camera_params(scene.camera, scene.film.width, scene.film.height);
  Check c;
  for (int y = 0; y < film.height; ++y)
    for (int x = 0; x < film.width; ++x) {
      size_t p = size_t(y) * size_t(film.width) + size_t(x);
      float3 ref = pixel_reference(scene, cam, x, y, 16, albedo);
      float3 ref_coarse = pixel_reference(scene, cam, x, y, 8, albedo);
      double n = film.sum[p].w;
      const float* sum = &film.sum[p].x;
      const float* sq = &film.sumsq[p].x;
      const float* r = &ref.x;
      const float* rc = &ref_coarse.x;
      for (int ch = 0; ch < 3; ++ch) {
        double mean = sum[ch] / n;
        double var = std::max(0.0, sq[ch] / n - mean * mean) * n / (n - 1.0);
        // 5 standard errors of the mean, plus the quadrature error of the reference (bounded by
        // the difference between the 8x8 and 16x16 rules) and float accumulation error.
        double bound = 5.0 * std::sqrt(var / n) + std::fabs(double(r[ch]) - double(rc[ch])) + 1e-5 * std::fabs(r[ch]);
        c.total_mean += mean;
        c.total_ref += r[ch];
        c.total_var += var / n;
        c.total_quad += std::fabs(double(r[ch]) - double(rc[ch]));
        if (std::fabs(mean - r[ch]) > bound) {
          if (c.violations < 10)
            ADD_FAILURE() << "pixel (" << x << "," << y << ") ch " << ch << ": mean " << mean << " vs analytic "
                          << r[ch] << ", bound " << bound;
          ++c.violations;
        }
        if (r[ch] > 0) {
          c.mean_rel_bound += bound / r[ch];
          ++c.checked;
        }
      }
    }
  c.mean_rel_bound /= std::max(1, c.checked);
  return c;
}

const std::vector<PointLight> kLights = {
    {make_float3(0.5f, 0.5f, 1.0f), make_float3(2.0f, 1.0f, 0.5f)},
    {make_float3(-1.0f, 0.2f, 2.0f), make_float3(1.0f, 3.0f, 1.0f)},
    {make_float3(0.2f, -1.5f, 0.7f), make_float3(0.5f, 0.5f, 2.0f)},
    {make_float3(3.0f, 3.0f, 3.0f), make_float3(10.0f, 10.0f, 10.0f)},
    {make_float3(0.0f, 0.0f, -1.0f), make_float3(5.0f, 5.0f, 5.0f)}, // below the plane: no light
};

} // namespace

class AnalyticPlane : public ::testing::TestWithParam<std::tuple<std::string, float>> {};

TEST_P(AnalyticPlane, PixelMeansMatchTheAnalyticRadiance) {
  const std::string sampler = std::get<0>(GetParam());
  const float scale = std::get<1>(GetParam());
  const float3 albedo = make_float3(0.8f, 0.5f, 0.3f);
  Scene scene = make_plane_scene(scale, kLights, albedo);
  ClRuntime rt;
  RendererOptions opt;
  opt.light_sampler = sampler;
  Renderer renderer(rt, scene, opt);
  RenderSettings rs;
  rs.spp = 2048;
  rs.seed = 3;
  rs.wave_size = 1 << 14; // several waves, each holding many samples of every pixel
  Film film = renderer.render(rs);
  EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
  for (const float4& s : film.sum) ASSERT_EQ(s.w, 2048.0f);
  Check c = compare_with_analytic(scene, film, albedo);
  std::printf("%s, scale %g: %d values checked, mean relative bound %.4f\n", sampler.c_str(), double(scale), c.checked, c.mean_rel_bound);
  EXPECT_EQ(c.violations, 0);
  double total_bound = 5.0 * std::sqrt(c.total_var) + c.total_quad + 1e-5 * c.total_ref;
  std::printf("image total %.6g vs analytic %.6g (bound %.3g, %.3f%%)\n", c.total_mean, c.total_ref,
              total_bound, 100.0 * total_bound / c.total_ref);
  EXPECT_NEAR(c.total_mean, c.total_ref, total_bound);
  EXPECT_LT(total_bound, 0.01 * c.total_ref);
  // Per pixel the bound is loose (uniform light choice is noisy) but still catches gross errors;
  // the image-wide total above is the tight check (a missing 1/pi or a wrong pmf fails it).
  EXPECT_LT(c.mean_rel_bound, 0.2);
}

INSTANTIATE_TEST_SUITE_P(
    SamplersAndScales, AnalyticPlane,
    ::testing::Combine(::testing::Values("uniform", "power", "tree", "tree-split", "exhaustive"),
                       ::testing::Values(1.0f, 1e-3f, 1e3f)),
    [](const auto& p) {
      std::string name = std::get<0>(p.param) + "_scale_" +
                         std::to_string(int(std::log10(std::get<1>(p.param)) + 3.5f) - 3);
      for (char& c : name)
        if (c == '-') c = '_';
      return name;
    });

TEST(AnalyticPlaneDeterminism, SameSeedSameImage) {
  const float3 albedo = make_float3(0.5f, 0.5f, 0.5f);
  Scene scene = make_plane_scene(1.0f, kLights, albedo);
  ClRuntime rt;
  Renderer renderer(rt, scene, RendererOptions{});
  RenderSettings rs;
  rs.spp = 8;
  rs.seed = 9;
  Film a = renderer.render(rs);
  rs.wave_size = 1000; // a different wave split must not change the image either
  Film b = renderer.render(rs);
  ASSERT_EQ(a.sum.size(), b.sum.size());
  for (size_t i = 0; i < a.sum.size(); ++i) {
    ASSERT_EQ(a.sum[i].x, b.sum[i].x) << i;
    ASSERT_EQ(a.sum[i].y, b.sum[i].y) << i;
    ASSERT_EQ(a.sum[i].z, b.sum[i].z) << i;
  }
}
