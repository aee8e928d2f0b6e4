// Distant lights (cl/types.h LIGHT_DISTANT) rendered against closed forms. A distant light is the
// same direction and irradiance E at every point and every shading point samples it with
// probability 1 (cl/integrator/light_pick.h), so an unshadowed diffuse plane is exactly
// rho / pi * E cos(theta) in every pixel and every sample, whatever the light sampler; a glossy
// plane is f(wo, wi) cos(theta) E, box-filtered over each pixel's footprint.
#include "bsdf/bsdf.h"
#include "geometry.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "scene/pbrt_reader.h"
#include "scene/scene.h"
#include "support/lit_plane.h"
#include "support/test_lights.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace canopy;

namespace {

constexpr float kPi = 3.14159265358979323846f;

// A 100 x 100 plane at z = 0 seen from above; `fov` degrees.
Scene plane_scene(MaterialDesc m, float fov) {
  return test::lit_plane_scene(std::move(m), fov, 50.0f, 24, 20);
}

Film render(Scene& scene, const std::string& sampler, int spp, int max_depth = 1) {
  scene.integrator.max_depth = max_depth;
  return test::render_lit_plane(scene, sampler, spp);
}

const char* const kSamplers[] = {"uniform",    "power",    "tree",         "tree-split",
                                 "exhaustive", "brdf-mis", "brdf-oriented"};

} // namespace

// E cos(theta) rho / pi in every pixel, exactly (up to float rounding), for every light sampler
// and with a bounce (max_depth 2: the bounce escapes and adds nothing). The bsdf sampler cannot
// find a delta light: black.
TEST(DistantLight, DiffusePlaneIsExactForEverySampler) {
  const float3 rho = make_float3(0.8f, 0.5f, 0.25f);
  const float3 E = make_float3(3.0f, 2.0f, 7.0f);
  const float3 travel = make_float3(0.3f, -0.6f, -0.8f);
  const float cos_t = -normalize(travel).z;
  for (const char* sampler : kSamplers)
    for (int depth : {1, 2}) {
      Scene scene = plane_scene(diffuse_material("white", rho), 40.0f);
      scene.infinite_lights.push_back(test::distant_light(travel, E));
      Film film = render(scene, sampler, 4, depth);
      const float3 expect = rho * E * (cos_t / kPi);
      for (size_t p = 0; p < film.sum.size(); ++p) {
        const double n = film.sum[p].w;
        ASSERT_EQ(n, 4.0);
        EXPECT_NEAR(film.sum[p].x / n, expect.x, 2e-6 * expect.x) << sampler << " pixel " << p;
        EXPECT_NEAR(film.sum[p].y / n, expect.y, 2e-6 * expect.y) << sampler << " pixel " << p;
        EXPECT_NEAR(film.sum[p].z / n, expect.z, 2e-6 * expect.z) << sampler << " pixel " << p;
      }
    }
  Scene scene = plane_scene(diffuse_material("white", rho), 40.0f);
  scene.infinite_lights.push_back(test::distant_light(travel, E));
  Film film = render(scene, "bsdf", 4);
  for (const double4& s : film.sum)
    EXPECT_EQ(s.x + s.y + s.z, 0.0);
}

// Two distant lights and a point light: each pixel is the sum of the three closed forms. The point
// light is the only light in the tree, so every sampler picks it with probability 1 too: exact.
// A light below the horizon (travelling upwards) adds nothing.
TEST(DistantLight, SumsWithTheTreeLightsExactly) {
  const float3 rho = make_float3(0.6f, 0.6f, 0.6f);
  const float3 t1 = make_float3(0.0f, 0.0f, -1.0f), t2 = make_float3(-0.5f, 0.2f, -0.4f);
  const float3 E1 = make_float3(1.0f, 2.0f, 3.0f), E2 = make_float3(0.5f, 0.5f, 0.1f);
  const float3 I = make_float3(4.0f, 4.0f, 4.0f), pl = make_float3(0.2f, 0.1f, 1.5f);
  for (const char* sampler : kSamplers) {
    Scene scene = plane_scene(diffuse_material("grey", rho), 1.0f); // narrow: x barely varies
    scene.infinite_lights.push_back(test::distant_light(t1, E1));
    scene.infinite_lights.push_back(test::distant_light(t2, E2));
    scene.infinite_lights.push_back(
        test::distant_light(make_float3(0, 0, 1), E2 * 100.0f)); // below
    Light point{};
    point.type = LIGHT_POINT;
    point.p = f4_from3(pl, 0.0f);
    point.emission = f4_from3(I, 0.0f);
    point.prim = -1;
    scene.lights.push_back(point);
    Film film = render(scene, sampler, 8);
    CameraParams cam = make_camera_params(scene.camera, scene.film.width, scene.film.height);
    for (int y = 0; y < film.height; ++y)
      for (int x = 0; x < film.width; ++x) {
        // The pixel's footprint on the plane at fov 1 degree spans ~4e-3: the point light's term
        // is taken at the footprint's centre and its spread bounds the tolerance.
        float3 X;
        test::camera_ray_to_plane(cam, float(x) + 0.5f, float(y) + 0.5f, &X);
        float3 to = pl - X;
        float d2 = dot(to, to);
        float3 E = E1 * -normalize(t1).z + E2 * -normalize(t2).z + I * (to.z / std::sqrt(d2) / d2);
        float3 expect = rho * E * (1.0f / kPi);
        size_t p = size_t(y) * size_t(film.width) + size_t(x);
        double n = film.sum[p].w;
        EXPECT_NEAR(film.sum[p].x / n, expect.x, 2e-3 * expect.x)
            << sampler << " " << x << "," << y;
        EXPECT_NEAR(film.sum[p].z / n, expect.z, 2e-3 * expect.z)
            << sampler << " " << x << "," << y;
      }
  }
}

