// The light tree on smooth-shaded meshes (issue 20, part 0). A coarse UV sphere (8 x 5 segments:
// shading and geometric normals differ by up to ~20 degrees) of glossy plastic under 2,000 point
// lights close to it, rendered as direct light (max_depth 1) with its vertex normals (smooth) and
// without (flat). The BSDF's cosine is taken with the shading normal, so the tree's importance must
// bound it with that normal too (light_query_normal): bounded with the geometric normal, lights
// near a facet's horizon got a far smaller pmf than their contribution. Measured here with the
// geometric normal: the tree's variance grew 2.60x from flat to smooth, power's 1.11x; with the
// shading normal the tree's grows 1.03x. So:
// - the tree's variance may grow from flat to smooth by no more than power's does;
// - the tree's image mean equals the exhaustive sum within its standard error (point lights: the
//   exhaustive estimator's only noise is the pixel filter's).
#include "render/renderer.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

using namespace canopy;

namespace {

// A UV sphere of radius 1 (nu segments around, nv rings), with per-vertex normals if `smooth`.
std::filesystem::path write_uv_sphere(bool smooth, int nu = 8, int nv = 5) {
  auto dir = std::filesystem::temp_directory_path() / "canopy-smooth-sphere";
  std::filesystem::create_directories(dir);
  auto path = dir / (smooth ? "smooth.obj" : "flat.obj");
  std::ofstream f(path);
  auto vertex = [&](int i, int j) { // ring j in [0, nv], segment i
    double th = M_PI * j / nv, ph = 2.0 * M_PI * i / nu;
    double x = std::sin(th) * std::cos(ph), y = std::cos(th), z = std::sin(th) * std::sin(ph);
    f << "v " << x << " " << y << " " << z << "\n";
    if (smooth) f << "vn " << x << " " << y << " " << z << "\n";
  };
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i < nu; ++i)
      vertex(i, j);
  auto idx = [&](int i, int j) { return j * nu + (i % nu) + 1; };
  auto face = [&](int a, int b, int c) {
    if (smooth)
      f << "f " << a << "//" << a << " " << b << "//" << b << " " << c << "//" << c << "\n";
    else
      f << "f " << a << " " << b << " " << c << "\n";
  };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) { // outward winding (counter-clockwise seen from outside)
      int a = idx(i, j), b = idx(i + 1, j), c = idx(i + 1, j + 1), d = idx(i, j + 1);
      if (j > 0) face(a, b, c);
      if (j + 1 < nv) face(a, c, d);
    }
  return path;
}

// 2,000 point lights on a shell of radii 1.05 to 1.65 around the sphere (fixed seed): many are
// near a facet's horizon.
std::string lights_json() {
  std::mt19937 rng(20);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::string s = "[";
  for (int k = 0; k < 2000; ++k) {
    double z = 2 * u(rng) - 1, ph = 2 * M_PI * u(rng), r = 1.05 + 0.6 * u(rng);
    double sx = std::sqrt(1 - z * z);
    double I = 0.02 + 0.08 * u(rng);
    s += (k ? "," : "") + std::string(R"({"type": "point", "position": [)") +
         std::to_string(r * sx * std::cos(ph)) + "," + std::to_string(r * z) + "," +
         std::to_string(r * sx * std::sin(ph)) + R"(], "intensity": [)" + std::to_string(I) + "," +
         std::to_string(I) + "," + std::to_string(I) + "]}";
  }
  return s + "]";
}

struct ImageStats {
  double mean = 0;     // image mean (channel average) of the pixel means
  double mean_se2 = 0; // its squared standard error
  double variance = 0; // mean over pixels of a single sample's variance
};

ImageStats render(bool smooth, const std::string& sampler, int spp) {
  std::filesystem::path obj = write_uv_sphere(smooth);
  std::string json = R"({ "camera": { "position": [0, 0.6, 3.2], "look_at": [0, 0, 0],
                                      "up": [0, 1, 0], "fov": 42 },
    "film": { "width": 32, "height": 32 }, "integrator": { "max_depth": 1 },
    "materials": [ { "name": "m", "type": "plastic", "albedo": [0.3, 0.25, 0.2],
                     "roughness": 0.6 } ],
    "shapes": [ { "type": "obj", "file": ")" +
                     obj.filename().string() + R"(", "material": "m" } ],
    "lights": )" + lights_json() +
                     "}";
  Scene scene = load_scene_from_string(json, "smooth-sphere", obj.parent_path());
  EXPECT_EQ(scene.shading_normals.empty(), !smooth);
  ClRuntime rt;
  RendererOptions opt;
  opt.light_sampler = sampler;
  Renderer r(rt, scene, opt);
  RenderSettings rs;
  rs.spp = spp;
  rs.seed = 3;
  Film film = r.render(rs);
  EXPECT_EQ(r.stats().nonfinite_samples, 0u);
  ImageStats st;
  const double npix = double(film.sum.size());
  for (size_t p = 0; p < film.sum.size(); ++p) {
    double n = film.sum[p].w;
    const double* sum = &film.sum[p].x;
    const double* sq = &film.sumsq[p].x;
    for (int c = 0; c < 3; ++c) {
      double m = sum[c] / n, var = std::max(0.0, sq[c] / n - m * m) * n / (n - 1.0);
      st.mean += m / (3 * npix);
      st.mean_se2 += var / n / (9 * npix * npix);
      st.variance += var / (3 * npix);
    }
  }
  // The channels of one pixel are correlated (same samples): bound the mean's variance by
  // treating them as fully correlated, (sum of 3 SEs)^2 <= 3 * sum of SE^2.
  st.mean_se2 *= 3.0;
  std::printf("%-10s %-6s mean %.6f (se %.2e), per-sample variance %.4e\n", sampler.c_str(),
              smooth ? "smooth" : "flat", st.mean, std::sqrt(st.mean_se2), st.variance);
  return st;
}

} // namespace

TEST(RenderSmoothSphere, TreeVarianceFollowsTheShadingNormal) {
  const int spp = 64;
  ImageStats tree_s = render(true, "tree", spp), tree_f = render(false, "tree", spp);
  ImageStats power_s = render(true, "power", spp), power_f = render(false, "power", spp);
  ImageStats exh_s = render(true, "exhaustive", spp), exh_f = render(false, "exhaustive", spp);
  ASSERT_GT(tree_f.variance, 0.0);
  ASSERT_GT(power_f.variance, 0.0);
  double tree_ratio = tree_s.variance / tree_f.variance;
  double power_ratio = power_s.variance / power_f.variance;
  std::printf("smooth / flat variance: tree %.2f, power %.2f\n", tree_ratio, power_ratio);
  EXPECT_LE(tree_ratio, power_ratio);
  // Unbiased: the tree's image mean is the exhaustive sum's within 5 standard errors, smooth and
  // flat; and the smooth sphere is lit differently from the flat one (the test sees the normals).
  EXPECT_NEAR(tree_s.mean, exh_s.mean, 5.0 * std::sqrt(tree_s.mean_se2 + exh_s.mean_se2));
  EXPECT_NEAR(tree_f.mean, exh_f.mean, 5.0 * std::sqrt(tree_f.mean_se2 + exh_f.mean_se2));
  EXPECT_NEAR(power_s.mean, exh_s.mean, 5.0 * std::sqrt(power_s.mean_se2 + exh_s.mean_se2));
  EXPECT_GT(std::fabs(exh_s.mean - exh_f.mean), 5.0 * std::sqrt(exh_s.mean_se2 + exh_f.mean_se2));
}
