// Film precision and range (issue 9, finding 4): the film must give the right finite mean at the
// scene format's largest sample counts and at emissions from the float maximum down to denormals,
// and a pixel whose value float32 cannot hold must be counted and written finite.
//
// The scene: one point light of intensity I at height h above a diffuse plane of albedo rho,
// max_depth 1 (camera ray, next-event estimate, no bounce), a camera looking straight down at the
// light's foot. The exact radiance leaving the plane point x at distance r from the foot is
//   L(r) = rho/pi * I cos(theta) / d^2 = rho/pi * I h / (h^2 + r^2)^(3/2),
// and a pixel's exact value is L box-filtered over its footprint (a 64 x 64 midpoint rule in
// double; the footprint is small, so its error is ~1e-9 relative). With one point light every
// sample is exact up to float rounding: the only randomness is the pixel jitter, so the image mean
// must match to far better than 0.5% unless the film itself loses precision or range.
#include "render/camera.h"
#include "render/renderer.h"
#include "render/stats_report.h"

#include <gtest/gtest.h>

#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstdio>

using namespace canopy;

namespace {

constexpr double kAlbedo = 0.75;

Scene make_scene(float intensity, float height, int film_size, float fov_deg) {
  Scene s;
  s.path = "film-plane";
  s.camera.position = make_float3(0.0f, 0.0f, 4.0f);
  s.camera.look_at = make_float3(0.0f, 0.0f, 0.0f);
  s.camera.up = make_float3(0.0f, 1.0f, 0.0f);
  s.camera.fov_y_deg = fov_deg;
  s.film.width = film_size;
  s.film.height = film_size;
  s.integrator.max_depth = 1;
  const float a = float(kAlbedo);
  s.materials.push_back(diffuse_material("plane", make_float3(a, a, a)));
  const float e = 10.0f;
  s.vertices = {make_float3(-e, -e, 0), make_float3(e, -e, 0), make_float3(e, e, 0),
                make_float3(-e, e, 0)};
  s.indices = {0, 1, 2, 0, 2, 3};
  s.triangle_material = {0, 0};
  s.triangle_light = {-1, -1};
  Light l{};
  l.type = LIGHT_POINT;
  l.p = make_float4(0.0f, 0.0f, height, 0.0f);
  l.emission = make_float4(intensity, intensity, intensity, 0.0f);
  l.prim = -1;
  s.lights.push_back(l);
  return s;
}

// Exact pixel values (one channel: the scene is grey), in double: the sum over the lights of the
// box-filtered radiance, by an n x n midpoint rule over each pixel's footprint.
std::vector<double> exact_pixels(const Scene& s, int n = 64) {
  CameraParams cam = make_camera_params(s.camera, s.film.width, s.film.height);
  std::vector<double> out;
  for (int py = 0; py < s.film.height; ++py)
    for (int px = 0; px < s.film.width; ++px) {
      double acc = 0.0;
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
          double x = px + (a + 0.5) / n, y = py + (b + 0.5) / n;
          double d[3], o[3] = {cam.origin.x, cam.origin.y, cam.origin.z};
          const float* ll = &cam.lower_left.x;
          const float* du = &cam.du.x;
          const float* dv = &cam.dv.x;
          for (int c = 0; c < 3; ++c)
            d[c] = double(ll[c]) + double(du[c]) * x + double(dv[c]) * y;
          double t = -o[2] / d[2];
          double hx = o[0] + d[0] * t, hy = o[1] + d[1] * t;
          for (const Light& l : s.lights) {
            double I = double(l.emission.x), h = double(l.p.z);
            double rx = hx - double(l.p.x), ry = hy - double(l.p.y);
            acc += kAlbedo / M_PI * I * h / std::pow(h * h + rx * rx + ry * ry, 1.5);
          }
        }
      out.push_back(acc / (n * n));
    }
  return out;
}

struct Result {
  RgbImage image;
  RenderStats stats;
  double seconds = 0.0;
};

