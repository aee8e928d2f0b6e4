// Scenes far from the origin (issue 20, part 4): the loader subtracts a double-precision scene
// origin (the camera position) from every coordinate before rounding to float, so a unit-size
// scene keeps its shape at any translation. test_render_translation lays its scene out on the
// float grid on purpose; this scene is written as JSON text with coordinates off any float grid
// and goes through the real loader, so float rounding of world coordinates would change it.
//
// A point light 0.2 above a 0.2 x 0.3 black occluder casts a shadow magnified 6.35 times on a
// diffuse floor; a camera looks straight down on the shadow and sees all of it, but not the
// occluder. Direct light only: the floor's radiance is albedo/pi * I cos(theta) / d^2, whose
// integral over a floor rectangle is albedo/pi * I times the rectangle's solid angle from the
// light. The light the shadow removes from the view, measured from the image, must therefore
// equal albedo/pi * I times the occluder's solid angle from the light, a closed form.
#include "render/renderer.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <cstdio>

using namespace canopy;

namespace {

// Relative layout (y up), translated by (T, T, T).
constexpr double kLight[3] = {-0.16, 1.27, -0.02};  // point light
constexpr double kI = 3.0;                          // its intensity
constexpr double kOccY = 1.07;                      // occluder plane, 0.2 below the light
constexpr double kOcc[4] = {0.16, 0.36, -0.2, 0.1}; // occluder x0, x1, z0, z1
constexpr double kAlbedo = 0.6;
constexpr double kCamH = 6.0;     // camera height above the floor
constexpr double kHalfView = 1.2; // half the side of the (square) view on the floor
constexpr int kFilm = 64;

// Solid angle of the rectangle [x0, x1] x [z0, z1] in a plane at distance d from a point whose
// foot in that plane is (0, 0): the sum over corners of +-atan(x z / (d r)).
double rect_solid_angle(double x0, double x1, double z0, double z1, double d) {
  auto f = [d](double x, double z) {
    return std::atan(x * z / (d * std::sqrt(x * x + z * z + d * d)));
  };
  return f(x1, z1) - f(x0, z1) - f(x1, z0) + f(x0, z0);
}

// The shadow of the occluder on the floor: the occluder scaled from the light's foot.
double shadow(int i) {
  double k = kLight[1] / (kLight[1] - kOccY);
  double c = i < 2 ? kLight[0] : kLight[2];
  return c + k * (kOcc[i] - c);
}
double cam_x() {
  return 0.5 * (shadow(0) + shadow(1));
}
double cam_z() {
  return 0.5 * (shadow(2) + shadow(3));
}

std::string num(double v) {
  return fmt::format("{:.17g}", v);
}
std::string vec(double T, double x, double y, double z) {
  return fmt::format("[{}, {}, {}]", num(T + x), num(T + y), num(T + z));
}

std::string scene_json(double T) {
  double fov = 2.0 * std::atan(kHalfView / kCamH) * 180.0 / M_PI;
  return fmt::format(
      R"({{
  "camera": {{"position": {}, "look_at": {}, "up": [0, 0, -1], "fov": {}}},
  "film": {{"width": {}, "height": {}}},
  "integrator": {{"spp": 64, "max_depth": 1, "light_sampler": "tree", "seed": 3}},
  "materials": [{{"name": "floor", "albedo": {}}}, {{"name": "black", "albedo": 0}}],
  "shapes": [
    {{"type": "quad", "material": "floor", "corner": {}, "edge1": [0, 0, 8], "edge2": [10, 0, 0]}},
    {{"type": "quad", "material": "black", "corner": {}, "edge1": [0, 0, {}], "edge2": [{}, 0, 0]}}
  ],
  "lights": [{{"type": "point", "position": {}, "intensity": {}}}]
}})",
      vec(T, cam_x(), kCamH, cam_z()), vec(T, cam_x(), 0.0, cam_z()), num(fov), kFilm, kFilm,
      num(kAlbedo), vec(T, -2.0, 0.0, -4.0), vec(T, kOcc[0], kOccY, kOcc[2]),
      num(kOcc[3] - kOcc[2]), num(kOcc[1] - kOcc[0]), vec(T, kLight[0], kLight[1], kLight[2]),
      num(kI));
}

// The occluder's solid angle from the light, measured: the view's exact unshadowed light minus
// the light in the image, divided by albedo/pi * I.
double measured_solid_angle(ClRuntime& rt, double T) {
  Scene scene = load_scene_from_string(scene_json(T), "far-origin.json", ".");
  RendererOptions opt;
  opt.light_sampler = scene.integrator.light_sampler;
  Renderer renderer(rt, scene, opt);
  RenderSettings rs;
  rs.spp = scene.integrator.spp;
  rs.seed = scene.integrator.seed;
  Film film = renderer.render(rs);
  EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
  // The camera looks straight down, so every pixel's footprint is a square of the same area.
  double pixel_area = std::pow(2.0 * kHalfView / kFilm, 2);
  double sum = 0;
  for (const auto& p : film.sum)
    sum += double(p.x) / double(p.w);
  double view =
      rect_solid_angle(cam_x() - kHalfView - kLight[0], cam_x() + kHalfView - kLight[0],
                       cam_z() - kHalfView - kLight[2], cam_z() + kHalfView - kLight[2], kLight[1]);
  return view - sum * pixel_area / (kAlbedo / M_PI * kI);
}

} // namespace

TEST(RenderFarOrigin, ShadowOfAnOccluderKeepsItsExactSizeFarFromTheOrigin) {
  // The layout: the shadow lies inside the view with a margin; the occluder, seen from the
  // camera, lies outside it.
  ASSERT_LT(cam_x() - kHalfView + 0.2, shadow(0));
  ASSERT_LT(cam_z() - kHalfView + 0.2, shadow(2));
  double occ_seen = cam_x() + (kOcc[1] - cam_x()) * kCamH / (kCamH - kOccY);
  ASSERT_LT(occ_seen, cam_x() - kHalfView);
  const double exact =
      rect_solid_angle(kOcc[0] - kLight[0], kOcc[1] - kLight[0], kOcc[2] - kLight[2],
                       kOcc[3] - kLight[2], kLight[1] - kOccY);
  // The shadow subtends the same solid angle: a check of shadow() and rect_solid_angle.
  ASSERT_NEAR(rect_solid_angle(shadow(0) - kLight[0], shadow(1) - kLight[0], shadow(2) - kLight[2],
                               shadow(3) - kLight[2], kLight[1]),
              exact, 1e-12);
  ClRuntime rt;
  for (double T : {0.0, 1e3, 1e5, 1e6}) {
    double m = measured_solid_angle(rt, T);
    double rel = m / exact - 1.0;
    std::printf("T = %g: shadow solid angle %.6f vs exact %.6f (%+.3f%%)\n", T, m, exact,
                100.0 * rel);
    EXPECT_LT(std::fabs(rel), 0.005) << "T = " << T;
  }
}
