// Image textures and texture coordinates in the loaders other than JSON:
// pbrt-v4 Texture directives and texture-valued material parameters, uv of pbrt shapes
// (trianglemesh, bilinearmesh, plymesh, the tessellated sphere and disk), OBJ vt and MTL map_Kd.
// Checked are the TextureDesc fields, the materials' texture indices and Scene::triangle_uvs (exact
// values), and the warnings and errors (one line naming file:line).
#include "scene/pbrt_reader.h"
#include "scene/scene.h"

#include "support/pbrt_text.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace canopy;

namespace {

const std::filesystem::path& kData = test::kPbrtData;
const std::filesystem::path kChecker = kData / "textures" / "checker.png";
const std::filesystem::path kRough = kData / "textures" / "rough.png";

Scene load(const std::string& text, bool strict = false) {
  return test::load_pbrt(text, strict);
}

std::string error_of(const std::string& text, bool strict = false) {
  return test::pbrt_error_of(text, strict);
}

const std::string& kHead = test::kPbrtHead;
const std::string& kTri = test::kPbrtTriangle;

const std::string kWood =
    "Texture \"wood\" \"spectrum\" \"imagemap\" \"string filename\" \"textures/checker.png\"\n";
const std::string kRoughTex =
    "Texture \"r\" \"float\" \"imagemap\" \"string filename\" \"textures/rough.png\"\n";

// The uv tests put a triangle without uv first, so each also checks that a mesh with uv after one
// without gets its own (and the earlier one the default): triangle kLead is the first one tested.
// FirstMeshOfTheSceneKeepsItsUv covers a first mesh with uv.
const std::string kLeadTri =
    "Shape \"trianglemesh\" \"point3 P\" [0 0 -1  1 0 -1  0 1 -1] \"integer indices\" [0 1 2]\n";
constexpr size_t kLead = 1;

const Material& material_of(const Scene& s, size_t tri) {
  return s.materials[size_t(s.triangle_material[tri])].gpu;
}

void expect_uv(const Scene& s, size_t tri, std::vector<float> want) {
  ASSERT_GE(s.triangle_uvs.size(), 3 * tri + 3);
  for (int k = 0; k < 3; ++k) {
    EXPECT_FLOAT_EQ(s.triangle_uvs[3 * tri + size_t(k)].x, want[size_t(2 * k)])
        << "triangle " << tri << " vertex " << k;
    EXPECT_FLOAT_EQ(s.triangle_uvs[3 * tri + size_t(k)].y, want[size_t(2 * k + 1)])
        << "triangle " << tri << " vertex " << k;
  }
}

// A per-test temporary directory, removed at the end.
struct TempDir {
  std::filesystem::path dir;
  explicit TempDir(const std::string& name) {
    dir = std::filesystem::temp_directory_path() /
          ("canopy-test-textures-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    std::ofstream(dir / name, std::ios::binary) << text;
    return dir / name;
  }
};

} // namespace

// ---------------------------------------------------------------------------- pbrt Texture

TEST(SceneTexturesPbrt, ImagemapFieldsAndTheMaterialsIndex) {
  Scene s = load(
      kHead +
      "Texture \"wood\" \"spectrum\" \"imagemap\" \"string filename\" \"textures/checker.png\"\n"
      "  \"string wrap\" \"clamp\" \"float scale\" 0.5 \"string encoding\" \"gamma 2.2\"\n"
      "  \"float uscale\" 2 \"float vscale\" 3 \"float udelta\" 0.25 \"float vdelta\" -0.5 "
      "\"string filter\" \"bilinear\" \"float maxanisotropy\" 4\n"
      "Material \"diffuse\" \"texture reflectance\" \"wood\"\n" +
      kTri);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  ASSERT_EQ(s.textures.size(), 1u);
  const TextureDesc& t = s.textures[0];
  EXPECT_EQ(t.file, kChecker);
  EXPECT_EQ(t.where, "t.pbrt:5: texture \"wood\"");
  EXPECT_EQ(t.channels, 3);
  EXPECT_EQ(t.encoding, ImageEncoding::Gamma);
  EXPECT_FLOAT_EQ(t.gamma, 2.2f);
  EXPECT_FLOAT_EQ(t.scale.x, 0.5f);
  EXPECT_FLOAT_EQ(t.scale.y, 0.5f);
  EXPECT_FLOAT_EQ(t.scale.z, 0.5f);
  EXPECT_FLOAT_EQ(t.uvmap.x, 2.0f);
  EXPECT_FLOAT_EQ(t.uvmap.y, 3.0f);
  EXPECT_FLOAT_EQ(t.uvmap.z, 0.25f);
  EXPECT_FLOAT_EQ(t.uvmap.w, -0.5f);
  EXPECT_EQ(t.wrap, TEXTURE_WRAP_CLAMP);
  EXPECT_EQ(t.map, TEXTURE_MAP_VALUE);
  const Material& m = material_of(s, 0);
  EXPECT_EQ(m.type, MATERIAL_DIFFUSE);
  EXPECT_EQ(m.albedo_texture, 1);
  EXPECT_EQ(m.alpha_texture, 0);
}

TEST(SceneTexturesPbrt, DefaultsWrapModesAndEncodings) {
  Scene s =
      load(kHead + kWood +
           "Texture \"b\" \"spectrum\" \"imagemap\" \"string filename\" \"textures/checker.png\" "
           "\"string wrap\" \"black\" \"string encoding\" \"sRGB\"\n"
           "Texture \"l\" \"spectrum\" \"imagemap\" \"string filename\" \"textures/checker.png\" "
           "\"string wrap\" \"repeat\" \"string encoding\" \"linear\"\n"
           "Material \"diffuse\" \"texture reflectance\" \"wood\"\n" +
           kTri + "Material \"diffuse\" \"texture reflectance\" \"b\"\n" + kTri +
           "Material \"diffuse\" \"texture reflectance\" \"l\"\n" + kTri);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  ASSERT_EQ(s.textures.size(), 3u);
  EXPECT_EQ(s.textures[0].wrap, TEXTURE_WRAP_REPEAT);
  EXPECT_EQ(s.textures[0].encoding,
            ImageEncoding::Auto); // pbrt-v4: sRGB for 8 bits, else linear
  EXPECT_FLOAT_EQ(s.textures[0].scale.x, 1.0f);
  EXPECT_FLOAT_EQ(s.textures[0].uvmap.x, 1.0f);
  EXPECT_FLOAT_EQ(s.textures[0].uvmap.y, 1.0f);
  EXPECT_FLOAT_EQ(s.textures[0].uvmap.z, 0.0f);
  EXPECT_FLOAT_EQ(s.textures[0].uvmap.w, 0.0f);
  EXPECT_EQ(s.textures[1].wrap, TEXTURE_WRAP_BLACK);
  EXPECT_EQ(s.textures[1].encoding, ImageEncoding::Srgb);
  EXPECT_EQ(s.textures[2].wrap, TEXTURE_WRAP_REPEAT);
  EXPECT_EQ(s.textures[2].encoding, ImageEncoding::Linear);
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(material_of(s, size_t(i)).albedo_texture, i + 1);
}

TEST(SceneTexturesPbrt, EncodingCountsForPngOnlyAsInPbrt) {
  TempDir d("encoding");
  d.write("a.exr", "x"); // only its existence is checked while loading
  Scene s = load_pbrt_scene_from_string(kHead +
                                            "Texture \"e\" \"spectrum\" \"imagemap\" \"string "
                                            "filename\" \"a.exr\" \"string encoding\" \"sRGB\"\n"
                                            "Material \"diffuse\" \"texture reflectance\" \"e\"\n" +
                                            kTri,
                                        "t.pbrt", d.dir, {});
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].encoding, ImageEncoding::Auto);
}

