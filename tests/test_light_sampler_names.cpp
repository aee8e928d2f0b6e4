// The one list of light-sampler names (kLightSamplerNames, indexed by SAMPLER_*): every mapping
// (scene format, CLI, host samplers, make_light_sampler_data) derives from it; and the "bsdf"
// sampler (SAMPLER_BSDF: BSDF sampling only) picks nothing, reports pmf 0 and builds no tree.
#include "light_tree/light_sampler.h"
#include "light_tree/synthetic_lights.h"
#include "render/features.h"
#include "render/light_sampler_data.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace canopy {
namespace {

TEST(LightSamplerNames, EveryMappingAgreesWithTheList) {
  std::vector<Light> lights = random_point_lights(50, 3);
  ASSERT_EQ(light_sampler_names().size(), kLightSamplerNames.size());
  for (int k = 0; k < int(kLightSamplerNames.size()); ++k) {
    std::string name(kLightSamplerNames[size_t(k)]);
    EXPECT_EQ(light_sampler_kind(name), k) << name;
    EXPECT_EQ(light_sampler_from_name(name), k) << name;
    EXPECT_EQ(std::string(light_sampler_name(k)), name);
    EXPECT_EQ(light_sampler_names()[size_t(k)], name);
    EXPECT_EQ(std::string(make_light_sampler(name, lights)->name()), name);
    EXPECT_EQ(make_light_sampler_data(lights, name, 0.25f, 4).kind, k) << name;
  }
  EXPECT_EQ(light_sampler_kind("bogus"), -1);
  EXPECT_EQ(light_sampler_kind(""), -1);
  EXPECT_EQ(std::string(light_sampler_name(int(kLightSamplerNames.size()))), "?");
  EXPECT_EQ(std::string(light_sampler_name(-1)), "?");
  // Unknown names are rejected with every valid name listed.
  try {
    light_sampler_from_name("bogus");
    ADD_FAILURE() << "no SceneError";
  } catch (const SceneError& e) {
    for (std::string_view n : kLightSamplerNames)
      EXPECT_NE(std::string(e.what()).find(std::string(n)), std::string::npos) << e.what();
  }
  try {
    make_light_sampler("bogus", lights);
    ADD_FAILURE() << "no std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    for (std::string_view n : kLightSamplerNames)
      EXPECT_NE(std::string(e.what()).find(std::string(n)), std::string::npos) << e.what();
  }
}

TEST(LightSamplerNames, BsdfSamplesNoLight) {
  std::vector<Light> lights = mixed_lights(200, 7);
  float3 P = make_float3(0.5f, 0.5f, 0.5f), N = make_float3(0, 0, 1);

  auto s = make_light_sampler("bsdf", lights);
  EXPECT_EQ(s->tree(), nullptr);
  Rng rng = lt_rng_make(1, 2);
  std::vector<LightPick> out;
  for (int i = 0; i < 100; ++i)
    s->sample(P, N, rng, out);
  EXPECT_TRUE(out.empty());
  for (int l = 0; l < int(lights.size()); ++l)
    EXPECT_EQ(s->pmf(P, N, l), 0.0f);

  LightSamplerData d = make_light_sampler_data(lights, "bsdf", 0.25f, 4);
  EXPECT_EQ(d.kind, SAMPLER_BSDF);
  EXPECT_EQ(d.tree.num_nodes(), 0); // no light tree built
  EXPECT_TRUE(d.power_pmf.empty());
  EXPECT_FALSE(d.splits());
  LightSamplerCtx ls = d.host_view(lights);
  LtRng r = lt_rng_make(3, 4);
  for (int i = 0; i < 100; ++i) {
    float pmf = -1.0f;
    EXPECT_EQ(light_sampler_pick(&ls, 0, P, N, &r, &pmf), -1);
    EXPECT_EQ(pmf, 0.0f);
  }
  for (int l = 0; l < int(lights.size()); ++l)
    EXPECT_EQ(light_sampler_pmf(&ls, P, N, l), 0.0f);
}

} // namespace
} // namespace canopy
