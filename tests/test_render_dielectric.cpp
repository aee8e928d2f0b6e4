// Glass in whole renders, against closed forms (PoCL, the full wavefront). A camera with a 1 deg
// field of view looks at a smooth glass slab (a box 0.2 thick) at incidence theta; a large
// emitter of radiance 1 lies behind the slab, in front of it (behind the camera), or both. Over
// every sample, the image's mean must match, within 5 standard errors of the samples:
//   behind:  the slab's transmittance (1 - R) / (1 + R),
//   front:   its reflectance 2R / (1 + R),
//   both:    1 (glass absorbs nothing),
// with R the Fresnel reflectance at theta in double (written here; the faces are parallel, so the
// inside angle gives the same R, and the series of inter-reflections sums to these forms). A thin
// sheet (one quad) has the same transmittance at every angle. The refracted rays leave the slab
// from its far side (an origin on the near side would hit the slab again and never escape) and
// the radiance scale 1 / eta^2 inside is undone on the way out. A rough slab (no closed form): the
// tree sampler's MIS agrees with BSDF sampling alone. max_depth 64 leaves the series'
// tail (R^62) far below the noise; Russian roulette adds noise only. The pixels' angles differ
// from theta by at most 0.7 deg, which moves R by less than a tenth of the bound.
#include "render/renderer.h"
#include "scene/scene.h"
#include "support/film_stats.h"
#include "support/fresnel_reference.h"

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <string>

using namespace canopy;
using namespace canopy::test;

namespace {

// The scene: the slab (or sheet) in the plane z = 0, the camera 5 units away at angle theta from
// the normal in the y-z plane; emitters of radiance 1 at z = -2 facing +z and at z = +8 facing -z.
SampleStats render_glass(ClRuntime& rt, double theta_deg, double ior, bool thin, bool behind,
                         bool front, const std::string& sampler, double roughness = 0,
                         int spp = 256) {
  const double t = theta_deg * M_PI / 180;
  std::string shape =
      thin ? R"({"type": "quad", "material": "glass", "corner": [-6, -6, 0], "edge1": [12, 0, 0],
                  "edge2": [0, 12, 0]})"
           : R"({"type": "box", "material": "glass", "min": [-6, -6, -0.1], "max": [6, 6, 0.1]})";
  std::string lights;
  if (behind)
    lights += R"({"type": "quad", "corner": [-1000, -1000, -2], "edge1": [2000, 0, 0],
                  "edge2": [0, 2000, 0], "radiance": 1})";
  if (front)
    lights += std::string(behind ? ", " : "") +
              R"({"type": "quad", "corner": [-1000, -1000, 8], "edge1": [0, 2000, 0],
                  "edge2": [2000, 0, 0], "radiance": 1})";
  std::string json = fmt::format(
      R"({{"camera": {{"position": [0, {y}, {z}], "look_at": [0, 0, 0], "up": [1, 0, 0],
                      "fov": 1}},
          "film": {{"width": 16, "height": 16}},
          "integrator": {{"max_depth": 64}},
          "materials": [{{"name": "glass", "type": "dielectric", "ior": {ior}, "thin": {thin}{rough}}}],
          "shapes": [{shape}],
          "lights": [{lights}]}})",
      fmt::arg("y", -5 * std::sin(t)), fmt::arg("z", 5 * std::cos(t)), fmt::arg("ior", ior),
      fmt::arg("thin", thin ? "true" : "false"), fmt::arg("shape", shape),
      fmt::arg("rough", roughness > 0 ? fmt::format(", \"roughness\": {}", roughness) : ""),
      fmt::arg("lights", lights));
  Scene scene = load_scene_from_string(json, "glass.json", ".");
  RendererOptions opt;
  opt.light_sampler = sampler;
  Renderer renderer(rt, scene, opt);
  RenderSettings rs;
  rs.spp = spp;
  rs.seed = 11;
  Film film = renderer.render(rs);
  EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
  // Over every sample (the scene is grey).
  return film_sample_stats(film);
}

struct GlassCase {
  double theta, ior;
  bool thin;
  const char* sampler;
};

class GlassSlab : public ::testing::TestWithParam<GlassCase> {};

void expect_mean(const SampleStats& s, double expected, const std::string& what) {
  // An exact answer (zero variance) still gets a float-rounding allowance.
  EXPECT_NEAR(s.mean, expected, 5 * s.se + 1e-5) << what << " (SE " << s.se << ")";
}

} // namespace

TEST_P(GlassSlab, TransmitsAndReflectsByFresnel) {
  const GlassCase c = GetParam();
  ClRuntime rt;
  const double r = ref_fresnel(std::cos(c.theta * M_PI / 180), c.ior);
  const std::string what =
      fmt::format("theta {} ior {} {} {}", c.theta, c.ior, c.thin ? "sheet" : "slab", c.sampler);
  expect_mean(render_glass(rt, c.theta, c.ior, c.thin, true, false, c.sampler), (1 - r) / (1 + r),
              what + ": transmittance");
  expect_mean(render_glass(rt, c.theta, c.ior, c.thin, false, true, c.sampler), 2 * r / (1 + r),
              what + ": reflectance");
  expect_mean(render_glass(rt, c.theta, c.ior, c.thin, true, true, c.sampler), 1.0,
              what + ": no absorption");
}

INSTANTIATE_TEST_SUITE_P(
    Angles, GlassSlab,
    ::testing::Values(GlassCase{0, 1.5, false, "tree"}, GlassCase{60, 1.5, false, "tree"},
                      GlassCase{80, 2.4, false, "power"}, GlassCase{45, 1.5, false, "brdf-mis"},
                      GlassCase{0, 1.5, true, "tree"}, GlassCase{70, 1.5, true, "tree"}));

// Index 1: the slab is invisible; every sample sees the emitter behind it, exactly.
TEST(GlassSlabIndexOne, IsInvisible) {
  ClRuntime rt;
  SampleStats s = render_glass(rt, 30, 1.0, false, true, false, "tree");
  EXPECT_NEAR(s.mean, 1.0, 1e-5);
  EXPECT_LT(s.se, 1e-6);
}

// Rough glass has no closed form here, but light sampling (on the camera's side only) and BSDF
// sampling (which alone reaches the light behind the slab, through two rough refractions) are
// MIS-combined: the emission a refracted ray finds must keep its full weight, since no light
// sample can produce that path. The tree sampler's image must then agree with BSDF sampling
// alone, with light behind the slab, in front of it, and both.
TEST(RoughGlassSlab, MisAgreesWithBsdfSampling) {
  ClRuntime rt;
  for (int lights = 1; lights <= 3; ++lights) {
    bool behind = lights & 1, front = lights & 2;
    SampleStats a = render_glass(rt, 40, 1.5, false, behind, front, "tree", 0.3, 1024);
    SampleStats b = render_glass(rt, 40, 1.5, false, behind, front, "bsdf", 0.3, 1024);
    EXPECT_GT(a.mean, 0.05);
    EXPECT_NEAR(a.mean, b.mean, 5 * std::hypot(a.se, b.se))
        << "behind " << behind << " front " << front;
  }
}