TEST(SceneTexturesPbrt, RoughnessTexturesMapToAlpha) {
  Scene s = load(
      kHead + kRoughTex + kWood + "Material \"conductor\" \"texture roughness\" \"r\"\n" + kTri +
      "Material \"conductor\" \"texture roughness\" \"r\" \"bool remaproughness\" false\n" + kTri +
      "Material \"coateddiffuse\" \"texture reflectance\" \"wood\" \"texture uroughness\" \"r\" "
      "\"texture vroughness\" \"r\"\n" +
      kTri + "Material \"conductor\" \"texture roughness\" \"r\"\n" + kTri);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  // r with remapping, r without, wood; the fourth material reuses the first texture.
  ASSERT_EQ(s.textures.size(), 3u);
  EXPECT_EQ(s.textures[0].file, kRough);
  EXPECT_EQ(s.textures[0].channels, 1);
  EXPECT_EQ(s.textures[0].map, TEXTURE_MAP_ALPHA_SQRT);
  EXPECT_EQ(s.textures[0].where, "t.pbrt:5: texture \"r\"");
  EXPECT_EQ(s.textures[1].channels, 1);
  EXPECT_EQ(s.textures[1].map, TEXTURE_MAP_VALUE);
  EXPECT_EQ(s.textures[2].channels, 3);
  EXPECT_EQ(s.textures[2].file, kChecker);
  const Material &a = material_of(s, 0), &b = material_of(s, 1), &c = material_of(s, 2),
                 &e = material_of(s, 3);
  EXPECT_EQ(a.type, MATERIAL_CONDUCTOR);
  EXPECT_EQ(a.alpha_texture, 1);
  EXPECT_EQ(a.albedo_texture, 0);
  EXPECT_EQ(b.alpha_texture, 2);
  EXPECT_EQ(c.type, MATERIAL_COATED_DIFFUSE);
  EXPECT_EQ(c.alpha_texture, 1);
  EXPECT_EQ(c.albedo_texture, 3);
  EXPECT_EQ(e.alpha_texture, 1);
}

