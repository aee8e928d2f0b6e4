// The Sobol path sampler's stratification in a render: direct light (max depth 1, MIS) from a
// diffuse quad light over a diffuse floor, no emitter in view. Each pixel's error against a
// reference (a Sobol render of 16384 spp with another seed) is measured at 1, 4, 16, 64 and 256
// spp over 4 seeds per sampler; the slope of log RMSE against log spp is -0.5 for independent
// samples (Monte Carlo), and must be below -0.55 with Sobol points, whose pixel, light-point and
// BSDF dimensions are each stratified over a pixel's samples. The same seeds every run: the test
// is deterministic.
#include "render/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

using namespace canopy;
namespace fs = std::filesystem;

namespace {

const char* kScene = R"({
  "camera": { "position": [0, 1, 2.5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": 30 },
  "film": { "width": 16, "height": 16 },
  "integrator": { "spp": 1, "max_depth": 1 },
  "materials": [ { "name": "floor", "albedo": 0.6 } ],
  "shapes": [ { "type": "box", "material": "floor", "min": [-4, -1, -4], "max": [4, 0, 4] } ],
  "lights": [
    { "type": "quad", "corner": [-1, 2, -1], "edge1": [2, 0, 0], "edge2": [0, 0, 2], "radiance": 4 }
  ]
})";

class SamplerConvergence : public ::testing::Test {
protected:
  void SetUp() override {
    path_ =
        fs::temp_directory_path() / ("canopy-test-sampler-" + std::to_string(::getpid()) + ".json");
    std::ofstream(path_) << kScene;
    scene_ = load_scene(path_);
  }
  void TearDown() override { fs::remove(path_); }

  // Per-pixel means of a render of `spp` samples.
  std::vector<double> render(const std::string& path_sampler, int spp, uint32_t seed) {
    RendererOptions opt;
    opt.path_sampler = path_sampler;
    Renderer renderer(rt_, scene_, opt);
    RenderSettings rs;
    rs.spp = spp;
    rs.seed = seed;
    Film f = renderer.render(rs);
    EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
    std::vector<double> m;
    for (const double4& s : f.sum)
      m.push_back((s.x + s.y + s.z) / (3.0 * s.w));
    return m;
  }

  fs::path path_;
  Scene scene_;
  ClRuntime rt_;
};

// Least-squares slope of y against x.
double slope(const std::vector<double>& x, const std::vector<double>& y) {
  double mx = 0, my = 0;
  for (size_t i = 0; i < x.size(); ++i)
    mx += x[i], my += y[i];
  mx /= double(x.size());
  my /= double(y.size());
  double sxy = 0, sxx = 0;
  for (size_t i = 0; i < x.size(); ++i)
    sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
  return sxy / sxx;
}

} // namespace

TEST_F(SamplerConvergence, SobolErrorFallsFasterThanIndependent) {
  const std::vector<double> ref = render("sobol", 16384, 1000);
  double mean_ref = 0.0;
  for (double v : ref)
    mean_ref += v / double(ref.size());
  ASSERT_GT(mean_ref, 0.01) << "the floor must be lit";
  const std::vector<int> spps = {1, 4, 16, 64, 256};
  const int seeds = 4;
  double slopes[2] = {0, 0}, rmse256[2] = {0, 0};
  const char* names[2] = {"independent", "sobol"};
  for (int s = 0; s < 2; ++s) {
    std::vector<double> lx, ly;
    for (int spp : spps) {
      double mse = 0.0;
      for (int k = 0; k < seeds; ++k) {
        std::vector<double> m = render(names[s], spp, uint32_t(1 + k));
        for (size_t p = 0; p < m.size(); ++p)
          mse += (m[p] - ref[p]) * (m[p] - ref[p]) / double(m.size() * seeds);
      }
      const double rmse = std::sqrt(mse) / mean_ref;
      std::printf("%-11s %4d spp: relative RMSE %.5f\n", names[s], spp, rmse);
      lx.push_back(std::log(double(spp)));
      ly.push_back(std::log(rmse));
      if (spp == 256) rmse256[s] = rmse;
    }
    slopes[s] = slope(lx, ly);
    std::printf("%-11s log-log slope %.3f\n", names[s], slopes[s]);
  }
  EXPECT_GT(slopes[0], -0.6); // Monte Carlo: -0.5
  EXPECT_LT(slopes[0], -0.4);
  EXPECT_LT(slopes[1], -0.55);
  EXPECT_LT(rmse256[1], 0.7 * rmse256[0]);
}
