// Good scenes: every value lands where docs/scene-format.md says it does.
#include "scene/metal_presets.h"
#include "test_scene_util.h"

#include <fmt/format.h>

#include <cmath>
#include <set>

using namespace canopy;
using namespace canopy::test;

namespace {

float3 tri_normal(const Scene& s, size_t t) {
  float3 a = s.vertices[s.indices[3 * t]], b = s.vertices[s.indices[3 * t + 1]],
         c = s.vertices[s.indices[3 * t + 2]];
  return normalize(cross(b - a, c - a));
}

float3 tri_centroid(const Scene& s, size_t t) {
  float3 a = s.vertices[s.indices[3 * t]], b = s.vertices[s.indices[3 * t + 1]],
         c = s.vertices[s.indices[3 * t + 2]];
  return (a + b + c) * (1.0f / 3.0f);
}

constexpr float kDeg = 3.14159265358979323846f / 180.0f;

} // namespace

TEST(SceneLoader, CameraFilmIntegrator) {
  Scene s = load_str(R"({
    "camera": {"position": [1, 2, 3], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 60},
    "film": {"width": 320, "height": 200},
    "integrator": {"spp": 7, "max_depth": 4, "light_sampler": "tree-split",
                   "split_threshold": 0.5, "max_cut": 9, "seed": 4294967295, "mis": false},
    "lights": [{"type": "point", "position": [0, 2, 0], "intensity": 1}]
  })");
  // The camera position is the scene origin (scene.h): the camera sits at 0.
  EXPECT_EQ(s.origin.x, 1.0);
  EXPECT_EQ(s.origin.y, 2.0);
  EXPECT_EQ(s.origin.z, 3.0);
  EXPECT_EQ(s.camera.position.x, 0.0f);
  EXPECT_EQ(s.camera.position.y, 0.0f);
  EXPECT_EQ(s.camera.position.z, 0.0f);
  EXPECT_FLOAT_EQ(s.camera.look_at.x, -1);
  EXPECT_FLOAT_EQ(s.camera.look_at.z, -3);
  EXPECT_FLOAT_EQ(s.camera.up.z, 1);
  EXPECT_FLOAT_EQ(s.camera.fov_y_deg, 60);
  EXPECT_EQ(s.film.width, 320);
  EXPECT_EQ(s.film.height, 200);
  EXPECT_EQ(s.integrator.spp, 7);
  EXPECT_EQ(s.integrator.max_depth, 4);
  EXPECT_EQ(s.integrator.light_sampler, "tree-split");
  EXPECT_FLOAT_EQ(s.integrator.split_threshold, 0.5f);
  EXPECT_EQ(s.integrator.max_cut, 9);
  EXPECT_EQ(s.integrator.seed, 4294967295u);
  EXPECT_FALSE(s.integrator.mis);
  EXPECT_EQ(s.path, "scene.json");
}

TEST(SceneLoader, Defaults) {
  Scene s = load_str(scene_with(""));
  EXPECT_FLOAT_EQ(s.camera.up.y, 1);
  EXPECT_FLOAT_EQ(s.camera.fov_y_deg, 45);
  EXPECT_EQ(s.film.width, 640);
  EXPECT_EQ(s.film.height, 480);
  EXPECT_EQ(s.integrator.spp, 16);
  // Without sampler settings the renderer shows its best: auto (a pilot picks power, tree or
  // brdf-mis per scene), within 10% of the best on every table of docs/results.md.
  EXPECT_EQ(s.integrator.max_depth, 5);
  EXPECT_EQ(s.integrator.light_sampler, "auto");
  EXPECT_FLOAT_EQ(s.integrator.split_threshold, LT_DEFAULT_SPLIT_THRESHOLD);
  EXPECT_EQ(s.integrator.max_cut, 64);
  EXPECT_EQ(s.integrator.seed, 1u);
  EXPECT_TRUE(s.integrator.mis);
  ASSERT_EQ(s.materials.size(), 1u);
  EXPECT_EQ(s.materials[0].name, "default");
  EXPECT_FLOAT_EQ(s.materials[0].gpu.albedo.x, 0.8f);
  EXPECT_EQ(s.triangle_count(), 0u);
}

TEST(SceneLoader, CommentsAndIntegralFloats) {
  Scene s = load_str(R"({
    // a comment
    "camera": {"position": [0, 1, 5], "look_at": [0, 1, 0]}, /* another */
    "film": {"width": 1e3, "height": 5.0e2},
    "lights": [{"type": "point", "position": [0, 2, 0], "intensity": 1}]
  })");
  EXPECT_EQ(s.film.width, 1000);
  EXPECT_EQ(s.film.height, 500);
}

TEST(SceneLoader, Materials) {
  Scene s = load_str(scene_with(R"("materials": [
      {"name": "red", "albedo": [0.9, 0.1, 0.0]},
      {"name": "grey", "type": "diffuse", "albedo": 0.25},
      {"name": "default", "albedo": 0.5}])"));
  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.materials[0].name, "default"); // replaced in place: index 0 stays the default
  EXPECT_FLOAT_EQ(s.materials[0].gpu.albedo.y, 0.5f);
  EXPECT_EQ(s.materials[1].name, "red");
  EXPECT_FLOAT_EQ(s.materials[1].gpu.albedo.x, 0.9f);
  EXPECT_FLOAT_EQ(s.materials[1].gpu.albedo.y, 0.1f);
  EXPECT_EQ(s.materials[1].gpu.type, MATERIAL_DIFFUSE);
  EXPECT_FLOAT_EQ(s.materials[2].gpu.albedo.z, 0.25f);
}

