// The shipped scenes load and contain what they promise.
#include "scene/scene.h"
#include "test_scene_util.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>

using namespace canopy;
using canopy::test::world;

TEST(SceneFiles, DefaultLoads) {
  Scene s = load_scene(std::filesystem::path(CANOPY_SCENES_DIR) / "default.json");
  EXPECT_EQ(s.film.width, 512);
  EXPECT_EQ(s.film.height, 512);
  EXPECT_EQ(s.integrator.spp, 16);
  EXPECT_EQ(s.integrator.max_depth, 3);
  EXPECT_EQ(s.lights.size(), 256u);
  for (const Light& l : s.lights) {
    EXPECT_EQ(l.type, LIGHT_QUAD);
    EXPECT_FLOAT_EQ(l.n.y, -1.0f); // facing down into the box
    EXPECT_NEAR(l.n.w, 0.03f * 0.03f, 1e-7f);
    EXPECT_LT(world(s, l.p).y, 2.0f);
  }
  // 5 walls (2 triangles each) + 2 boxes (12 each).
  EXPECT_EQ(s.triangle_count(), 10u + 24u);
  EXPECT_EQ(s.triangle_light.size(), s.triangle_count());
  EXPECT_EQ(s.triangle_material.size(), s.triangle_count());
  // default + box_white + white, red, green from the MTL.
  EXPECT_EQ(s.materials.size(), 5u);
}

TEST(SceneFiles, Spiral10kLoads) {
  auto t0 = std::chrono::steady_clock::now();
  Scene s = load_scene(std::filesystem::path(CANOPY_SCENES_DIR) / "spiral-10k.json");
  double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::printf("spiral-10k.json loaded in %.1f ms\n", ms);
  EXPECT_EQ(s.lights.size(), 10000u);
  EXPECT_EQ(s.triangle_count(), 2u + 10000u * 12u);
  for (const Light& l : s.lights) {
    EXPECT_EQ(l.type, LIGHT_POINT);
    float3 p = world(s, l.p);
    // Stored relative to the camera (14 units above): float precision of that distance.
    EXPECT_NEAR(p.y, 0.1f, 2e-6f);
    float r = std::sqrt(p.x * p.x + p.z * p.z);
    EXPECT_GE(r, 0.5f - 1e-4f);
    EXPECT_LE(r, 10.0f + 1e-4f);
  }
}

// The complete example in docs/scene-format.md is a valid scene.
TEST(SceneFiles, DocumentationExampleLoads) {
  std::filesystem::path doc =
      std::filesystem::path(CANOPY_SCENES_DIR).parent_path() / "docs" / "scene-format.md";
  std::ifstream in(doc);
  ASSERT_TRUE(in) << doc;
  std::stringstream ss;
  ss << in.rdbuf();
  std::string md = ss.str();
  size_t a = md.find("## Complete example");
  ASSERT_NE(a, std::string::npos);
  a = md.find("```json\n", a);
  ASSERT_NE(a, std::string::npos);
  a += 8;
  size_t b = md.find("```", a);
  ASSERT_NE(b, std::string::npos);
  Scene s = load_scene_from_string(md.substr(a, b - a), "example.json", CANOPY_SCENES_DIR);
  // 5 analytic + 400 grid + 5000 random + 300 spiral + 1000 mesh_surface lights, plus the
  // emissive quad shape (2 triangles).
  EXPECT_EQ(s.lights.size(), 2u + 5u + 400u + 5000u + 300u + 1000u);
  EXPECT_EQ(s.film.width, 800);
}

// The glossy scenes of issue 11 (after Liu et al. 2019, Figs. 14 and 1).
TEST(SceneFiles, GlossyCornellLoads) {
  Scene s = load_scene(std::filesystem::path(CANOPY_SCENES_DIR) / "glossy-cornell.json");
  EXPECT_EQ(s.lights.size(), 10000u);
  for (const Light& l : s.lights)
    EXPECT_EQ(l.type, LIGHT_SPHERE);
  int plastic = 0;
  for (const MaterialDesc& m : s.materials)
    plastic += m.gpu.type == MATERIAL_PLASTIC;
  EXPECT_EQ(plastic, 3);
  EXPECT_FALSE(s.shading_normals.empty()); // the spheres are smooth-shaded meshes
}

TEST(SceneFiles, ShowroomLoads) {
  Scene s = load_scene(std::filesystem::path(CANOPY_SCENES_DIR) / "showroom.json");
  size_t disks = 0, quads = 0;
  for (const Light& l : s.lights) {
    disks += l.type == LIGHT_DISK;
    quads += l.type == LIGHT_QUAD;
  }
  EXPECT_EQ(disks, 3744u);
  EXPECT_EQ(quads, 1u);
  int conductor = 0, plastic = 0;
  for (const MaterialDesc& m : s.materials) {
    conductor += m.gpu.type == MATERIAL_CONDUCTOR;
    plastic += m.gpu.type == MATERIAL_PLASTIC;
  }
  EXPECT_GE(conductor, 1);
  EXPECT_GE(plastic, 1);
  EXPECT_FALSE(s.shading_normals.empty());
}
