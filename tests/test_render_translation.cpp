// Shadows and self-intersection under translation (issue 9, finding 3). One scene -- a point
// light, a small black square occluder 1 above a diffuse floor, a camera looking straight down --
// rendered at x = 0, 1e3, 1e4, 1e5 and 1e6. Ray origins and shadow-ray ends must follow the float
// error of each point's own coordinates, so every translated image is the untranslated one up to
// noise: the umbra stays dark, the lit floor keeps the analytic radiance, no pixel is speckled by
// a ray that hits the surface it leaves.
//
// At x = 1e6 floats are 1/16 apart, so hit points snap to that grid whatever the renderer does.
// The scene is laid out on that grid so the snapping itself cannot bias a pixel: every coordinate
// is a multiple of 1/16, the shadow's edges fall on pixel boundaries, and each pixel's footprint
// (1/8 wide, the camera looks straight down so footprints are equal squares) covers whole grid
// cells symmetrically (rounding to nearest is then unbiased to first order over the pixel).
#include "render/camera.h"
#include "render/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace canopy;

namespace {

constexpr int kFilm = 32;        // pixels per side; the view is 4 x 4 units
constexpr double kPixel = 0.125; // footprint side on the floor
constexpr double kViewX0 = -1.0; // footprint of pixel column 0 starts here (relative x)
constexpr double kViewY0 = 2.0;  // footprint of row 0 starts here (relative y, rows go to -y)
constexpr double kCamH = 8.0;    // camera height above the floor
constexpr double kLx = -1.5, kLz = 2.0; // point light at (kLx, 0, kLz)
constexpr double kI = 4.0;              // its intensity
constexpr double kAlbedo = 0.5;
// The occluder [0, 0.5] x [-0.25, 0.25] at z = 1 (half-way to the light) casts the umbra
// [1.5, 2.5] x [-0.5, 0.5]; seen from the camera it covers [-1/7, 3/7] x [-2/7, 2/7] of the floor.
constexpr double kOcc[4] = {0.0, 0.5, -0.25, 0.25};
constexpr double kUmbra[4] = {1.5, 2.5, -0.5, 0.5};
constexpr double kOccSeen[4] = {1.0 - 8.0 / 7.0, 1.0 - 4.0 / 7.0, -2.0 / 7.0, 2.0 / 7.0};

// The whole scene is turned by 20 deg about the x axis (the axis of the translation), so the floor
// is not axis-aligned: its hit points then carry rounding error in y and z, and a ray that leaves
// the floor without a sufficient offset can hit it again. Rotating about x keeps every x
// coordinate, hence the layout on the float grid, and the exact image, which is the untilted one.
float3 place(float T, double x, double y, double z) {
  const double a = 20.0 * M_PI / 180.0, c = std::cos(a), s = std::sin(a);
  return make_float3(T + float(x), float(c * y - s * z), float(s * y + c * z));
}

Scene make_scene(float T, bool occluder) {
  Scene s;
  s.path = "translated-occluder";
  s.camera.position = place(T, 1.0, 0.0, kCamH);
  s.camera.look_at = place(T, 1.0, 0.0, 0.0);
  s.camera.up = place(0.0f, 0.0, 1.0, 0.0);
  s.camera.fov_y_deg = float(2.0 * std::atan(2.0 / kCamH) * 180.0 / M_PI);
  s.film.width = kFilm;
  s.film.height = kFilm;
  s.integrator.max_depth = 1;
  const float a = float(kAlbedo);
  s.materials = {diffuse_material("floor", make_float3(a, a, a)),
                 diffuse_material("black", make_float3(0, 0, 0))};
  // Each triangle has one edge along x and one across it, so a hit point's x is one rounding of
  // v0.x + u * e.x (cl/geometry.h primitive_hit_point).
  auto add_rect = [&](double x0, double x1, double y0, double y1, double z, int material) {
    uint32_t b = uint32_t(s.vertices.size());
    s.vertices.push_back(place(T, x0, y0, z));
    s.vertices.push_back(place(T, x1, y0, z));
    s.vertices.push_back(place(T, x1, y1, z));
    s.vertices.push_back(place(T, x0, y1, z));
    for (uint32_t i : {0u, 1u, 3u, 2u, 3u, 1u})
      s.indices.push_back(b + i);
    s.triangle_material.insert(s.triangle_material.end(), {material, material});
    s.triangle_light.insert(s.triangle_light.end(), {-1, -1});
  };
  add_rect(-3.0, 5.0, -4.0, 4.0, 0.0, 0);
  if (occluder) add_rect(kOcc[0], kOcc[1], kOcc[2], kOcc[3], 1.0, 1);
  Light l{};
  l.type = LIGHT_POINT;
  l.p = f4_from3(place(T, kLx, 0.0, kLz), 0.0f);
  l.emission = make_float4(float(kI), float(kI), float(kI), 0.0f);
  l.prim = -1;
  s.lights.push_back(l);
  return s;
}

// Exact unshadowed radiance of the floor at relative (x, y), in double.
double floor_radiance(double x, double y) {
  double dx = kLx - x, dz = kLz, d2 = dx * dx + y * y + dz * dz;
  return kAlbedo / M_PI * kI * (dz / std::sqrt(d2)) / d2;
}

// Footprint of pixel (px, py): [x0, x1] x [y0, y1] relative to the translation.
void footprint(int px, int py, double r[4]) {
  r[0] = kViewX0 + px * kPixel;
  r[1] = r[0] + kPixel;
  r[3] = kViewY0 - py * kPixel;
  r[2] = r[3] - kPixel;
}
bool overlaps(const double a[4], const double b[4], double m) {
  return a[0] < b[1] + m && b[0] - m < a[1] && a[2] < b[3] + m && b[2] - m < a[3];
}
bool inside(const double a[4], const double b[4], double m) {
  return a[0] >= b[0] + m && a[1] <= b[1] - m && a[2] >= b[2] + m && a[3] <= b[3] - m;
}

// The pixel's box-filtered unshadowed radiance by an n x n midpoint rule over the footprint.
double pixel_reference(int px, int py, int n) {
  double r[4];
  footprint(px, py, r);
  double acc = 0;
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b)
      acc += floor_radiance(r[0] + (a + 0.5) / n * kPixel, r[2] + (b + 0.5) / n * kPixel);
  return acc / (n * n);
}