TEST(SceneLoader, ConductorWithEtaAndK) {
  Scene s = load_str(scene_with(R"("materials": [
      {"name": "c", "type": "conductor", "roughness": 0.3, "eta": [0.2, 0.5, 1.5],
       "k": [3.5, 2.5, 1.75]},
      {"name": "mirror", "type": "conductor", "roughness": 0, "eta": 1, "k": 0}])"));
  ASSERT_EQ(s.materials.size(), 3u);
  const Material& m = s.materials[1].gpu;
  EXPECT_EQ(s.materials[1].name, "c");
  EXPECT_EQ(m.type, MATERIAL_CONDUCTOR);
  EXPECT_FLOAT_EQ(m.alpha, 0.3f * 0.3f); // alpha = roughness^2
  EXPECT_FLOAT_EQ(m.specular.x, 0.2f);   // eta lives in `specular`
  EXPECT_FLOAT_EQ(m.specular.y, 0.5f);
  EXPECT_FLOAT_EQ(m.specular.z, 1.5f);
  EXPECT_FLOAT_EQ(m.k.x, 3.5f);
  EXPECT_FLOAT_EQ(m.k.y, 2.5f);
  EXPECT_FLOAT_EQ(m.k.z, 1.75f);
  const Material& mirror = s.materials[2].gpu;
  EXPECT_EQ(mirror.alpha, 0.0f); // a perfect mirror
  EXPECT_FLOAT_EQ(mirror.specular.z, 1.0f);
  EXPECT_EQ(mirror.k.y, 0.0f);
}

// Coated materials: pbrt-v4's defaults where absent, roughness r as GGX alpha r^2, the conductor's
// own index as given (the BSDF divides it by the coat's); rough glass.
TEST(SceneLoader, CoatedMaterialsAndRoughGlass) {
  Scene s = load_str(scene_with(R"("materials": [
      {"name": "cd", "type": "coated_diffuse"},
      {"name": "cd2", "type": "coated_diffuse", "albedo": [0.1, 0.2, 0.3], "roughness": 0.5,
       "ior": 1.33, "thickness": 0.2, "medium_albedo": [0.4, 0.5, 0.6], "g": -0.3,
       "max_depth": 30, "samples": 4},
      {"name": "cc", "type": "coated_conductor"},
      {"name": "cc2", "type": "coated_conductor", "roughness": 0.1, "eta": [0.2, 0.5, 1.5],
       "k": [3.5, 2.5, 1.75], "conductor_roughness": 0.4, "ior": 1.4},
      {"name": "frosted", "type": "dielectric", "ior": 1.5, "roughness": 0.3}])"));
  ASSERT_EQ(s.materials.size(), 6u);
  const Material& cd = s.materials[1].gpu;
  EXPECT_EQ(cd.type, MATERIAL_COATED_DIFFUSE);
  EXPECT_FLOAT_EQ(cd.albedo.y, 0.5f); // pbrt-v4: reflectance 0.5, roughness 0, eta 1.5,
  EXPECT_EQ(cd.alpha, 0.0f);          // thickness 0.01, albedo 0, g 0, maxdepth 10, nsamples 1
  EXPECT_FLOAT_EQ(cd.ior, 1.5f);
  EXPECT_FLOAT_EQ(cd.thickness, 0.01f);
  EXPECT_EQ(cd.medium.x, 0.0f);
  EXPECT_EQ(cd.medium.w, 0.0f);
  EXPECT_EQ(cd.max_depth, 10);
  EXPECT_EQ(cd.n_samples, 1);
  const Material& cd2 = s.materials[2].gpu;
  EXPECT_FLOAT_EQ(cd2.albedo.z, 0.3f);
  EXPECT_FLOAT_EQ(cd2.alpha, 0.25f);
  EXPECT_FLOAT_EQ(cd2.ior, 1.33f);
  EXPECT_FLOAT_EQ(cd2.thickness, 0.2f);
  EXPECT_FLOAT_EQ(cd2.medium.y, 0.5f);
  EXPECT_FLOAT_EQ(cd2.medium.w, -0.3f);
  EXPECT_EQ(cd2.max_depth, 30);
  EXPECT_EQ(cd2.n_samples, 4);
  const Material& cc = s.materials[3].gpu;
  const MetalPreset* cu = find_metal_preset("copper"); // pbrt-v4's default conductor: Cu
  EXPECT_EQ(cc.type, MATERIAL_COATED_CONDUCTOR);
  EXPECT_EQ(cc.specular.x, cu->eta[0]);
  EXPECT_EQ(cc.k.z, cu->k[2]);
  EXPECT_EQ(cc.base_alpha, 0.0f);
  const Material& cc2 = s.materials[4].gpu;
  EXPECT_FLOAT_EQ(cc2.alpha, 0.01f);
  EXPECT_FLOAT_EQ(cc2.base_alpha, 0.16f);
  EXPECT_FLOAT_EQ(cc2.specular.z, 1.5f);
  EXPECT_FLOAT_EQ(cc2.k.x, 3.5f);
  EXPECT_FLOAT_EQ(cc2.ior, 1.4f);
  const Material& glass = s.materials[5].gpu;
  EXPECT_EQ(glass.type, MATERIAL_DIELECTRIC);
  EXPECT_FLOAT_EQ(glass.alpha, 0.09f);
}

// A coated diffuse base's albedo and a coat's roughness may be textures (cl/texture.h replaces
// Material.albedo and alpha at the hit: the base reflectance and the coat's alpha).
TEST(SceneLoader, CoatedTextures) {
  Scene s = load_str(scene_with(R"("materials": [
      {"name": "cd", "type": "coated_diffuse", "albedo": {"texture": "textures/colours.png"},
       "roughness": {"texture": "textures/roughness.png"}},
      {"name": "cc", "type": "coated_conductor", "roughness": {"texture": "textures/roughness.png"}}
      ])"));
  ASSERT_EQ(s.textures.size(), 3u);
  const Material& cd = s.materials[1].gpu;
  EXPECT_EQ(cd.type, MATERIAL_COATED_DIFFUSE);
  ASSERT_GT(cd.albedo_texture, 0);
  ASSERT_GT(cd.alpha_texture, 0);
  EXPECT_EQ(s.textures[size_t(cd.albedo_texture - 1)].channels, 3);
  EXPECT_EQ(s.textures[size_t(cd.alpha_texture - 1)].map, TEXTURE_MAP_ALPHA_SQUARE);
  const Material& cc = s.materials[2].gpu;
  EXPECT_EQ(cc.type, MATERIAL_COATED_CONDUCTOR);
  EXPECT_EQ(cc.albedo_texture, 0);
  ASSERT_GT(cc.alpha_texture, 0);
  EXPECT_EQ(s.textures[size_t(cc.alpha_texture - 1)].map, TEXTURE_MAP_ALPHA_SQUARE);
}

