// The mix and diffuse-transmission materials and the checkerboard, mix and scale textures in the
// pbrt-v4 reader and the JSON loader: each becomes the Scene entities stated (materials with their
// indices and amounts, texture trees in postfix order with their constants and uv mappings), and
// each bad parameter is a one-line error naming file:line (pbrt) or the JSON path.
#include "scene/scene.h"

#include "support/pbrt_text.h"

#include <gtest/gtest.h>

#include <string>

using namespace canopy;

namespace {

const std::string& kHead = test::kPbrtHead;
const std::string& kTri = test::kPbrtTriangle;

const Material& material_of(const Scene& s, size_t tri) {
  return s.materials[size_t(s.triangle_material[tri])].gpu;
}

void expect_one_line(const std::string& msg, const std::string& start, const std::string& part) {
  EXPECT_EQ(msg.rfind(start, 0), 0u) << msg;
  EXPECT_NE(msg.find(part), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
}

std::string json_error_of(const std::string& materials, const std::string& shape_material) {
  const std::string text =
      R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]}, "materials": )" + materials +
      R"(, "shapes": [{"type": "quad", "material": ")" + shape_material +
      R"(", "corner": [-1, -1, 0], "edge1": [2, 0, 0], "edge2": [0, 2, 0]}]})";
  try {
    load_scene_from_string(text, "m.json", ".");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

Scene load_json(const std::string& materials) {
  const std::string text =
      R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]}, "materials": )" + materials +
      R"(, "shapes": [{"type": "quad", "material": "m", "corner": [-1, -1, 0], "edge1": [2, 0, 0],
          "edge2": [0, 2, 0]}]})";
  return load_scene_from_string(text, "m.json", ".");
}

} // namespace

// ---------------------------------------------------------------- pbrt-v4: mix
TEST(SceneMixPbrt, MixRefersToItsTwoNamedMaterialsWithItsAmount) {
  Scene s = test::load_pbrt(
      kHead +
      "MakeNamedMaterial \"a\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.1 0.2 0.3]\n" +
      "MakeNamedMaterial \"b\" \"string type\" \"conductor\" \"float roughness\" 0.1\n" +
      "Material \"mix\" \"string materials\" [\"a\" \"b\"] \"float amount\" 0.3\n" + kTri +
      "MakeNamedMaterial \"ab\" \"string type\" \"mix\" \"string materials\" [\"b\" \"a\"]\n" +
      "Material \"mix\" \"string materials\" [\"ab\" \"a\"] \"float amount\" 0.75\n" + kTri);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const Material& m = material_of(s, 0);
  ASSERT_EQ(m.type, MATERIAL_MIX);
  EXPECT_FLOAT_EQ(m.mix_amount, 0.3f);
  EXPECT_EQ(m.mix_amount_texture, 0);
  EXPECT_EQ(s.materials[size_t(m.mix_material[0])].gpu.type, MATERIAL_DIFFUSE);
  EXPECT_FLOAT_EQ(s.materials[size_t(m.mix_material[0])].gpu.albedo.y, 0.2f);
  EXPECT_EQ(s.materials[size_t(m.mix_material[1])].gpu.type, MATERIAL_CONDUCTOR);
  // Nested: the inner mix keeps pbrt-v4's default amount 0.5.
  const Material& n = material_of(s, 1);
  ASSERT_EQ(n.type, MATERIAL_MIX);
  EXPECT_FLOAT_EQ(n.mix_amount, 0.75f);
  const Material& inner = s.materials[size_t(n.mix_material[0])].gpu;
  ASSERT_EQ(inner.type, MATERIAL_MIX);
  EXPECT_FLOAT_EQ(inner.mix_amount, 0.5f);
  EXPECT_EQ(inner.mix_material[0], m.mix_material[1]);
  EXPECT_EQ(mix_depth(s.materials, s.triangle_material[1]), 2);
}

