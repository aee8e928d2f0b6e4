// Environment lights (cl/types.h LIGHT_ENVIRONMENT, cl/lights/environment.h): the projections,
// the texel distribution (chi-square against its pmf, the sampled pdf against the evaluated one,
// the integral of the radiance), and renders against closed forms: a diffuse plane under a
// constant sky is rho L, a glossy one L times its directional albedo, and a map with one bright
// texel gives the plane that texel's irradiance.
#include "bsdf/bsdf.h"
#include "image/image_io.h"
#include "lights/environment.h"
#include "render/camera.h"
#include "render/environment_map.h"
#include "render/renderer.h"
#include "scene/pbrt_reader.h"
#include "scene/scene.h"
#include "support/lit_plane.h"

#include "support/test_temp_dir.h"
#include <fmt/format.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

using namespace canopy;

namespace {

constexpr double kPi = 3.14159265358979323846;

std::filesystem::path temp_dir() {
  return test::test_temp_dir("env");
}

// An environment light with frame (x, y, z) = world axes.
Light env_light(float3 scale, int map_index) {
  Light l{};
  l.type = LIGHT_ENVIRONMENT;
  l.prim = -1;
  l.pad = map_index;
  l.emission = f4_from3(scale, 0.0f);
  l.e1 = make_float4(1, 0, 0, 0);
  l.e2 = make_float4(0, 1, 0, 0);
  l.n = make_float4(0, 0, 1, 0);
  return l;
}

// A map written as EXR (rgb per texel, row 0 on top).
std::filesystem::path write_map(const std::string& name, int w, int h,
                                const std::vector<float>& rgb) {
  RgbImage img;
  img.width = w;
  img.height = h;
  img.rgb = rgb;
  auto f = temp_dir() / name;
  write_exr(f, img);
  return f;
}

std::vector<float> random_map(int w, int h, uint32_t seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> rgb(size_t(w) * size_t(h) * 3);
  for (size_t i = 0; i < rgb.size(); ++i) {
    float x = u(gen);
    rgb[i] = x * x * x * 20.0f; // a wide dynamic range
  }
  for (int k = 0; k < 3; ++k)
    rgb[size_t(5) * 3 + size_t(k)] = 0.0f; // one black texel: never sampled
  return rgb;
}

struct HostEnv {
  std::vector<Light> lights;
  EnvironmentData data;
  EnvBuffers buffers() const {
    return {data.texels.data(), data.pmf.data(), data.alias_prob.data(), data.alias_index.data()};
  }
};

HostEnv host_env(int projection, int w, int h, const std::vector<float>& rgb) {
  HostEnv e;
  std::vector<EnvironmentMap> maps = {{write_map("map.exr", w, h, rgb), projection}};
  e.lights = {env_light(make_float3(1, 1, 1), 0)};
  e.data = build_environment_data(e.lights, maps);
  return e;
}

} // namespace

TEST(EnvironmentProjection, RoundTripsAndKnownDirections) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<float> u(0.001f, 0.999f);
  for (int i = 0; i < 10000; ++i) {
    float2 uv = make_float2(u(gen), u(gen));
    float3 d = env_octahedral_dir(uv);
    EXPECT_NEAR(length(d), 1.0f, 1e-5f);
    float2 back = env_octahedral_uv(d);
    EXPECT_NEAR(back.x, uv.x, 2e-5f);
    EXPECT_NEAR(back.y, uv.y, 2e-5f);
    float3 e = env_equirect_dir(uv);
    float2 eb = env_equirect_uv(e);
    EXPECT_NEAR(eb.x, uv.x, 2e-5f);
    EXPECT_NEAR(eb.y, uv.y, 2e-5f);
  }
  // pbrt-v4's equal-area square: the centre is +z, the corners -z, the edge midpoints the equator.
  auto near = [](float3 a, float3 b) { return length(a - b) < 1e-5f; };
  EXPECT_TRUE(near(env_octahedral_dir(make_float2(0.5f, 0.5f)), make_float3(0, 0, 1)));
  EXPECT_TRUE(near(env_octahedral_dir(make_float2(0.0f, 0.0f)), make_float3(0, 0, -1)));
  EXPECT_TRUE(near(env_octahedral_dir(make_float2(1.0f, 1.0f)), make_float3(0, 0, -1)));
  EXPECT_TRUE(near(env_octahedral_dir(make_float2(1.0f, 0.5f)), make_float3(1, 0, 0)));
  EXPECT_TRUE(near(env_octahedral_dir(make_float2(0.5f, 1.0f)), make_float3(0, 1, 0)));
  EXPECT_TRUE(near(env_octahedral_dir(make_float2(0.0f, 0.5f)), make_float3(-1, 0, 0)));
  // Equirectangular: u = 0 along +x, u = 1/4 along +y, v = 0 at +z, v = 1/2 on the equator.
  EXPECT_TRUE(near(env_equirect_dir(make_float2(0.0f, 0.5f)), make_float3(1, 0, 0)));
  EXPECT_TRUE(near(env_equirect_dir(make_float2(0.25f, 0.5f)), make_float3(0, 1, 0)));
  EXPECT_TRUE(near(env_equirect_dir(make_float2(0.3f, 0.0f)), make_float3(0, 0, 1)));
}