TEST(SceneLoader, ConductorPresets) {
  // Every preset loads by name and gives exactly the table's eta and k.
  std::string mats;
  for (const MetalPreset& p : metal_presets())
    mats += std::string(mats.empty() ? "" : ", ") + R"({"name": ")" + std::string(p.name) +
            R"(", "type": "conductor", "roughness": 0.5, "metal": ")" + std::string(p.name) +
            R"("})";
  Scene s = load_str(scene_with("\"materials\": [" + mats + "]"));
  ASSERT_EQ(s.materials.size(), 1 + kMetalPresetCount);
  for (size_t i = 0; i < kMetalPresetCount; ++i) {
    const MetalPreset& p = metal_presets()[i];
    const Material& m = s.materials[i + 1].gpu;
    SCOPED_TRACE(std::string(p.name));
    EXPECT_EQ(m.type, MATERIAL_CONDUCTOR);
    EXPECT_FLOAT_EQ(m.alpha, 0.25f);
    EXPECT_EQ(m.specular.x, p.eta[0]);
    EXPECT_EQ(m.specular.y, p.eta[1]);
    EXPECT_EQ(m.specular.z, p.eta[2]);
    EXPECT_EQ(m.k.x, p.k[0]);
    EXPECT_EQ(m.k.y, p.k[1]);
    EXPECT_EQ(m.k.z, p.k[2]);
  }
  // Spot values against scripts/metal-presets.py (Johnson & Christy 1972 at 650/550/450 nm).
  const MetalPreset* gold = find_metal_preset("gold");
  ASSERT_NE(gold, nullptr);
  EXPECT_FLOAT_EQ(gold->eta[1], 0.424f);
  EXPECT_FLOAT_EQ(gold->k[0], 3.602f);
  EXPECT_EQ(find_metal_preset("unobtainium"), nullptr);
}

namespace {
// Normal-incidence reflectance of a conductor, ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2).
double f0(double n, double k) {
  return ((n - 1) * (n - 1) + k * k) / ((n + 1) * (n + 1) + k * k);
}
} // namespace

TEST(SceneLoader, ConductorPresetsLookLikeTheirMetals) {
  // The presets are measured data; these are properties every correct table has (a swapped
  // channel, eta/k mix-up or typo breaks one): gold and copper reflect red far more than blue,
  // silver and aluminium are bright and nearly neutral, and every value is inside the range the
  // scene format accepts for "eta" and "k".
  std::set<std::string_view> names;
  for (const MetalPreset& p : metal_presets()) {
    SCOPED_TRACE(std::string(p.name));
    EXPECT_TRUE(names.insert(p.name).second);
    for (int c = 0; c < 3; ++c) {
      EXPECT_GE(p.eta[c], kMinConductorEta);
      EXPECT_LE(p.eta[c], kMaxConductorIndex);
      EXPECT_GE(p.k[c], 0.0f);
      EXPECT_LE(p.k[c], kMaxConductorIndex);
      EXPECT_GT(f0(p.eta[c], p.k[c]), 0.4); // every metal here reflects > 40% at normal incidence
    }
  }
  auto r = [](const char* name, int c) {
    const MetalPreset* p = find_metal_preset(name);
    return f0(p->eta[c], p->k[c]);
  };
  EXPECT_GT(r("gold", 0), r("gold", 1));
  EXPECT_GT(r("gold", 1), r("gold", 2) + 0.2);
  EXPECT_GT(r("copper", 0), r("copper", 1) + 0.2);
  EXPECT_GT(r("copper", 1), r("copper", 2));
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(r("silver", c), 0.95);
    EXPECT_GT(r("aluminium", c), 0.88);
    EXPECT_LT(r("aluminium", c), 0.95);
  }
}

TEST(SceneLoader, Plastic) {
  Scene s = load_str(scene_with(R"("materials": [
      {"name": "p", "type": "plastic", "albedo": [0.8, 0.1, 0.2], "roughness": 0.1},
      {"name": "q", "type": "plastic", "albedo": 0.5, "specular": [0.5, 2, 0], "roughness": 1,
       "ior": 2.4},
      {"name": "default", "type": "plastic", "albedo": 0.3, "roughness": 0, "ior": 1}])"));
  ASSERT_EQ(s.materials.size(), 3u);
  const Material& p = s.materials[1].gpu;
  EXPECT_EQ(p.type, MATERIAL_PLASTIC);
  EXPECT_FLOAT_EQ(p.albedo.x, 0.8f);
  EXPECT_FLOAT_EQ(p.albedo.z, 0.2f);
  EXPECT_EQ(p.specular.x, 1.0f); // default specular 1
  EXPECT_EQ(p.specular.y, 1.0f);
  EXPECT_EQ(p.specular.z, 1.0f);
  EXPECT_FLOAT_EQ(p.alpha, 0.1f * 0.1f);
  EXPECT_EQ(p.ior, 1.5f); // default ior
  const Material& q = s.materials[2].gpu;
  EXPECT_FLOAT_EQ(q.specular.x, 0.5f);
  EXPECT_FLOAT_EQ(q.specular.y, 2.0f);
  EXPECT_EQ(q.specular.z, 0.0f);
  EXPECT_EQ(q.alpha, 1.0f);
  EXPECT_FLOAT_EQ(q.ior, 2.4f);
  // The built-in default may be replaced by a glossy material.
  EXPECT_EQ(s.materials[0].name, "default");
  EXPECT_EQ(s.materials[0].gpu.type, MATERIAL_PLASTIC);
  EXPECT_EQ(s.materials[0].gpu.alpha, 0.0f);
  EXPECT_EQ(s.materials[0].gpu.ior, 1.0f);
}