TEST(SceneMixPbrt, TexturedAmountIsAFloatTexture) {
  Scene s = test::load_pbrt(
      kHead + "MakeNamedMaterial \"a\" \"string type\" \"diffuse\"\n" +
      "MakeNamedMaterial \"b\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.9 0.9 0.9]\n" +
      "Texture \"amt\" \"float\" \"checkerboard\" \"float uscale\" 4 \"float tex1\" 0.2 "
      "\"float tex2\" 0.6\n" +
      "Material \"mix\" \"string materials\" [\"a\" \"b\"] \"texture amount\" \"amt\"\n" + kTri);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const Material& m = material_of(s, 0);
  ASSERT_EQ(m.mix_amount_texture, 3); // constants 0.2, 0.6, then the checkerboard
  ASSERT_EQ(s.textures.size(), 3u);
  EXPECT_EQ(s.textures[0].kind, TEXTURE_CONSTANT);
  EXPECT_FLOAT_EQ(s.textures[0].scale.x, 0.2f);
  EXPECT_FLOAT_EQ(s.textures[1].scale.x, 0.6f);
  EXPECT_EQ(s.textures[2].kind, TEXTURE_CHECKERBOARD);
  EXPECT_EQ(s.textures[2].nodes, 3);
  EXPECT_FLOAT_EQ(s.textures[2].uvmap.x, 4.0f);
  EXPECT_TRUE(material_textured(m));
}

TEST(SceneMixPbrt, BadMixesAreOneLineErrorsNamingFileAndLine) {
  const std::string a = "MakeNamedMaterial \"a\" \"string type\" \"diffuse\"\n";
  expect_one_line(test::pbrt_error_of(kHead + a + "Material \"mix\" \"string materials\" \"a\"\n"),
                  "t.pbrt:6: ", "needs \"string materials\" with two material names");
  expect_one_line(test::pbrt_error_of(kHead + a + "Material \"mix\"\n"),
                  "t.pbrt:6: ", "needs \"string materials\"");
  expect_one_line(
      test::pbrt_error_of(kHead + a + "Material \"mix\" \"string materials\" [\"a\" \"nope\"]\n"),
      "t.pbrt:6: ", "no material named \"nope\"");
  expect_one_line(test::pbrt_error_of(kHead + a +
                                      "MakeNamedMaterial \"i\" \"string type\" \"interface\"\n" +
                                      "Material \"mix\" \"string materials\" [\"a\" \"i\"]\n"),
                  "t.pbrt:7: ", "\"i\" is an interface");
  // Nested deeper than the device resolves.
  std::string deep = kHead + a + "MakeNamedMaterial \"m0\" \"string type\" \"diffuse\"\n";
  for (int i = 1; i <= MATERIAL_MIX_MAX_DEPTH + 1; ++i)
    deep += "MakeNamedMaterial \"m" + std::to_string(i) +
            "\" \"string type\" \"mix\" \"string materials\" [\"a\" \"m" + std::to_string(i - 1) +
            "\"]\n";
  expect_one_line(test::pbrt_error_of(deep), "t.pbrt:" + std::to_string(7 + MATERIAL_MIX_MAX_DEPTH),
                  "mixes nested more than");
  // An unknown parameter is a warning naming its line.
  Scene s = test::load_pbrt(kHead + a +
                            "Material \"mix\" \"string materials\" [\"a\" \"a\"]\n"
                            "  \"float wobble\" 2\n" +
                            kTri);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].rfind("t.pbrt:7: ", 0), 0u) << s.warnings[0];
}