Result render(Scene& scene, int spp, const std::string& sampler = "uniform",
              size_t wave_size = size_t(1) << 18) {
  auto t0 = std::chrono::steady_clock::now();
  ClRuntime rt;
  RendererOptions opt;
  opt.light_sampler = sampler;
  Renderer renderer(rt, scene, opt);
  RenderSettings rs;
  rs.spp = spp;
  rs.seed = 7;
  rs.wave_size = wave_size;
  Result r;
  r.image = renderer.render(rs).mean();
  r.stats = renderer.stats();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

// Every value finite and every pixel's mean within `rel` of the exact value (all channels).
void expect_matches_exact(const Scene& scene, const Result& r, double rel, int quadrature = 64) {
  std::vector<double> ref = exact_pixels(scene, quadrature);
  ASSERT_EQ(r.image.rgb.size(), 3 * ref.size());
  double worst = 0.0;
  for (size_t p = 0; p < ref.size(); ++p)
    for (int c = 0; c < 3; ++c) {
      float v = r.image.rgb[3 * p + size_t(c)];
      ASSERT_TRUE(std::isfinite(v)) << "pixel " << p << " channel " << c << ": " << v;
      double err = std::fabs(double(v) - ref[p]) / ref[p];
      worst = std::max(worst, err);
      EXPECT_LT(err, rel) << "pixel " << p << " channel " << c << ": " << v << " vs exact "
                          << ref[p];
    }
  std::printf("worst relative error %.3g (exact pixel 0: %.6g), %.2f s\n", worst, ref[0],
              r.seconds);
  EXPECT_EQ(r.stats.nonfinite_samples, 0u);
}

} // namespace

TEST(RenderFilm, TwoToThe22SamplesPerPixelGiveTheExactMean) {
  // 2^22 samples of each of 16 pixels: a float32 film stops resolving a sample once the pixel's
  // sum is ~2^24 samples big and came out 3-5% low; a double film is exact to ~1e-9.
  const int spp = 1 << 22;
  Scene scene = make_scene(1.0f, 1.0f, 4, 2.0f);
  Result r = render(scene, spp, "uniform", size_t(1) << 20);
  EXPECT_EQ(r.stats.samples, uint64_t(16) * uint64_t(spp));
  expect_matches_exact(scene, r, 0.005);
}

TEST(RenderFilm, TheFormatsLargestSampleCountGivesTheExactMean) {
  // 2^24 spp (the scene format's limit) on one pixel: the sample count, the per-sample seeds
  // (distinct within a pixel: rng_seed is a bijection of the sample index) and the sums hold.
  const int spp = 1 << 24;
  Scene scene = make_scene(1.0f, 1.0f, 1, 0.5f);
  Result r = render(scene, spp, "uniform", size_t(1) << 20);
  EXPECT_EQ(r.stats.samples, uint64_t(spp));
  uint64_t cuts = 0;
  for (uint64_t c : r.stats.cut_size_histogram)
    cuts += c;
  EXPECT_EQ(cuts, r.stats.shading_points);
  EXPECT_EQ(r.stats.shading_points, uint64_t(spp));
  expect_matches_exact(scene, r, 0.005);
}

class RenderFilmEmission : public ::testing::TestWithParam<std::tuple<float, std::string>> {};

TEST_P(RenderFilmEmission, ExtremeEmissionGivesAFiniteExactMean) {
  // Intensity 1e37 at height 0.5: radiance ~1e37 per sample, whose float sum overflows after a
  // few dozen samples. Intensity 1e-40 is a float denormal; each sample (~1e-40) still holds ~5
  // significant digits, so this checks that the emission scale and its undoing are exact (the
  // film-level failure of denormal emission is ManyDenormalLightsEachBelowTheSmallestFloatAddUp).
  const float intensity = std::get<0>(GetParam());
  Scene scene = make_scene(intensity, 0.5f, 4, 2.0f);
  Result r = render(scene, 256, std::get<1>(GetParam()));
  expect_matches_exact(scene, r, 0.005);
  EXPECT_EQ(stats_to_json(r.stats, RunTimings{}).value("overflowed_pixels", -1), 0);
}