// Image textures for albedo and roughness (docs/scene-format.md, Textures): each becomes a
// TextureDesc the material refers to by 1 + its index; the file is resolved against the scene's
// directory and must exist.
TEST(SceneLoader, Textures) {
  Scene s = load_str(scene_with(R"("materials": [
      {"name": "wood", "albedo": {"texture": "textures/colours.png"}},
      {"name": "worn", "type": "plastic", "roughness": 0.2,
       "albedo": {"texture": "textures/colours.png", "scale": [0.5, 1, 2], "wrap": "clamp",
                  "encoding": "linear", "uv_scale": [2, 3], "uv_offset": [0.25, -1]}},
      {"name": "brushed", "type": "conductor", "metal": "gold",
       "roughness": {"texture": "textures/roughness.png", "scale": 0.5, "encoding": 2.2,
                     "wrap": "black"}},
      {"name": "plain", "albedo": 0.5}])"));
  ASSERT_EQ(s.textures.size(), 3u);
  const Material& wood = s.materials[1].gpu;
  EXPECT_EQ(wood.albedo_texture, 1);
  EXPECT_EQ(wood.alpha_texture, 0);
  const TextureDesc& w = s.textures[0];
  EXPECT_EQ(w.file, std::filesystem::path(CANOPY_TEST_DATA_DIR) / "textures/colours.png");
  EXPECT_EQ(w.channels, 3);
  EXPECT_EQ(w.encoding, ImageEncoding::Auto);
  EXPECT_EQ(w.wrap, TEXTURE_WRAP_REPEAT);
  EXPECT_EQ(w.map, TEXTURE_MAP_VALUE);
  EXPECT_EQ(w.scale.x, 1.0f);
  EXPECT_EQ(w.uvmap.x, 1.0f);
  EXPECT_EQ(w.uvmap.z, 0.0f);
  EXPECT_NE(w.where.find("scene.json"), std::string::npos);
  const Material& worn = s.materials[2].gpu;
  EXPECT_EQ(worn.type, MATERIAL_PLASTIC);
  EXPECT_EQ(worn.albedo_texture, 2);
  EXPECT_EQ(worn.alpha_texture, 0);
  EXPECT_FLOAT_EQ(worn.alpha, 0.04f);
  const TextureDesc& t = s.textures[1];
  EXPECT_EQ(t.scale.z, 2.0f);
  EXPECT_EQ(t.wrap, TEXTURE_WRAP_CLAMP);
  EXPECT_EQ(t.encoding, ImageEncoding::Linear);
  EXPECT_EQ(t.uvmap.x, 2.0f);
  EXPECT_EQ(t.uvmap.y, 3.0f);
  EXPECT_EQ(t.uvmap.z, 0.25f);
  EXPECT_EQ(t.uvmap.w, -1.0f);
  const Material& brushed = s.materials[3].gpu;
  EXPECT_EQ(brushed.type, MATERIAL_CONDUCTOR);
  EXPECT_EQ(brushed.albedo_texture, 0);
  EXPECT_EQ(brushed.alpha_texture, 3);
  const TextureDesc& r = s.textures[2];
  EXPECT_EQ(r.channels, 1);
  EXPECT_EQ(r.map, TEXTURE_MAP_ALPHA_SQUARE); // Canopy's roughness: alpha = r^2
  EXPECT_EQ(r.encoding, ImageEncoding::Gamma);
  EXPECT_EQ(r.gamma, 2.2f);
  EXPECT_EQ(r.scale.x, 0.5f);
  EXPECT_EQ(r.wrap, TEXTURE_WRAP_BLACK);
  EXPECT_EQ(s.materials[4].gpu.albedo_texture, 0);
}

// Quads and boxes carry uv (0, 0) at the corner, (1, 0) along edge1 and (0, 1) along edge2; an
// OBJ without vt then gets pbrt's default per triangle.
TEST(SceneLoader, QuadUv) {
  Scene s = load_str(scene_with(R"("shapes": [
      {"type": "obj", "file": "triangle.obj"},
      {"type": "quad", "corner": [0, 0, 0], "edge1": [0, 0, 1], "edge2": [1, 0, 0]}])"));
  ASSERT_EQ(s.triangle_count(), 3u);
  ASSERT_EQ(s.triangle_uvs.size(), 9u);
  const float expect[9][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 0},
                              {1, 1}, {0, 0}, {1, 1}, {0, 1}};
  for (size_t i = 0; i < 9; ++i) {
    EXPECT_EQ(s.triangle_uvs[i].x, expect[i][0]) << i;
    EXPECT_EQ(s.triangle_uvs[i].y, expect[i][1]) << i;
  }
}

TEST(SceneLoader, TextureErrors) {
  auto mat = [](const std::string& m) {
    return error_of(scene_with(R"("materials": [)" + m + "]"));
  };
  EXPECT_NE(
      mat(R"({"name": "a", "albedo": {"texture": "nope.png"}})").find("nope.png: no such file"),
      std::string::npos);
  EXPECT_NE(mat(R"({"name": "a", "albedo": {"texture": ""}})").find("must not be empty"),
            std::string::npos);
  EXPECT_NE(mat(R"({"name": "a", "albedo": {"texture": "textures/colours.png", "wrap": "mirror"}})")
                .find("wrap"),
            std::string::npos);
  EXPECT_NE(mat(R"({"name": "a", "albedo": {"texture": "textures/colours.png", "scale": -1}})")
                .find("scale"),
            std::string::npos);
  EXPECT_NE(mat(R"({"name": "a", "albedo": {"texture": "textures/colours.png", "uv_scale": 2}})")
                .find("array of 2 numbers"),
            std::string::npos);
  EXPECT_NE(mat(R"({"name": "a", "albedo": {"texture": "textures/colours.png", "filter": "x"}})")
                .find("unknown key"),
            std::string::npos);
  EXPECT_NE(mat(R"({"name": "a", "type": "conductor", "metal": "gold",
                    "roughness": {"texture": "textures/roughness.png", "scale": [1, 2, 3]}})")
                .find("scale"),
            std::string::npos);
  EXPECT_NE(mat(R"({"name": "a", "albedo": {"texture": "textures/colours.png",
                    "encoding": "rec709"}})")
                .find("encoding"),
            std::string::npos);
}

TEST(SceneLoader, PointAndSpot) {
  Scene s = load_str(scene_with("", R"([
      {"type": "point", "position": [1, 2, 3], "intensity": [4, 5, 6]},
      {"type": "spot", "position": [0, 3, 0], "direction": [0, -2, 0], "intensity": 10,
       "cone_angle": 30, "falloff_start": 20},
      {"type": "spot", "position": [0, 3, 0], "direction": [1, 0, 0], "intensity": 1,
       "cone_angle": 50}])"));
  ASSERT_EQ(s.lights.size(), 3u);
  const Light& p = s.lights[0];
  EXPECT_EQ(p.type, LIGHT_POINT);
  EXPECT_EQ(p.prim, -1);
  EXPECT_EQ(p.flags, 0);
  EXPECT_FLOAT_EQ(world(s, p.p).x, 1);
  EXPECT_FLOAT_EQ(world(s, p.p).z, 3);
  EXPECT_FLOAT_EQ(p.emission.x, 4);
  EXPECT_FLOAT_EQ(p.emission.z, 6);
  const Light& sp = s.lights[1];
  EXPECT_EQ(sp.type, LIGHT_SPOT);
  EXPECT_EQ(sp.prim, -1);
  EXPECT_FLOAT_EQ(sp.e1.x, 0);
  EXPECT_FLOAT_EQ(sp.e1.y, -1); // unit axis
  EXPECT_NEAR(sp.e1.w, std::cos(30 * kDeg), 1e-6f);
  EXPECT_NEAR(sp.e2.w, std::cos(20 * kDeg), 1e-6f);
  EXPECT_FLOAT_EQ(sp.emission.y, 10);
  // Default falloff start: 80% of the cone angle.
  EXPECT_NEAR(s.lights[2].e2.w, std::cos(40 * kDeg), 1e-6f);
}