// ---------------------------------------------------------------- pbrt-v4: diffuse transmission
TEST(SceneMixPbrt, DiffuseTransmissionScalesAndClampsItsReflectances) {
  Scene s = test::load_pbrt(
      kHead + "Material \"diffusetransmission\"\n" + kTri +
      "Material \"diffusetransmission\" \"rgb reflectance\" [0.2 0.4 0.6] \"rgb transmittance\" "
      "[0.5 0.1 0.3] \"float scale\" 2\n" +
      kTri);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const Material& d = material_of(s, 0); // pbrt-v4's defaults: 0.25 and 0.25
  ASSERT_EQ(d.type, MATERIAL_DIFFUSE_TRANSMISSION);
  EXPECT_FLOAT_EQ(d.albedo.x, 0.25f);
  EXPECT_FLOAT_EQ(d.specular.z, 0.25f);
  const Material& m = material_of(s, 1);
  EXPECT_FLOAT_EQ(m.albedo.x, 0.4f);
  EXPECT_FLOAT_EQ(m.albedo.y, 0.8f);
  EXPECT_FLOAT_EQ(m.albedo.z, 1.0f); // 1.2 clamped
  EXPECT_FLOAT_EQ(m.specular.x, 1.0f);
  EXPECT_FLOAT_EQ(m.specular.y, 0.2f);
  EXPECT_FLOAT_EQ(m.specular.z, 0.6f);
}

TEST(SceneMixPbrt, DiffuseTransmissionTexturesTakeTheScale) {
  Scene s = test::load_pbrt(
      kHead +
      "Texture \"c\" \"spectrum\" \"checkerboard\" \"rgb tex1\" [0.2 0.2 0.2] \"rgb tex2\" [0.4 "
      "0.4 0.4]\n" +
      "Material \"diffusetransmission\" \"texture transmittance\" \"c\" \"float scale\" 0.5\n" +
      kTri);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  const Material& m = material_of(s, 0);
  EXPECT_EQ(m.albedo_texture, 0);
  EXPECT_FLOAT_EQ(m.albedo.x, 0.125f);
  ASSERT_EQ(m.transmittance_texture, 5); // 0.2, 0.4, checkerboard, 0.5, scale
  ASSERT_EQ(s.textures.size(), 5u);
  EXPECT_EQ(s.textures[4].kind, TEXTURE_SCALE);
  EXPECT_EQ(s.textures[4].nodes, 5);
  EXPECT_EQ(s.textures[3].kind, TEXTURE_CONSTANT);
  EXPECT_FLOAT_EQ(s.textures[3].scale.x, 0.5f);
  EXPECT_EQ(s.textures[2].kind, TEXTURE_CHECKERBOARD);
  EXPECT_EQ(s.textures[2].nodes, 3);
  expect_one_line(
      test::pbrt_error_of(kHead + "Material \"diffusetransmission\" \"float scale\" -1\n" + kTri),
      "t.pbrt:5: ", "\"float scale\": must be >= 0");
}

