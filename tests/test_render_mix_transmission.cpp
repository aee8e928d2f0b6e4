// Rendered closed forms of the mix material, the checkerboard texture and diffuse transmission
// (direct light, max_depth 1, on the plane of support/lit_plane.h):
// - a plate of mix(A, B, amount) under the sun: each sample is A's or B's exact radiance, so every
//   pixel's mean is the amount-weighted one within its sample standard error, and the share of
//   samples that saw B (from the image mean) is `amount` within its binomial bound;
// - a checkerboard-textured plate under the sun: each pixel inside one square is exactly that
//   square's reflectance's radiance;
// - a diffuse-transmission plate lit from behind (a sun, a point light) and in front: T / pi and
//   R / pi closed forms on the camera's side, for every light sampler (the light tree's bound must
//   see the light behind the plate), and MIS with BSDF rays through the plate (an area light
//   behind it) agrees with BSDF sampling alone;
// - kernels of scenes without these features hold none of their code (their programs are smaller
//   than the same programs with it), and the minimal kernels render the same images as kernels
//   with every feature.
#include "render/camera.h"
#include "render/features.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "support/lit_plane.h"
#include "support/test_lights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace canopy;

namespace {

constexpr float kPi = 3.14159265358979323846f;

// Pixel p's mean and the standard error of its red channel (k = 0), green (1) or blue (2).
void pixel_stats(const Film& f, size_t p, int k, double* mean, double* se) {
  const double n = f.sum[p].w;
  const double s = k == 0 ? f.sum[p].x : (k == 1 ? f.sum[p].y : f.sum[p].z);
  const double q = k == 0 ? f.sumsq[p].x : (k == 1 ? f.sumsq[p].y : f.sumsq[p].z);
  *mean = s / n;
  *se = std::sqrt(std::max(0.0, q / n - *mean * *mean) / (n - 1.0));
}

TextureDesc constant_desc(float3 v) {
  TextureDesc t;
  t.kind = TEXTURE_CONSTANT;
  t.scale = v;
  return t;
}

} // namespace

// mix(A, B, 0.3) under the sun: a sample is A's or B's rho / pi E cos exactly.
TEST(RenderMix, PlateOfTwoDiffuseMaterialsIsTheAmountWeightedMean) {
  const float3 A = make_float3(0.8f, 0.2f, 0.1f), B = make_float3(0.1f, 0.3f, 0.9f);
  const float amount = 0.3f;
  const float3 E = make_float3(2.0f, 2.0f, 2.0f), travel = make_float3(0.2f, 0.3f, -0.9f);
  const float cos_t = -normalize(travel).z;
  for (const char* sampler : {"power", "tree-split"}) {
    SCOPED_TRACE(sampler);
    Scene scene = test::lit_plane_scene(mix_material("mix", 1, 2, amount), 20.0f, 1.0f, 24, 24);
    scene.materials.push_back(diffuse_material("A", A));
    scene.materials.push_back(diffuse_material("B", B));
    scene.infinite_lights.push_back(test::distant_light(travel, E));
    Film film = test::render_lit_plane(scene, sampler, 64);
    const float a = A.x * E.x * cos_t / kPi, b = B.x * E.x * cos_t / kPi;
    const double expect = (1.0 - amount) * a + amount * b;
    double total = 0.0, samples = 0.0;
    for (size_t p = 0; p < film.sum.size(); ++p) {
      double mean, se;
      pixel_stats(film, p, 0, &mean, &se);
      // 5 standard errors, and at least the error of a pixel whose samples all took one material
      // less or more than the binomial's 5 sigma (se is 0 when every sample took the same one).
      const double n = film.sum[p].w;
      const double floor = (a - b) * 5.0 * std::sqrt(amount * (1 - amount) / n);
      EXPECT_NEAR(mean, expect, std::max(5.0 * se, std::fabs(floor))) << "pixel " << p;
      total += film.sum[p].x;
      samples += n;
    }
    // The device's choice: the share of samples that took B.
    const double share = (total / samples - a) / (b - a);
    EXPECT_NEAR(share, amount, 5.0 * std::sqrt(amount * (1 - amount) / samples));
  }
}