// The texel drawn by env_sample follows the pmf (chi-square), the returned pdf is env_pdf of the
// returned direction, the pmf is luminance x solid angle normalised, and L / pdf averages to the
// integral of the radiance over the sphere (its exact texel sum).
TEST(EnvironmentSampling, TexelsFollowThePmfAndPdfsAgree) {
  for (int projection : {ENV_EQUIRECT, ENV_OCTAHEDRAL}) {
    const int w = 8, h = projection == ENV_OCTAHEDRAL ? 8 : 5;
    std::vector<float> rgb = random_map(w, h, 11u + uint32_t(projection));
    HostEnv e = host_env(projection, w, h, rgb);
    const Light& l = e.lights[0];
    ASSERT_EQ(l.flags, projection);
    EnvBuffers eb = e.buffers();
    std::vector<double> weights = environment_texel_weights(e.data.texels, w, h, projection);
    double wsum = 0.0;
    for (double x : weights)
      wsum += x;
    double integral = 0.0; // exact: sum of luminance x solid angle
    for (double x : weights)
      integral += x;
    const int n = 200000;
    int edge_cases = 0;
    std::vector<int> counts(size_t(w * h), 0);
    double sum = 0.0, sum2 = 0.0;
    LtRng rng = lt_rng_make(5, 9);
    for (int i = 0; i < n; ++i) {
      float pdf;
      float3 L;
      float3 d = env_sample(&l, &eb, make_float3(0, 0, 0), &rng, &pdf, &L);
      ASSERT_GT(pdf, 0.0f);
      uint k = env_texel_of(&l, env_to_map(&l, d));
      counts[k] += 1;
      // The evaluated pdf (escaped rays' MIS) is the sampled one, but where the rounded direction
      // falls in a neighbouring texel (a patch's edge): counted, and rare.
      float pe = env_pdf(&l, &eb, make_float3(0, 0, 0), d);
      if (std::fabs(pe - pdf) > 1e-4f * pdf) ++edge_cases;
      EXPECT_NEAR(e.data.pmf[k], weights[k] / wsum, 1e-6 * (1.0 + weights[k] / wsum));
      double f = double(luminance3(L)) / double(pdf);
      sum += f;
      sum2 += f * f;
    }
    EXPECT_LT(edge_cases, n / 10000) << "projection " << projection;
    double chi2 = 0.0;
    int dof = -1;
    for (int k = 0; k < w * h; ++k) {
      double expect = n * e.data.pmf[size_t(k)];
      if (expect == 0.0) {
        EXPECT_EQ(counts[size_t(k)], 0) << "a black texel was drawn";
        continue;
      }
      chi2 += (counts[size_t(k)] - expect) * (counts[size_t(k)] - expect) / expect;
      ++dof;
    }
    // 99.99th percentile of chi-square with dof ~ 40-64: below dof + 6 sqrt(2 dof).
    EXPECT_LT(chi2, dof + 6.0 * std::sqrt(2.0 * dof)) << "projection " << projection;
    double mean = sum / n, se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, integral, 5.0 * se + 1e-4 * integral) << "projection " << projection;
  }
}