TEST(SceneTexturesPbrt, AnisotropicRoughnessTexturesWarnAndUseURoughness) {
  const std::string text =
      kHead + kRoughTex +
      "Texture \"r2\" \"float\" \"imagemap\" \"string filename\" \"textures/checker.png\"\n"
      "Material \"conductor\"\n"
      "  \"texture uroughness\" \"r2\" \"texture vroughness\" \"r\"\n" +
      kTri;
  Scene s = load(text);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0],
            "t.pbrt:8: Material \"conductor\": uroughness and vroughness differ: Canopy's GGX is "
            "isotropic, the texture \"r2\" used, anisotropy ignored");
  ASSERT_EQ(s.textures.size(), 1u);
  EXPECT_EQ(s.textures[0].file, kChecker);
  EXPECT_EQ(material_of(s, 0).alpha_texture, 1);
  EXPECT_EQ(error_of(text, true), s.warnings[0] + " (--strict: warnings are errors)");
}

TEST(SceneTexturesPbrt, ScaleAndConstantTexturesFold) {
  Scene s = load(
      kHead + kWood + kRoughTex +
      "Texture \"half\" \"spectrum\" \"scale\" \"texture tex\" \"wood\" \"float scale\" 0.5\n"
      "Texture \"q\" \"float\" \"constant\" \"float value\" 0.25\n"
      "Texture \"rs\" \"float\" \"scale\" \"texture tex\" \"q\" \"texture scale\" \"r\"\n"
      "Texture \"c\" \"spectrum\" \"constant\" \"rgb value\" [0.2 0.3 0.4]\n"
      "Texture \"c2\" \"spectrum\" \"scale\" \"texture tex\" \"c\" \"texture scale\" \"q\"\n"
      "Material \"coateddiffuse\" \"texture reflectance\" \"half\" \"texture roughness\" \"rs\"\n" +
      kTri + "Material \"diffuse\" \"texture reflectance\" \"c\"\n" + kTri +
      "Material \"conductor\" \"texture roughness\" \"q\"\n" + kTri +
      "Material \"diffuse\" \"texture reflectance\" \"c2\"\n" + kTri);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  ASSERT_EQ(s.textures.size(), 2u);
  // The scaled reflectance first (the material reads it first), then the roughness.
  EXPECT_EQ(s.textures[0].file, kChecker);
  EXPECT_FLOAT_EQ(s.textures[0].scale.x, 0.5f);
  EXPECT_FLOAT_EQ(s.textures[0].scale.z, 0.5f);
  EXPECT_EQ(s.textures[0].where, "t.pbrt:7: texture \"half\"");
  EXPECT_EQ(s.textures[1].file, kRough);
  EXPECT_FLOAT_EQ(s.textures[1].scale.x, 0.25f);
  EXPECT_EQ(s.textures[1].where, "t.pbrt:9: texture \"rs\"");
  const Material& a = material_of(s, 0);
  EXPECT_EQ(a.albedo_texture, 1);
  EXPECT_EQ(a.alpha_texture, 2);
  const Material& b = material_of(s, 1);
  EXPECT_EQ(b.albedo_texture, 0);
  EXPECT_FLOAT_EQ(b.albedo.x, 0.2f);
  EXPECT_FLOAT_EQ(b.albedo.y, 0.3f);
  EXPECT_FLOAT_EQ(b.albedo.z, 0.4f);
  const Material& c = material_of(s, 2); // roughness 0.25, remapped: alpha = sqrt(0.25)
  EXPECT_EQ(c.alpha_texture, 0);
  EXPECT_NEAR(c.alpha, 0.5f, 1e-6f);
  const Material& e = material_of(s, 3);
  EXPECT_FLOAT_EQ(e.albedo.x, 0.05f);
  EXPECT_FLOAT_EQ(e.albedo.z, 0.1f);
}

TEST(SceneTexturesPbrt, TexturesAreGlobalAcrossAttributes) {
  Scene s = load(kHead + "AttributeBegin\n" + kWood + "AttributeEnd\n" +
                 "Material \"diffuse\" \"texture reflectance\" \"wood\"\n" + kTri);
  EXPECT_EQ(material_of(s, 0).albedo_texture, 1);
}

TEST(SceneTexturesPbrt, UnsupportedClassesWarnOnceAndKeepTheDefault) {
  const std::string text =
      kHead + "Texture \"t\" \"spectrum\" \"dots\" \"float uscale\" 4\n" +
      "Texture \"f\" \"float\" \"fbm\"\n" +
      "Material \"coateddiffuse\" \"texture reflectance\" \"t\" \"texture roughness\" \"f\"\n" +
      kTri;
  Scene s = load(text);
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_EQ(s.warnings[0], "t.pbrt:5: Texture \"t\": the texture class \"dots\" is not "
                           "supported (a material using it keeps its constant default), ignored");
  EXPECT_EQ(s.warnings[1].rfind("t.pbrt:6: Texture \"f\": the texture class \"fbm\"", 0), 0u);
  EXPECT_TRUE(s.textures.empty());
  const Material& m = material_of(s, 0);
  EXPECT_EQ(m.albedo_texture, 0);
  EXPECT_EQ(m.alpha_texture, 0);
  EXPECT_FLOAT_EQ(m.albedo.x, 0.5f);
  EXPECT_FLOAT_EQ(m.alpha, 0.0f);
  EXPECT_EQ(error_of(text, true), s.warnings[0] + " (--strict: warnings are errors)");
}