// ---------------------------------------------------------------- pbrt-v4: textures
TEST(SceneMixPbrt, CheckerboardMixAndScaleBecomeTextureTrees) {
  Scene s = test::load_pbrt(
      kHead +
      "Texture \"wood\" \"spectrum\" \"imagemap\" \"string filename\" \"textures/checker.png\"\n" +
      "Texture \"c\" \"spectrum\" \"checkerboard\" \"float uscale\" 8 \"float vscale\" 2 "
      "\"float udelta\" 0.5 \"float vdelta\" 0.25 \"texture tex1\" \"wood\" \"rgb tex2\" [0.1 0.2 "
      "0.3]\n" +
      "Texture \"a\" \"float\" \"constant\" \"float value\" 0.25\n" +
      "Texture \"m\" \"spectrum\" \"mix\" \"texture tex1\" \"c\" \"texture amount\" \"a\"\n" +
      "Texture \"r\" \"float\" \"imagemap\" \"string filename\" \"textures/rough.png\"\n" +
      "Texture \"s\" \"spectrum\" \"scale\" \"texture tex\" \"m\" \"texture scale\" \"r\"\n" +
      "Material \"diffuse\" \"texture reflectance\" \"s\"\n" + kTri +
      // Constants fold: a mix of constants is a constant.
      "Texture \"k\" \"spectrum\" \"mix\" \"rgb tex1\" [0 0 0] \"rgb tex2\" [0.8 0.4 0.2]\n" +
      "Material \"diffuse\" \"texture reflectance\" \"k\"\n" + kTri);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  // s = scale(mix(checkerboard(wood, [0.1 0.2 0.3]), default tex2 1, amount 0.25), r), postfix:
  // wood, const, checkerboard, const 1, const 0.25, mix, r, scale.
  ASSERT_EQ(s.textures.size(), 8u);
  const int kinds[8] = {TEXTURE_IMAGE,    TEXTURE_CONSTANT, TEXTURE_CHECKERBOARD, TEXTURE_CONSTANT,
                        TEXTURE_CONSTANT, TEXTURE_MIX,      TEXTURE_IMAGE,        TEXTURE_SCALE};
  const int nodes[8] = {1, 1, 3, 1, 1, 6, 1, 8};
  for (int i = 0; i < 8; ++i) {
    EXPECT_EQ(s.textures[size_t(i)].kind, kinds[i]) << i;
    EXPECT_EQ(s.textures[size_t(i)].nodes, nodes[i]) << i;
  }
  EXPECT_EQ(s.textures[0].channels, 3);
  EXPECT_EQ(s.textures[6].channels, 1); // a float input: one channel
  EXPECT_FLOAT_EQ(s.textures[1].scale.z, 0.3f);
  EXPECT_FLOAT_EQ(s.textures[3].scale.x, 1.0f);
  EXPECT_FLOAT_EQ(s.textures[4].scale.x, 0.25f);
  const float4 uv = s.textures[2].uvmap;
  EXPECT_FLOAT_EQ(uv.x, 8.0f);
  EXPECT_FLOAT_EQ(uv.y, 2.0f);
  EXPECT_FLOAT_EQ(uv.z, 0.5f);
  EXPECT_FLOAT_EQ(uv.w, 0.25f);
  EXPECT_EQ(material_of(s, 0).albedo_texture, 8);
  const Material& k = material_of(s, 1);
  EXPECT_EQ(k.albedo_texture, 0);
  EXPECT_FLOAT_EQ(k.albedo.x, 0.4f);
  EXPECT_FLOAT_EQ(k.albedo.y, 0.2f);
}

TEST(SceneMixPbrt, ThreeDimensionalCheckerboardWarnsAndBadOnesFail) {
  Scene s = test::load_pbrt(
      kHead + "Texture \"c\" \"spectrum\" \"checkerboard\" \"integer dimension\" 3\n" +
      "Material \"diffuse\" \"texture reflectance\" \"c\"\n" + kTri);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].rfind("t.pbrt:5: ", 0), 0u) << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("3D checkerboard"), std::string::npos) << s.warnings[0];
  EXPECT_TRUE(s.textures.empty());
  EXPECT_FLOAT_EQ(material_of(s, 0).albedo.x, 0.5f);
  expect_one_line(test::pbrt_error_of(kHead + "Texture \"c\" \"spectrum\" \"checkerboard\" "
                                              "\"integer dimension\" 4\n"),
                  "t.pbrt:5: ", "a checkerboard has 2 or 3 dimensions");
  expect_one_line(test::pbrt_error_of(kHead + "Texture \"c\" \"spectrum\" \"mix\" "
                                              "\"texture tex1\" \"nope\"\n"),
                  "t.pbrt:5: ", "no spectrum texture named \"nope\"");
  // An amount is a float texture.
  expect_one_line(
      test::pbrt_error_of(kHead + "Texture \"c\" \"spectrum\" \"constant\"\n" +
                          "Texture \"m\" \"spectrum\" \"mix\" \"texture amount\" \"c\"\n"),
      "t.pbrt:6: ", "(\"c\" is a spectrum texture)");
  // Trees deeper than the device's evaluation stack.
  std::string deep = kHead + "Texture \"t0\" \"float\" \"constant\"\n";
  for (int i = 1; i <= TEXTURE_STACK; ++i)
    deep += "Texture \"t" + std::to_string(i) +
            "\" \"float\" \"checkerboard\" \"float tex1\" 0.5 \"texture tex2\" \"t" +
            std::to_string(i - 1) + "\"\n";
  expect_one_line(test::pbrt_error_of(deep), "t.pbrt:" + std::to_string(5 + TEXTURE_STACK),
                  "nested too deeply");
}