TEST(EnvironmentSampling, BadMapsAreOneLineErrors) {
  const auto wide = write_map("wide.exr", 4, 2, std::vector<float>(24, 1.0f));
  std::vector<EnvironmentMap> maps = {{wide, ENV_OCTAHEDRAL, "sky.pbrt:3: LightSource"}};
  std::vector<Light> lights = {env_light(make_float3(1, 1, 1), 0)};
  try {
    build_environment_data(lights, maps);
    ADD_FAILURE() << "a 4x2 octahedral map was accepted";
  } catch (const SceneError& err) {
    // where the map is named (EnvironmentMap::where), then the file
    EXPECT_EQ(std::string(err.what()), "sky.pbrt:3: LightSource: " + wide.string() +
                                           ": the equal-area octahedral projection needs "
                                           "a square map, not 4x2");
  }
  std::vector<float> neg(12, 1.0f);
  neg[4] = -1.0f;
  maps = {{write_map("neg.exr", 2, 2, neg), ENV_EQUIRECT}};
  try {
    build_environment_data(lights, maps);
    ADD_FAILURE() << "a negative texel was accepted";
  } catch (const SceneError& err) {
    EXPECT_NE(std::string(err.what()).find("neg.exr: texel (1, 0) is -1"), std::string::npos)
        << err.what();
  }
}

namespace {

// Every pixel sees the plane (a narrow field), wide enough to hide the lower hemisphere.
Scene plane_under_sky(MaterialDesc m) {
  return test::lit_plane_scene(std::move(m), 10.0f, 1e3f, 16, 12);
}

Film render(Scene& scene, const std::string& sampler, int spp, bool mis = true) {
  return test::render_lit_plane(scene, sampler, spp, mis);
}

// Image mean of channel 0 and its standard error (pixels as independent estimates).
std::pair<double, double> image_mean(const Film& f) {
  double s = 0.0, s2 = 0.0;
  size_t n = f.sum.size();
  for (const double4& p : f.sum) {
    double m = p.x / p.w;
    s += m;
    s2 += m * m;
  }
  double mean = s / double(n);
  return {mean, std::sqrt(std::max(0.0, s2 / double(n) - mean * mean) / double(n))};
}

const char* const kSamplers[] = {"uniform",    "power",    "tree",          "tree-split",
                                 "exhaustive", "brdf-mis", "brdf-oriented", "bsdf"};

} // namespace

// Under a constant sky L the plane's upper hemisphere sees L everywhere: a diffuse plane is
// exactly rho L (the light sample's cosine density cancels the BRDF's cosine; MIS weights add up
// to 1 per direction), with MIS and without, for every sampler.
TEST(EnvironmentRender, ConstantSkyOnADiffusePlaneIsRhoL) {
  for (const char* sampler : kSamplers)
    for (bool mis : {true, false}) {
      Scene scene = plane_under_sky(diffuse_material("white", make_float3(0.7f, 0.5f, 0.2f)));
      scene.infinite_lights.push_back(env_light(make_float3(2.0f, 3.0f, 4.0f), -1));
      Film film = render(scene, sampler, 4, mis);
      for (const double4& p : film.sum) {
        EXPECT_NEAR(p.x / p.w, 1.4, 1e-5) << sampler << (mis ? "" : " no MIS");
        EXPECT_NEAR(p.z / p.w, 0.8, 1e-5) << sampler << (mis ? "" : " no MIS");
      }
    }
}

// A glossy conductor under a constant sky: L times the directional albedo of its BRDF, whose
// host estimate (BSDF sampling weights of the kernel's own bsdf_sample, 10^6 samples at the
// image centre's wo) carries its own standard error. The camera's narrow field keeps wo nearly
// constant across the image.
TEST(EnvironmentRender, ConstantSkyOnAGlossyPlaneIsLTimesTheAlbedo) {
  MaterialDesc gold = conductor_material("gold", 0.4f, make_float3(0.143f, 0.374f, 1.442f),
                                         make_float3(3.983f, 2.385f, 1.603f));
  const float L = 1.5f;
  Scene probe = plane_under_sky(gold);
  float3 wo = normalize(probe.camera.position - probe.camera.look_at);
  double albedo_se;
  const double albedo = test::directional_albedo(gold.gpu, wo, 1000000, 1u, &albedo_se);
  for (const char* sampler : {"tree", "power", "brdf-mis", "brdf-oriented", "bsdf"}) {
    Scene scene = plane_under_sky(gold);
    scene.infinite_lights.push_back(env_light(make_float3(L, L, L), -1));
    Film film = render(scene, sampler, 64);
    auto [mean, se] = image_mean(film);
    // The image spans wo within ~5 degrees of the centre's: the albedo varies by < 0.5% there.
    EXPECT_NEAR(mean, L * albedo, 5.0 * (se + L * albedo_se) + 0.005 * L * albedo) << sampler;
  }
}

