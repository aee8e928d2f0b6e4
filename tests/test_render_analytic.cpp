// End-to-end render against an analytic answer: a diffuse plane under point lights with no
// occluders. Each pixel's expected value is the box-filtered radiance
//   L(x) = albedo/pi * sum_l I_l cos(theta_l) / d_l^2
// integrated over the pixel footprint; the renderer's per-pixel mean must match it within a bound
// derived from that pixel's own sample variance.
#include "geometry.h"
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
  s.materials.push_back(diffuse_material("plane", albedo));
  float e = 20.0f * scale;
  s.vertices = {make_float3(-e, -e, 0), make_float3(e, -e, 0), make_float3(e, e, 0),
                make_float3(-e, e, 0)};
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
float3 pixel_reference(const Scene& s, const CameraParams& cam, int px, int py, int n,
                       float3 albedo) {
  float3 acc = make_float3(0, 0, 0);
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      float x = float(px) + (float(a) + 0.5f) / float(n),
            y = float(py) + (float(b) + 0.5f) / float(n);
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
      const double* sum = &film.sum[p].x;
      const double* sq = &film.sumsq[p].x;
      const float* r = &ref.x;
      const float* rc = &ref_coarse.x;
      for (int ch = 0; ch < 3; ++ch) {
        double mean = sum[ch] / n;
        double var = std::max(0.0, sq[ch] / n - mean * mean) * n / (n - 1.0);
        // 5 standard errors of the mean, plus the quadrature error of the reference (bounded by
        // the difference between the 8x8 and 16x16 rules) and float accumulation error.
        double bound = 5.0 * std::sqrt(var / n) + std::fabs(double(r[ch]) - double(rc[ch])) +
                       1e-5 * std::fabs(r[ch]);
        c.total_mean += mean;
        c.total_ref += r[ch];
        c.total_var += var / n;
        c.total_quad += std::fabs(double(r[ch]) - double(rc[ch]));
        if (std::fabs(mean - r[ch]) > bound) {
          if (c.violations < 10)
            ADD_FAILURE() << "pixel (" << x << "," << y << ") ch " << ch << ": mean " << mean
                          << " vs analytic " << r[ch] << ", bound " << bound;
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

// The render of the plane with `sampler` at `scale` against the analytic radiance.
void check_analytic_plane(const std::string& sampler, float scale,
                          const std::string& path_sampler) {
  const float3 albedo = make_float3(0.8f, 0.5f, 0.3f);
  Scene scene = make_plane_scene(scale, kLights, albedo);
  ClRuntime rt;
  RendererOptions opt;
  opt.light_sampler = sampler;
  opt.path_sampler = path_sampler;
  Renderer renderer(rt, scene, opt);
  RenderSettings rs;
  rs.spp = 2048;
  rs.seed = 3;
  rs.wave_size = 1 << 14; // several waves, each holding many samples of every pixel
  Film film = renderer.render(rs);
  EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
  for (const double4& s : film.sum)
    ASSERT_EQ(s.w, 2048.0);
  Check c = compare_with_analytic(scene, film, albedo);
  std::printf("%s (%s), scale %g: %d values checked, mean relative bound %.4f\n", sampler.c_str(),
              path_sampler.c_str(), double(scale), c.checked, c.mean_rel_bound);
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

} // namespace

class AnalyticPlane : public ::testing::TestWithParam<std::tuple<std::string, float>> {};

TEST_P(AnalyticPlane, PixelMeansMatchTheAnalyticRadiance) {
  check_analytic_plane(std::get<0>(GetParam()), std::get<1>(GetParam()), "independent");
}

// The Sobol sampler (cl/sampler.h) is unbiased too: its pixel jitter, light selection word and
// light point, BSDF and lobe numbers feed the same estimators. (Its per-pixel error is below the
// bound from the sample variance, which ignores stratification: the bound stays conservative.)
TEST(AnalyticPlaneSobol, PixelMeansMatchTheAnalyticRadiance) {
  for (const char* sampler : {"uniform", "power", "tree", "tree-split"})
    check_analytic_plane(sampler, 1.0f, "sobol");
}

INSTANTIATE_TEST_SUITE_P(SamplersAndScales, AnalyticPlane,
                         ::testing::Combine(::testing::Values("uniform", "power", "tree",
                                                              "tree-split", "exhaustive"),
                                            ::testing::Values(1.0f, 1e-3f, 1e3f)),
                         [](const auto& p) {
                           std::string name =
                               std::get<0>(p.param) + "_scale_" +
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

// ---------------------------------------------------------------- area lights and MIS
// The same plane under one area light. With max_depth 1 only light sampling sees the light; with
// max_depth 2 light sampling and BSDF sampling are combined with MIS weights, which must add up
// to 1 for every direction: both renders must match the irradiance integrated by quadrature.

namespace {

// Irradiance at plane point x (normal +z) from light l, exactly: Lambert's formula for a polygon
// entirely above the horizon, E = L/2 |sum_i theta_i (n . normalize(v_i x v_i+1))| with v_i the
// unit vectors to its vertices (both test polygons face the plane), and E = L pi (r/d)^2 cos(theta)
// for a sphere entirely above the horizon. Evaluated in double.
float3 area_light_irradiance(const Light& l, float3 x) {
  float3 L = xyz_of(l.emission);
  if (l.type == LIGHT_DISK) {
    // A disk parallel to the plane (normal -z, or +z two-sided), radius r, height h above x and
    // horizontal offset a from x: the view factor of a differential area to a parallel disk,
    // F = (1 - (a^2 + h^2 - r^2) / sqrt((a^2 + h^2 + r^2)^2 - 4 a^2 r^2)) / 2 (Siegel & Howell,
    // configuration factor B-2 family), and E = pi L F; on axis (a = 0), pi L r^2 / (r^2 + h^2).
    double ax = double(l.p.x) - x.x, ay = double(l.p.y) - x.y, h = double(l.p.z) - x.z;
    double a2 = ax * ax + ay * ay, r2 = double(l.p.w) * l.p.w, h2 = h * h;
    double s = a2 + h2 + r2;
    double F = 0.5 * (1.0 - (a2 + h2 - r2) / std::sqrt(s * s - 4.0 * a2 * r2));
    return L * float(M_PI * F);
  }
  if (l.type == LIGHT_SPHERE) {
    double tx = l.p.x - x.x, ty = l.p.y - x.y, tz = l.p.z - x.z;
    double d2 = tx * tx + ty * ty + tz * tz, r = l.p.w;
    return L * float(M_PI * r * r / d2 * (tz / std::sqrt(d2)));
  }
  float3 p = xyz_of(l.p), e1 = xyz_of(l.e1), e2 = xyz_of(l.e2);
  std::vector<float3> poly = {p, p + e1};
  if (l.type == LIGHT_QUAD) poly.push_back(p + e1 + e2);
  poly.push_back(p + e2);
  double sum = 0.0;
  for (size_t i = 0; i < poly.size(); ++i) {
    float3 a3 = poly[i] - x, b3 = poly[(i + 1) % poly.size()] - x;
    double a[3] = {a3.x, a3.y, a3.z}, b[3] = {b3.x, b3.y, b3.z};
    double la = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    double lb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
    for (int k = 0; k < 3; ++k)
      a[k] /= la, b[k] /= lb;
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    double lc = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    double theta = std::atan2(lc, a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
    if (lc > 0) sum += theta * c[2] / lc; // n = +z
  }
  return L * float(0.5 * std::fabs(sum));
}

Scene make_area_light_scene(const Light& light, int max_depth) {
  Scene s = make_plane_scene(1.0f, {}, make_float3(0.6f, 0.6f, 0.6f));
  s.lights = {light};
  s.integrator.max_depth = max_depth;
  return s;
}

Light quad_light() {
  Light l{};
  l.type = LIGHT_QUAD;
  l.p = make_float4(-0.8f, -0.5f, 1.2f, 0);
  l.e1 = make_float4(0.0f, 0.7f, 0.0f, 0);
  l.e2 = make_float4(0.9f, 0.0f, 0.3f, 0);
  float3 c = cross(xyz_of(l.e1), xyz_of(l.e2)); // faces down: (0.21, 0, -0.63)
  l.n = f4_from3(normalize(c), length(c));
  l.emission = make_float4(3.0f, 2.0f, 1.0f, 0);
  l.prim = -1;
  return l;
}

Light triangle_light() {
  Light l{};
  l.type = LIGHT_TRIANGLE;
  l.flags = LIGHT_FLAG_TWO_SIDED;
  l.p = make_float4(0.4f, 0.3f, 0.9f, 0);
  l.e1 = make_float4(0.5f, 0.2f, 0.3f, 0);
  l.e2 = make_float4(-0.1f, 0.6f, -0.2f, 0);
  float3 c = cross(xyz_of(l.e1), xyz_of(l.e2));
  l.n = f4_from3(normalize(c), 0.5f * length(c));
  l.emission = make_float4(4.0f, 4.0f, 6.0f, 0);
  l.prim = -1;
  return l;
}

// Parallel to the plane: one-sided facing it, and two-sided facing away (it lights the plane with
// its back face).
Light disk_light(bool two_sided) {
  Light l{};
  l.type = LIGHT_DISK;
  l.flags = two_sided ? LIGHT_FLAG_TWO_SIDED : 0;
  float r = two_sided ? 0.35f : 0.5f;
  l.p = two_sided ? make_float4(-0.3f, 0.4f, 0.7f, r) : make_float4(0.2f, -0.1f, 1.1f, r);
  l.e1 = make_float4(1, 0, 0, 0);
  l.e2 = two_sided ? make_float4(0, 1, 0, 0) : make_float4(0, -1, 0, 0); // e1 x e2 = n
  l.n = make_float4(0, 0, two_sided ? 1.0f : -1.0f, float(M_PI * double(r) * r));
  l.emission = two_sided ? make_float4(2.0f, 4.0f, 3.0f, 0) : make_float4(3.0f, 2.0f, 1.0f, 0);
  l.prim = -1;
  return l;
}

Light sphere_light() {
  Light l{};
  l.type = LIGHT_SPHERE;
  l.p = make_float4(0.3f, -0.2f, 0.8f, 0.25f);
  l.emission = make_float4(2.0f, 3.0f, 2.0f, 0);
  l.prim = -1;
  return l;
}

} // namespace

class AreaLightMis : public ::testing::TestWithParam<std::tuple<int, int>> {};

TEST_P(AreaLightMis, PixelMeansMatchTheIrradianceIntegral) {
  const int which = std::get<0>(GetParam()), max_depth = std::get<1>(GetParam());
  Light light = which == 0   ? quad_light()
                : which == 1 ? triangle_light()
                : which == 2 ? sphere_light()
                             : disk_light(which == 4);
  Scene scene = make_area_light_scene(light, max_depth);
  ClRuntime rt;
  RendererOptions opt;
  opt.light_sampler = "tree";
  Renderer renderer(rt, scene, opt);
  RenderSettings rs;
  rs.spp = 1024;
  rs.seed = 11;
  Film film = renderer.render(rs);
  EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
  const SceneGeometry& g = renderer.geometry();
  CameraParams cam = make_camera_params(scene.camera, scene.film.width, scene.film.height);
  const float albedo = 0.6f;
  double total_mean = 0, total_ref = 0, total_var = 0, total_quad = 0;
  int checked = 0, violations = 0;
  for (int y = 0; y < film.height; ++y)
    for (int x = 0; x < film.width; ++x) {
      // The pixel's reference: the exact radiance of the plane averaged over a 6 x 6 grid in the
      // pixel (and over 3 x 3 to bound that rule's error). Pixels that see the light, even in part
      // (a one-sided quad seen from behind is black), are skipped.
      double ref6 = 0, ref3 = 0;
      bool sees_light = false;
      for (int n : {16, 3, 6})
        for (int a = 0; a < n; ++a)
          for (int b = 0; b < n; ++b) {
            float fx = float(x) + (float(a) + 0.5f) / float(n),
                  fy = float(y) + (float(b) + 0.5f) / float(n);
            float3 d =
                normalize(xyz_of(cam.lower_left) + xyz_of(cam.du) * fx + xyz_of(cam.dv) * fy);
            float3 o = xyz_of(cam.origin);
            Hit h;
            bvh_intersect(g.bvh.nodes.data(), g.bvh.leaf_blocks.data(), g.prims.data(), o, d, 0,
                          FLT_INF, 0, &h);
            if (h.prim < 0 || g.prims[size_t(h.prim)].light >= 0) {
              sees_light = true;
              continue;
            }
            if (n == 16) continue; // the 16 x 16 grid only finds pixels the light covers in part
            float3 e = area_light_irradiance(light, o + d * (-o.z / d.z));
            double v = double(luminance3(e)) * albedo / M_PI / double(n * n);
            (n == 3 ? ref3 : ref6) += v;
          }
      if (sees_light) continue;
      size_t p = size_t(y) * size_t(film.width) + size_t(x);
      double cnt = film.sum[p].w;
      const double4& s = film.sum[p];
      double mean = (0.2126 * s.x + 0.7152 * s.y + 0.0722 * s.z) / cnt; // luminance3 in double
      // Variance of the luminance from the per-channel moments (channels treated as independent:
      // an upper bound for these positively correlated colour channels is not needed here, the
      // sum of per-channel variances weighted by the squared luminance coefficients).
      double var = 0;
      const float w[3] = {0.2126f, 0.7152f, 0.0722f};
      const double* sm = &film.sum[p].x;
      const double* sq = &film.sumsq[p].x;
      for (int c = 0; c < 3; ++c) {
        double m = sm[c] / cnt;
        var += double(w[c]) * w[c] * std::max(0.0, sq[c] / cnt - m * m) * cnt / (cnt - 1);
      }
      double se = std::sqrt(var / cnt);
      double bound = 6.0 * se + std::fabs(ref6 - ref3) + 1e-4 * ref6;
      if (std::fabs(mean - ref6) > bound && violations < 8)
        std::printf("  pixel (%d,%d): mean %.5g ref %.5g bound %.3g\n", x, y, mean, ref6, bound);
      violations += std::fabs(mean - ref6) > bound;
      total_mean += mean;
      total_ref += ref6;
      total_var += var / cnt;
      total_quad += std::fabs(ref6 - ref3);
      ++checked;
    }
  double total_bound = 5.0 * std::sqrt(total_var) + total_quad + 1e-4 * total_ref;
  std::printf("light %d, max_depth %d: %d pixels, total %.5g vs %.5g (bound %.3g = %.2f%%)\n",
              which, max_depth, checked, total_mean, total_ref, total_bound,
              100.0 * total_bound / total_ref);
  EXPECT_GT(checked, 300);
  EXPECT_LE(violations, 1); // 6-sigma per pixel (and a rare quadrature outlier near a light's edge)
  EXPECT_NEAR(total_mean, total_ref, total_bound);
  EXPECT_LT(total_bound, 0.02 * total_ref); // tight enough to catch a wrong MIS weight or pdf
}

// 3: a one-sided disk, 4: a two-sided disk lighting the plane with its back face.
INSTANTIATE_TEST_SUITE_P(QuadTriangleSphereDisk, AreaLightMis,
                         ::testing::Combine(::testing::Values(0, 1, 2, 3, 4),
                                            ::testing::Values(1, 2)));