// A diffuse plate with a checkerboard albedo (2 x 2 squares over the plate: uv scale 2): every
// pixel whose footprint lies inside one square is that square's rho / pi E cos exactly.
TEST(RenderMix, CheckerboardSquaresAreExactUnderTheSun) {
  const float3 c1 = make_float3(0.9f, 0.2f, 0.1f), c2 = make_float3(0.1f, 0.6f, 0.3f);
  const float3 E = make_float3(3.0f, 2.0f, 5.0f), travel = make_float3(0.3f, -0.6f, -0.8f);
  const float cos_t = -normalize(travel).z;
  MaterialDesc m = diffuse_material("checks", make_float3(0, 0, 0));
  m.gpu.albedo_texture = 3;
  Scene scene = test::uv_plane_scene(m, 40);
  scene.textures = {constant_desc(c1), constant_desc(c2), TextureDesc{}};
  scene.textures[2].kind = TEXTURE_CHECKERBOARD;
  scene.textures[2].nodes = 3;
  scene.textures[2].uvmap = make_float4(2, 2, 0, 0);
  scene.infinite_lights.push_back(test::distant_light(travel, E));
  Film film = test::render_lit_plane(scene, "tree", 4);
  CameraParams cam = make_camera_params(scene.camera, scene.film.width, scene.film.height);
  int seen[2] = {0, 0};
  for (int y = 0; y < film.height; ++y)
    for (int x = 0; x < film.width; ++x) {
      int square = -1;
      for (int c = 0; c < 4; ++c) { // the square of each footprint corner, in world x, y
        float3 X;
        test::camera_ray_to_plane(cam, float(x + (c & 1)), float(y + (c >> 1)), &X);
        const float m0 = 1e-3f;
        if (std::fabs(X.x) < m0 || std::fabs(X.y) < m0 || std::fabs(X.x) > 1 - m0 ||
            std::fabs(X.y) > 1 - m0) {
          square = -2;
          break;
        }
        int s = (X.x > 0) ^ (X.y > 0); // floor(2u) + floor(2v) odd
        if (square >= 0 && s != square) {
          square = -2;
          break;
        }
        square = s;
      }
      if (square < 0) continue;
      ++seen[square];
      const size_t p = size_t(y) * size_t(film.width) + size_t(x);
      const double n = film.sum[p].w;
      const float3 want = (square ? c2 : c1) * E * (cos_t / kPi);
      EXPECT_NEAR(film.sum[p].x / n, want.x, 2e-6f * want.x) << x << "," << y;
      EXPECT_NEAR(film.sum[p].y / n, want.y, 2e-6f * want.y) << x << "," << y;
      EXPECT_NEAR(film.sum[p].z / n, want.z, 2e-6f * want.z) << x << "," << y;
    }
  EXPECT_GT(seen[0], 200);
  EXPECT_GT(seen[1], 200);
}

// A thin diffuse-transmission plate between a sun below it and one above, seen from above: every
// pixel is (T E_below |cos_below| + R E_above cos_above) / pi exactly, for every sampler.
TEST(RenderTransmission, PlateLitFromBehindShowsTOverPi) {
  const float3 R = make_float3(0.2f, 0.3f, 0.1f), T = make_float3(0.6f, 0.4f, 0.7f);
  const float3 E_below = make_float3(3.0f, 2.0f, 4.0f), E_above = make_float3(1.0f, 1.0f, 1.0f);
  const float3 up = make_float3(0.3f, -0.2f, 0.9f), down = make_float3(-0.1f, 0.4f, -0.8f);
  const float cos_b = normalize(up).z, cos_a = -normalize(down).z;
  for (const char* sampler : {"power", "tree", "tree-split", "exhaustive", "brdf-mis"}) {
    SCOPED_TRACE(sampler);
    Scene scene =
        test::lit_plane_scene(diffuse_transmission_material("dt", R, T), 20.0f, 1.0f, 16, 16);
    scene.infinite_lights.push_back(
        test::distant_light(up, E_below)); // travels up: lights the far side
    scene.infinite_lights.push_back(test::distant_light(down, E_above));
    Film film = test::render_lit_plane(scene, sampler, 2);
    const float3 want = (T * E_below * cos_b + R * E_above * cos_a) * (1.0f / kPi);
    for (size_t p = 0; p < film.sum.size(); ++p) {
      const double n = film.sum[p].w;
      EXPECT_NEAR(film.sum[p].x / n, want.x, 2e-6f * want.x) << p;
      EXPECT_NEAR(film.sum[p].z / n, want.z, 2e-6f * want.z) << p;
    }
  }
}

