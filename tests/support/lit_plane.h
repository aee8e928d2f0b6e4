// A plane at z = 0 seen from above, with nothing else in the scene (lights are the caller's), and
// a render of it: the fixture of the closed-form tests of lights at infinity
// (test_render_distant.cpp, test_render_environment.cpp).
#pragma once

#include "bsdf/bsdf.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

namespace canopy::test {

// The mean of f(fx, fy) over pixel (x, y) by the midpoint rule on an n x n grid (f: a float3 or a
// double of film coordinates). A test's reference is the 16 x 16 mean, and its difference from the
// 4 x 4 mean bounds the rule's error.
template <class F> auto pixel_average(const F& f, int x, int y, int n) {
  decltype(f(0.0f, 0.0f)) sum{};
  for (int a = 0; a < n; ++a)
    for (int c = 0; c < n; ++c)
      sum += f(float(x) + (float(a) + 0.5f) / float(n), float(y) + (float(c) + 0.5f) / float(n));
  return sum * (1.0f / float(n * n));
}

// A (2 half) x (2 half) square of material m at z = 0, the camera at (0.3, -0.2, 5) looking at the
// origin with a vertical field of fov degrees, a width x height film, direct light (max_depth 1).
inline Scene lit_plane_scene(MaterialDesc m, float fov, float half, int width, int height) {
  Scene s;
  s.path = "lit-plane";
  s.camera.position = make_float3(0.3f, -0.2f, 5.0f);
  s.camera.look_at = make_float3(0.0f, 0.0f, 0.0f);
  s.camera.up = make_float3(0.0f, 1.0f, 0.0f);
  s.camera.fov_y_deg = fov;
  s.film.width = width;
  s.film.height = height;
  s.integrator.max_depth = 1;
  s.materials.push_back(std::move(m));
  s.vertices = {make_float3(-half, -half, 0), make_float3(half, -half, 0),
                make_float3(half, half, 0), make_float3(-half, half, 0)};
  s.indices = {0, 1, 2, 0, 2, 3};
  s.triangle_material = {0, 0};
  s.triangle_light = {-1, -1};
  return s;
}

// A size x size film of lit_plane_scene (fov 20, the 2 x 2 plane) with uv = ((x + 1) / 2,
// (y + 1) / 2).
inline Scene uv_plane_scene(MaterialDesc m, int size) {
  Scene s = lit_plane_scene(std::move(m), 20.0f, 1.0f, size, size);
  s.triangle_uvs = {make_float2(0, 0), make_float2(1, 0), make_float2(1, 1),
                    make_float2(0, 0), make_float2(1, 1), make_float2(0, 1)};
  return s;
}

// The unit direction of the camera ray through raster point (fx, fy) and where it meets the plane
// z = 0 (*X).
inline float3 camera_ray_to_plane(const CameraParams& cam, float fx, float fy, float3* X) {
  float3 d = normalize(xyz_of(cam.lower_left) + xyz_of(cam.du) * fx + xyz_of(cam.dv) * fy);
  float3 o = xyz_of(cam.origin);
  *X = o + d * (-o.z / d.z);
  return d;
}

// Renders `scene` with `sampler` at spp (seed 5); no sample may be non-finite.
inline Film render_lit_plane(Scene& scene, const std::string& sampler, int spp, bool mis = true) {
  ClRuntime rt;
  RendererOptions opt;
  opt.light_sampler = sampler;
  opt.mis = mis;
  Renderer renderer(rt, scene, opt);
  RenderSettings rs;
  rs.spp = spp;
  rs.seed = 5;
  Film film = renderer.render(rs);
  EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
  return film;
}

// The red channel of the directional albedo of m at wo (local frame, z up), integral of
// f cos over the hemisphere, estimated from n of the kernels' own BSDF samples; *se: its
// standard error.
inline double directional_albedo(const Material& m, float3 wo, int n, unsigned seed, double* se) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double a = 0.0, a2 = 0.0;
  for (int i = 0; i < n; ++i) {
    BsdfSample bs = bsdf_sample(&m, wo, make_float3(u(gen), u(gen), u(gen)));
    double x = bs.pdf > 0.0f && bs.wi.z > 0.0f ? double(bs.weight.x) : 0.0;
    a += x;
    a2 += x * x;
  }
  double mean = a / n;
  *se = std::sqrt(std::max(0.0, a2 / n - mean * mean) / n);
  return mean;
}

} // namespace canopy::test
