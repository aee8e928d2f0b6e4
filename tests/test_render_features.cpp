// Kernels compiled for the scene (DESIGN §7) render exactly what kernels with every feature
// compiled in render, and a render is bit-identical from run to run and for any wave size.
#include "light_tree/synthetic_lights.h"
#include "render/renderer.h"

#include <gtest/gtest.h>

using namespace canopy;

namespace {

Scene small_default_scene() {
  Scene s = load_scene(std::string(CANOPY_SCENES_DIR) + "/default.json");
  s.film.width = 48;
  s.film.height = 40;
  return s;
}

// A world position as the loaded scene stores it: relative to its origin (the camera position).
float3 at(const Scene& s, float x, float y, float z) {
  return make_float3(float(x - s.origin.x), float(y - s.origin.y), float(z - s.origin.z));
}

Film render(Scene& scene, const std::string& sampler, bool all_features, size_t wave_size,
            std::string* options = nullptr) {
  ClRuntime rt;
  RendererOptions opt;
  opt.light_sampler = sampler;
  opt.all_features = all_features;
  Renderer r(rt, scene, opt);
  RenderSettings rs;
  rs.spp = 4;
  rs.seed = 5;
  rs.wave_size = wave_size;
  Film f = r.render(rs);
  if (options) *options = r.stats().kernel_options;
  return f;
}

void expect_identical(const Film& a, const Film& b) {
  ASSERT_EQ(a.sum.size(), b.sum.size());
  int differ = 0;
  for (size_t i = 0; i < a.sum.size(); ++i)
    differ += a.sum[i].x != b.sum[i].x || a.sum[i].y != b.sum[i].y || a.sum[i].z != b.sum[i].z;
  EXPECT_EQ(differ, 0) << "pixels that differ";
  double total = 0;
  for (const double4& s : a.sum)
    total += s.x + s.y + s.z;
  EXPECT_GT(total, 0.0); // the image is not black
}

} // namespace

class RenderFeatures : public ::testing::TestWithParam<std::string> {};

TEST_P(RenderFeatures, MinimalFeatureSetRendersTheSameImageAsEveryFeature) {
  Scene scene = small_default_scene();
  std::string minimal_opts, all_opts;
  Film minimal = render(scene, GetParam(), false, 1 << 18, &minimal_opts);
  Film all = render(scene, GetParam(), true, 1 << 18, &all_opts);
  // The default scene has only quad lights: the minimal build must leave the others out.
  EXPECT_NE(minimal_opts.find("-DHAS_LIGHT_QUAD=1"), std::string::npos) << minimal_opts;
  EXPECT_NE(minimal_opts.find("-DHAS_LIGHT_SPHERE=0"), std::string::npos) << minimal_opts;
  EXPECT_NE(minimal_opts.find("-DHAS_LIGHT_POINT=0"), std::string::npos) << minimal_opts;
  EXPECT_NE(all_opts.find("-DHAS_LIGHT_SPHERE=1"), std::string::npos) << all_opts;
  // no disk code for a scene without disks
  EXPECT_NE(minimal_opts.find("-DHAS_LIGHT_DISK=0"), std::string::npos) << minimal_opts;
  EXPECT_NE(minimal_opts.find("-DHAS_PRIM_DISK=0"), std::string::npos) << minimal_opts;
  EXPECT_NE(all_opts.find("-DHAS_LIGHT_DISK=1 -DHAS_LIGHT_DISTANT=1 -DHAS_LIGHT_ENVIRONMENT=1 "
                          "-DHAS_PRIM_SPHERE=1 -DHAS_PRIM_DISK=1"),
            std::string::npos)
      << all_opts;
  // nor distant- or environment-light code without such a light
  EXPECT_NE(minimal_opts.find("-DHAS_LIGHT_DISTANT=0 -DHAS_LIGHT_ENVIRONMENT=0"), std::string::npos)
      << minimal_opts;
  // a diffuse-only scene compiles no GGX or Fresnel code (cl/bsdf/bsdf.h)
  EXPECT_NE(minimal_opts.find("-DHAS_MATERIAL_CONDUCTOR=0 -DHAS_MATERIAL_PLASTIC=0"),
            std::string::npos)
      << minimal_opts;
  EXPECT_NE(all_opts.find("-DHAS_MATERIAL_CONDUCTOR=1 -DHAS_MATERIAL_PLASTIC=1"), std::string::npos)
      << all_opts;
  // no medium code (shade_volume, segment picks) for a scene without a medium
  EXPECT_NE(minimal_opts.find("-DHAS_MEDIUM=0"), std::string::npos) << minimal_opts;
  EXPECT_NE(all_opts.find("-DHAS_MEDIUM=1"), std::string::npos) << all_opts;
  expect_identical(minimal, all);
}