TEST(SceneLoader, Disk) {
  Scene s = load_str(scene_with("", R"([
      {"type": "disk", "center": [1, 2, 3], "normal": [0, -3, 0], "radius": 0.5,
       "radiance": [1, 2, 3]},
      {"type": "disk", "center": [0, 1, 0], "normal": [1, 1e-30, 2], "radius": 2, "radiance": 4,
       "two_sided": true}])"));
  ASSERT_EQ(s.lights.size(), 2u);
  const Light& d = s.lights[0];
  EXPECT_EQ(d.type, LIGHT_DISK);
  EXPECT_EQ(d.prim, -1);
  EXPECT_EQ(d.flags, 0);
  EXPECT_FLOAT_EQ(world(s, d.p).x, 1);
  EXPECT_FLOAT_EQ(world(s, d.p).z, 3);
  EXPECT_FLOAT_EQ(d.p.w, 0.5f);               // radius
  EXPECT_FLOAT_EQ(d.n.y, -1);                 // unit normal
  EXPECT_FLOAT_EQ(d.n.w, float(M_PI * 0.25)); // area
  EXPECT_FLOAT_EQ(d.emission.z, 3);
  for (const Light& l : s.lights) {
    // e1, e2: an orthonormal tangent frame with e1 x e2 = n
    float3 t1 = xyz_of(l.e1), t2 = xyz_of(l.e2), n = xyz_of(l.n);
    EXPECT_NEAR(length(t1), 1.0f, 1e-6f);
    EXPECT_NEAR(length(t2), 1.0f, 1e-6f);
    EXPECT_NEAR(length(n), 1.0f, 1e-6f);
    EXPECT_NEAR(dot(t1, n), 0.0f, 1e-6f);
    EXPECT_NEAR(dot(t2, n), 0.0f, 1e-6f);
    EXPECT_NEAR(dot(t1, t2), 0.0f, 1e-6f);
    float3 c = cross(t1, t2);
    EXPECT_NEAR(dot(c, n), 1.0f, 1e-6f);
  }
  const Light& d2 = s.lights[1];
  EXPECT_EQ(d2.flags, LIGHT_FLAG_TWO_SIDED);
  EXPECT_NEAR(d2.n.x, 1.0 / std::sqrt(5.0), 1e-7);
  EXPECT_NEAR(d2.n.z, 2.0 / std::sqrt(5.0), 1e-7);
  EXPECT_FLOAT_EQ(d2.n.w, float(M_PI * 4.0));
  EXPECT_EQ(s.triangle_count(), 0u);
}

TEST(SceneLoader, SphereQuadTriangle) {
  Scene s = load_str(scene_with("", R"([
      {"type": "sphere", "center": [1, 2, 3], "radius": 0.5, "radiance": [1, 2, 3]},
      {"type": "quad", "corner": [0, 2, 0], "edge1": [2, 0, 0], "edge2": [0, 0, 3],
       "radiance": 7},
      {"type": "quad", "corner": [0, 2, 0], "edge1": [0, 0, 3], "edge2": [2, 0, 0],
       "radiance": 7, "two_sided": true},
      {"type": "triangle", "v0": [0, 0, 0], "v1": [2, 0, 0], "v2": [0, 2, 0], "radiance": 1}])"));
  ASSERT_EQ(s.lights.size(), 4u);
  const Light& sp = s.lights[0];
  EXPECT_EQ(sp.type, LIGHT_SPHERE);
  EXPECT_FLOAT_EQ(world(s, sp.p).y, 2);
  EXPECT_FLOAT_EQ(sp.p.w, 0.5f);
  EXPECT_FLOAT_EQ(sp.emission.z, 3);
  const Light& q = s.lights[1];
  EXPECT_EQ(q.type, LIGHT_QUAD);
  EXPECT_EQ(q.flags, 0);
  EXPECT_FLOAT_EQ(world(s, q.p).y, 2);
  EXPECT_FLOAT_EQ(q.e1.x, 2);
  EXPECT_FLOAT_EQ(q.e2.z, 3);
  // cross([2,0,0], [0,0,3]) = [0,-6,0]: facing down, area 6.
  EXPECT_FLOAT_EQ(q.n.x, 0);
  EXPECT_FLOAT_EQ(q.n.y, -1);
  EXPECT_FLOAT_EQ(q.n.z, 0);
  EXPECT_FLOAT_EQ(q.n.w, 6);
  const Light& q2 = s.lights[2];
  EXPECT_FLOAT_EQ(q2.n.y, 1);
  EXPECT_EQ(q2.flags, LIGHT_FLAG_TWO_SIDED);
  const Light& t = s.lights[3];
  EXPECT_EQ(t.type, LIGHT_TRIANGLE);
  EXPECT_EQ(t.prim, -1);
  EXPECT_FLOAT_EQ(t.n.z, 1);
  EXPECT_FLOAT_EQ(t.n.w, 2); // |cross| / 2
  EXPECT_FLOAT_EQ(t.e2.y, 2);
  // Analytic lights are not in the triangle soup.
  EXPECT_EQ(s.triangle_count(), 0u);
}

