// Narrow spot lights against their exact irradiance (issue 9, finding 5). A spot of half-angle
// 0.1 deg or 0.01 deg, pointing straight down or tilted 30 deg, lights a diffuse floor; a camera
// looking straight down frames the lit spot with pixels that resolve the falloff band. The
// renderer's image must match the exact radiance
//   L(x) = albedo/pi * I * falloff(theta) * cos(theta_surface) / d^2
// integrated over each pixel's footprint in double: per pixel within that pixel's noise, and over
// the whole film (the spot's total power on the floor) within 0.5%. With cos(theta) in float the
// falloff band of such a spot is only a few float steps wide (+2.7% / -0.85% at 0.1 deg). A
// hard-edged spot (falloff_start == cone_angle) is checked the same way. The scenes go through
// the scene loader, so the host's conversion of the angles is part of what is checked.
#include "render/camera.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <ostream>
#include <string>

using namespace canopy;

namespace {

constexpr int kFilm = 64;
constexpr double kDeg = M_PI / 180.0;
constexpr double kAlbedo = 0.5;
constexpr double kI = 1.0;
constexpr double kCamH = 1.0; // camera height above the floor (z = 0)

struct SpotCase {
  double cone_deg;
  double tilt_deg;   // of the axis from straight down, towards +x
  double start_frac; // falloff_start = start_frac * cone_angle (1: hard edge)
  bool write_start;  // false: leave falloff_start at its default (0.8 cone_angle)
};

// Readable test parameters in gtest and ctest listings (not the struct's raw bytes).
void PrintTo(const SpotCase& c, std::ostream* os) {
  *os << "cone " << c.cone_deg << " deg, tilt " << c.tilt_deg << " deg, falloff_start "
      << (c.write_start ? std::to_string(c.start_frac) + " cone" : std::string("default"));
}

struct Spot {
  double p[3], a[3];          // position, unit axis (double, from the loaded float values)
  double omc_edge, omc_start; // 1 - cos of the half-angles
};

double omc_of(double deg) {
  double h = std::sin(0.5 * deg * kDeg);
  return 2.0 * h * h;
}

// Exact radiance of the floor point (x, y, 0), in double: the smoothstep falloff in cos(theta)
// between the edge and the falloff start (docs/scene-format.md), 1 - cos(theta) = |w - a|^2 / 2.
double floor_radiance(const Spot& s, double x, double y) {
  double w[3] = {x - s.p[0], y - s.p[1], -s.p[2]};
  double d2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2], d = std::sqrt(d2);
  double q = 0;
  for (int k = 0; k < 3; ++k) {
    double c = w[k] / d - s.a[k];
    q += c * c;
  }
  double omc = 0.5 * q, f;
  if (omc <= s.omc_start)
    f = omc < s.omc_edge ? 1.0 : 0.0;
  else if (omc >= s.omc_edge)
    f = 0.0;
  else {
    double t = (s.omc_edge - omc) / (s.omc_edge - s.omc_start);
    f = t * t * (3.0 - 2.0 * t);
  }
  double cos_surface = s.p[2] / d;
  return kAlbedo / M_PI * kI * f * cos_surface / d2;
}

// The pixel's box-filtered radiance by an n x n midpoint rule over its footprint (the camera looks
// straight down, so the footprint is the film square scaled by the height), and the mean of its
// square (for the exact variance of one uniformly jittered sample of the pixel).
struct PixelRef {
  double mean, mean2;
};
PixelRef pixel_reference(const Spot& s, const CameraParams& cam, int px, int py, int n) {
  double acc = 0, acc2 = 0;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      double fx = px + (a + 0.5) / n, fy = py + (b + 0.5) / n;
      double d[3];
      for (int k = 0; k < 3; ++k)
        d[k] = double((&cam.lower_left.x)[k]) + double((&cam.du.x)[k]) * fx +
               double((&cam.dv.x)[k]) * fy;
      double t = -double(cam.origin.z) / d[2];
      double L =
          floor_radiance(s, double(cam.origin.x) + d[0] * t, double(cam.origin.y) + d[1] * t);
      acc += L;
      acc2 += L * L;
    }
  return {acc / (n * n), acc2 / (n * n)};
}