std::string emission_case_name(const ::testing::TestParamInfo<std::tuple<float, std::string>>& p) {
  std::string name =
      std::string(std::get<0>(p.param) > 1.0f ? "Bright" : "Denormal") + "_" + std::get<1>(p.param);
  for (char& c : name)
    if (c == '-') c = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Bright, RenderFilmEmission,
                         ::testing::Combine(::testing::Values(1e37f),
                                            ::testing::Values("uniform", "exhaustive", "power",
                                                              "tree", "tree-split")),
                         emission_case_name);
// The tree samplers need the light tree's energies normalised too (its emitter records and node
// energies would otherwise be denormal and flush to zero on the device).
INSTANTIATE_TEST_SUITE_P(Denormal, RenderFilmEmission,
                         ::testing::Combine(::testing::Values(1e-40f),
                                            ::testing::Values("uniform", "exhaustive", "power",
                                                              "tree", "tree-split")),
                         emission_case_name);

TEST(RenderFilm, ManyDenormalLightsEachBelowTheSmallestFloatAddUp) {
  // 4096 lights of intensity 1e-40 at height 250 (a 64 x 64 grid, spacing 0.01): each light's
  // share of a sample, rho/pi * I cos / d^2 ~ 3.8e-46, is below half the smallest float denormal,
  // so rendered at its own scale it rounds to zero and the image is black; the sum over the lights,
  // ~1.6e-42 per pixel, is a float (a denormal with ~1e-3 relative spacing). With the emission
  // scaled by 2^-k on the device every share is a normal float. The exhaustive sampler shades
  // every light at every shading point.
  Scene scene = make_scene(1e-40f, 250.0f, 4, 2.0f);
  Light base = scene.lights[0];
  scene.lights.clear();
  for (int i = 0; i < 64; ++i)
    for (int j = 0; j < 64; ++j) {
      Light l = base;
      l.p.x = 0.01f * float(i - 32);
      l.p.y = 0.01f * float(j - 32);
      scene.lights.push_back(l);
    }
  Result r = render(scene, 16, "exhaustive");
  expect_matches_exact(scene, r, 0.005, 8);
}

TEST(RenderFilm, APixelBeyondTheFloatRangeIsCountedAndWrittenFinite) {
  // Intensity 3e38 at height 0.1: every pixel's exact value is ~7e39 > FLT_MAX. The samples (at
  // the device's emission scale) are finite; the resolved pixels are written as FLT_MAX and
  // counted in the stats (table and JSON).
  Scene scene = make_scene(3e38f, 0.1f, 4, 2.0f);
  std::vector<double> ref = exact_pixels(scene);
  for (double v : ref)
    ASSERT_GT(v, double(FLT_MAX));
  Result r = render(scene, 64);
  for (float v : r.image.rgb)
    EXPECT_EQ(v, FLT_MAX);
  EXPECT_EQ(r.stats.nonfinite_samples, 0u);
  nlohmann::json j = stats_to_json(r.stats, RunTimings{});
  EXPECT_EQ(j.value("overflowed_pixels", -1), 16);
  std::string table = stats_to_table(r.stats, RunTimings{});
  EXPECT_NE(table.find("pixels beyond the float range 16"), std::string::npos) << table;
}

TEST(RenderFilm, NonFiniteSamplesAreCountedAndReported) {
  // A light whose emission is NaN (possible only through the API: the loader refuses it) makes
  // every sample NaN: each is counted, recorded as zero, and reported by the stats.
  Scene scene = make_scene(1.0f, 1.0f, 4, 2.0f);
  scene.lights[0].emission.y = std::nanf("");
  Result r = render(scene, 8);
  EXPECT_EQ(r.stats.nonfinite_samples, 16u * 8u);
  for (float v : r.image.rgb)
    EXPECT_EQ(v, 0.0f);
  EXPECT_EQ(stats_to_json(r.stats, RunTimings{}).value("nonfinite_samples", -1), 128);
  std::string table = stats_to_table(r.stats, RunTimings{});
  EXPECT_NE(table.find("non-finite samples 128"), std::string::npos) << table;
}