TEST(SceneLoader, QuadAndBoxShapes) {
  Scene s = load_str(scene_with(R"(
      "materials": [{"name": "m", "albedo": 0.3}],
      "shapes": [
        {"type": "quad", "corner": [0, 0, 0], "edge1": [0, 0, 1], "edge2": [1, 0, 0],
         "material": "m"},
        {"type": "box", "min": [-1, -2, -3], "max": [1, 2, 3]}])"));
  ASSERT_EQ(s.triangle_count(), 2u + 12u);
  EXPECT_EQ(s.triangle_material[0], 1);
  EXPECT_EQ(s.triangle_material[2], 0); // the box: default material
  for (size_t t = 0; t < 2; ++t)
    EXPECT_FLOAT_EQ(tri_normal(s, t).y, 1.0f);
  for (size_t t = 2; t < 14; ++t) {
    // Outward: the normal points away from the box centre (the origin).
    EXPECT_GT(dot(tri_normal(s, t), world(s, tri_centroid(s, t))), 0.0f) << "triangle " << t;
    EXPECT_EQ(s.triangle_light[t], -1);
  }
  EXPECT_EQ(s.vertices.size(), 4u + 24u);
}

TEST(SceneLoader, BoxRotateY) {
  Scene s = load_str(scene_with(R"("shapes": [
      {"type": "box", "min": [1, 0, -1], "max": [3, 1, 1], "rotate_y": 90}])"));
  // Rotation about the box's own vertical axis (x = 2, z = 0): x extent becomes [1.0, 3.0] in z
  // terms: the 2 x 1 x 2 box is square in xz, so its footprint stays [1,3] x [-1,1].
  for (const float3& rv : s.vertices) {
    float3 v = world(s, rv);
    EXPECT_NEAR(std::fabs(v.x - 2.0f), 1.0f, 1e-5f);
    EXPECT_NEAR(std::fabs(v.z), 1.0f, 1e-5f);
  }
}

TEST(SceneLoader, TransformOrder) {
  // scale, then rotate, then translate.
  Scene s = load_str(scene_with(R"("shapes": [
      {"type": "obj", "file": "triangle.obj",
       "transform": {"scale": 2, "rotate": {"axis": [0, 0, 1], "degrees": 90},
                     "translate": [10, 0, 0]}}])"));
  ASSERT_EQ(s.vertices.size(), 3u);
  // (1,0,0) -> (2,0,0) -> (0,2,0) -> (10,2,0)
  EXPECT_NEAR(world(s, s.vertices[1]).x, 10.0f, 1e-5f);
  EXPECT_NEAR(world(s, s.vertices[1]).y, 2.0f, 1e-5f);
  // (0,1,0) -> (0,2,0) -> (-2,0,0) -> (8,0,0)
  EXPECT_NEAR(world(s, s.vertices[2]).x, 8.0f, 1e-5f);
  EXPECT_NEAR(world(s, s.vertices[2]).y, 0.0f, 1e-5f);
}

TEST(SceneLoader, MirrorKeepsNormalMeaning) {
  // A mirroring scale swaps the winding, so the geometric normal is the transformed normal
  // (inverse transpose): the triangle's +z normal mirrored in z is -z ...
  Scene s = load_str(scene_with(R"("shapes": [
      {"type": "obj", "file": "triangle.obj", "transform": {"scale": [1, 1, -1]}}])"));
  EXPECT_FLOAT_EQ(tri_normal(s, 0).z, -1.0f);
  // ... and mirrored in x it stays +z (without the swap it would flip).
  Scene s2 = load_str(scene_with(R"("shapes": [
      {"type": "obj", "file": "triangle.obj", "transform": {"scale": [-1, 1, 1]}}])"));
  EXPECT_FLOAT_EQ(tri_normal(s2, 0).z, 1.0f);
}

TEST(SceneLoader, ObjMtlEmission) {
  Scene s = load_str(scene_with(R"("shapes": [{"type": "obj", "file": "emissive.obj"}])", "[]"));
  // 2 (quad) + 1 (degenerate) + 1 (floor) triangles
  ASSERT_EQ(s.triangle_count(), 4u);
  ASSERT_EQ(s.lights.size(), 2u); // the zero-area triangle is no light
  // materials: default, lamp, grey (named after the MTL)
  ASSERT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.materials[1].name, "lamp");
  EXPECT_EQ(s.materials[2].name, "grey");
  EXPECT_FLOAT_EQ(s.materials[2].gpu.albedo.x, 0.5f);
  EXPECT_EQ(s.triangle_material[0], 1);
  EXPECT_EQ(s.triangle_material[3], 2);
  EXPECT_EQ(s.triangle_light[0], 0);
  EXPECT_EQ(s.triangle_light[1], 1);
  EXPECT_EQ(s.triangle_light[2], -1);
  EXPECT_EQ(s.triangle_light[3], -1);
  for (int i = 0; i < 2; ++i) {
    const Light& l = s.lights[size_t(i)];
    EXPECT_EQ(l.type, LIGHT_TRIANGLE);
    EXPECT_EQ(l.flags, LIGHT_FLAG_FROM_MESH);
    EXPECT_EQ(l.prim, -1);
    EXPECT_FLOAT_EQ(l.emission.x, 5);
    EXPECT_FLOAT_EQ(l.emission.y, 4);
    EXPECT_FLOAT_EQ(l.emission.z, 3);
    EXPECT_FLOAT_EQ(l.n.w, 0.5f);
    // p = v0, e1 = v1 - v0, e2 = v2 - v0 of the triangle it belongs to
    size_t t = size_t(i);
    float3 v0 = s.vertices[s.indices[3 * t]], v1 = s.vertices[s.indices[3 * t + 1]];
    EXPECT_FLOAT_EQ(l.p.x, v0.x);
    EXPECT_FLOAT_EQ(l.e1.x, v1.x - v0.x);
    EXPECT_FLOAT_EQ(l.e1.z, v1.z - v0.z);
    float3 n = tri_normal(s, t);
    EXPECT_FLOAT_EQ(l.n.y, n.y);
  }
  // f 1 2 3 4 at y = 1 is wound clockwise seen from above: it faces down.
  EXPECT_FLOAT_EQ(s.lights[0].n.y, -1.0f);
}