// A map that is black but for one texel: the plane's radiance is rho / pi times that texel's
// irradiance, the integral of L cos(theta) over its patch (a 64 x 64 midpoint rule, far finer than
// the patch's curvature). Every light sample lands in the texel; BSDF rays find it rarely. At
// 10^38 and 10^-36 (near float's limits) too: the renderer's emission scale must take the map's
// brightest texel into account, not only the light's scale.
TEST(EnvironmentRender, OneBrightTexelIsItsIrradiance) {
  for (auto [projection, Lt] : {std::pair{ENV_EQUIRECT, 50.0f}, std::pair{ENV_OCTAHEDRAL, 50.0f},
                                std::pair{ENV_EQUIRECT, 1e38f}, std::pair{ENV_EQUIRECT, 1e-36f}}) {
    const int w = 16, h = projection == ENV_OCTAHEDRAL ? 16 : 8;
    const int ti = 5, tj = projection == ENV_OCTAHEDRAL ? 7 : 2; // a texel above the horizon
    std::vector<float> rgb(size_t(w * h * 3), 0.0f);
    for (int k = 0; k < 3; ++k)
      rgb[(size_t(tj) * size_t(w) + size_t(ti)) * 3 + size_t(k)] = Lt;
    Scene scene = plane_under_sky(diffuse_material("white", make_float3(0.5f, 0.5f, 0.5f)));
    Light l = env_light(make_float3(1, 1, 1), 0);
    scene.environment_maps.push_back(
        {write_map(fmt::format("map-{}-{}.exr", projection, Lt), w, h, rgb), projection});
    scene.infinite_lights.push_back(l);
    double E = 0.0;
    const int q = 64;
    for (int a = 0; a < q; ++a)
      for (int b = 0; b < q; ++b) {
        float2 uv = make_float2((float(ti) + (a + 0.5f) / q) / float(w),
                                (float(tj) + (b + 0.5f) / q) / float(h));
        float3 d = projection == ENV_OCTAHEDRAL ? env_octahedral_dir(uv) : env_equirect_dir(uv);
        double jac = projection == ENV_OCTAHEDRAL
                         ? 4.0 * kPi
                         : 2.0 * kPi * kPi * std::sqrt(std::max(0.0, 1.0 - double(d.z) * d.z));
        E += Lt * std::max(0.0, double(d.z)) * jac / (double(w) * h * q * q);
      }
    ASSERT_GT(E, 0.0);
    const double expect = 0.5 / kPi * E;
    for (const char* sampler : {"tree", "tree-split", "bsdf"}) {
      Scene s = scene;
      Film film = render(s, sampler, std::string(sampler) == "bsdf" ? 256 : 16);
      auto [mean, se] = image_mean(film);
      EXPECT_NEAR(mean, expect, 5.0 * se + 1e-4 * expect)
          << sampler << ", projection " << projection << ", texel " << Lt;
    }
  }
}

