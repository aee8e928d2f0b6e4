// Procedural light sets: counts, bounds, determinism by seed, templates, instances, and a
// million-light scene from a few lines of JSON.
#include "test_scene_util.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>

using namespace canopy;
using namespace canopy::test;

namespace {

// The scene with its light positions and vertices back in world space (the loader stores them
// relative to the camera position, Scene::origin), as the tests below state them.
Scene with_sets(const std::string& sets, const std::string& more = "") {
  std::string members = more.empty() ? "" : more + ", ";
  Scene s = load_str(scene_with(members + "\"light_sets\": " + sets, ""));
  for (Light& l : s.lights) {
    float3 w = world(s, l.p);
    l.p = make_float4(w.x, w.y, w.z, l.p.w);
  }
  for (float3& v : s.vertices)
    v = world(s, v);
  return s;
}

bool same_lights(const Scene& a, const Scene& b) {
  if (a.lights.size() != b.lights.size()) return false;
  for (size_t i = 0; i < a.lights.size(); ++i)
    if (std::memcmp(&a.lights[i], &b.lights[i], sizeof(Light)) != 0) return false;
  return true;
}

} // namespace

TEST(SceneLightSets, GridNxNy) {
  Scene s = with_sets(R"([{"type": "grid", "origin": [0, 3, 0], "edge1": [2, 0, 0],
      "edge2": [0, 0, 4], "nx": 4, "ny": 8,
      "light": {"type": "point", "position": [0, -0.5, 0], "intensity": [1, 2, 3]}}])");
  ASSERT_EQ(s.lights.size(), 32u);
  // Cell centres: x = (i + 0.5) / 4 * 2, z = (j + 0.5) / 8 * 4; the template offset is added.
  EXPECT_FLOAT_EQ(s.lights[0].p.x, 0.25f);
  EXPECT_FLOAT_EQ(s.lights[0].p.z, 0.25f);
  EXPECT_FLOAT_EQ(s.lights[5].p.x, 0.75f); // i = 1, j = 1
  EXPECT_FLOAT_EQ(s.lights[5].p.z, 0.75f);
  for (const Light& l : s.lights) {
    EXPECT_EQ(l.type, LIGHT_POINT);
    EXPECT_FLOAT_EQ(l.p.y, 2.5f);
    EXPECT_GT(l.p.x, 0.0f);
    EXPECT_LT(l.p.x, 2.0f);
    EXPECT_GT(l.p.z, 0.0f);
    EXPECT_LT(l.p.z, 4.0f);
    EXPECT_FLOAT_EQ(l.emission.z, 3.0f);
    EXPECT_EQ(l.prim, -1);
  }
}

TEST(SceneLightSets, GridCount) {
  Scene s = with_sets(R"([{"type": "grid", "origin": [0, 0, 0], "edge1": [1, 0, 0],
      "edge2": [0, 1, 0], "count": 10, "light": {"type": "point", "intensity": 1}}])");
  EXPECT_EQ(s.lights.size(), 10u);
}

TEST(SceneLightSets, QuadTemplateCentredOnSite) {
  Scene s = with_sets(R"([{"type": "grid", "origin": [0, 2, 0], "edge1": [1, 0, 0],
      "edge2": [0, 0, 1], "nx": 1, "ny": 1,
      "light": {"type": "quad", "edge1": [0.2, 0, 0], "edge2": [0, 0, 0.2], "radiance": 1}}])");
  ASSERT_EQ(s.lights.size(), 1u);
  const Light& l = s.lights[0];
  EXPECT_FLOAT_EQ(l.p.x, 0.4f); // site 0.5 minus half the edge
  EXPECT_FLOAT_EQ(l.p.z, 0.4f);
  EXPECT_FLOAT_EQ(l.n.y, -1.0f);
  EXPECT_NEAR(l.n.w, 0.04f, 1e-7f);
}

