// The bound multiple importance sampling guarantees (issue 20, part 1). With the power heuristic,
// a light sample of density p_L at a vertex whose BSDF sample has density p_B contributes
//   f cos L w / p_L = f cos L p_L / (p_L^2 + p_B^2) <= f cos L / (2 p_B),
// whatever p_L is: MIS caps the heavy tail of light sampling at glossy vertices by what BSDF
// sampling would have given. Now that the last vertex also traces its BSDF ray, every light
// sample of a non-delta light is weighted, the last vertex's included. Over random configurations
// (diffuse, conductor and plastic at roughness 0.01 to 1; quad, sphere, triangle and disk lights
// near and far; random pmfs), light_pick_shadow_item's contribution must stay within that bound;
// delta lights (point, spot), which BSDF sampling never finds, keep weight 1.
#include "integrator/light_pick.h"
#include "render/light_sampler_data.h"
#include "scene/scene.h"

#include "support/glossy_points.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace canopy;
using canopy::test::HostPaths;

namespace {

constexpr const char* kLightsJson = R"({
  "camera": { "position": [0, 0, 0], "look_at": [0, 0, 1] },
  "film": { "width": 4, "height": 4 },
  "materials": [ { "name": "m", "albedo": 0.5 } ],
  "lights": [
    { "type": "quad", "corner": [-0.5, -0.5, 1], "edge1": [1, 0, 0], "edge2": [0, 1, 0],
      "radiance": [3, 2, 1] },
    { "type": "quad", "corner": [3, -0.02, 0.3], "edge1": [0.04, 0, 0], "edge2": [0, 0.04, 0.01],
      "radiance": [50, 50, 50] },
    { "type": "sphere", "center": [0.6, 0.2, 0.4], "radius": 0.25, "radiance": [1, 2, 3] },
    { "type": "sphere", "center": [-8, 5, 9], "radius": 0.01, "radiance": [900, 900, 900] },
    { "type": "triangle", "v0": [-1, 0.3, 0.2], "v1": [-0.4, 0.9, 0.5], "v2": [-0.7, 0.2, 1.1],
      "radiance": [2, 2, 2] },
    { "type": "disk", "center": [0.1, -0.7, 0.6], "normal": [0.2, 0.5, -1], "radius": 0.3,
      "radiance": [4, 1, 1] },
    { "type": "point", "position": [0.2, 0.1, 0.9], "intensity": [1, 1, 1] },
    { "type": "spot", "position": [-0.3, 0.4, 1.2], "direction": [0, 0, -1], "cone_angle": 40,
      "intensity": [2, 2, 2] }
  ]
})";

} // namespace

TEST(MisBound, WeightedLightSamplesNeverExceedHalfTheBsdfEstimate) {
  Scene scene = load_scene_from_string(kLightsJson, "mis-bound.json", ".");
  ASSERT_EQ(scene.lights.size(), 8u);
  LightSamplerData data =
      make_light_sampler_data(scene.lights, "exhaustive", LT_DEFAULT_SPLIT_THRESHOLD, 8, true, {});
  LightSamplerCtx ls = data.host_view(scene.lights, nullptr);
  std::vector<Material> mats(1);
  Medium vacuum{};
  SceneBuffers sc{};
  sc.materials = mats.data();
  sc.medium = &vacuum;
  HostPaths p;
#define PATH_RESIZE(T, name) p.name.assign(1, T{});
  PATH_STATE_BUFFERS(PATH_RESIZE)
#undef PATH_RESIZE
  PathBuffers pb = p.host();

  std::mt19937 rng(2020);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  auto unit = [&] {
    float z = 2 * u(rng) - 1, ph = 6.2831853f * u(rng), s = std::sqrt(1 - z * z);
    return make_float3(s * std::cos(ph), s * std::sin(ph), z);
  };
  int area_samples = 0, near_bound = 0, delta_samples = 0;
  for (int k = 0; k < 200000; ++k) {
    float roughness = std::exp(std::log(0.01f) * u(rng)); // 0.01 .. 1, log-uniform
    int kind = k % 3;
    mats[0] = kind == 0   ? test::make_diffuse(make_float3(0.8f, 0.5f, 0.3f))
              : kind == 1 ? test::gold_conductor(roughness)
                          : test::blue_plastic(roughness);
    // A shading point within ~2 of the lights, sometimes very close to one, with a geometric
    // normal and a shading normal tilted from it, and a viewer above both.
    float3 P = make_float3(2.4f * u(rng) - 1.2f, 2.4f * u(rng) - 1.2f, 1.3f * u(rng) - 0.2f);
    float3 N = unit();
    float3 Ns = normalize(N + unit() * (0.3f * u(rng)));
    if (dot(Ns, N) <= 0.0f) Ns = N;
    float3 wo = unit();
    if (dot(wo, N) < 0.0f) wo = -wo;
    if (dot(wo, Ns) <= 0.0f) continue;
    p.shade_P[0] = f4_from3(P, 0.0f);
    p.shade_N[0] = f4_from3(N, 0.0f);
    p.shade_Ns[0] = f4_from3(Ns, uint_as_float_(0u));
    p.shade_wo[0] = f4_from3(wo, 0.0f);
    p.shade_f[0] = make_float4(1.0f, 1.0f, 1.0f, 1.0f); // MIS against the BSDF ray
    const int light = int(rng() % scene.lights.size());
    const float pmf = std::exp(std::log(1e-4f) * u(rng)); // 1e-4 .. 1
    LtRng r = lt_rng_make(uint32_t(k), 7u);
    LtRng r_copy = r;
    ShadowItem item;
    if (!light_pick_shadow_item(&ls, &sc, &pb, 0, light, pmf, &r, &item)) continue;
    // The same light point, for the bound.
    float u1 = lt_rng_next(&r_copy), u2 = lt_rng_next(&r_copy);
    LightPoint lp;
    ASSERT_TRUE(light_point_sample(&ls, &sc, &pb, 0, light, u1, u2, &lp));
    float3 c = xyz_of(item.contribution);
    float3 full = lp.f_cos * lp.s.Li;
    for (int ch = 0; ch < 3; ++ch) {
      float ci = (&c.x)[ch], fi = (&full.x)[ch];
      ASSERT_TRUE(std::isfinite(ci)) << "sample " << k;
      if (lp.s.is_delta) { // weight 1: the plain light-sampling estimate
        ASSERT_NEAR(ci, fi / (pmf * lp.s.pdf), 1e-5f * fi / (pmf * lp.s.pdf)) << "sample " << k;
        continue;
      }
      ASSERT_GT(lp.bsdf_pdf, 0.0f) << "sample " << k;
      float bound = fi / (2.0f * lp.bsdf_pdf);
      ASSERT_LE(ci, bound * (1.0f + 1e-5f))
          << "sample " << k << " light " << light << " ch " << ch << ": pmf " << pmf << " pdf "
          << lp.s.pdf << " bsdf pdf " << lp.bsdf_pdf;
      near_bound += ci > 0.9f * bound;
    }
    (lp.s.is_delta ? delta_samples : area_samples) += 1;
  }
  // The random configurations cover both kinds of light, and reach the bound's neighbourhood
  // (p_L close to p_B), so a weight that overshot it would be seen.
  EXPECT_GT(area_samples, 20000);
  EXPECT_GT(delta_samples, 5000);
  EXPECT_GT(near_bound, 100);
}