// The scene formats: a JSON environment (constant and mapped) and pbrt-v4's "infinite".
TEST(EnvironmentScene, JsonAndPbrt) {
  auto dir = temp_dir();
  write_map("sky.exr", 4, 2, std::vector<float>(24, 1.0f));
  const std::string head = R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
    "shapes": [{"type": "quad", "corner": [-1, -1, 0], "edge1": [2, 0, 0], "edge2": [0, 2, 0]}],)";
  Scene s =
      load_scene_from_string(head + R"("lights": [{"type": "environment", "radiance": [1, 2, 3]},
                {"type": "environment", "map": "sky.exr", "scale": 2, "up": [0, 0, 1],
                 "front": [1, 0, 0]}]})",
                             "sky.json", dir);
  ASSERT_EQ(s.infinite_lights.size(), 2u);
  EXPECT_EQ(s.infinite_lights[0].pad, -1);
  EXPECT_FLOAT_EQ(s.infinite_lights[0].emission.z, 3.0f);
  const Light& m = s.infinite_lights[1];
  ASSERT_EQ(s.environment_maps.size(), 1u);
  EXPECT_EQ(m.pad, 0);
  EXPECT_EQ(s.environment_maps[0].projection, ENV_EQUIRECT);
  EXPECT_EQ(s.environment_maps[0].where, "sky.json: lights[1]");
  EXPECT_FLOAT_EQ(m.n.z, 1.0f);   // the pole: up
  EXPECT_FLOAT_EQ(m.e1.x, -1.0f); // the image centre (phi = pi, -e1) looks along front
  EXPECT_FLOAT_EQ(m.emission.x, 2.0f);
  auto error_of = [&](const std::string& lights) {
    try {
      load_scene_from_string(head + lights, "sky.json", dir);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of(R"("lights": [{"type": "environment", "map": "none.exr"}]})")
                .find("sky.json: lights[0].map: " + (dir / "none.exr").string() + ": no such file"),
            std::string::npos);
  EXPECT_NE(error_of(R"("lights": [{"type": "environment", "map": "sky.exr", "up": [0, 1, 0],
                        "front": [0, 2, 0]}]})")
                .find("front: must not be parallel to up"),
            std::string::npos);

  const std::string cam = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n";
  Scene p = load_pbrt_scene_from_string(
      cam + "LightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5] \"float scale\" 4\n"
            "AttributeBegin\nRotate 90 1 0 0\n"
            "LightSource \"infinite\" \"string filename\" \"sky.exr\"\nAttributeEnd\n",
      "sky.pbrt", dir, SceneLoadOptions{});
  ASSERT_EQ(p.infinite_lights.size(), 2u);
  EXPECT_FLOAT_EQ(p.infinite_lights[0].emission.y, 2.0f);
  ASSERT_EQ(p.environment_maps.size(), 1u);
  EXPECT_EQ(p.environment_maps[0].projection, ENV_OCTAHEDRAL);
  EXPECT_EQ(p.environment_maps[0].where, "sky.pbrt:7: LightSource \"infinite\"");
  // Rotate 90 about x takes the map's z (its pole) to -y... up to the reader's handedness mirror,
  // which leaves y alone.
  EXPECT_NEAR(std::fabs(p.infinite_lights[1].n.y), 1.0f, 1e-6f);
  try {
    load_pbrt_scene_from_string(cam + "LightSource \"infinite\" \"string filename\" \"no.exr\"\n",
                                "sky.pbrt", dir, SceneLoadOptions{});
    ADD_FAILURE() << "a missing map was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("sky.pbrt:4"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no such file"), std::string::npos) << e.what();
  }
}

// The sky and a light of the tree together at glossy points: a point light above the gold plane
// adds f(wo, wi) cos(theta) I / d^2 (exact at each pixel's centre; the narrow field keeps it
// nearly constant over the footprint) to the sky's L times the albedo. Checks that the sky's
// escaped rays and light samples keep their weights beside the tree's techniques (brdf-mis'
// three at glossy points).
TEST(EnvironmentRender, SkyAndATreeLightAddUpAtGlossyPoints) {
  MaterialDesc gold = conductor_material("gold", 0.4f, make_float3(0.143f, 0.374f, 1.442f),
                                         make_float3(3.983f, 2.385f, 1.603f));
  const float L = 0.8f, I = 6.0f;
  const float3 pl = make_float3(0.6f, 0.3f, 2.0f);
  Scene probe = plane_under_sky(gold);
  float3 wo0 = normalize(probe.camera.position - probe.camera.look_at);
  const Material m = gold.gpu;
  double albedo_se;
  const double albedo = test::directional_albedo(m, wo0, 1000000, 2u, &albedo_se);
  CameraParams cam = make_camera_params(probe.camera, probe.film.width, probe.film.height);
  double point_term = 0.0; // image mean of the point light's exact radiance at pixel centres
  for (int y = 0; y < probe.film.height; ++y)
    for (int x = 0; x < probe.film.width; ++x) {
      float3 X;
      float3 d = test::camera_ray_to_plane(cam, float(x) + 0.5f, float(y) + 0.5f, &X);
      float3 to = pl - X;
      float d2 = dot(to, to);
      float3 wi = to * (1.0f / std::sqrt(d2));
      point_term += double(bsdf_eval(&m, d * -1.0f, wi).x) * wi.z * I / d2;
    }
  point_term /= double(probe.film.width * probe.film.height);
  const double expect = L * albedo + point_term;
  for (const char* sampler : {"tree", "tree-split", "brdf-mis", "brdf-oriented"}) {
    Scene scene = plane_under_sky(gold);
    scene.infinite_lights.push_back(env_light(make_float3(L, L, L), -1));
    Light point{};
    point.type = LIGHT_POINT;
    point.p = f4_from3(pl, 0.0f);
    point.emission = make_float4(I, I, I, 0.0f);
    point.prim = -1;
    scene.lights.push_back(point);
    Film film = render(scene, sampler, 64);
    auto [mean, se] = image_mean(film);
    EXPECT_NEAR(mean, expect, 5.0 * (se + L * albedo_se) + 0.005 * expect) << sampler;
  }
}