// ---------------------------------------------------------------- JSON
TEST(SceneMixJson, MixDiffuseTransmissionAndTextureTrees) {
  Scene s = load_json(R"([
    {"name": "a", "albedo": [0.2, 0.3, 0.4]},
    {"name": "t", "type": "diffuse_transmission", "albedo": 0.3,
     "transmittance": {"type": "checkerboard", "tex1": 0.1, "tex2": [0.5, 0.6, 0.7],
                       "uv_scale": [4, 2], "uv_offset": [0.5, 0]}},
    {"name": "m", "type": "mix", "materials": ["a", "t"],
     "amount": {"type": "mix", "tex1": 0.2, "tex2": 0.8,
                "amount": {"type": "scale", "tex": 0.5, "scale": 2}}}])");
  const Material& m = material_of(s, 0);
  ASSERT_EQ(m.type, MATERIAL_MIX);
  const Material& a = s.materials[size_t(m.mix_material[0])].gpu;
  const Material& t = s.materials[size_t(m.mix_material[1])].gpu;
  EXPECT_EQ(a.type, MATERIAL_DIFFUSE);
  ASSERT_EQ(t.type, MATERIAL_DIFFUSE_TRANSMISSION);
  EXPECT_FLOAT_EQ(t.albedo.x, 0.3f);
  ASSERT_EQ(t.transmittance_texture, 3);
  EXPECT_EQ(s.textures[2].kind, TEXTURE_CHECKERBOARD);
  EXPECT_FLOAT_EQ(s.textures[2].uvmap.x, 4.0f);
  EXPECT_FLOAT_EQ(s.textures[2].uvmap.z, 0.5f);
  EXPECT_FLOAT_EQ(s.textures[1].scale.y, 0.6f);
  // amount: 0.2, 0.8, (0.5, 2, scale), mix
  ASSERT_EQ(m.mix_amount_texture, 3 + 6);
  EXPECT_EQ(s.textures[7].kind, TEXTURE_SCALE);
  EXPECT_EQ(s.textures[8].kind, TEXTURE_MIX);
  EXPECT_EQ(s.textures[8].nodes, 6);
}

TEST(SceneMixJson, BadMixesAndTexturesNameTheirJsonPath) {
  const std::string a = R"({"name": "a", "albedo": 0.5})";
  expect_one_line(
      json_error_of("[" + a + R"(, {"name": "m", "type": "mix", "materials": ["a"]}])", "m"),
      "m.json: materials[1].materials", "must be an array of 2 material names");
  expect_one_line(
      json_error_of("[" + a + R"(, {"name": "m", "type": "mix", "materials": ["a", "b"]}])", "m"),
      "m.json: materials[1].materials[1]", "unknown material \"b\"");
  expect_one_line(json_error_of("[" + a + R"(, {"name": "m", "type": "mix", "materials": ["a", "a"],
                                  "amount": 1.5}])",
                                "m"),
                  "m.json: materials[1].amount", "");
  expect_one_line(json_error_of(R"([{"name": "m", "type": "diffuse_transmission", "albedo": 0.6,
                                     "transmittance": 0.6}])",
                                "m"),
                  "m.json: materials[0]", "at most 1");
  expect_one_line(
      json_error_of(R"([{"name": "m", "albedo": {"type": "checkerboard", "tex1": 0.5}}])", "m"),
      "m.json: materials[0].albedo", "tex2");
  expect_one_line(json_error_of(R"([{"name": "m", "albedo": {"type": "plaid"}}])", "m"),
                  "m.json: materials[0].albedo.type", "");
}