TEST(SceneLoader, ObjMaterialOverrideAndSceneEmission) {
  Scene s = load_str(scene_with(R"(
      "materials": [{"name": "grey", "albedo": 0.2}, {"name": "blue", "albedo": [0, 0, 1]}],
      "shapes": [
        {"type": "obj", "file": "emissive.obj", "material": "blue"},
        {"type": "obj", "file": "emissive.obj", "emission": [1, 1, 1], "two_sided": true},
        {"type": "quad", "corner": [0, 5, 0], "edge1": [1, 0, 0], "edge2": [0, 0, 1],
         "emission": 2}])",
                                "[]"));
  ASSERT_EQ(s.triangle_count(), 4u + 4u + 2u);
  // Override: every triangle "blue" (index 2), but Ke still makes the lamp emit.
  for (size_t t = 0; t < 4; ++t)
    EXPECT_EQ(s.triangle_material[t], 2);
  // No override: the scene's "grey" wins over the MTL's grey; "lamp" comes from the MTL.
  EXPECT_EQ(s.triangle_material[7], 1);
  EXPECT_EQ(s.materials[size_t(s.triangle_material[4])].name, "lamp");
  // emission in the scene: every non-degenerate triangle of the second OBJ emits 1, two-sided.
  EXPECT_EQ(s.lights.size(), 2u + 3u + 2u);
  const Light& l = s.lights[2];
  EXPECT_FLOAT_EQ(l.emission.x, 1.0f);
  EXPECT_EQ(l.flags, LIGHT_FLAG_FROM_MESH | LIGHT_FLAG_TWO_SIDED);
  EXPECT_EQ(s.triangle_light[7], 4); // the floor triangle of the second OBJ
  EXPECT_FLOAT_EQ(s.lights.back().emission.y, 2.0f);
  EXPECT_EQ(s.triangle_light[9], 6);
}

TEST(SceneLoader, MtlMapping) {
  // tests/data/glossy.mtl: one material per case, one triangle each, in order.
  Scene s = load_str(scene_with(R"("shapes": [{"type": "obj", "file": "glossy.obj"}])"));
  ASSERT_EQ(s.triangle_count(), 6u);
  auto mat = [&](size_t t) -> const MaterialDesc& {
    return s.materials[size_t(s.triangle_material[t])];
  };
  // Roughness from Ns: alpha = sqrt(2 / (Ns + 2)) (Walter et al. 2007, eq. 33), r = sqrt(alpha).
  auto alpha_of_ns = [](double ns) { return std::sqrt(2.0 / (ns + 2.0)); };

  // illum 1: diffuse Kd, Ks ignored.
  EXPECT_EQ(mat(0).name, "matte_illum1");
  EXPECT_EQ(mat(0).gpu.type, MATERIAL_DIFFUSE);
  EXPECT_FLOAT_EQ(mat(0).gpu.albedo.x, 0.5f);
  // illum 2 with Ks = 0: diffuse.
  EXPECT_EQ(mat(1).gpu.type, MATERIAL_DIFFUSE);
  EXPECT_FLOAT_EQ(mat(1).gpu.albedo.z, 0.4f);
  // illum 2, Ks > 0: plastic with albedo Kd, specular Ks, roughness of Ns, ior Ni.
  const Material& shiny = mat(2).gpu;
  EXPECT_EQ(mat(2).name, "shiny");
  EXPECT_EQ(shiny.type, MATERIAL_PLASTIC);
  EXPECT_FLOAT_EQ(shiny.albedo.y, 0.2f);
  EXPECT_FLOAT_EQ(shiny.specular.x, 0.04f);
  EXPECT_FLOAT_EQ(shiny.specular.z, 0.06f);
  EXPECT_NEAR(shiny.alpha, alpha_of_ns(98), 1e-6);
  EXPECT_NEAR(shiny.alpha, 0.1414214, 1e-6); // sqrt(2/100)
  EXPECT_FLOAT_EQ(shiny.ior, 1.45f);
  // Ns 0: roughness 1; no Ni: ior 1.5.
  const Material& rough = mat(3).gpu;
  EXPECT_EQ(rough.type, MATERIAL_PLASTIC);
  EXPECT_NEAR(rough.alpha, 1.0, 1e-6);
  EXPECT_EQ(rough.ior, 1.5f);
  EXPECT_FLOAT_EQ(rough.specular.y, 1.0f);
  // illum 3 is plastic too; Ni 1 (MTL's "unset") gives 1.5.
  const Material& mirror = mat(4).gpu;
  EXPECT_EQ(mirror.type, MATERIAL_PLASTIC);
  EXPECT_NEAR(mirror.alpha, alpha_of_ns(1000), 1e-6);
  EXPECT_EQ(mirror.ior, 1.5f);
  EXPECT_EQ(mirror.albedo.x, 0.0f);
  // No illum line (illum 0): diffuse even with Ks.
  EXPECT_EQ(mat(5).gpu.type, MATERIAL_DIFFUSE);
  EXPECT_FLOAT_EQ(mat(5).gpu.albedo.x, 0.7f);
}

TEST(SceneLoader, SceneMaterialReplacesMtlMaterial) {
  // A scene material named like an MTL material wins, of any type: how a scene makes an OBJ's
  // material a metal.
  Scene s = load_str(scene_with(R"("materials": [{"name": "mirror_like", "type": "conductor",
      "roughness": 0, "metal": "silver"}], "shapes": [{"type": "obj", "file": "glossy.obj"}])"));
  EXPECT_EQ(s.triangle_material[4], 1);
  EXPECT_EQ(s.materials[1].gpu.type, MATERIAL_CONDUCTOR);
}

TEST(SceneLoader, SceneFileRelativePaths) {
  // load_scene resolves OBJ paths against the scene file's directory.
  Scene s = load_scene(std::filesystem::path(CANOPY_TEST_DATA_DIR) / "good_obj_scene.json");
  EXPECT_EQ(s.triangle_count(), 4u);
  EXPECT_EQ(s.lights.size(), 2u);
}