TEST(SceneLightSets, DiskTemplate) {
  // grid sites move the centre (an offset from the site); normal, radius and flags come from the
  // template; on a mesh surface with align_to_normal the disk faces along the surface normal.
  Scene s = with_sets(R"([{"type": "grid", "origin": [0, 2, 0], "edge1": [1, 0, 0],
      "edge2": [0, 0, 1], "nx": 2, "ny": 2,
      "light": {"type": "disk", "center": [0, -0.1, 0], "normal": [0, -1, 0], "radius": 0.1,
                "radiance": 1, "two_sided": true}},
      {"type": "mesh_surface", "shape": 0, "count": 50, "offset": 0.01, "align_to_normal": true,
      "light": {"type": "disk", "normal": [1, 0, 0], "radius": 0.02, "radiance": 2}}])",
                      R"("shapes": [{"type": "box", "min": [5, 5, 5], "max": [6, 6, 6]}])");
  ASSERT_EQ(s.lights.size(), 54u);
  for (size_t i = 0; i < 4; ++i) {
    const Light& l = s.lights[i];
    EXPECT_EQ(l.type, LIGHT_DISK);
    EXPECT_EQ(l.flags, LIGHT_FLAG_TWO_SIDED);
    EXPECT_FLOAT_EQ(l.p.y, 1.9f);
    EXPECT_FLOAT_EQ(l.p.w, 0.1f);
    EXPECT_FLOAT_EQ(l.n.y, -1.0f);
  }
  EXPECT_FLOAT_EQ(s.lights[3].p.x, 0.75f); // the last of the 2 x 2 cell centres
  for (size_t i = 4; i < 54; ++i) {
    const Light& l = s.lights[i];
    EXPECT_EQ(l.type, LIGHT_DISK);
    EXPECT_FLOAT_EQ(l.p.w, 0.02f);
    float3 c = xyz_of(l.p) - make_float3(5.5f, 5.5f, 5.5f);
    float3 n = xyz_of(l.n);
    EXPECT_NEAR(length(n), 1.0f, 1e-6f);
    EXPECT_NEAR(dot(c, n), 0.51f, 1e-5f); // outward face normal, offset 0.01 along it
    EXPECT_NEAR(dot(xyz_of(l.e1), n), 0.0f, 1e-6f);
    EXPECT_NEAR(dot(xyz_of(l.e2), n), 0.0f, 1e-6f);
  }
}

TEST(SceneLightSets, RandomBoxBoundsAndDeterminism) {
  const char* set = R"([{"type": "random_box", "min": [-1, 2, 3], "max": [1, 2.5, 7],
      "count": 5000, "seed": 42, "light": {"type": "sphere", "radius": 0.01, "radiance": 1}}])";
  Scene a = with_sets(set), b = with_sets(set);
  ASSERT_EQ(a.lights.size(), 5000u);
  EXPECT_TRUE(same_lights(a, b));
  float3 lo = make_float3(1e9f, 1e9f, 1e9f), hi = make_float3(-1e9f, -1e9f, -1e9f);
  for (const Light& l : a.lights) {
    EXPECT_EQ(l.type, LIGHT_SPHERE);
    EXPECT_FLOAT_EQ(l.p.w, 0.01f);
    ASSERT_GE(l.p.x, -1.0f);
    ASSERT_LE(l.p.x, 1.0f);
    ASSERT_GE(l.p.y, 2.0f);
    ASSERT_LE(l.p.y, 2.5f);
    ASSERT_GE(l.p.z, 3.0f);
    ASSERT_LE(l.p.z, 7.0f);
    lo = fmin(lo, xyz_of(l.p));
    hi = fmax(hi, xyz_of(l.p));
  }
  // 5000 uniform points fill the box.
  EXPECT_LT(lo.x, -0.99f);
  EXPECT_GT(hi.x, 0.99f);
  EXPECT_LT(lo.z, 3.01f);
  EXPECT_GT(hi.z, 6.99f);
  std::string other(set);
  other.replace(other.find("42"), 2, "43");
  EXPECT_FALSE(same_lights(a, with_sets(other)));
}

TEST(SceneLightSets, Spiral) {
  Scene s = with_sets(R"([{"type": "spiral", "center": [1, 0, 2], "inner_radius": 0.5,
      "radius": 3, "turns": 4, "height": 1, "count": 1000,
      "light": {"type": "point", "intensity": 1}}])");
  ASSERT_EQ(s.lights.size(), 1000u);
  for (const Light& l : s.lights) {
    float dx = l.p.x - 1.0f, dz = l.p.z - 2.0f;
    float r = std::sqrt(dx * dx + dz * dz);
    EXPECT_GE(r, 0.5f - 1e-4f);
    EXPECT_LE(r, 3.0f + 1e-4f);
    EXPECT_GE(l.p.y, 0.0f);
    EXPECT_LE(l.p.y, 1.0f + 1e-6f);
    // the height rises linearly with the radius
    EXPECT_NEAR(l.p.y, (r - 0.5f) / 2.5f, 1e-3f);
  }
  EXPECT_NEAR(s.lights.front().p.x, 1.5f, 1e-5f);
  EXPECT_NEAR(s.lights.back().p.x, 4.0f, 1e-4f); // 4 whole turns end on +x
}

