// The pbrt-v4 reader (host/scene/pbrt/): properties of the Scene it builds, checked
// against values worked out by hand from pbrt-v4's conventions, and its errors and warnings.
#include "scene/metal_presets.h"
#include "scene/pbrt_reader.h"
#include "scene/scene.h"

#include "support/pbrt_text.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

using namespace canopy;

namespace {

const std::filesystem::path& kData = test::kPbrtData;

Scene load(const std::string& text, bool strict = false) {
  return test::load_pbrt(text, strict);
}

std::string error_of(const std::string& text, bool strict = false) {
  return test::pbrt_error_of(text, strict);
}

std::string error_of_file(const std::filesystem::path& f) {
  try {
    load_scene(f);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

// A camera whose frames agree with Canopy's (Scale -1 1 1: pbrt's raster +x is world +x), so the
// world is kept as written and world = vertex + origin.
const char* kKeptCamera = "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\n";

double3 world_of(const Scene& s, float3 v) {
  return {double(v.x) + s.origin.x, double(v.y) + s.origin.y, double(v.z) + s.origin.z};
}

// Where a point of the scene (its float, rebased coordinate) lands on Canopy's image, in
// normalised device coordinates: x in [-1, 1] left to right, y in [-1, 1] bottom to top. The
// same frame as host/render/camera.cpp (right = cross(forward, up), raster x along right, the
// top row along up), which lives in canopy_core and so is restated here.
std::pair<double, double> project(const Scene& s, float3 p) {
  const Camera& c = s.camera;
  float3 f = normalize(c.look_at - c.position);
  float3 r = normalize(cross(f, c.up));
  float3 u = cross(r, f);
  float3 d = p - c.position;
  double z = dot(d, f);
  double half_h = std::tan(0.5 * double(c.fov_y_deg) * M_PI / 180.0);
  double half_w = half_h * double(s.film.width) / double(s.film.height);
  return {double(dot(d, r)) / z / half_w, double(dot(d, u)) / z / half_h};
}

std::string tri_at(const std::string& p) {
  return "Shape \"trianglemesh\" \"point3 P\" [" + p + "] \"integer indices\" [0 1 2]\n";
}

} // namespace

// ---------------------------------------------------------------------------------- camera

TEST(ScenePbrt, LookAtTargetProjectsToTheImageCentre) {
  for (const char* pre : {"", "Scale -1 1 1\n"}) {
    Scene s = load(std::string(pre) +
                   "LookAt 1 2 5  0.5 0 -1  0 1 0\nCamera \"perspective\"\n"
                   "WorldBegin\n" +
                   tri_at("0.5 0 -1  0.6 0 -1  0.5 0.1 -1"));
    auto [x, y] = project(s, s.vertices[0]);
    EXPECT_NEAR(x, 0.0, 1e-5) << pre;
    EXPECT_NEAR(y, 0.0, 1e-5) << pre;
    EXPECT_EQ(s.origin.x, 1.0);
    EXPECT_EQ(s.origin.z, 5.0);
  }
}

// pbrt-v4's LookAt (transform.cpp) builds the camera's +x axis as cross(up, dir): for
// LookAt 0 0 5  0 0 0  0 1 0, dir = (0, 0, -1) and camera +x = (0,1,0) x (0,0,-1) = (-1, 0, 0).
// Its PerspectiveCamera maps screen +x to growing raster x (rasterFromScreen scales x by
// +resolution.x) and screen +y to the top row. So pbrt shows world -x on the RIGHT of the image
// and world +y at the top. Canopy must show the same picture.
TEST(ScenePbrt, PlainLookAtShowsWorldMinusXOnTheRightAsPbrtDoes) {
  Scene s = load("LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n" +
                 tri_at("-1 0 0  -1 0.1 0  -1.1 0 0") + tri_at("0 1 0  0.1 1 0  0 1.1 0"));
  auto [x, y] = project(s, s.vertices[0]); // world (-1, 0, 0)
  EXPECT_GT(x, 0.1);
  EXPECT_NEAR(y, 0.0, 1e-6);
  auto [x2, y2] = project(s, s.vertices[3]); // world (0, 1, 0)
  EXPECT_NEAR(x2, 0.0, 1e-6);
  EXPECT_GT(y2, 0.1);
}

// With "Scale -1 1 1" before LookAt (the usual way to get a right-handed view in pbrt), camera
// +x is world +x: world +x on the right; the world is kept as written.
TEST(ScenePbrt, ScaleMinusOneLookAtShowsWorldPlusXOnTheRight) {
  Scene s = load(std::string(kKeptCamera) + "WorldBegin\n" + tri_at("1 0 0  1 0.1 0  1.1 0 0"));
  auto [x, y] = project(s, s.vertices[0]);
  EXPECT_GT(x, 0.1);
  EXPECT_NEAR(y, 0.0, 1e-6);
  double3 w = world_of(s, s.vertices[0]);
  EXPECT_NEAR(w.x, 1.0, 1e-6);
  EXPECT_NEAR(w.y, 0.0, 1e-6);
  EXPECT_NEAR(w.z, 0.0, 1e-6);
}

// pbrt's fov spans the shorter image axis; Canopy's fov_y_deg the vertical one.
TEST(ScenePbrt, FovOfTheShorterAxisBecomesTheVerticalFov) {
  Scene wide = load("Camera \"perspective\" \"float fov\" 60\n"
                    "Film \"rgb\" \"integer xresolution\" 400 \"integer yresolution\" 200\n");
  EXPECT_NEAR(wide.camera.fov_y_deg, 60.0, 1e-4);
  EXPECT_EQ(wide.film.width, 400);
  Scene tall = load("Camera \"perspective\" \"float fov\" 60\n"
                    "Film \"rgb\" \"integer xresolution\" 200 \"integer yresolution\" 400\n");
  // The horizontal half-width is tan(30 deg); the vertical one twice that.
  double want = 2.0 * std::atan(2.0 * std::tan(M_PI / 6.0)) * 180.0 / M_PI; // 98.21 deg
  EXPECT_NEAR(tall.camera.fov_y_deg, want, 1e-3);
  Scene def = load("Camera \"perspective\"\n");
  EXPECT_EQ(def.film.width, 1280); // pbrt's default film
  EXPECT_EQ(def.film.height, 720);
  EXPECT_NEAR(def.camera.fov_y_deg, 90.0, 1e-4);
}

// Film "filename" is the default output; scale x iso / 100 the image scale (pbrt-v4 RGBFilm's
// imaging ratio for the default sensor); another extension than .exr/.png becomes .exr.
TEST(ScenePbrt, FilmFilenameAndImageScale) {
  Scene s = load("Film \"rgb\" \"string filename\" \"renders/room.png\" \"float iso\" 400 "
                 "\"float scale\" 0.5\n");
  EXPECT_EQ(s.film.output, "renders/room.png");
  EXPECT_FLOAT_EQ(s.film.image_scale, 2.0f); // 0.5 x 400 / 100
  EXPECT_TRUE(s.warnings.empty());
  Scene def = load("Film \"rgb\"\n");
  EXPECT_EQ(def.film.output, "");
  EXPECT_FLOAT_EQ(def.film.image_scale, 1.0f);
  Scene tga = load("Film \"rgb\" \"string filename\" \"a.tga\"\n");
  EXPECT_EQ(tga.film.output, "a.exr");
  ASSERT_EQ(tga.warnings.size(), 1u);
  EXPECT_NE(tga.warnings[0].find("t.pbrt:1: "), std::string::npos) << tga.warnings[0];
  EXPECT_NE(error_of("Film \"rgb\" \"float iso\" 0\n").find("t.pbrt:1: "), std::string::npos);
}

TEST(ScenePbrt, SamplerAndIntegratorSettings) {
  Scene s = load("Sampler \"zsobol\" \"integer pixelsamples\" 64\n"
                 "Integrator \"path\" \"integer maxdepth\" 7\n");
  EXPECT_EQ(s.integrator.spp, 64);
  EXPECT_EQ(s.integrator.max_depth, 7);
  EXPECT_TRUE(s.warnings.empty());
}

// --------------------------------------------------------------------------------- geometry

// CTM = Translate(1,2,3) * Scale(2) * Rotate(90, z): a local point is rotated, then scaled, then
// translated. (1,0,0) -> (0,1,0) -> (0,2,0) -> (1,4,3); (0,1,0) -> (-1,0,0) -> (-2,0,0) ->
// (-1,2,3); (0,0,1) -> (0,0,1) -> (0,0,2) -> (1,2,5).
TEST(ScenePbrt, TriangleMeshUnderTranslateScaleRotateLandsAtHandComputedVertices) {
  Scene s = load(std::string(kKeptCamera) + "WorldBegin\nTranslate 1 2 3\nScale 2 2 2\n" +
                 "Rotate 90 0 0 1\n" + tri_at("1 0 0  0 1 0  0 0 1"));
  ASSERT_EQ(s.vertices.size(), 3u);
  const double want[3][3] = {{1, 4, 3}, {-1, 2, 3}, {1, 2, 5}};
  for (int i = 0; i < 3; ++i) {
    double3 w = world_of(s, s.vertices[size_t(i)]);
    EXPECT_NEAR(w.x, want[i][0], 1e-5) << i;
    EXPECT_NEAR(w.y, want[i][1], 1e-5) << i;
    EXPECT_NEAR(w.z, want[i][2], 1e-5) << i;
  }
}

TEST(ScenePbrt, TransformMatrixIsColumnMajorAndCoordSysCameraWorks) {
  // Transform's elements 12..14 are the translation (the format page).
  Scene s = load(std::string(kKeptCamera) +
                 "WorldBegin\nTransform [1 0 0 0  0 1 0 0  0 0 1 0  3 4 5 1]\n" +
                 tri_at("0 0 0  1 0 0  0 1 0"));
  double3 w = world_of(s, s.vertices[0]);
  EXPECT_NEAR(w.x, 3.0, 1e-6);
  EXPECT_NEAR(w.y, 4.0, 1e-6);
  EXPECT_NEAR(w.z, 5.0, 1e-6);
  // CoordSysTransform "camera": a shape in camera space, 1 unit ahead, is on the view axis.
  Scene c = load("LookAt 3 1 2  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n"
                 "CoordSysTransform \"camera\"\n" +
                 tri_at("0 0 1  0.01 0 1  0 0.01 1"));
  auto [x, y] = project(c, c.vertices[0]);
  EXPECT_NEAR(x, 0.0, 1e-5);
  EXPECT_NEAR(y, 0.0, 1e-5);
  EXPECT_NEAR(length(c.vertices[0]), 1.0, 1e-5);
}

TEST(ScenePbrt, AttributeEndRestoresTransformAndMaterial) {
  Scene s =
      load(std::string(kKeptCamera) + "WorldBegin\n" +
           "Material \"diffuse\" \"rgb reflectance\" [0.1 0.2 0.3]\n" + "AttributeBegin\n" +
           "  Translate 10 0 0\n" +
           "  Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" "
           "\"spectrum k\" \"metal-Au-k\"\n" +
           "  " + tri_at("0 0 0  1 0 0  0 1 0") + "AttributeEnd\n" + tri_at("0 0 0  1 0 0  0 1 0"));
  ASSERT_EQ(s.triangle_count(), 2u);
  EXPECT_NEAR(world_of(s, s.vertices[0]).x, 10.0, 1e-6);
  EXPECT_NEAR(world_of(s, s.vertices[3]).x, 0.0, 1e-6);
  const Material& inner = s.materials[size_t(s.triangle_material[0])].gpu;
  const Material& outer = s.materials[size_t(s.triangle_material[1])].gpu;
  EXPECT_EQ(inner.type, MATERIAL_CONDUCTOR);
  EXPECT_EQ(outer.type, MATERIAL_DIFFUSE);
  EXPECT_FLOAT_EQ(outer.albedo.x, 0.1f);
  EXPECT_FLOAT_EQ(outer.albedo.z, 0.3f);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
}

TEST(ScenePbrt, ObjectInstanceCopiesGeometryWithItsTransform) {
  Scene s = load(std::string(kKeptCamera) + "WorldBegin\n" + "ObjectBegin \"tri\"\n" +
                 "  Translate 0 1 0\n  " + tri_at("0 0 0  1 0 0  0 1 0") + "ObjectEnd\n" +
                 "AttributeBegin\n  Translate 5 0 0\n  ObjectInstance \"tri\"\nAttributeEnd\n" +
                 "ObjectInstance \"tri\"\n");
  ASSERT_EQ(s.triangle_count(), 2u); // the definition itself adds nothing
  double3 a = world_of(s, s.vertices[0]), b = world_of(s, s.vertices[3]);
  EXPECT_NEAR(a.x, 5.0, 1e-6);
  EXPECT_NEAR(a.y, 1.0, 1e-6);
  EXPECT_NEAR(b.x, 0.0, 1e-6);
  EXPECT_NEAR(b.y, 1.0, 1e-6);
}

TEST(ScenePbrt, BilinearMeshIsTwoTrianglesWithThePatchNormal) {
  Scene s = load(std::string(kKeptCamera) + "WorldBegin\n" +
                 "Shape \"bilinearmesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 0]\n");
  ASSERT_EQ(s.triangle_count(), 2u);
  // pbrt's patch normal is cross(p10 - p00, p01 - p00) = +z.
  for (size_t t = 0; t < 2; ++t) {
    float3 a = s.vertices[s.indices[3 * t]], b = s.vertices[s.indices[3 * t + 1]],
           c = s.vertices[s.indices[3 * t + 2]];
    EXPECT_GT(cross(b - a, c - a).z, 0.0f) << t;
  }
}

// ----------------------------------------------------------------------------------- lights

TEST(ScenePbrt, AreaLightMakesEmissiveTrianglesWithLTimesScaleAndTwoSided) {
  Scene s = load(std::string(kKeptCamera) + "WorldBegin\nAttributeBegin\n" +
                 "AreaLightSource \"diffuse\" \"rgb L\" [1 2 3] \"float scale\" 2 "
                 "\"bool twosided\" true\n" +
                 tri_at("0 0 0  1 0 0  0 1 0") + "AttributeEnd\n" + tri_at("0 0 0  1 0 0  0 1 0"));
  ASSERT_EQ(s.lights.size(), 1u);
  const Light& l = s.lights[0];
  EXPECT_EQ(l.type, LIGHT_TRIANGLE);
  EXPECT_TRUE(l.flags & LIGHT_FLAG_FROM_MESH);
  EXPECT_TRUE(l.flags & LIGHT_FLAG_TWO_SIDED);
  EXPECT_FLOAT_EQ(l.emission.x, 2.0f);
  EXPECT_FLOAT_EQ(l.emission.y, 4.0f);
  EXPECT_FLOAT_EQ(l.emission.z, 6.0f);
  EXPECT_EQ(s.triangle_light[0], 0);
  EXPECT_EQ(s.triangle_light[1], -1); // the area light ends with its attribute scope
}

// A one-sided emitter that faces pbrt's camera faces Canopy's camera too, whether or not the
// reader mirrors the world (the winding is swapped with the reflection).
TEST(ScenePbrt, OneSidedEmitterFacingTheCameraStillFacesIt) {
  for (const char* pre : {"", "Scale -1 1 1\n"}) {
    Scene s = load(std::string(pre) + "LookAt 2 1 5  0 0 0  0 1 0\nCamera \"perspective\"\n" +
                   "WorldBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n" +
                   tri_at("0 0 0  1 0 0  0 1 0")); // normal +z, towards the eye
    ASSERT_EQ(s.lights.size(), 1u);
    float3 n = xyz_of(s.lights[0].n);
    float3 to_eye = s.camera.position - xyz_of(s.lights[0].p);
    EXPECT_GT(dot(n, to_eye), 0.0f) << pre;
  }
}

TEST(ScenePbrt, SphereAndDiskAreaLightsAreAnalytic) {
  Scene s = load(std::string(kKeptCamera) + "WorldBegin\n" +
                 "AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n" +
                 "AttributeBegin\nTranslate 0 3 0\nScale 2 2 2\nShape \"sphere\" \"float radius\" "
                 "0.5\nAttributeEnd\n" +
                 "Rotate 90 1 0 0\nShape \"disk\" \"float radius\" 0.25 \"float height\" 1\n");
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.triangle_count(), 0u);
  EXPECT_EQ(s.lights[0].type, LIGHT_SPHERE);
  EXPECT_NEAR(s.lights[0].p.w, 1.0, 1e-6); // radius 0.5 x 2
  EXPECT_NEAR(world_of(s, xyz_of(s.lights[0].p)).y, 3.0, 1e-6);
  EXPECT_EQ(s.lights[1].type, LIGHT_DISK);
  // Rotate 90 about x takes the disk's +z normal and centre (0, 0, 1) to -y.
  EXPECT_NEAR(s.lights[1].n.y, -1.0, 1e-6);
  EXPECT_NEAR(world_of(s, xyz_of(s.lights[1].p)).y, -1.0, 1e-6);
}

TEST(ScenePbrt, PointAndSpotLights) {
  Scene s =
      load(std::string(kKeptCamera) + "WorldBegin\nTranslate 1 0 0\n" +
           "LightSource \"point\" \"rgb I\" [1 2 3] \"float scale\" 3 \"point3 from\" [0 2 0]\n" +
           "LightSource \"spot\" \"rgb I\" [5 5 5] \"point3 from\" [0 0 0] "
           "\"point3 to\" [0 -1 0] \"float coneangle\" 40 \"float conedelta\" 10\n");
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].type, LIGHT_POINT);
  EXPECT_FLOAT_EQ(s.lights[0].emission.z, 9.0f);
  double3 p = world_of(s, xyz_of(s.lights[0].p));
  EXPECT_NEAR(p.x, 1.0, 1e-6);
  EXPECT_NEAR(p.y, 2.0, 1e-6);
  const Light& sp = s.lights[1];
  EXPECT_EQ(sp.type, LIGHT_SPOT);
  EXPECT_NEAR(sp.e1.y, -1.0, 1e-6);
  // The cone edge at 40 degrees, the smoothstep starting at 40 - 10 = 30 (set_spot_cone).
  EXPECT_NEAR(sp.e1.w, std::cos(40.0 * M_PI / 180.0), 1e-6);
  EXPECT_NEAR(sp.e2.w, std::cos(30.0 * M_PI / 180.0), 1e-6);
}