TEST_P(RenderFeatures, SceneWithMediumRendersTheSameImageWithEveryFeature) {
  // The default scene with a coloured, forward-scattering medium filling its lower half: the
  // minimal build has the medium but no sphere, point or disk code.
  Scene scene = small_default_scene();
  scene.has_medium = true;
  scene.medium.sigma_t = make_float4(0.5f, 0.6f, 0.8f, 0.3f);
  scene.medium.sigma_s = make_float4(0.4f, 0.5f, 0.6f, 1.0f);
  scene.medium.bmin = f4_from3(at(scene, -5, -1, -5), 0);
  scene.medium.bmax = f4_from3(at(scene, 5, 1, 5), 0);
  std::string minimal_opts;
  Film minimal = render(scene, GetParam(), false, 1 << 18, &minimal_opts);
  Film all = render(scene, GetParam(), true, 1 << 18);
  EXPECT_NE(minimal_opts.find("-DHAS_MEDIUM=1"), std::string::npos) << minimal_opts;
  EXPECT_NE(minimal_opts.find("-DHAS_LIGHT_SPHERE=0"), std::string::npos) << minimal_opts;
  expect_identical(minimal, all);
  Film waves = render(scene, GetParam(), false, 777); // many small waves
  expect_identical(minimal, waves);
}

TEST_P(RenderFeatures, SceneWithGlossyMaterialsRendersTheSameImageWithEveryFeature) {
  // The default scene with its materials made conductors (rough and a perfect mirror) and
  // plastics: the minimal build has the glossy code but no sphere, point or disk code.
  Scene scene = small_default_scene();
  ASSERT_GE(scene.materials.size(), 3u);
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    Material& m = scene.materials[i].gpu;
    if (i % 3 == 0) {
      m.type = MATERIAL_PLASTIC;
      m.specular = make_float4(1, 1, 1, 0);
      m.alpha = 0.04f;
      m.ior = 1.5f;
    } else {
      m.type = MATERIAL_CONDUCTOR;
      m.specular = make_float4(0.2f, 0.9f, 1.1f, 0); // eta
      m.k = make_float4(3.9f, 2.5f, 2.4f, 0);
      m.alpha = i % 3 == 1 ? 0.09f : 0.0f;
    }
  }
  std::string minimal_opts;
  Film minimal = render(scene, GetParam(), false, 1 << 18, &minimal_opts);
  Film all = render(scene, GetParam(), true, 1 << 18);
  EXPECT_NE(minimal_opts.find("-DHAS_MATERIAL_CONDUCTOR=1 -DHAS_MATERIAL_PLASTIC=1"),
            std::string::npos)
      << minimal_opts;
  EXPECT_NE(minimal_opts.find("-DHAS_LIGHT_DISK=0"), std::string::npos) << minimal_opts;
  expect_identical(minimal, all);
}

TEST_P(RenderFeatures, SceneWithDisksRendersTheSameImageWithEveryFeature) {
  // The default scene plus a one-sided disk on the ceiling and a two-sided one in view: the
  // minimal build has the disk light and primitive but no sphere or point code.
  Scene scene = small_default_scene();
  scene.lights.push_back(make_disk_light(at(scene, 0.5f, 1.95f, 0.3f), make_float3(0, -1, 0), 0.3f,
                                         make_float3(4, 4, 3)));
  scene.lights.push_back(make_disk_light(at(scene, -0.6f, 1.0f, 0.2f), make_float3(0.4f, 0.2f, 1),
                                         0.25f, make_float3(1, 3, 2), true));
  std::string minimal_opts;
  Film minimal = render(scene, GetParam(), false, 1 << 18, &minimal_opts);
  Film all = render(scene, GetParam(), true, 1 << 18);
  EXPECT_NE(minimal_opts.find("-DHAS_LIGHT_DISK=1"), std::string::npos) << minimal_opts;
  EXPECT_NE(minimal_opts.find("-DHAS_PRIM_DISK=1"), std::string::npos) << minimal_opts;
  EXPECT_NE(minimal_opts.find("-DHAS_PRIM_SPHERE=0"), std::string::npos) << minimal_opts;
  expect_identical(minimal, all);
}

TEST_P(RenderFeatures, RendersAreBitIdenticalAcrossRunsAndWaveSizes) {
  Scene scene = small_default_scene();
  Film a = render(scene, GetParam(), false, 1 << 18);
  Film b = render(scene, GetParam(), false, 1 << 18);
  Film c = render(scene, GetParam(), false, 777); // many small waves
  expect_identical(a, b);
  expect_identical(a, c);
}

INSTANTIATE_TEST_SUITE_P(Samplers, RenderFeatures, ::testing::Values("tree", "tree-split"),
                         [](const auto& p) {
                           return p.param == "tree" ? std::string("tree")
                                                    : std::string("tree_split");
                         });