TEST(SceneLightSets, MeshSurfaceByNameAndIndex) {
  const char* shapes = R"("shapes": [
      {"type": "box", "min": [5, 5, 5], "max": [6, 6, 6]},
      {"type": "quad", "name": "floor", "corner": [0, 1, 0], "edge1": [0, 0, 2],
       "edge2": [3, 0, 0]}])";
  Scene s = with_sets(R"([{"type": "mesh_surface", "shape": "floor", "count": 2000, "seed": 3,
      "offset": 0.25, "light": {"type": "point", "intensity": 1}},
      {"type": "mesh_surface", "shape": 0, "count": 500,
      "light": {"type": "spot", "direction": [1, 0, 0], "cone_angle": 40, "intensity": 1},
      "align_to_normal": true}])",
                      shapes);
  ASSERT_EQ(s.lights.size(), 2500u);
  for (size_t i = 0; i < 2000; ++i) {
    const Light& l = s.lights[i];
    EXPECT_FLOAT_EQ(l.p.y, 1.25f); // on the quad, offset along its +y normal
    EXPECT_GE(l.p.x, 0.0f);
    EXPECT_LE(l.p.x, 3.0f);
    EXPECT_GE(l.p.z, 0.0f);
    EXPECT_LE(l.p.z, 2.0f);
  }
  for (size_t i = 2000; i < 2500; ++i) {
    const Light& l = s.lights[i];
    EXPECT_EQ(l.type, LIGHT_SPOT);
    // On the unit box surface, the axis is the outward face normal.
    float3 c = xyz_of(l.p) - make_float3(5.5f, 5.5f, 5.5f);
    float3 a = xyz_of(l.e1);
    EXPECT_FLOAT_EQ(length(a), 1.0f);
    EXPECT_NEAR(std::fmax(std::fabs(c.x), std::fmax(std::fabs(c.y), std::fabs(c.z))), 0.5f, 1e-5f);
    EXPECT_NEAR(dot(c, a), 0.5f, 1e-5f);
  }
}

TEST(SceneLightSets, Variation) {
  const char* set = R"([{"type": "random_box", "min": [0, 0, 0], "max": [1, 1, 1],
      "count": 2000, "seed": 9, "light": {"type": "point", "intensity": [2, 4, 8]},
      "variation": {"scale": [0.5, 1.5], "color": 0.5}}])";
  Scene a = with_sets(set);
  EXPECT_TRUE(same_lights(a, with_sets(set)));
  float min_s = 10, max_s = 0;
  for (const Light& l : a.lights) {
    // each channel: base * s * (1 - 0.5 u), s in [0.5, 1.5], u in [0, 1)
    EXPECT_GE(l.emission.x, 2 * 0.5f * 0.5f - 1e-6f);
    EXPECT_LE(l.emission.x, 2 * 1.5f + 1e-6f);
    EXPECT_GT(l.emission.z, 0.0f);
    min_s = std::fmin(min_s, l.emission.z / 8);
    max_s = std::fmax(max_s, l.emission.z / 8);
  }
  EXPECT_LT(min_s, 0.35f);
  EXPECT_GT(max_s, 1.3f);
  // The variation stream is separate from positions: positions equal those without variation.
  std::string plain(set);
  plain.erase(plain.find(",\n      \"variation\""),
              plain.find("}}]") + 1 - plain.find(",\n      \"variation\""));
  Scene b = with_sets(plain);
  ASSERT_EQ(b.lights.size(), a.lights.size());
  for (size_t i = 0; i < a.lights.size(); ++i)
    EXPECT_EQ(a.lights[i].p.x, b.lights[i].p.x);
}

TEST(SceneLightSets, InstanceShapes) {
  Scene s = with_sets(R"([{"type": "grid", "origin": [0, 0, 0], "edge1": [10, 0, 0],
      "edge2": [0, 0, 10], "nx": 3, "ny": 2,
      "instance": {"type": "box", "min": [-0.1, 0, -0.1], "max": [0.1, 0.2, 0.1]},
      "light": {"type": "point", "position": [0, 0.5, 0], "intensity": 1}}])");
  EXPECT_EQ(s.lights.size(), 6u);
  EXPECT_EQ(s.triangle_count(), 6u * 12u);
  // The first box sits on the first site.
  float3 lo = s.vertices[0], hi = s.vertices[0];
  for (size_t v = 0; v < 24; ++v) {
    lo = fmin(lo, s.vertices[v]);
    hi = fmax(hi, s.vertices[v]);
  }
  EXPECT_NEAR(lo.x, 10.0f / 6 - 0.1f, 1e-5f);
  EXPECT_NEAR(hi.y, 0.2f, 1e-6f);
  EXPECT_NEAR(hi.z, 2.5f + 0.1f, 1e-5f);
}

TEST(SceneLightSets, EmissiveInstancesBecomeMeshLights) {
  Scene s = with_sets(R"([{"type": "grid", "origin": [0, 0, 0], "edge1": [10, 0, 0],
      "edge2": [0, 0, 10], "nx": 2, "ny": 1,
      "instance": {"type": "quad", "corner": [0, 1, 0], "edge1": [0, 0, 1], "edge2": [1, 0, 0],
                   "emission": 3},
      "light": {"type": "point", "intensity": 1}}])");
  EXPECT_EQ(s.lights.size(), 2u + 4u);
  EXPECT_EQ(s.triangle_light[3], 5);
}

TEST(SceneLightSets, MillionLights) {
  std::string json = scene_with(R"("light_sets": [{"type": "random_box", "min": [-10, 0, -10],
      "max": [10, 5, 10], "count": 1000000, "seed": 1,
      "light": {"type": "point", "intensity": 0.001}, "variation": {"scale": [0.5, 2]}}])",
                                "");
  auto t0 = std::chrono::steady_clock::now();
  Scene s = load_str(json);
  double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::printf("10^6-light scene loaded in %.1f ms\n", ms);
  EXPECT_EQ(s.lights.size(), 1000000u);
}
