// Multiple scattering in a medium with area lights: three unbiased estimators of the same image
// must agree within their standard errors.
// - tree-split with MIS: the segment's equiangular and free-flight light samples and the
//   phase-function ray that finds an emitter, combined by the power heuristic (volume_light.h);
// - tree-split without MIS: light samples alone (two techniques in t), phase rays' emission not
//   counted;
// - bsdf: no light sampling at all, emission found by phase-function and BSDF rays only (with one
//   more bounce, see render()).
// The three share no weights, so MIS weights that do not sum to one (or a density in the wrong
// measure) show as a difference. Compared per block of pixels, with a bound from the films' own
// second moments.
#include "render/renderer.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace canopy;

namespace {

// A diffuse floor and a back wall in a forward-scattering, coloured medium that fills space, lit
// by a ceiling-sized quad (it subtends a large solid angle, so phase-function rays find it with
// densities close to light sampling's and the three-way weights matter), a small quad, a sphere and
// a two-sided disk (every light an area light: BSDF and phase rays can find them all). Paths of 3
// vertices: single and double scattering, floor and wall bounces.
const char* kScene = R"({
  "camera": { "position": [0, 1.2, 4], "look_at": [0, 0.8, 0], "fov": 55 },
  "film": { "width": 24, "height": 16 },
  "integrator": { "max_depth": 3 },
  "materials": [ { "name": "floor", "albedo": 0.6 }, { "name": "wall", "albedo": [0.3, 0.5, 0.6] } ],
  "shapes": [
    { "type": "quad", "material": "floor", "corner": [-4, 0, -4], "edge1": [0, 0, 8], "edge2": [8, 0, 0] },
    { "type": "quad", "material": "wall", "corner": [-4, 0, -2], "edge1": [8, 0, 0], "edge2": [0, 4, 0] }
  ],
  "lights": [
    { "type": "quad", "corner": [-4, 2.0, -4], "edge1": [8, 0, 0], "edge2": [0, 0, 8], "radiance": [0.6, 0.6, 0.5] },
    { "type": "quad", "corner": [1.0, 0.6, 0.0], "edge1": [0, 0.3, 0], "edge2": [0, 0, 0.3], "radiance": [10, 4, 2], "two_sided": true },
    { "type": "sphere", "center": [-1.3, 0.5, 0.5], "radius": 0.15, "radiance": [2, 6, 9] },
    { "type": "disk", "center": [0.5, 1.5, -1.5], "normal": [0, -0.5, 1], "radius": 0.3, "radiance": 5, "two_sided": true }
  ],
  "medium": { "sigma_a": [0.05, 0.08, 0.1], "sigma_s": [0.35, 0.3, 0.25], "g": 0.5 }
})";

// bsdf finds a light only from the vertex before: a path of k scattering vertices needs k + 1
// bounces of it, so it renders with one more than the light samplers for the same paths.
Film render(const std::string& sampler, bool mis, int spp) {
  Scene scene = load_scene_from_string(kScene, "medium-mis.json", ".");
  if (sampler == "bsdf") scene.integrator.max_depth += 1;
  ClRuntime rt;
  RendererOptions opt;
  opt.light_sampler = sampler;
  opt.mis = mis;
  Renderer r(rt, scene, opt);
  RenderSettings rs;
  rs.spp = spp;
  rs.seed = 11;
  Film f = r.render(rs);
  EXPECT_EQ(r.stats().nonfinite_samples, 0u) << sampler;
  if (sampler != "bsdf") {
    EXPECT_GT(r.stats().medium_segments, 0u);
    EXPECT_GT(r.stats().medium_shadow_rays, 0u);
  }
  return f;
}

// Means and variances of the means over blocks of 4 x 4 pixels, per channel.
struct Blocks {
  std::vector<double> mean, var;
};
Blocks blocks(const Film& f) {
  const int B = 4;
  Blocks b;
  for (int by = 0; by < f.height / B; ++by)
    for (int bx = 0; bx < f.width / B; ++bx)
      for (int c = 0; c < 3; ++c) {
        double m = 0, v = 0;
        for (int y = by * B; y < (by + 1) * B; ++y)
          for (int x = bx * B; x < (bx + 1) * B; ++x) {
            const double4& s = f.sum[size_t(y * f.width + x)];
            const double4& q = f.sumsq[size_t(y * f.width + x)];
            double n = s.w, sx = c == 0 ? s.x : c == 1 ? s.y : s.z;
            double qx = c == 0 ? q.x : c == 1 ? q.y : q.z;
            double pm = sx / n;
            m += pm;
            v += std::max(qx / n - pm * pm, 0.0) / n; // variance of the pixel's mean
          }
        b.mean.push_back(m / (B * B));
        b.var.push_back(v / (B * B * B * B));
      }
  return b;
}