TEST(SceneTexturesPbrt, ParametersCanopyCannotRenderWarnWithFileAndLine) {
  struct Case {
    std::string params, want;
  };
  const Case cases[] = {
      {"\"bool invert\" true",
       "t.pbrt:6: Texture \"w\": \"bool invert\" true (1 - value) is not supported, ignored"},
      {"\"string filter\" \"ewa\" \"float maxanisotropy\" 16",
       "t.pbrt:6: Texture \"w\": \"string filter\" \"ewa\" (maxanisotropy 16): Canopy filters "
       "bilinearly, ignored"},
      {"\"string mapping\" \"planar\" \"vector3 v1\" [1 0 0]",
       "t.pbrt:6: Texture \"w\": \"string mapping\" \"planar\": only \"uv\" mapping is supported "
       "(uv used), ignored"},
      {"\"float frobnicate\" 1",
       "t.pbrt:6: Texture \"w\": unknown parameter \"float frobnicate\" ignored"},
  };
  for (const Case& c : cases) {
    const std::string text =
        kHead +
        "Texture \"w\" \"spectrum\" \"imagemap\" \"string filename\" \"textures/checker.png\"\n"
        "  " +
        c.params + "\n";
    Scene s = load(text);
    ASSERT_EQ(s.warnings.size(), 1u) << c.params;
    EXPECT_EQ(s.warnings[0], c.want);
    EXPECT_EQ(error_of(text, true), c.want + " (--strict: warnings are errors)");
  }
}

TEST(SceneTexturesPbrt, ConductorReflectanceImageWarnsAndFallsBack) {
  Scene s =
      load(kHead + kWood + "Material \"conductor\" \"texture reflectance\" \"wood\"\n" + kTri);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].rfind("t.pbrt:6: Material \"conductor\": \"texture reflectance\" "
                                "\"wood\": Canopy's conductor takes no reflectance image",
                                0),
            0u)
      << s.warnings[0];
  EXPECT_TRUE(s.textures.empty());
  EXPECT_NEAR(material_of(s, 0).specular.x, 0.238f, 1e-6f); // copper
}

