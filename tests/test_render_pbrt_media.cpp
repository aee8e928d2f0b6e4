// Media from pbrt-v4 files (host/scene/pbrt/media.cpp) in whole renders, against closed forms.
// The camera sits in an absorbing fog (MediumInterface before Camera, sigma_s = 0, so the answer
// is a transmittance) and looks with a 1 deg field of view through a glass slab 1 unit thick at an
// emitter of radiance 1, 14 units of fog away in all:
//   - a slab with vacuum inside (MediumInterface "" "fog"): exp(-sigma_a 14) (1 - R) / (1 + R);
//   - a slab filled with the fog (no interface): exp(-sigma_a 15) (1 - R) / (1 + R);
//   - Integrator "path", which renders no media in pbrt-v4: (1 - R) / (1 + R);
// R = ((eta - 1) / (eta + 1))^2 at normal incidence (the pixels' angles, below 0.7 deg, move R by
// under 1e-4 of it). Within 5 standard errors of the samples.
#include "render/renderer.h"
#include "scene/pbrt_reader.h"
#include "scene/scene.h"

#include "support/film_stats.h"
#include "support/pbrt_text.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

using namespace canopy;
using namespace canopy::test;

namespace {

constexpr double kSigmaA = 0.1, kEta = 1.5;

// A closed box mesh, wound outward.
std::string box(double x0, double y0, double z0, double x1, double y1, double z1) {
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "Shape \"trianglemesh\" \"point3 P\" [%g %g %g  %g %g %g  %g %g %g  %g %g %g  "
                "%g %g %g  %g %g %g  %g %g %g  %g %g %g] \"integer indices\" [0 2 1  0 3 2  "
                "4 5 6  4 6 7  0 1 5  0 5 4  2 3 7  2 7 6  1 2 6  1 6 5  0 4 7  0 7 3]\n",
                x0, y0, z0, x1, y0, z0, x1, y1, z0, x0, y1, z0, x0, y0, z1, x1, y0, z1, x1, y1, z1,
                x0, y1, z1);
  return buf;
}

SampleStats render(const std::string& integrator, bool vacuum_inside) {
  std::string text =
      "Integrator \"" + integrator + "\" \"integer maxdepth\" 64\n" +
      "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.1 0.1 0.1] "
      "\"rgb sigma_s\" [0 0 0]\n"
      "MediumInterface \"\" \"fog\"\n"
      "LookAt 0 0 10  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 1\n"
      "Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\n"
      "WorldBegin\n"
      "AttributeBegin\n" +
      std::string(vacuum_inside ? "" : "MediumInterface \"fog\" \"fog\"\n") +
      "Material \"dielectric\" \"float eta\" 1.5\n" + box(-5, -5, -0.5, 5, 5, 0.5) +
      "AttributeEnd\n"
      "AttributeBegin\n"
      "AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
      "Material \"diffuse\" \"rgb reflectance\" [0 0 0]\n" // (pbrt's default would reflect)
      "Shape \"trianglemesh\" \"point3 P\" [-100 -100 -5  100 -100 -5  100 100 -5  -100 100 -5] "
      "\"integer indices\" [0 1 2  0 2 3]\n"
      "AttributeEnd\n";
  Scene scene = test::load_pbrt(text);
  ClRuntime rt;
  RendererOptions opt;
  opt.light_sampler = "tree";
  Renderer renderer(rt, scene, opt);
  RenderSettings rs;
  rs.spp = 256;
  rs.seed = 5;
  Film film = renderer.render(rs);
  EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
  return film_sample_stats(film);
}

double slab_transmittance() {
  double r = (kEta - 1) / (kEta + 1);
  r *= r;
  return (1 - r) / (1 + r);
}

} // namespace

TEST(PbrtMedia, GlassWithAVacuumInsideIsCrossedWithoutTheFog) {
  SampleStats s = render("volpath", true);
  double expected = std::exp(-kSigmaA * 14) * slab_transmittance();
  EXPECT_NEAR(s.mean, expected, 5 * s.se + 1e-6) << "SE " << s.se;
}

TEST(PbrtMedia, GlassFilledWithTheFogAttenuatesInsideToo) {
  SampleStats s = render("volpath", false);
  double expected = std::exp(-kSigmaA * 15) * slab_transmittance();
  EXPECT_NEAR(s.mean, expected, 5 * s.se + 1e-6) << "SE " << s.se;
}

TEST(PbrtMedia, PathIntegratorRendersNoMediaAsPbrt) {
  SampleStats s = render("path", true);
  EXPECT_NEAR(s.mean, slab_transmittance(), 5 * s.se + 1e-6) << "SE " << s.se;
}