std::string fmt_num(double v) {
  return fmt::format("{:.17g}", v);
}

struct Result {
  double total = 0, total_ref = 0, total_var = 0, total_quad = 0;
  int bad_pixels = 0, lit_pixels = 0;
};

Result render_spot(ClRuntime& rt, const SpotCase& c) {
  const double theta = c.cone_deg * kDeg, tilt = c.tilt_deg * kDeg;
  // The axis meets the floor at the origin, one unit from the light.
  const double axis[3] = {std::sin(tilt), 0.0, -std::cos(tilt)};
  const double pos[3] = {-axis[0], 0.0, -axis[2]};
  // View: 1.8 x the lit radius (stretched by up to 1/cos^2(tilt) along x when tilted).
  const double half = 1.8 * std::tan(theta) / (std::cos(tilt) * std::cos(tilt)) * kCamH;
  const double fov = 2.0 * std::atan(half / kCamH) / kDeg;
  std::string start =
      c.write_start ? fmt::format(", \"falloff_start\": {}", fmt_num(c.start_frac * c.cone_deg))
                    : std::string();
  // With a hard edge, falloff_start is written as the very same number as cone_angle.
  if (c.write_start && c.start_frac == 1.0)
    start = fmt::format(", \"falloff_start\": {}", fmt_num(c.cone_deg));
  std::string json = fmt::format(
      R"({{"camera": {{"position": [0, 0, {h}], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov": {fov}}},
          "film": {{"width": {n}, "height": {n}}},
          "integrator": {{"max_depth": 1}},
          "materials": [{{"name": "grey", "albedo": {alb}}}],
          "shapes": [{{"type": "quad", "corner": [-0.05, -0.05, 0], "edge1": [0.1, 0, 0],
                       "edge2": [0, 0.1, 0], "material": "grey"}}],
          "lights": [{{"type": "spot", "position": [{px}, {py}, {pz}],
                       "direction": [{ax}, {ay}, {az}], "intensity": {I},
                       "cone_angle": {cone}{start}}}]}})",
      fmt::arg("h", fmt_num(kCamH)), fmt::arg("fov", fmt_num(fov)), fmt::arg("n", kFilm),
      fmt::arg("alb", fmt_num(kAlbedo)), fmt::arg("px", fmt_num(pos[0])),
      fmt::arg("py", fmt_num(pos[1])), fmt::arg("pz", fmt_num(pos[2])),
      fmt::arg("ax", fmt_num(axis[0])), fmt::arg("ay", fmt_num(axis[1])),
      fmt::arg("az", fmt_num(axis[2])), fmt::arg("I", fmt_num(kI)),
      fmt::arg("cone", fmt_num(c.cone_deg)), fmt::arg("start", start));
  Scene scene = load_scene_from_string(json, "spot.json", ".");
  const Light& l = scene.lights.at(0);
  // The reference uses the light as loaded (float position and direction), in double, back in
  // world space (the loader stores positions relative to the camera, scene.origin).
  Spot s;
  double dir[3] = {double(float(axis[0])), double(float(axis[1])), double(float(axis[2]))};
  double dl = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
  for (int k = 0; k < 3; ++k) {
    s.p[k] = double((&l.p.x)[k]) + (&scene.origin.x)[k];
    s.a[k] = dir[k] / dl;
  }
  s.omc_edge = omc_of(double(float(c.cone_deg)));
  s.omc_start =
      c.write_start
          ? omc_of(double(float(c.start_frac == 1.0 ? c.cone_deg : c.start_frac * c.cone_deg)))
          : omc_of(double(0.8f * float(c.cone_deg)));

  RendererOptions opt;
  opt.light_sampler = "tree";
  Renderer renderer(rt, scene, opt);
  RenderSettings rs;
  rs.spp = 128;
  rs.seed = 7;
  Film film = renderer.render(rs);
  EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
  CameraParams cam = make_camera_params(scene.camera, scene.film.width, scene.film.height);
  cam.origin = make_float4(float(scene.origin.x), float(scene.origin.y), float(scene.origin.z),
                           cam.origin.w);
  Result r;
  for (int py = 0; py < kFilm; ++py)
    for (int px = 0; px < kFilm; ++px) {
      size_t p = size_t(py) * kFilm + size_t(px);
      double n = double(film.sum[p].w);
      double mean = double(film.sum[p].x) / n;
      double sample_var = std::max(0.0, double(film.sumsq[p].x) / n - mean * mean) * n / (n - 1.0);
      // Quadrature: 8 x 8, its error bounded by the difference to 4 x 4; where the falloff band or
      // the edge crosses the pixel (the two disagree) 128 x 128, bounded by the difference to
      // 64 x 64.
      PixelRef r8 = pixel_reference(s, cam, px, py, 8), r4 = pixel_reference(s, cam, px, py, 4);
      PixelRef rf = r8;
      double quad = std::fabs(r8.mean - r4.mean);
      if (quad > 1e-9 * r8.mean) {
        rf = pixel_reference(s, cam, px, py, 128);
        quad = std::fabs(rf.mean - pixel_reference(s, cam, px, py, 64).mean);
      }
      double ref = rf.mean;
      // The variance of one sample: the larger of the sample variance and the exact one over the
      // footprint. The sample variance alone fails both ways here: a pixel that the edge clips
      // by a few percent often has no sample outside the cone among its 128, and the float film's
      // sum of squares loses the tiny spread of a fully lit pixel to cancellation.
      double var = std::max(sample_var, std::max(0.0, rf.mean2 - rf.mean * rf.mean));
      double bound = 5.0 * std::sqrt(var / n) + quad + 1e-5 * ref;
      if (std::fabs(mean - ref) > bound) {
        if (r.bad_pixels < 5)
          ADD_FAILURE() << "pixel (" << px << "," << py << "): mean " << mean << " vs exact " << ref
                        << ", bound " << bound;
        ++r.bad_pixels;
      }
      r.lit_pixels += ref > 0;
      r.total += mean;
      r.total_ref += ref;
      r.total_var += var / n;
      r.total_quad += quad;
    }
  return r;
}