TEST(ScenePbrt, BlackbodyIsNearWhiteAt6500KAndReddishAt3000K) {
  float3 w = blackbody_rgb(6500.0);
  float y = 0.2126f * w.x + 0.7152f * w.y + 0.0722f * w.z;
  ASSERT_GT(y, 0.0f);
  for (float c : {w.x, w.y, w.z})
    EXPECT_NEAR(c / y, 1.0f, 0.08f); // D65 is 6504 K, slightly off the Planckian locus
  float3 r = blackbody_rgb(3000.0);
  EXPECT_GT(r.x, r.y);
  EXPECT_GT(r.y, r.z);
  // As an emitter pbrt-v4 normalises the blackbody to luminance 1 (1 nit times scale).
  Scene s = load(std::string(kKeptCamera) + "WorldBegin\n" +
                 "LightSource \"point\" \"blackbody I\" [3000] \"float scale\" 2\n");
  ASSERT_EQ(s.lights.size(), 1u);
  float3 e = xyz_of(s.lights[0].emission);
  EXPECT_NEAR(0.2126f * e.x + 0.7152f * e.y + 0.0722f * e.z, 2.0f, 1e-4f);
}

// -------------------------------------------------------------------------------- materials

// pbrt-v4: alpha = sqrt(roughness) with remaproughness (the default), else alpha = roughness.
TEST(ScenePbrt, ConductorRoughnessAndMetalPresets) {
  Scene s =
      load(std::string(kKeptCamera) + "WorldBegin\n" +
           "MakeNamedMaterial \"a\" \"string type\" \"conductor\" \"float roughness\" 0.01\n" +
           "MakeNamedMaterial \"b\" \"string type\" \"conductor\" \"float roughness\" 0.04 "
           "\"bool remaproughness\" false \"spectrum eta\" \"metal-Ag-eta\" "
           "\"spectrum k\" \"metal-Ag-k\"\n" +
           "MakeNamedMaterial \"c\" \"string type\" \"coateddiffuse\" "
           "\"rgb reflectance\" [0.2 0.4 0.6] \"float roughness\" 0.0625 \"float eta\" 1.4\n" +
           "MakeNamedMaterial \"d\" \"string type\" \"coatedconductor\" "
           "\"float interface.roughness\" 0.01 \"float conductor.roughness\" 0.04 "
           "\"spectrum conductor.eta\" \"metal-Au-eta\" \"spectrum conductor.k\" \"metal-Au-k\" "
           "\"bool remaproughness\" false \"float thickness\" 0.5 \"integer nsamples\" 4\n" +
           "NamedMaterial \"a\"\n" + tri_at("0 0 0  1 0 0  0 1 0") + "NamedMaterial \"b\"\n" +
           tri_at("0 0 0  1 0 0  0 1 0") + "NamedMaterial \"c\"\n" + tri_at("0 0 0  1 0 0  0 1 0") +
           "NamedMaterial \"d\"\n" + tri_at("0 0 0  1 0 0  0 1 0"));
  ASSERT_EQ(s.triangle_count(), 4u);
  const Material& a = s.materials[size_t(s.triangle_material[0])].gpu;
  const Material& b = s.materials[size_t(s.triangle_material[1])].gpu;
  const Material& c = s.materials[size_t(s.triangle_material[2])].gpu;
  EXPECT_EQ(a.type, MATERIAL_CONDUCTOR);
  EXPECT_NEAR(a.alpha, 0.1f, 1e-6f);
  EXPECT_NEAR(a.specular.x, 0.238f, 1e-6f); // copper, pbrt's default conductor
  EXPECT_NEAR(b.alpha, 0.04f, 1e-6f);
  EXPECT_NEAR(b.specular.x, 0.052f, 1e-6f); // silver
  EXPECT_NEAR(b.k.z, 2.648f, 1e-6f);
  // pbrt-v4's layered materials with its defaults (thickness 0.01, maxdepth 10, nsamples 1).
  EXPECT_EQ(c.type, MATERIAL_COATED_DIFFUSE);
  EXPECT_NEAR(c.alpha, 0.25f, 1e-6f);
  EXPECT_FLOAT_EQ(c.albedo.y, 0.4f);
  EXPECT_FLOAT_EQ(c.ior, 1.4f);
  EXPECT_FLOAT_EQ(c.thickness, 0.01f);
  EXPECT_EQ(c.max_depth, 10);
  EXPECT_EQ(c.n_samples, 1);
  const Material& d = s.materials[size_t(s.triangle_material[3])].gpu;
  EXPECT_EQ(d.type, MATERIAL_COATED_CONDUCTOR);
  EXPECT_NEAR(d.alpha, 0.01f, 1e-6f);
  EXPECT_NEAR(d.base_alpha, 0.04f, 1e-6f);
  EXPECT_FLOAT_EQ(d.ior, 1.5f);
  EXPECT_FLOAT_EQ(d.thickness, 0.5f);
  EXPECT_EQ(d.n_samples, 4);
  const MetalPreset* gold = find_metal_preset("gold");
  EXPECT_FLOAT_EQ(d.specular.x, gold->eta[0]); // the index in vacuum (the BSDF divides by ior)
  EXPECT_FLOAT_EQ(d.k.y, gold->k[1]);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
}