TEST(SceneTexturesPbrt, ErrorsAreOneLineNamingFileAndLine) {
  const std::string tex = "Texture \"w\" \"spectrum\" \"imagemap\" \"string filename\" ";
  struct Case {
    std::string text, want;
  };
  const Case cases[] = {
      {tex + "\"textures/none.png\"\n", "t.pbrt:5: Texture \"w\": \"string filename\" " +
                                            (kData / "textures/none.png").string() +
                                            ": no such file"},
      {tex + "\"textures\"\n", "t.pbrt:5: Texture \"w\": \"string filename\" " +
                                   (kData / "textures").string() + ": no such file"},
      {"Texture \"w\" \"spectrum\" \"imagemap\"\n",
       "t.pbrt:5: Texture \"w\": needs \"string filename\""},
      {tex + "\"textures/checker.png\"\n"
             " \"string wrap\" \"mirror\"\n",
       "t.pbrt:6: Texture \"w\": \"string wrap\" \"mirror\": unknown wrap mode (want \"repeat\", "
       "\"clamp\" or \"black\")"},
      {tex + "\"textures/checker.png\" \"string encoding\" \"gamma 0\"\n",
       "t.pbrt:5: Texture \"w\": \"string encoding\" \"gamma 0\": unknown encoding (want \"sRGB\", "
       "\"linear\" or \"gamma <value>\" with a value > 0)"},
      {tex + "\"textures/checker.png\" \"float scale\" -1\n",
       "t.pbrt:5: Texture \"w\": \"float scale\": must be >= 0 and a finite float"},
      {"Texture \"w\" \"color\" \"imagemap\"\n",
       "t.pbrt:5: Texture \"w\": texture type \"color\" unknown (want \"float\" or \"spectrum\")"},
      {"Texture \"w\" \"spectrum\"\n", "t.pbrt:5: Texture: expected a quoted name"},
      {kWood + kWood, "t.pbrt:6: Texture \"wood\": the spectrum texture \"wood\" is defined twice"},
      {"Material \"diffuse\" \"texture reflectance\" \"nothing\"\n",
       "t.pbrt:5: Material \"diffuse\": \"texture reflectance\": no spectrum texture named "
       "\"nothing\""},
      {kRoughTex + "Material \"diffuse\" \"texture reflectance\" \"r\"\n",
       "t.pbrt:6: Material \"diffuse\": \"texture reflectance\": no spectrum texture named \"r\" "
       "(\"r\" is a float texture)"},
      {kWood + "Material \"conductor\" \"texture roughness\" \"wood\"\n",
       "t.pbrt:6: Material \"conductor\": \"texture roughness\": no float texture named \"wood\" "
       "(\"wood\" is a spectrum texture)"},
  };
  for (const Case& c : cases) {
    std::string e = error_of(kHead + c.text);
    EXPECT_EQ(e, c.want);
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  EXPECT_EQ(error_of("Texture \"w\" \"spectrum\" \"imagemap\"\n"),
            "t.pbrt:1: Texture is not allowed before WorldBegin");
}

// --------------------------------------------------------------------------------- pbrt uv

TEST(SceneTexturesPbrt, TriangleMeshUvAndDefaultsForMeshesWithout) {
  Scene s = load(kHead + kTri +
                 "Shape \"trianglemesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 0] \"integer "
                 "indices\" [0 1 2  2 1 3]\n"
                 "  \"point2 uv\" [0.1 0.2  0.3 0.4  0.5 0.6  0.7 0.8]\n" +
                 kTri);
  ASSERT_EQ(s.triangle_count(), 4u);
  ASSERT_EQ(s.triangle_uvs.size(), 12u);
  expect_uv(s, 0, {0, 0, 1, 0, 1, 1}); // before the first mesh with uv: the default
  expect_uv(s, 1, {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f});
  expect_uv(s, 2, {0.5f, 0.6f, 0.3f, 0.4f, 0.7f, 0.8f});
  expect_uv(s, 3, {0, 0, 1, 0, 1, 1}); // after
}

TEST(SceneTexturesPbrt, UvCountMustMatchTheVertexCount) {
  struct Case {
    std::string text, want;
  };
  const Case cases[] = {
      {"Shape \"trianglemesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0]\n"
       "  \"point2 uv\" [0 0  1 0]\n",
       "t.pbrt:6: Shape \"trianglemesh\": \"point2 uv\": wrong count of values (4; want 6, one "
       "pair per vertex)"},
      {"Shape \"bilinearmesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 0]\n"
       "  \"point2 uv\" [0 0 1 0 0 1 1 1 2 2]\n",
       "t.pbrt:6: Shape \"bilinearmesh\": \"point2 uv\": wrong count of values (10; want 8, one "
       "pair per vertex)"},
  };
  for (const Case& c : cases) {
    std::string e = error_of(kHead + c.text);
    EXPECT_EQ(e, c.want);
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(SceneTexturesPbrt, UvFollowTheWindingWhenItIsReversed) {
  const std::string mesh = "Shape \"trianglemesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0] \"integer "
                           "indices\" [0 1 2] \"point2 uv\" [0.1 0.2  0.3 0.4  0.5 0.6]\n";
  for (const std::string& pre :
       {std::string("ReverseOrientation\n"), std::string("Scale -1 1 1\n"), std::string()}) {
    Scene s = load(kHead + kLeadTri + pre + mesh);
    ASSERT_EQ(s.triangle_uvs.size(), 3 * (kLead + 1));
    // Vertex a keeps its uv wherever it ends up in the triangle's order.
    for (int k = 0; k < 3; ++k) {
      float3 p = s.vertices[s.indices[3 * kLead + size_t(k)]] +
                 make_float3(float(s.origin.x), float(s.origin.y), float(s.origin.z));
      float2 uv = s.triangle_uvs[3 * kLead + size_t(k)];
      float x = std::fabs(p.x); // Scale -1 1 1 mirrors x
      if (x == 0.0f && p.y == 0.0f) {
        EXPECT_FLOAT_EQ(uv.x, 0.1f) << pre;
      } else if (x == 1.0f) {
        EXPECT_FLOAT_EQ(uv.x, 0.3f) << pre;
      } else {
        EXPECT_FLOAT_EQ(uv.x, 0.5f) << pre;
      }
    }
    if (pre.empty())
      expect_uv(s, kLead, {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f});
    else
      expect_uv(s, kLead, {0.1f, 0.2f, 0.5f, 0.6f, 0.3f, 0.4f});
  }
}

TEST(SceneTexturesPbrt, BilinearMeshUvGivenAndDefault) {
  Scene s = load(kHead + kLeadTri +
                 "Shape \"bilinearmesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 0]\n"
                 "Shape \"bilinearmesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 0]\n"
                 "  \"point2 uv\" [0.1 0.2  0.3 0.4  0.5 0.6  0.7 0.8]\n");
  ASSERT_EQ(s.triangle_count(), kLead + 4);
  // pbrt-v4's default for a patch: (u, v) of its own parameterisation at p00 p10 p01 p11.
  expect_uv(s, kLead, {0, 0, 1, 0, 1, 1});
  expect_uv(s, kLead + 1, {0, 0, 1, 1, 0, 1});
  expect_uv(s, kLead + 2, {0.1f, 0.2f, 0.3f, 0.4f, 0.7f, 0.8f});
  expect_uv(s, kLead + 3, {0.1f, 0.2f, 0.7f, 0.8f, 0.5f, 0.6f});
}

// pbrt-v4's sphere and disk parameterisation at every tessellated vertex: the uv of a vertex is a
// function of its object-space position (u from phi, v from theta or r), with u = 1 instead of 0 on
// the seam side of a triangle, and at a pole or the disk's centre (where phi is undefined) the
// middle of the triangle's u range.
void expect_polar_uv(const Scene& s, bool sphere, double radius) {
  const double pi = 3.14159265358979323846;
  ASSERT_EQ(s.triangle_uvs.size(), 3 * s.triangle_count());
  for (size_t t = kLead; t < s.triangle_count(); ++t) {
    double u[3], v[3];
    bool pole[3];
    for (int k = 0; k < 3; ++k) {
      float3 q = s.vertices[s.indices[3 * t + size_t(k)]];
      double x = q.x + s.origin.x, y = q.y + s.origin.y, z = q.z + s.origin.z;
      double phi = std::atan2(y, x);
      if (phi < 0) phi += 2 * pi;
      double r = std::sqrt(x * x + y * y);
      pole[k] = r < 1e-6;
      u[k] = phi / (2 * pi);
      v[k] = sphere ? 1.0 - std::acos(std::clamp(z / radius, -1.0, 1.0)) / pi : 1.0 - r / radius;
    }
    double umax = 0;
    for (int k = 0; k < 3; ++k)
      if (!pole[k]) umax = std::max(umax, u[k]);
    double umin = 1, uref[3];
    for (int k = 0; k < 3; ++k) {
      uref[k] = u[k];
      if (!pole[k] && u[k] < 1e-6 && umax > 0.5) uref[k] = 1.0; // the seam
      if (!pole[k]) umin = std::min(umin, uref[k]);
    }
    for (int k = 0; k < 3; ++k) {
      float2 uv = s.triangle_uvs[3 * t + size_t(k)];
      double want_u = pole[k] ? 0.0 : uref[k];
      if (pole[k]) {
        double hi = 0;
        for (int j = 0; j < 3; ++j)
          if (!pole[j]) hi = std::max(hi, uref[j]);
        want_u = 0.5 * (umin + hi);
      }
      EXPECT_NEAR(uv.x, want_u, 1e-5) << "triangle " << t << " vertex " << k;
      EXPECT_NEAR(uv.y, v[k], 1e-5) << "triangle " << t << " vertex " << k;
    }
  }
}

TEST(SceneTexturesPbrt, SphereUvIsPbrtsParameterisationWithASeam) {
  Scene s = load(kHead + kLeadTri + "Shape \"sphere\" \"float radius\" 2\n");
  expect_polar_uv(s, true, 2.0);
  // The first triangle touches the north pole (v = 1), the 48th closes the seam at u = 1.
  expect_uv(s, kLead, {0.5f / 48, 1, 0, 1 - 1.0f / 24, 1.0f / 48, 1 - 1.0f / 24});
  expect_uv(s, kLead + 47, {47.5f / 48, 1, 47.0f / 48, 1 - 1.0f / 24, 1, 1 - 1.0f / 24});
}

TEST(SceneTexturesPbrt, ReversedSphereAndDiskUv) {
  Scene s = load(kHead + kLeadTri +
                 "ReverseOrientation\n"
                 "Shape \"sphere\"\n");
  expect_polar_uv(s, true, 1.0);
  expect_uv(s, kLead, {0.5f / 48, 1, 1.0f / 48, 1 - 1.0f / 24, 0, 1 - 1.0f / 24});
  Scene d = load(kHead + kLeadTri + "Shape \"disk\" \"float radius\" 3\n");
  expect_polar_uv(d, false, 3.0);
  expect_uv(d, kLead + 63, {63.5f / 64, 1, 63.0f / 64, 0, 1, 0});
  Scene r = load(kHead + kLeadTri +
                 "Scale 1 -1 1\n"
                 "Shape \"disk\" \"float radius\" 3\n");
  ASSERT_EQ(r.triangle_uvs.size(), 3 * (kLead + 64));
  expect_uv(r, kLead + 63, {63.5f / 64, 1, 1, 0, 63.0f / 64, 0});
}

TEST(SceneTexturesPbrt, PlyMeshUvAndObjectInstances) {
  TempDir d("ply");
  d.write("uv.ply", "ply\n"
                    "format ascii 1.0\n"
                    "element vertex 4\n"
                    "property float x\n"
                    "property float y\n"
                    "property float z\n"
                    "property float u\n"
                    "property float v\n"
                    "element face 1\n"
                    "property list uchar int vertex_indices\n"
                    "end_header\n"
                    "0 0 0 0.1 0.2\n"
                    "1 0 0 0.3 0.4\n"
                    "1 1 0 0.5 0.6\n"
                    "0 1 0 0.7 0.8\n"
                    "4 0 1 2 3\n");
  Scene s = load_pbrt_scene_from_string(kHead + kLeadTri +
                                            "ObjectBegin \"o\"\n"
                                            "Shape \"plymesh\" \"string filename\" \"uv.ply\"\n"
                                            "ObjectEnd\n"
                                            "ObjectInstance \"o\"\n"
                                            "Translate 0 0 1\n"
                                            "ReverseOrientation\n"
                                            "ObjectInstance \"o\"\n",
                                        "t.pbrt", d.dir, {});
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  ASSERT_EQ(s.triangle_count(), kLead + 4);
  expect_uv(s, kLead, {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f});
  expect_uv(s, kLead + 1, {0.1f, 0.2f, 0.5f, 0.6f, 0.7f, 0.8f});
  // ReverseOrientation after ObjectEnd does not apply to the object's shapes (pbrt: attributes are
  // those at the shape's definition).
  expect_uv(s, kLead + 2, {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f});
}

// ----------------------------------------------------------------------------- OBJ and MTL

namespace {

// `shapes` is the JSON array's content after a first OBJ triangle without uv (kLead).
Scene load_json(const TempDir& d, const std::string& shapes, const std::string& extra = "") {
  d.write("lead.obj", "v 0 0 -1\n"
                      "v 1 0 -1\n"
                      "v 0 1 -1\n"
                      "f 1 2 3\n");
  std::string json = R"({"camera": {"position": [0, 1, 5], "look_at": [0, 1, 0]},)" + extra +
                     R"("shapes": [{"type": "obj", "file": "lead.obj"}, )" + shapes + "]" +
                     R"(, "lights": [{"type": "point", "position": [0, 2, 0], "intensity": 1}]})";
  return load_scene_from_string(json, "scene.json", d.dir);
}

std::string json_error(const TempDir& d, const std::string& shapes) {
  try {
    load_json(d, shapes);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

} // namespace

TEST(SceneTexturesObj, VtBecomeUvAndFacesWithoutVtTheDefault) {
  TempDir d("obj-vt");
  d.write("m.obj", "v 0 0 0\n"
                   "v 1 0 0\n"
                   "v 0 1 0\n"
                   "v 1 1 0\n"
                   "vt 0.1 0.2\n"
                   "vt 0.3 0.4\n"
                   "vt 0.5 0.6 0.9\n"
                   "f 1 2 3\n"
                   "f 1/1 2/2 3/3\n"
                   "f 2/2 4/3 3/1\n"
                   "f 1 2/1 3/2\n");
  Scene s = load_json(d, R"({"type": "obj", "file": "m.obj"})");
  ASSERT_EQ(s.triangle_count(), kLead + 4);
  expect_uv(s, kLead, {0, 0, 1, 0, 1, 1});
  expect_uv(s, kLead + 1, {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f});
  expect_uv(s, kLead + 2, {0.3f, 0.4f, 0.5f, 0.6f, 0.1f, 0.2f});
  expect_uv(s, kLead + 3, {0, 0, 1, 0, 1, 1}); // vt at two of its vertices only
  // A mirroring transform swaps the winding, and the uv with it.
  Scene m = load_json(d, R"({"type": "obj", "file": "m.obj", "transform": {"scale": [-1, 1, 1]}})");
  expect_uv(m, kLead + 1, {0.1f, 0.2f, 0.5f, 0.6f, 0.3f, 0.4f});
  // A vt index out of range is an error.
  d.write("n.obj", "v 0 0 0\n"
                   "v 1 0 0\n"
                   "v 0 1 0\n"
                   "vt 0 0\n"
                   "f 1/1 2/1 3/4\n");
  EXPECT_EQ(json_error(d, R"({"type": "obj", "file": "n.obj"})"),
            "scene.json: shapes[1].file: n.obj: face 1 of '' has a texture coordinate index out of "
            "range");
}

TEST(SceneTexturesObj, MapKdIsAnAlbedoTextureWithItsOptions) {
  TempDir d("obj-map");
  std::filesystem::create_directories(d.dir / "mtl" / "tex");
  d.write("mtl/tex/wood.png", "x"); // only its existence is checked while loading
  d.write("mtl/m.mtl", "newmtl plain\n"
                       "Kd 0.2 0.3 0.4\n"
                       "map_Pr tex/wood.png\n" // a diffuse material has no roughness

                       "newmtl wood\n"
                       "Kd 0.2 0.3 0.4\n"
                       "map_Kd -s 2 3 -o 0.25 0.5 -clamp on -bm 2 tex/wood.png\n"
                       "newmtl shiny\n"
                       "Kd 1 1 1\n"
                       "Ks 0.5 0.5 0.5\n"
                       "Ns 100\n"
                       "illum 2\n"
                       "map_Kd -colorspace linear -o 0.5 -s 4 tex/wood.png\n"
                       "map_Pr -s 2 tex/wood.png\n");
  d.write("m.obj", "mtllib mtl/m.mtl\n"
                   "v 0 0 0\n"
                   "v 1 0 0\n"
                   "v 0 1 0\n"
                   "vt 0 0\n"
                   "vt 1 0\n"
                   "vt 0 1\n"
                   "usemtl plain\n"
                   "f 1/1 2/2 3/3\n"
                   "usemtl wood\n"
                   "f 1/1 2/2 3/3\n"
                   "usemtl shiny\n"
                   "f 1/1 2/2 3/3\n");
  Scene s = load_json(d, R"({"type": "obj", "file": "m.obj"})");
  ASSERT_EQ(s.textures.size(), 3u);
  const TextureDesc& t = s.textures[0];
  EXPECT_EQ(t.file, d.dir / "mtl" / "tex" / "wood.png");
  EXPECT_EQ(t.where, "scene.json: shapes[1].file: m.obj: mtl/m.mtl: material 'wood': map_Kd");
  EXPECT_EQ(t.channels, 3);
  EXPECT_EQ(t.encoding, ImageEncoding::Auto);
  EXPECT_FLOAT_EQ(t.uvmap.x, 2.0f);
  EXPECT_FLOAT_EQ(t.uvmap.y, 3.0f);
  EXPECT_FLOAT_EQ(t.uvmap.z, 0.25f);
  EXPECT_FLOAT_EQ(t.uvmap.w, 0.5f);
  EXPECT_EQ(t.wrap, TEXTURE_WRAP_CLAMP);
  EXPECT_FLOAT_EQ(t.scale.x, 1.0f);
  EXPECT_EQ(s.textures[1].wrap, TEXTURE_WRAP_REPEAT);
  EXPECT_EQ(s.textures[1].encoding, ImageEncoding::Linear);
  // -s and -o with fewer than three numbers: the others take their defaults, the name stays.
  EXPECT_EQ(s.textures[1].file, d.dir / "mtl" / "tex" / "wood.png");
  EXPECT_FLOAT_EQ(s.textures[1].uvmap.x, 4.0f);
  EXPECT_FLOAT_EQ(s.textures[1].uvmap.y, 1.0f);
  EXPECT_FLOAT_EQ(s.textures[1].uvmap.z, 0.5f);
  EXPECT_FLOAT_EQ(s.textures[1].uvmap.w, 0.0f);
  EXPECT_EQ(material_of(s, kLead).albedo_texture, 0);
  EXPECT_EQ(material_of(s, kLead + 1).albedo_texture, 1);
  EXPECT_EQ(material_of(s, kLead + 1).type, MATERIAL_DIFFUSE);
  EXPECT_EQ(material_of(s, kLead + 2).albedo_texture, 2);
  // map_Pr of the plastic: its roughness (Canopy's: alpha = r^2).
  EXPECT_EQ(material_of(s, kLead + 2).alpha_texture, 3);
  EXPECT_EQ(material_of(s, kLead).alpha_texture, 0);
  EXPECT_EQ(s.textures[2].channels, 1);
  EXPECT_EQ(s.textures[2].map, TEXTURE_MAP_ALPHA_SQUARE);
  EXPECT_EQ(s.textures[2].where,
            "scene.json: shapes[1].file: m.obj: mtl/m.mtl: material 'shiny': map_Pr");
  EXPECT_FLOAT_EQ(s.textures[2].uvmap.x, 2.0f);
  EXPECT_FLOAT_EQ(s.textures[2].uvmap.y, 1.0f);
  EXPECT_EQ(material_of(s, kLead + 2).type, MATERIAL_PLASTIC);

  // The same OBJ twice: its materials, and so their textures, are added once.
  Scene twice =
      load_json(d, R"({"type": "obj", "file": "m.obj"}, {"type": "obj", "file": "m.obj"})");
  EXPECT_EQ(twice.textures.size(), 3u);
  EXPECT_EQ(material_of(twice, kLead + 4).albedo_texture, 1);
  // A scene material of the same name replaces the MTL one: no texture.
  Scene named = load_json(d, R"({"type": "obj", "file": "m.obj"})",
                          R"("materials": [{"name": "wood", "type": "diffuse", "albedo": 0.5}],)");
  EXPECT_EQ(named.textures.size(), 2u);
  EXPECT_EQ(material_of(named, kLead + 1).albedo_texture, 0);
  // A material override replaces every MTL material: no texture.
  Scene over = load_json(d, R"({"type": "obj", "file": "m.obj", "material": "grey"})",
                         R"("materials": [{"name": "grey", "type": "diffuse", "albedo": 0.5}],)");
  EXPECT_TRUE(over.textures.empty());
}

TEST(SceneTexturesObj, MissingMapKdFileIsAnErrorNamingTheMtlAndTheMap) {
  TempDir d("obj-missing");
  d.write("m.mtl", "newmtl wood\n"
                   "Kd 0.5 0.5 0.5\n"
                   "map_Kd nothing.png\n");
  d.write("m.obj", "mtllib m.mtl\n"
                   "v 0 0 0\n"
                   "v 1 0 0\n"
                   "v 0 1 0\n"
                   "usemtl wood\n"
                   "f 1 2 3\n");
  std::string e = json_error(d, R"({"type": "obj", "file": "m.obj"})");
  EXPECT_EQ(e, "scene.json: shapes[1].file: m.obj: m.mtl: material 'wood': map_Kd '" +
                   (d.dir / "nothing.png").string() + "': no such file");
}

// The scene's first mesh with uv keeps them (Builder::add_mesh once kept none when no triangle
// came before it).
TEST(SceneTexturesPbrt, FirstMeshOfTheSceneKeepsItsUv) {
  Scene s = load(kHead + "Shape \"trianglemesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0] \"integer "
                         "indices\" [0 1 2] \"point2 uv\" [0.1 0.2  0.3 0.4  0.5 0.6]\n");
  expect_uv(s, 0, {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f});
}