// A point light behind the plate (and a dimmer one in front, bright enough that every sampler
// picks it in a fair share of the 64 samples, so that the standard error is a fair one): T / pi I
// |cos| / d^2 plus the front light's R term, box-filtered over each pixel (16 x 16 midpoint rule;
// its distance to a 4 x 4 rule and 5 standard errors bound the tolerance). The light tree's query
// at a transmitting point has no normal: a one-sided bound would give the light behind importance 0
// (a black plate).
TEST(RenderTransmission, PointLightBehindThePlateForEveryLightSampler) {
  const float3 R = make_float3(0.3f, 0.3f, 0.3f), T = make_float3(0.5f, 0.5f, 0.5f);
  const float3 behind = make_float3(0.2f, -0.3f, -1.2f), front = make_float3(-0.4f, 0.2f, 1.5f);
  const float3 I_b = make_float3(4.0f, 4.0f, 4.0f), I_f = make_float3(2.0f, 2.0f, 2.0f);
  for (const char* sampler : {"uniform", "power", "tree", "tree-split", "exhaustive"}) {
    SCOPED_TRACE(sampler);
    Scene scene =
        test::lit_plane_scene(diffuse_transmission_material("dt", R, T), 20.0f, 1.0f, 16, 16);
    scene.lights.push_back(test::point_light(behind, I_b));
    scene.lights.push_back(test::point_light(front, I_f));
    Film film = test::render_lit_plane(scene, sampler, 64);
    CameraParams cam = make_camera_params(scene.camera, scene.film.width, scene.film.height);
    for (int y = 0; y < film.height; ++y)
      for (int x = 0; x < film.width; ++x) {
        auto radiance = [&](float fx, float fy) -> double { // summed in double
          float3 X;
          test::camera_ray_to_plane(cam, fx, fy, &X);
          float3 tb = behind - X, tf = front - X;
          float db = dot(tb, tb), df = dot(tf, tf);
          return T.x / kPi * I_b.x * std::fabs(tb.z) / (db * std::sqrt(db)) +
                 R.x / kPi * I_f.x * tf.z / (df * std::sqrt(df));
        };
        const double ref = test::pixel_average(radiance, x, y, 16);
        const double coarse = test::pixel_average(radiance, x, y, 4);
        const size_t p = size_t(y) * size_t(film.width) + size_t(x);
        double mean, se;
        pixel_stats(film, p, 0, &mean, &se);
        EXPECT_NEAR(mean, ref, 5.0 * se + std::fabs(ref - coarse) + 1e-5 * ref) << x << "," << y;
      }
  }
}

// A quad light behind the plate (depth 1): light samples through the plate and BSDF rays through
// it are MIS-weighted against each other; the image equals BSDF sampling alone's (no light
// sampling) within their standard errors. Weighting the transmitted BSDF rays as delta bounces
// (weight 1) would count the light twice.
TEST(RenderTransmission, MisThroughThePlateAgreesWithBsdfSampling) {
  auto render = [](const std::string& sampler) {
    Scene scene =
        test::lit_plane_scene(diffuse_transmission_material("dt", make_float3(0.2f, 0.2f, 0.2f),
                                                            make_float3(0.7f, 0.7f, 0.7f)),
                              20.0f, 1.0f, 12, 12);
    Light q{};
    q.type = LIGHT_QUAD;
    q.p = make_float4(-1.5f, -1.5f, -0.8f, 0.0f);
    q.e1 = make_float4(3.0f, 0.0f, 0.0f, 0.0f);
    q.e2 = make_float4(0.0f, 3.0f, 0.0f, 0.0f);
    q.n = make_float4(0.0f, 0.0f, 1.0f, 9.0f); // facing the plate
    q.emission = make_float4(1.0f, 1.0f, 1.0f, 0.0f);
    q.prim = -1;
    scene.lights.push_back(q);
    return test::render_lit_plane(scene, sampler, 256);
  };
  Film mis = render("tree"), bsdf = render("bsdf");
  double sm = 0, sb = 0, vm = 0, vb = 0, n = 0;
  for (size_t p = 0; p < mis.sum.size(); ++p) {
    double m, se_m, b, se_b;
    pixel_stats(mis, p, 0, &m, &se_m);
    pixel_stats(bsdf, p, 0, &b, &se_b);
    sm += m;
    sb += b;
    vm += se_m * se_m;
    vb += se_b * se_b;
    n += 1;
  }
  EXPECT_NEAR(sm / n, sb / n, 5.0 * std::sqrt(vm + vb) / n);
  EXPECT_GT(sm / n, 0.05); // the light behind is seen
}