TEST(ScenePbrt, UnknownMaterialAndTextureFallBackWithWarnings) {
  Scene s =
      load(std::string(kKeptCamera) + "WorldBegin\n" + "Texture \"t\" \"spectrum\" \"dots\"\n" +
           "Material \"hair\" \"float eta\" 1.5\n" + tri_at("0 0 0  1 0 0  0 1 0") +
           "Material \"diffuse\" \"texture reflectance\" \"t\"\n" + tri_at("0 0 0  1 0 0  0 1 0"));
  // The unsupported texture class warns where it is defined, not again where it is used.
  ASSERT_EQ(s.warnings.size(), 2u);
  EXPECT_EQ(s.warnings[0].rfind("t.pbrt:5: ", 0), 0u) << s.warnings[0];
  EXPECT_EQ(s.warnings[1].rfind("t.pbrt:6: ", 0), 0u) << s.warnings[1];
  for (size_t t = 0; t < 2; ++t) {
    const Material& m = s.materials[size_t(s.triangle_material[t])].gpu;
    EXPECT_EQ(m.type, MATERIAL_DIFFUSE);
    EXPECT_FLOAT_EQ(m.albedo.x, 0.5f);
  }
}

// A spectrum file (pbrt-v4's (wavelength, value) pairs) as its values at 650, 550 and 450 nm:
// the file's spectrum is 1 + (nm - 400) / 100.
TEST(ScenePbrt, SpectrumFilesAreReadAtTheRgbWavelengths) {
  Scene s = load(std::string(kKeptCamera) + "WorldBegin\n" +
                 "Material \"conductor\" \"spectrum eta\" \"spds/linear.spd\" "
                 "\"spectrum k\" \"spds/linear.spd\"\n" +
                 tri_at("0 0 0  1 0 0  0 1 0"));
  const Material& m = s.materials[size_t(s.triangle_material[0])].gpu;
  EXPECT_FLOAT_EQ(m.specular.x, 3.5f);
  EXPECT_FLOAT_EQ(m.specular.y, 2.5f);
  EXPECT_FLOAT_EQ(m.specular.z, 1.5f);
  EXPECT_FLOAT_EQ(m.k.x, 3.5f);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
  std::string e = error_of(std::string(kKeptCamera) + "WorldBegin\n" +
                           "Material \"conductor\" \"spectrum eta\" \"spds/odd.spd\"\n" +
                           tri_at("0 0 0  1 0 0  0 1 0"));
  EXPECT_EQ(e.rfind("t.pbrt:5: ", 0), 0u) << e;
  EXPECT_NE(e.find("spds/odd.spd"), std::string::npos) << e;
}