// A glossy conductor under the sun: f(wo, wi) cos(theta) E box-filtered over each pixel, against
// an 8 x 8 midpoint rule of the same closed form (the host's bsdf_eval: the kernel's code).
// brdf-mis and brdf-oriented treat the point as glossy: the distant light keeps MIS weight 1
// there, beside their BRDF-oriented samples of the (empty) tree.
TEST(DistantLight, GlossyPlaneMatchesTheBrdfForEverySampler) {
  const float3 E = make_float3(2.0f, 2.0f, 2.0f);
  const float3 travel = make_float3(-0.35f, 0.2f, -0.9f);
  MaterialDesc gold = conductor_material("gold", 0.3f, make_float3(0.143f, 0.374f, 1.442f),
                                         make_float3(3.983f, 2.385f, 1.603f));
  for (const char* sampler : kSamplers) {
    Scene scene = plane_scene(gold, 20.0f);
    scene.infinite_lights.push_back(test::distant_light(travel, E));
    Film film = render(scene, sampler, 64);
    CameraParams cam = make_camera_params(scene.camera, scene.film.width, scene.film.height);
    const Material m = scene.materials[0].gpu;
    const float3 wi = normalize(travel) * -1.0f;
    auto radiance = [&](float fx, float fy) {
      float3 d = normalize(xyz_of(cam.lower_left) + xyz_of(cam.du) * fx + xyz_of(cam.dv) * fy);
      // local frame of the plane: z up
      return bsdf_eval(&m, d * -1.0f, wi) * E * wi.z;
    };
    int checked = 0;
    for (int y = 0; y < film.height; ++y)
      for (int x = 0; x < film.width; ++x) {
        const float3 ref = test::pixel_average(radiance, x, y, 16);
        const float3 coarse = test::pixel_average(radiance, x, y, 4);
        size_t p = size_t(y) * size_t(film.width) + size_t(x);
        double n = film.sum[p].w;
        double mean = film.sum[p].x / n;
        double var = std::max(0.0, film.sumsq[p].x / n - mean * mean) * n / (n - 1.0);
        double bound = 5.0 * std::sqrt(var / n) + std::fabs(ref.x - coarse.x) + 1e-5 * ref.x;
        EXPECT_NEAR(mean, ref.x, bound) << sampler << " pixel " << x << "," << y;
        EXPECT_GT(ref.x, 0.0f);
        ++checked;
      }
    EXPECT_EQ(checked, 24 * 20);
  }
}

// An occluder between the plane and the sun: the plane point below its centre is in shadow (0),
// a point far from it is lit (the closed form). The unbounded shadow ray must still find the
// occluder, and must not be stopped by anything behind the plane point.
TEST(DistantLight, CastsAShadow) {
  const float3 rho = make_float3(0.5f, 0.5f, 0.5f);
  const float3 E = make_float3(1.0f, 1.0f, 1.0f);
  Scene scene = plane_scene(diffuse_material("white", rho), 1.0f);
  // A 1 x 1 occluder at z = 1 over the origin (the image centre); straight-down sun.
  const uint32_t b = uint32_t(scene.vertices.size());
  scene.vertices.push_back(make_float3(-0.5f, -0.5f, 1.0f));
  scene.vertices.push_back(make_float3(0.5f, -0.5f, 1.0f));
  scene.vertices.push_back(make_float3(0.5f, 0.5f, 1.0f));
  scene.vertices.push_back(make_float3(-0.5f, 0.5f, 1.0f));
  for (uint32_t i : {b, b + 1, b + 2, b, b + 2, b + 3})
    scene.indices.push_back(i);
  scene.triangle_material.insert(scene.triangle_material.end(), {0, 0});
  scene.triangle_light.insert(scene.triangle_light.end(), {-1, -1});
  // Light from +x above: the shadow falls on x in [-1.5, -0.5]. The camera sits below the
  // occluder, looking straight down at x = -1.
  scene.infinite_lights.push_back(test::distant_light(make_float3(-1.0f, 0.0f, -1.0f), E));
  scene.camera.position = make_float3(-1.0f, 0.0f, 0.5f);
  scene.camera.look_at = make_float3(-1.0f, 0.0f, 0.0f);
  Film film = render(scene, "tree", 4);
  for (const double4& s : film.sum)
    EXPECT_EQ(s.x, 0.0) << "the plane under the occluder's shadow is lit";
  scene.camera.position = make_float3(3.0f, 0.0f, 0.5f); // far from the shadow
  scene.camera.look_at = make_float3(3.0f, 0.0f, 0.0f);
  film = render(scene, "tree", 4);
  const float expect = 0.5f * (1.0f / std::sqrt(2.0f)) / kPi;
  for (const double4& s : film.sum)
    EXPECT_NEAR(s.x / s.w, expect, 2e-6 * expect);
}