class NarrowSpot : public ::testing::TestWithParam<SpotCase> {};

TEST_P(NarrowSpot, FilmMatchesTheExactSpotIrradiance) {
  const SpotCase c = GetParam();
  ClRuntime rt;
  Result r = render_spot(rt, c);
  double err = r.total / r.total_ref - 1.0;
  double bound = 5.0 * std::sqrt(r.total_var) + r.total_quad + 1e-5 * r.total_ref;
  std::printf("cone %g deg, tilt %g deg, falloff_start %s: %d lit pixels, film total %.7g vs "
              "exact %.7g (%+.3f%%, noise+quadrature bound %.3f%%), %d pixels off\n",
              c.cone_deg, c.tilt_deg,
              c.write_start ? fmt_num(c.start_frac * c.cone_deg).c_str() : "default", r.lit_pixels,
              r.total, r.total_ref, 100.0 * err, 100.0 * bound / r.total_ref, r.bad_pixels);
  EXPECT_GT(r.lit_pixels, 500); // the falloff is resolved by the film
  EXPECT_LT(std::fabs(err), 0.005);
  EXPECT_NEAR(r.total, r.total_ref, bound);
  EXPECT_LT(bound, 0.005 * r.total_ref); // the check above is tight enough to mean something
  EXPECT_EQ(r.bad_pixels, 0);
}

INSTANTIATE_TEST_SUITE_P(
    ConesAndTilts, NarrowSpot,
    ::testing::Values(SpotCase{0.1, 0.0, 0.8, false}, SpotCase{0.1, 30.0, 0.8, false},
                      SpotCase{0.01, 0.0, 0.8, false}, SpotCase{0.01, 30.0, 0.8, false},
                      SpotCase{0.1, 30.0, 1.0, true},  // hard edge
                      SpotCase{0.01, 0.0, 1.0, true}), // hard edge
    [](const auto& p) {
      const SpotCase& c = p.param;
      return fmt::format("cone_{}mdeg_tilt_{}{}", int(std::lround(c.cone_deg * 1000)),
                         int(c.tilt_deg), c.start_frac == 1.0 ? "_hard_edge" : "");
    });

} // namespace