TEST(ScenePbrt, DielectricsWithFloatOrNamedGlassIndex) {
  Scene s = load(
      std::string(kKeptCamera) + "WorldBegin\n" + "Material \"dielectric\" \"float eta\" 1.33\n" +
      tri_at("0 0 0  1 0 0  0 1 0") + "Material \"thindielectric\"\n" +
      tri_at("0 0 0  1 0 0  0 1 0") + "Material \"dielectric\" \"spectrum eta\" \"glass-BK7\"\n" +
      tri_at("0 0 0  1 0 0  0 1 0") + "Material \"dielectric\" \"float roughness\" 0.1\n" +
      tri_at("0 0 0  1 0 0  0 1 0"));
  ASSERT_EQ(s.triangle_count(), 4u);
  auto mat = [&](size_t t) { return s.materials[size_t(s.triangle_material[t])].gpu; };
  EXPECT_EQ(mat(0).type, MATERIAL_DIELECTRIC);
  EXPECT_FLOAT_EQ(mat(0).ior, 1.33f);
  EXPECT_EQ(mat(1).type, MATERIAL_THIN_DIELECTRIC);
  EXPECT_FLOAT_EQ(mat(1).ior, 1.5f);       // pbrt-v4's default
  EXPECT_NEAR(mat(2).ior, 1.5185f, 1e-4f); // BK7 at 550 nm
  EXPECT_FLOAT_EQ(mat(3).ior, 1.5f);
  EXPECT_NEAR(mat(3).alpha, std::sqrt(0.1f), 1e-6f); // rough glass, pbrt's remapped roughness
  // The named spectrum (no dispersion) warns at its line.
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].rfind("t.pbrt:9: ", 0), 0u) << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("glass-BK7"), std::string::npos) << s.warnings[0];
  EXPECT_NE(error_of(std::string(kKeptCamera) +
                     "WorldBegin\nMaterial \"dielectric\" "
                     "\"float eta\" -1\n" +
                     tri_at("0 0 0  1 0 0  0 1 0"))
                .find("t.pbrt:5: "),
            std::string::npos);
}