// Kernels are specialised: scenes without a mix or diffuse transmission compile none of their
// code; with them, the minimal kernels render what kernels with every feature render.
TEST(RenderMix, KernelsHoldTheseFeaturesOnlyWhereTheSceneUsesThem) {
  Scene plain = test::lit_plane_scene(diffuse_material("d", make_float3(0.5f, 0.5f, 0.5f)), 20.0f,
                                      1.0f, 8, 8);
  KernelFeatures f = scene_features(plain, SAMPLER_TREE);
  EXPECT_FALSE(f.material_mix);
  EXPECT_FALSE(f.material_diffuse_transmission);
  EXPECT_NE(f.build_options().find("-DHAS_MATERIAL_MIX=0 -DHAS_MATERIAL_DIFFUSE_TRANSMISSION=0"),
            std::string::npos);
  Scene mixed = test::lit_plane_scene(mix_material("m", 1, 2, 0.4f), 20.0f, 1.0f, 16, 16);
  mixed.materials.push_back(diffuse_material("a", make_float3(0.7f, 0.2f, 0.2f)));
  mixed.materials.push_back(diffuse_transmission_material("t", make_float3(0.3f, 0.3f, 0.3f),
                                                          make_float3(0.5f, 0.5f, 0.5f)));
  mixed.lights.push_back(test::point_light(make_float3(0.3f, 0.2f, -1.0f), make_float3(3, 3, 3)));
  mixed.lights.push_back(test::point_light(make_float3(-0.3f, 0.2f, 1.0f), make_float3(2, 2, 2)));
  // The code is gone, not just unused: the program of the plain scene's features is smaller than
  // the same program with the mix or the diffuse-transmission code.
  {
    ClRuntime rt;
    auto binary_size = [&](const KernelFeatures& k) {
      cl::Program p = rt.build_program(wavefront_kernel_files(), k.build_options());
      size_t total = 0;
      for (size_t n : p.getInfo<CL_PROGRAM_BINARY_SIZES>())
        total += n;
      return total;
    };
    KernelFeatures with_mix = f, with_dt = f;
    with_mix.material_mix = true;
    with_dt.material_diffuse_transmission = true;
    const size_t plain_size = binary_size(f);
    EXPECT_LT(plain_size, binary_size(with_mix));
    EXPECT_LT(plain_size, binary_size(with_dt));
  }
  KernelFeatures g = scene_features(mixed, SAMPLER_TREE_SPLIT);
  EXPECT_TRUE(g.material_mix);
  EXPECT_TRUE(g.material_diffuse_transmission);
  EXPECT_FALSE(g.material_conductor);
  auto render = [&](bool all) {
    ClRuntime rt;
    RendererOptions opt;
    opt.light_sampler = "tree-split";
    opt.all_features = all;
    Renderer r(rt, mixed, opt);
    RenderSettings rs;
    rs.spp = 4;
    rs.seed = 3;
    return r.render(rs);
  };
  Film a = render(false), b = render(true);
  ASSERT_EQ(a.sum.size(), b.sum.size());
  for (size_t p = 0; p < a.sum.size(); ++p) {
    ASSERT_EQ(a.sum[p].x, b.sum[p].x) << p;
    ASSERT_EQ(a.sum[p].z, b.sum[p].z) << p;
  }
}