TEST(SceneLoader, Medium) {
  const std::string head = R"({"camera": {"position": [0, 1, 5], "look_at": [0, 0, 0]},
    "lights": [{"type": "point", "position": [0, 2, 0], "intensity": 1}], )";
  Scene s = load_str(head + R"("medium": {"sigma_a": [0.1, 0.2, 0.3], "sigma_s": 0.5, "g": -0.4,
    "bounds": {"min": [-1, -2, -3], "max": [1, 2, 3]}}})");
  ASSERT_TRUE(s.has_medium);
  EXPECT_FLOAT_EQ(s.medium.sigma_t.x, 0.6f); // sigma_a + sigma_s
  EXPECT_FLOAT_EQ(s.medium.sigma_t.y, 0.7f);
  EXPECT_FLOAT_EQ(s.medium.sigma_t.z, 0.8f);
  EXPECT_FLOAT_EQ(s.medium.sigma_t.w, -0.4f); // g
  EXPECT_FLOAT_EQ(s.medium.sigma_s.y, 0.5f);
  EXPECT_EQ(s.medium.sigma_s.w, 1.0f); // bounded
  EXPECT_FLOAT_EQ(world(s, s.medium.bmin).z, -3.0f);
  EXPECT_FLOAT_EQ(world(s, s.medium.bmax).y, 2.0f);
  EXPECT_EQ(s.integrator.volume_importance, "segment");

  Scene u = load_str(head + R"("medium": {"sigma_a": 0, "sigma_s": [0, 0.1, 0]},
    "integrator": {"volume_importance": "midpoint"}})");
  ASSERT_TRUE(u.has_medium);
  EXPECT_EQ(u.medium.sigma_s.w, 0.0f);       // fills all space
  EXPECT_FLOAT_EQ(u.medium.sigma_t.w, 0.0f); // g defaults to isotropic
  EXPECT_EQ(u.integrator.volume_importance, "midpoint");

  // sigma_t = 0: vacuum, no medium at all
  EXPECT_FALSE(load_str(head + R"("medium": {"sigma_a": 0, "sigma_s": 0}})").has_medium);
  EXPECT_FALSE(load_str(head.substr(0, head.size() - 2) + "}").has_medium);
}

// Far from the origin (issue 20): every coordinate is stored relative to the camera position,
// subtracted in double before the rounding to float, so it keeps the precision of its distance
// from the camera. At 1e6, float world coordinates would be 1/16 apart.
TEST(SceneLoader, RebasesEveryCoordinateToTheCamera) {
  const double T[3] = {1e6, -2e5, 3e6};
  auto v = [&](double x, double y, double z) {
    return fmt::format("[{:.17g}, {:.17g}, {:.17g}]", T[0] + x, T[1] + y, T[2] + z);
  };
  Scene s = load_str(fmt::format(
      R"({{"camera": {{"position": {}, "look_at": {}}},
    "medium": {{"sigma_a": 0.1, "sigma_s": 0, "bounds": {{"min": {}, "max": {}}}}},
    "shapes": [
      {{"type": "quad", "corner": {}, "edge1": [0.2, 0, 0], "edge2": [0, 0, 0.3]}},
      {{"type": "box", "min": {}, "max": {}}},
      {{"type": "obj", "file": "triangle.obj", "transform": {{"translate": {}}}}}],
    "lights": [
      {{"type": "point", "position": {}, "intensity": 1}},
      {{"type": "sphere", "center": {}, "radius": 0.05, "radiance": 1}},
      {{"type": "triangle", "v0": {}, "v1": {}, "v2": {}, "radiance": 1}}],
    "light_sets": [{{"type": "grid", "origin": {}, "edge1": [0.2, 0, 0], "edge2": [0, 0, 0.2],
      "nx": 1, "ny": 1, "light": {{"type": "point", "intensity": 1}},
      "instance": {{"type": "quad", "corner": [-0.05, 0, -0.05], "edge1": [0.1, 0, 0],
                    "edge2": [0, 0, 0.1]}}}}]}})",
      v(0.3, 1.7, 5.1), v(0.3, 0.7, 0.1), v(-0.13, -0.17, -0.19), v(0.23, 0.29, 0.31),
      v(0.1, 0.3, 0.7), v(-0.33, 0.11, 0.21), v(-0.13, 0.37, 0.43), v(0.17, 0.19, 0.23),
      v(0.43, 1.1, 0.7), v(-0.3, 0.9, 0.3), v(0.1, 0.1, 0.1), v(0.3, 0.1, 0.1), v(0.1, 0.1, 0.4),
      v(0.7, 1.3, 0.9)));
  EXPECT_EQ(s.origin.x, T[0] + 0.3);
  EXPECT_EQ(s.origin.y, T[1] + 1.7);
  EXPECT_EQ(s.origin.z, T[2] + 5.1);
  EXPECT_EQ(s.camera.position.x, 0.0f);
  // Relative to the camera at (0.3, 1.7, 5.1) + T; a float error of 1e-6 is the rounding of a
  // coordinate of a few units.
  auto expect_at = [&](float3 got, double x, double y, double z, const char* what) {
    EXPECT_NEAR(got.x, x - 0.3, 1e-6) << what;
    EXPECT_NEAR(got.y, y - 1.7, 1e-6) << what;
    EXPECT_NEAR(got.z, z - 5.1, 1e-6) << what;
  };
  expect_at(s.camera.look_at, 0.3, 0.7, 0.1, "look_at");
  expect_at(xyz_of(s.medium.bmin), -0.13, -0.17, -0.19, "medium min");
  expect_at(xyz_of(s.medium.bmax), 0.23, 0.29, 0.31, "medium max");
  ASSERT_EQ(s.vertices.size(), 4u + 24u + 3u + 4u);
  expect_at(s.vertices[0], 0.1, 0.3, 0.7, "quad corner");
  expect_at(s.vertices[2], 0.3, 0.3, 1.0, "quad corner + edges");
  float3 lo = s.vertices[4], hi = s.vertices[4];
  for (size_t i = 4; i < 28; ++i) {
    lo = fmin(lo, s.vertices[i]);
    hi = fmax(hi, s.vertices[i]);
  }
  expect_at(lo, -0.33, 0.11, 0.21, "box min");
  expect_at(hi, -0.13, 0.37, 0.43, "box max");
  expect_at(s.vertices[29], 1.17, 0.19, 0.23, "obj vertex (1, 0, 0) translated");
  expect_at(s.vertices[31], 0.75, 1.3, 0.95, "light-set instance corner");
  ASSERT_EQ(s.lights.size(), 4u);
  expect_at(xyz_of(s.lights[0].p), 0.43, 1.1, 0.7, "point light");
  expect_at(xyz_of(s.lights[1].p), -0.3, 0.9, 0.3, "sphere light");
  expect_at(xyz_of(s.lights[2].p), 0.1, 0.1, 0.1, "triangle light v0");
  EXPECT_NEAR(s.lights[2].e1.x, 0.2, 1e-7);
  EXPECT_NEAR(s.lights[2].e2.z, 0.3, 1e-7);
  EXPECT_NEAR(s.lights[2].n.w, 0.03, 1e-7); // area
  expect_at(xyz_of(s.lights[3].p), 0.8, 1.3, 1.0, "light-set site");
}