// A tetrahedron wound outward, subdivided: 4^levels triangles, all facing inward as pbrt-v4's do
// (its limit normals, Cross(S, T) in loopsubdiv.cpp, point against the winding, and a triangle
// with vertex normals faces them).
TEST(ScenePbrt, LoopSubdivisionTessellatesAtLoadFacingPbrtsNormals) {
  const std::string tet = "\"point3 P\" [1 1 1  1 -1 -1  -1 1 -1  -1 -1 1] "
                          "\"integer indices\" [0 1 2  0 3 1  0 2 3  1 3 2]";
  for (int levels : {0, 1, 2}) {
    Scene s =
        load(std::string(kKeptCamera) + "WorldBegin\nShape \"loopsubdiv\" \"integer levels\" " +
             std::to_string(levels) + " " + tet + "\n");
    ASSERT_EQ(s.triangle_count(), size_t(4) << (2 * levels));
    EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
    for (size_t t = 0; t < s.triangle_count(); ++t) {
      float3 a = s.vertices[s.indices[3 * t]], b = s.vertices[s.indices[3 * t + 1]],
             c = s.vertices[s.indices[3 * t + 2]];
      // (world = stored + origin; the tetrahedron's centre is the world origin)
      float3 o = make_float3(float(s.origin.x), float(s.origin.y), float(s.origin.z));
      float3 n = cross(b - a, c - a), centre = (a + b + c) * (1.0f / 3.0f) + o;
      EXPECT_LT(dot(n, centre), 0.0f) << "levels " << levels << " triangle " << t;
    }
  }
  EXPECT_NE(error_of(std::string(kKeptCamera) + "WorldBegin\nShape \"loopsubdiv\" " +
                     "\"point3 P\" [0 0 0  1 0 0  0 1 0  0 0 1] "
                     "\"integer indices\" [0 1 2  0 1 2  0 1 2]\n")
                .find("t.pbrt:5: "),
            std::string::npos);
}