void expect_agree(const Blocks& a, const Blocks& b, const char* what) {
  ASSERT_EQ(a.mean.size(), b.mean.size());
  double worst = 0, total_a = 0, total_b = 0, var_total = 0;
  for (size_t i = 0; i < a.mean.size(); ++i) {
    double z = (a.mean[i] - b.mean[i]) / std::sqrt(a.var[i] + b.var[i] + 1e-30);
    worst = std::max(worst, std::fabs(z));
    total_a += a.mean[i];
    total_b += b.mean[i];
    var_total += a.var[i] + b.var[i];
  }
  // 72 comparisons: |z| < 4.5 holds for all with probability > 0.9995 if both are unbiased.
  EXPECT_LT(worst, 4.5) << what;
  double z_total = (total_a - total_b) / std::sqrt(var_total);
  EXPECT_LT(std::fabs(z_total), 4.0) << what << ": image totals " << total_a << " vs " << total_b;
  EXPECT_GT(total_a, 0.0);
}

} // namespace

TEST(RenderMediumMis, LightSamplesPhaseRaysAndTheirMisAgree) {
  Blocks mis = blocks(render("tree-split", true, 64));
  Blocks light_only = blocks(render("tree-split", false, 64));
  Blocks phase_only = blocks(render("bsdf", true, 512));
  expect_agree(mis, light_only, "MIS against light samples alone");
  expect_agree(mis, phase_only, "MIS against BSDF and phase-function rays alone");
}

// Extreme but valid media render without a non-finite sample: coefficients from 1e-20 to 1e20,
// channels six decades apart, g near +-1, a box far smaller than a light's distance and one near
// the coordinate limit, lights of 1e-6 and 1e6 at the same place.
TEST(RenderMediumMis, ExtremeMediaStayFinite) {
  const char* media[] = {
      R"({"sigma_a": 0, "sigma_s": 1e20})",
      R"({"sigma_a": 1e-20, "sigma_s": 1e-20})",
      R"({"sigma_a": 0, "sigma_s": [1e6, 0, 1e-6], "g": 0.99999})",
      R"({"sigma_a": 0.1, "sigma_s": 0.5, "g": -0.999999,
          "bounds": {"min": [-0.001, 0.9999, -0.001], "max": [0.001, 1.0001, 0.001]}})",
      R"({"sigma_a": 0, "sigma_s": 0.3, "bounds": {"min": [-1e17, -1e17, -1e17], "max": [1e17, 1e17, 1e17]}})",
      R"({"sigma_a": 5, "sigma_s": 0})"};
  for (const char* m : media) {
    std::string json = std::string(R"({
      "camera": { "position": [0, 1, 4], "look_at": [0, 1, 0] },
      "film": { "width": 8, "height": 6 },
      "integrator": { "max_depth": 3 },
      "shapes": [ { "type": "quad", "corner": [-4, 0, -4], "edge1": [0, 0, 8], "edge2": [8, 0, 0] } ],
      "lights": [ { "type": "point", "position": [0, 1, 0], "intensity": 1e6 },
                  { "type": "point", "position": [0, 1, 0], "intensity": 1e-6 },
                  { "type": "spot", "position": [1, 2, 0], "direction": [0, -1, 0], "intensity": 3, "cone_angle": 20 },
                  { "type": "quad", "corner": [-0.5, 2, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "radiance": 2 } ],
      "medium": )") + m +
                       "}";
    Scene scene = load_scene_from_string(json, "extreme-medium.json", ".");
    ClRuntime rt;
    RendererOptions opt;
    Renderer r(rt, scene, opt);
    RenderSettings rs;
    rs.spp = 16;
    Film f = r.render(rs);
    EXPECT_EQ(r.stats().nonfinite_samples, 0u) << m;
    for (const double4& s : f.sum)
      ASSERT_TRUE(std::isfinite(s.x) && std::isfinite(s.y) && std::isfinite(s.z)) << m;
  }
}