struct PixelStat {
  double mean, se; // luminance-free: the scene is grey, channel 0 is used
};

std::vector<PixelStat> render(ClRuntime& rt, float T, bool occluder) {
  Scene scene = make_scene(T, occluder);
  RendererOptions opt;
  opt.light_sampler = "tree";
  Renderer renderer(rt, scene, opt);
  RenderSettings rs;
  rs.spp = 64;
  rs.seed = 5;
  Film film = renderer.render(rs);
  EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
  std::vector<PixelStat> out;
  for (size_t p = 0; p < film.sum.size(); ++p) {
    double n = double(film.sum[p].w);
    double m = double(film.sum[p].x) / n;
    double var = std::max(0.0, double(film.sumsq[p].x) / n - m * m) * n / (n - 1.0);
    out.push_back({m, std::sqrt(var / n)});
  }
  return out;
}

} // namespace

TEST(RenderTranslation, ShadowsAndLitFloorMatchTheUntranslatedImage) {
  ClRuntime rt;
  // Sanity of the layout: the umbra and the occluder as seen are apart, both inside the view.
  ASSERT_LT(kOccSeen[1], kUmbra[0]);
  const float Ts[] = {0.0f, 1e3f, 1e4f, 1e5f, 1e6f};
  std::vector<PixelStat> base_occ, base_free;
  for (float T : Ts) {
    std::vector<PixelStat> occ = render(rt, T, true), free = render(rt, T, false);
    if (T == 0.0f) {
      base_occ = occ;
      base_free = free;
    }
    int umbra_px = 0, lit_px = 0, bad_lit = 0, bad_free = 0, bad_vs_base = 0;
    double umbra_sum = 0, umbra_ref = 0, lit_sum = 0, lit_base = 0, lit_var = 0;
    for (int py = 0; py < kFilm; ++py)
      for (int px = 0; px < kFilm; ++px) {
        size_t p = size_t(py) * kFilm + size_t(px);
        double r[4];
        footprint(px, py, r);
        double ref = pixel_reference(px, py, 16);
        // bound of the 16 x 16 rule's error, from its difference to the 8 x 8 rule
        double quad = std::fabs(ref - pixel_reference(px, py, 8));
        // Without the occluder every pixel is lit: none may be darker (or brighter) than its
        // noise allows -- a ray hitting the floor it leaves would blacken some of its samples.
        const PixelStat& f = free[p];
        if (std::fabs(f.mean - ref) > 5.0 * f.se + quad + 1e-5 * ref) {
          if (bad_free < 5)
            ADD_FAILURE() << "T " << T << ", no occluder, pixel (" << px << "," << py << "): mean "
                          << f.mean << " vs exact " << ref << " (se " << f.se << ")";
          ++bad_free;
        }
        const PixelStat& o = occ[p];
        // Pixels along the shadow's edges are left out: at x = 1e6 their hit points snap onto the
        // edge itself, where lit or shadowed is a tie.
        if (inside(r, kUmbra, 0.5 * kPixel)) {
          ++umbra_px;
          umbra_sum += o.mean;
          umbra_ref += ref;
        } else if (!overlaps(r, kUmbra, 0.5 * kPixel) && !overlaps(r, kOccSeen, 1e-9)) {
          ++lit_px;
          const PixelStat& b = base_occ[p];
          lit_sum += o.mean;
          lit_base += b.mean;
          lit_var += o.se * o.se + b.se * b.se;
          if (std::fabs(o.mean - ref) > 5.0 * o.se + quad + 1e-5 * ref) ++bad_lit;
          if (std::fabs(o.mean - b.mean) > 5.0 * std::sqrt(o.se * o.se + b.se * b.se) + 1e-5 * ref)
            ++bad_vs_base;
        }
      }
    std::printf("T = %g: umbra %d px gets %.4g%% of the unshadowed light; lit %d px, mean %.6g vs "
                "untranslated %.6g; pixels off: %d lit, %d vs T=0, %d without occluder\n",
                double(T), umbra_px, 100.0 * umbra_sum / umbra_ref, lit_px, lit_sum / lit_px,
                lit_base / lit_px, bad_lit, bad_vs_base, bad_free);
    EXPECT_EQ(umbra_px, 36);
    EXPECT_LE(umbra_sum, 0.01 * umbra_ref) << "T = " << T << ": light leaks into the umbra";
    EXPECT_GT(lit_px, 800);
    EXPECT_EQ(bad_lit, 0) << "T = " << T;
    EXPECT_EQ(bad_vs_base, 0) << "T = " << T;
    EXPECT_EQ(bad_free, 0) << "T = " << T;
    // Region mean of the lit floor against the untranslated image, 5 standard errors.
    EXPECT_NEAR(lit_sum, lit_base, 5.0 * std::sqrt(lit_var) + 1e-6 * lit_base) << "T = " << T;
  }
}