// ---------------------------------------------------------------------- errors and warnings

TEST(ScenePbrt, EachErrorIsOneLineNamingFileAndLine) {
  struct Case {
    std::string text, want;
  };
  const Case cases[] = {
      {"WorldBegin\nShape \"sphere\n", "t.pbrt:2: unterminated string"},
      {"WorldBegin\n\nTranslate 1 2.3.4 5\n", "t.pbrt:3: bad number '2.3.4'"},
      {"WorldBegin\nTranslate 1 1e999 5\n", "t.pbrt:2: bad number '1e999'"},
      {"WorldBegin\nTranslate 1 -inf 5\n", "t.pbrt:2: number '-inf' is not finite"},
      {"WorldBegin\nMaterial \"diffuse\"\n  \"float reflectance\" 0.5\n",
       "t.pbrt:3: Material \"diffuse\": \"float reflectance\": wrong parameter type (want rgb, "
       "blackbody or spectrum)"},
      {"WorldBegin\nShape \"sphere\" \"float radius\" \"big\"\n",
       "t.pbrt:2: \"float radius\": expected a number, got \"big\""},
      {"WorldBegin\nAttributeBegin\nAttributeEnd\nAttributeEnd\n",
       "t.pbrt:4: AttributeEnd without AttributeBegin"},
      {"WorldBegin\nAttributeBegin\nTransformBegin\nAttributeEnd\n",
       "t.pbrt:4: AttributeEnd closes the TransformBegin of line 3"},
      {"WorldBegin\nLightSource \"point\" \"rgb I\" [1 2]\n",
       "t.pbrt:2: \"rgb I\": wrong count of values (2; want 3)"},
      {"Translate 1 2\n", "t.pbrt:1: Translate: wrong count of values (2; want 3 numbers)"},
      {"WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] "
       "\"integer indices\" [0 1]\n",
       "t.pbrt:2: Shape \"trianglemesh\": \"integer indices\": wrong count of values (2; want a "
       "multiple of 3)"},
      {"WorldBegin\nInclude \"no_such_file.pbrt\"\n",
       "t.pbrt:2: Include \"" + (kData / "no_such_file.pbrt").lexically_normal().string() +
           "\": cannot open file"},
      {"WorldBegin\nNamedMaterial \"x\"\n", "t.pbrt:2: NamedMaterial: unknown material \"x\""},
      {"WorldBegin\nShape \"sphere\" \"float radius\" -1\n",
       "t.pbrt:2: Shape \"sphere\": \"float radius\": must be > 0"},
      {"LookAt 0 0 0  0 0 0  0 1 0\n", "t.pbrt:1: LookAt: eye and target coincide"},
      {"WorldBegin\nCamera \"perspective\"\n", "t.pbrt:2: Camera is not allowed after WorldBegin"},
      {"WorldBegin\n\"float x\" 1\n", "t.pbrt:2: WorldBegin: unexpected \"float x\""},
      {"# comment\n\n[ 1 ]\n", "t.pbrt:3: expected a directive, got ["},
  };
  for (const Case& c : cases) {
    std::string e = error_of(c.text);
    EXPECT_EQ(e.rfind(c.want, 0), 0u) << "got: " << e << "\nwant: " << c.want;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST(ScenePbrt, IncludeIsRelativeToTheIncludingFileAndImportIsInclude) {
  Scene s = load_scene(kData / "include_main.pbrt");
  EXPECT_EQ(s.triangle_count(), 1u);
}

TEST(ScenePbrt, IncludeCycleNamesTheCycle) {
  std::string e = error_of_file(kData / "cycle_a.pbrt");
  std::string a = (kData / "cycle_a.pbrt").string(),
              b = (kData / "cycle_b.pbrt").lexically_normal().string();
  EXPECT_EQ(e, b + ":2: Include cycle: " + a + " -> " + b + " -> " +
                   (kData / "cycle_a.pbrt").lexically_normal().string());
}

TEST(ScenePbrt, EveryUnknownDirectiveOrParameterWarningNamesFileAndLine) {
  Scene s = load("Frobnicate 1 2 3\n"
                 "Camera \"perspective\" \"float fov\" 50 \"float lensradius\" 0.1\n"
                 "Option \"bool wavefront\" true\n"
                 "WorldBegin\n"
                 "Shape \"curve\"\n"
                 "LightSource \"goniometric\"\n"
                 "LightSource \"projection\"\n"
                 "Shape \"sphere\" \"float radius\" 1 \"float wobble\" 2\n");
  const char* want[] = {"t.pbrt:1: unknown directive 'Frobnicate' ignored",
                        "t.pbrt:2: Camera \"perspective\": \"lensradius\": Canopy's camera is a "
                        "pinhole (no thin lens), ignored",
                        "t.pbrt:3: Option",
                        "t.pbrt:5: Shape \"curve\" is not read in this slice",
                        "t.pbrt:6: LightSource \"goniometric\" is not read",
                        "t.pbrt:7: LightSource \"projection\" is not read",
                        "t.pbrt:8: Shape \"sphere\": unknown parameter \"float wobble\" ignored"};
  ASSERT_EQ(s.warnings.size(), std::size(want));
  for (size_t i = 0; i < std::size(want); ++i) {
    EXPECT_EQ(s.warnings[i].rfind(want[i], 0), 0u) << s.warnings[i];
    EXPECT_NE(s.warnings[i].find("ignored"), std::string::npos) << s.warnings[i];
  }
}

TEST(ScenePbrt, StrictTurnsAWarningIntoAnError) {
  const std::string text = "WorldBegin\nShape \"sphere\"\nLightSource \"goniometric\"\n";
  EXPECT_EQ(error_of(text), "");
  std::string e = error_of(text, true);
  EXPECT_EQ(e.rfind("t.pbrt:3: LightSource \"goniometric\" is not read in this slice, ignored", 0),
            0u)
      << e;
  EXPECT_EQ(e.find('\n'), std::string::npos);
}

TEST(ScenePbrt, ShippedExamplesLoadWithoutWarnings) {
  for (const auto& f : {std::filesystem::path(CANOPY_SCENES_DIR) / "pbrt" / "cornell.pbrt",
                        std::filesystem::path(CANOPY_SCENES_DIR) / "pbrt" / "outdoor.pbrt",
                        kData / "small.pbrt", kData / "ply_scene.pbrt"}) {
    Scene s = load_scene(f, SceneLoadOptions{true});
    EXPECT_GT(s.triangle_count(), 0u) << f;
    EXPECT_FALSE(s.lights.empty()) << f;
  }
}