// A JSON "distant" light, and the inputs that are refused with one line naming the file and the
// entry: a zero direction, a fourth distant light, a medium, a negative irradiance.
TEST(DistantLight, JsonScenes) {
  const std::string head = R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
    "shapes": [{"type": "quad", "corner": [-1, -1, 0], "edge1": [2, 0, 0], "edge2": [0, 2, 0]}],)";
  Scene s = load_scene_from_string(
      head +
          R"("lights": [{"type": "distant", "direction": [0, 0, -2], "irradiance": [1, 2, 3]}]})",
      "sun.json", ".");
  ASSERT_EQ(s.infinite_lights.size(), 1u);
  EXPECT_TRUE(s.lights.empty());
  EXPECT_EQ(s.infinite_lights[0].type, LIGHT_DISTANT);
  EXPECT_FLOAT_EQ(s.infinite_lights[0].e1.z, 1.0f); // towards the light
  EXPECT_FLOAT_EQ(s.infinite_lights[0].emission.y, 2.0f);

  auto refused = [&](const std::string& lights_and_more, const std::string& what) {
    try {
      load_scene_from_string(head + lights_and_more, "sun.json", ".");
      ADD_FAILURE() << "accepted: " << lights_and_more;
    } catch (const SceneError& e) {
      std::string m = e.what();
      EXPECT_NE(m.find("sun.json"), std::string::npos) << m;
      EXPECT_NE(m.find(what), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  };
  const std::string sun =
      R"({"type": "distant", "direction": [0, 0, -1], "irradiance": [1, 1, 1]})";
  refused(R"("lights": [{"type": "distant", "direction": [0, 0, 0], "irradiance": [1, 1, 1]}]})",
          "direction");
  refused(R"("lights": [)" + sun + "," + sun + "," + sun + "," + sun + "]}", "lights[3]");
  refused(R"("medium": {"sigma_a": [0.1, 0.1, 0.1], "sigma_s": [0.1, 0.1, 0.1]}, "lights": [)" +
              sun + "]}",
          "medium");
  refused(R"("lights": [{"type": "distant", "direction": [0, 0, -1], "irradiance": [-1, 1, 1]}]})",
          "irradiance");
}

// pbrt-v4 LightSource "distant": light travels from "from" to "to" under the current transform;
// L x scale, times "illuminance" when given (L is normalised to 1 nit first, as for every pbrt
// light: an "rgb L" keeps its values).
TEST(DistantLight, PbrtLightSource) {
  const std::string cam = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n";
  Scene s = load_pbrt_scene_from_string(
      cam + "Rotate 90 0 0 1\n"
            "LightSource \"distant\" \"point3 from\" [1 0 1] \"point3 to\" [0 0 0] "
            "\"rgb L\" [1 2 3] \"float scale\" 2\n"
            "LightSource \"distant\" \"rgb L\" [1 1 1] \"float illuminance\" 10\n",
      "sun.pbrt", ".", SceneLoadOptions{});
  ASSERT_EQ(s.infinite_lights.size(), 2u);
  EXPECT_TRUE(s.lights.empty());
  const Light& a = s.infinite_lights[0];
  // from - to = (1, 0, 1), rotated 90 degrees about z: (0, 1, 1) / sqrt(2) towards the light.
  EXPECT_NEAR(a.e1.x, 0.0f, 1e-6f);
  EXPECT_NEAR(a.e1.y, 1.0f / std::sqrt(2.0f), 1e-6f);
  EXPECT_NEAR(a.e1.z, 1.0f / std::sqrt(2.0f), 1e-6f);
  EXPECT_FLOAT_EQ(a.emission.z, 6.0f);
  const Light& b = s.infinite_lights[1];
  // Defaults from (0 0 0) to (0 0 1): light travelling +z, so towards -z; rotated: still -z.
  EXPECT_NEAR(b.e1.z, -1.0f, 1e-6f);
  EXPECT_FLOAT_EQ(b.emission.x, 10.0f);
  try {
    load_pbrt_scene_from_string(cam + "LightSource \"distant\" \"point3 from\" [0 0 1] "
                                      "\"point3 to\" [0 0 1]\n",
                                "sun.pbrt", ".", SceneLoadOptions{});
    ADD_FAILURE() << "from == to accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("sun.pbrt:4"), std::string::npos) << e.what();
  }
}
