// Bad input: every case gives one SceneError whose message is exactly
// "<file>: <json path>: <problem>" (or "<file>: line L, column C: <problem>" for JSON syntax).
#include "test_scene_util.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sys/stat.h>
#include <unistd.h>

using namespace canopy;
using namespace canopy::test;

namespace {

std::string light_error(const std::string& light) {
  return error_of(scene_with("", "[" + light + "]"));
}

} // namespace

// ------------------------------------------------------------------------------- JSON syntax

TEST(SceneErrors, MalformedJson) {
  EXPECT_EQ(error_of("{\n  \"camera\": {\n    \"position\": [0, 1, 5],\n  }\n}"),
            "scene.json: line 4, column 3: syntax error while parsing object key - unexpected "
            "'}'; expected string literal");
}

TEST(SceneErrors, TruncatedJson) {
  EXPECT_EQ(error_of("{\"camera\": {"),
            "scene.json: line 1, column 13: syntax error while parsing object key - unexpected "
            "end of input; expected string literal");
}

TEST(SceneErrors, EmptyInput) {
  EXPECT_EQ(error_of(""), "scene.json: line 1, column 1: syntax error while parsing value - "
                          "unexpected end of input; expected '[', '{', or a literal");
}

TEST(SceneErrors, NaNLiteralIsSyntaxError) {
  EXPECT_EQ(error_of(scene_with(R"("film": {"width": NaN})")),
            "scene.json: line 1, column 77: syntax error while parsing value - invalid literal; "
            "last read: '\"width\": N'");
}

TEST(SceneErrors, DuplicateKey) {
  EXPECT_EQ(error_of(scene_with(R"("film": {"width": 10, "width": 20})")),
            "scene.json: film.width: duplicate key");
}

TEST(SceneErrors, DuplicateKeyInArray) {
  EXPECT_EQ(light_error(R"({"type": "point", "type": "point", "intensity": 1})"),
            "scene.json: lights[0].type: duplicate key");
}

TEST(SceneErrors, RootNotObject) {
  EXPECT_EQ(error_of("[1, 2]"), "scene.json: (root): must be an object");
}

// ----------------------------------------------------------------------------- keys and types

TEST(SceneErrors, UnknownTopLevelKey) {
  EXPECT_EQ(error_of(scene_with(R"("camra": {})")), "scene.json: camra: unknown key");
}

TEST(SceneErrors, UnknownLightKey) {
  std::string lights = std::string("[") + kPointLight + ", " + kPointLight + R"(, {"type":
      "sphere", "center": [0, 1, 0], "radious": 1, "radiance": 1}])";
  EXPECT_EQ(error_of(scene_with("", lights)), "scene.json: lights[2].radious: unknown key");
}

TEST(SceneErrors, KeyOfAnotherLightType) {
  EXPECT_EQ(light_error(R"({"type": "point", "position": [0, 0, 0], "intensity": 1, "radius": 1})"),
            "scene.json: lights[0].radius: unknown key");
}

TEST(SceneErrors, UnknownLightType) {
  EXPECT_EQ(light_error(R"({"type": "laser", "intensity": 1})"),
            "scene.json: lights[0].type: unknown value \"laser\" (expected one of: point, spot, "
            "sphere, quad, triangle, disk, distant, environment)");
}

TEST(SceneErrors, UnknownShapeType) {
  EXPECT_EQ(
      error_of(scene_with(R"("shapes": [{"type": "teapot"}])")),
      "scene.json: shapes[0].type: unknown value \"teapot\" (expected one of: obj, quad, box)");
}

TEST(SceneErrors, UnknownLightSetType) {
  EXPECT_EQ(error_of(scene_with(R"("light_sets": [{"type": "cloud", "light": {}}])")),
            "scene.json: light_sets[0].type: unknown value \"cloud\" (expected one of: grid, "
            "random_box, spiral, mesh_surface)");
}

TEST(SceneErrors, MissingCamera) {
  EXPECT_EQ(error_of(R"({"lights": []})"), "scene.json: camera: required key is missing");
}

TEST(SceneErrors, MissingRequiredKey) {
  EXPECT_EQ(light_error(R"({"type": "sphere", "center": [0, 1, 0], "radiance": 1})"),
            "scene.json: lights[0].radius: required key is missing");
}

TEST(SceneErrors, WrongTypeNumber) {
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, 1, 5], "look_at": [0, 1, 0], "fov": "wide"},
                         "lights": []})"),
            "scene.json: camera.fov: must be a number");
}

TEST(SceneErrors, WrongTypeVector) {
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, 1], "look_at": [0, 1, 0]}})"),
            "scene.json: camera.position: must be an array of 3 numbers");
}

TEST(SceneErrors, WrongTypeVectorElement) {
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, "1", 5], "look_at": [0, 1, 0]}})"),
            "scene.json: camera.position[1]: must be a number");
}

TEST(SceneErrors, WrongTypeObject) {
  EXPECT_EQ(error_of(scene_with(R"("film": [640, 480])")), "scene.json: film: must be an object");
}

TEST(SceneErrors, WrongTypeArray) {
  EXPECT_EQ(error_of(scene_with("", "{}")), "scene.json: lights: must be an array");
}

TEST(SceneErrors, WrongTypeBool) {
  EXPECT_EQ(light_error(R"({"type": "quad", "corner": [0, 0, 0], "edge1": [1, 0, 0],
                             "edge2": [0, 1, 0], "radiance": 1, "two_sided": 1})"),
            "scene.json: lights[0].two_sided: must be true or false");
}

TEST(SceneErrors, WrongTypeString) {
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"light_sampler": 3})")),
            "scene.json: integrator.light_sampler: must be a string");
}

TEST(SceneErrors, NotAnInteger) {
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"spp": 1.5})")),
            "scene.json: integrator.spp: must be an integer");
}

// -------------------------------------------------------------------------------- NaN and Inf

TEST(SceneErrors, InfiniteNumber) {
  // JSON has no NaN or Inf; a literal beyond the double range is the closest thing.
  EXPECT_EQ(error_of("{\n  \"camera\": {\"position\": [0, 1e999, 0]}}"),
            "scene.json: line 2, column 30: number 1e999 is out of range (must be finite)");
}

TEST(SceneErrors, NumberOutOfFloatRange) {
  EXPECT_EQ(light_error(R"({"type": "point", "position": [0, 0, 0], "intensity": 1e39})"),
            "scene.json: lights[0].intensity: must be finite");
}

// ------------------------------------------------------------------------------------ camera

TEST(SceneErrors, UpParallelToView) {
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, 5, 0], "look_at": [0, 0, 0],
                                    "up": [0, 2, 0]}})"),
            "scene.json: camera.up: must not be parallel to the view direction");
}

TEST(SceneErrors, DefaultUpParallelToView) {
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, 5, 0], "look_at": [0, 0, 0]}})"),
            "scene.json: camera.up: the default [0, 1, 0] is parallel to the view direction; "
            "give camera.up");
}

TEST(SceneErrors, UpZero) {
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0],
                                    "up": [0, 0, 0]}})"),
            "scene.json: camera.up: must not be the zero vector");
}

TEST(SceneErrors, LookAtEqualsPosition) {
  EXPECT_EQ(error_of(R"({"camera": {"position": [1, 2, 3], "look_at": [1, 2, 3]}})"),
            "scene.json: camera.look_at: must differ from camera.position");
}

TEST(SceneErrors, FovZero) {
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 0}})"),
            "scene.json: camera.fov: must be in (0, 180)");
}

TEST(SceneErrors, Fov180) {
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 180}})"),
            "scene.json: camera.fov: must be in (0, 180)");
}

// -------------------------------------------------------------------------- film, integrator

TEST(SceneErrors, FilmZeroWidth) {
  EXPECT_EQ(error_of(scene_with(R"("film": {"width": 0, "height": 10})")),
            "scene.json: film.width: must be in [1, 16384]");
}

TEST(SceneErrors, FilmMillionHeight) {
  EXPECT_EQ(error_of(scene_with(R"("film": {"width": 10, "height": 1000000})")),
            "scene.json: film.height: must be in [1, 16384]");
}

TEST(SceneErrors, SppZero) {
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"spp": 0})")),
            "scene.json: integrator.spp: must be in [1, 16777216]");
}

TEST(SceneErrors, MaxDepthZero) {
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"max_depth": 0})")),
            "scene.json: integrator.max_depth: must be in [1, 1024]");
}

TEST(SceneErrors, BrdfParametersOutOfRange) {
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"brdf_n_max": 0})")),
            "scene.json: integrator.brdf_n_max: must be in [1, 1024]");
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"brdf_lambda": -1})")),
            "scene.json: integrator.brdf_lambda: must be in [0.001, 1000000]");
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"brdf_adaptive": 1})"))
                .rfind("scene.json: integrator.brdf_adaptive: ", 0),
            0u);
}

TEST(SceneErrors, UnknownLightSampler) {
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"light_sampler": "best"})")),
            "scene.json: integrator.light_sampler: unknown value \"best\" (expected one of: "
            "auto, uniform, power, tree, tree-split, exhaustive, bsdf, brdf-mis, brdf-oriented)");
}

TEST(SceneErrors, SplitThresholdAboveOne) {
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"split_threshold": 1.5})")),
            "scene.json: integrator.split_threshold: must be in [0, 1]");
}

TEST(SceneErrors, MaxCutOutOfRange) {
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"max_cut": 0})")),
            "scene.json: integrator.max_cut: must be in [1, 65536]");
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"max_cut": 65537})")),
            "scene.json: integrator.max_cut: must be in [1, 65536]");
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"max_cut": 2.5})")),
            "scene.json: integrator.max_cut: must be an integer");
}

TEST(SceneErrors, MisNotABool) {
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"mis": 0})")),
            "scene.json: integrator.mis: must be true or false");
}

TEST(SceneErrors, SeedNegative) {
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"seed": -1})")),
            "scene.json: integrator.seed: must be in [0, 4294967295]");
}

TEST(SceneErrors, SeedTooLarge) {
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"seed": 4294967296})")),
            "scene.json: integrator.seed: must be in [0, 4294967295]");
}

// --------------------------------------------------------------------------------- materials

TEST(SceneErrors, AlbedoAboveOne) {
  EXPECT_EQ(error_of(scene_with(R"("materials": [{"name": "m", "albedo": [0.5, 1.2, 0.5]}])")),
            "scene.json: materials[0].albedo[1]: must be in [0, 1]");
}

TEST(SceneErrors, AlbedoNegative) {
  EXPECT_EQ(error_of(scene_with(R"("materials": [{"name": "m", "albedo": -0.1}])")),
            "scene.json: materials[0].albedo: must be in [0, 1]");
}

TEST(SceneErrors, DuplicateMaterialName) {
  EXPECT_EQ(error_of(scene_with(R"("materials": [{"name": "m", "albedo": 0.1},
                                                  {"name": "m", "albedo": 0.2}])")),
            "scene.json: materials[1].name: duplicate material name \"m\"");
}

TEST(SceneErrors, UnknownMaterialType) {
  EXPECT_EQ(error_of(scene_with(R"("materials": [{"name": "m", "type": "glass", "albedo": 1}])")),
            "scene.json: materials[0].type: unknown value \"glass\" (expected one of: diffuse, "
            "conductor, plastic, dielectric, coated_diffuse, coated_conductor, "
            "diffuse_transmission, mix)");
}

TEST(SceneErrors, CoatedAndRoughGlassValues) {
  auto err = [](const std::string& m) {
    return error_of(scene_with(R"("materials": [)" + m + "]"));
  };
  EXPECT_EQ(err(R"({"name": "m", "type": "coated_diffuse", "conductor_roughness": 0.1})"),
            "scene.json: materials[0].conductor_roughness: unknown key");
  EXPECT_EQ(err(R"({"name": "m", "type": "coated_conductor", "albedo": 0.5})"),
            "scene.json: materials[0].albedo: unknown key");
  EXPECT_EQ(err(R"({"name": "m", "type": "coated_diffuse", "samples": 0})"),
            "scene.json: materials[0].samples: must be in [1, 64]");
  EXPECT_EQ(err(R"({"name": "m", "type": "coated_conductor", "metal": "gold", "k": 1})"),
            "scene.json: materials[0].k: not allowed together with \"metal\" (give a preset or "
            "eta and k)");
  EXPECT_EQ(err(R"({"name": "m", "type": "dielectric", "thin": true, "roughness": 0.2})"),
            "scene.json: materials[0].roughness: a thin dielectric is smooth");
}

namespace {
std::string material_error(const std::string& material) {
  return error_of(scene_with(R"("materials": [{"name": "ok", "albedo": 0.5}, )" + material + "]"));
}
} // namespace

TEST(SceneErrors, KeyOfAnotherMaterialType) {
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "roughness": 0.1,
      "metal": "gold", "albedo": 0.5})"),
            "scene.json: materials[1].albedo: unknown key");
  EXPECT_EQ(material_error(R"({"name": "m", "roughness": 0.1, "albedo": 0.5})"),
            "scene.json: materials[1].roughness: unknown key"); // diffuse by default
  EXPECT_EQ(material_error(R"({"name": "m", "type": "plastic", "roughness": 0.1,
      "albedo": 0.5, "metal": "gold"})"),
            "scene.json: materials[1].metal: unknown key");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "plastic", "roughness": 0.1,
      "albedo": 0.5, "k": 1})"),
            "scene.json: materials[1].k: unknown key");
}

TEST(SceneErrors, MaterialRoughness) {
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "metal": "gold"})"),
            "scene.json: materials[1].roughness: required key is missing");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "plastic", "albedo": 0.5})"),
            "scene.json: materials[1].roughness: required key is missing");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "metal": "gold",
      "roughness": 1.01})"),
            "scene.json: materials[1].roughness: must be in [0, 1]");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "plastic", "albedo": 0.5,
      "roughness": -0.5})"),
            "scene.json: materials[1].roughness: must be in [0, 1]");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "plastic", "albedo": 0.5,
      "roughness": [0.5]})"),
            "scene.json: materials[1].roughness: must be a number");
}

TEST(SceneErrors, ConductorMetalOrEtaK) {
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "roughness": 0.2})"),
            "scene.json: materials[1]: a conductor needs \"metal\" (a preset name) or \"eta\" "
            "and \"k\"");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "roughness": 0.2,
      "metal": "gold", "eta": 1})"),
            "scene.json: materials[1].eta: not allowed together with \"metal\" (give a preset "
            "or eta and k)");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "roughness": 0.2,
      "k": 1, "metal": "gold"})"),
            "scene.json: materials[1].k: not allowed together with \"metal\" (give a preset or "
            "eta and k)");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "roughness": 0.2, "eta": 1})"),
            "scene.json: materials[1].k: required key is missing");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "roughness": 0.2, "k": 1})"),
            "scene.json: materials[1].eta: required key is missing");
}

TEST(SceneErrors, UnknownMetalListsThePresets) {
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "roughness": 0.2,
      "metal": "Gold"})"),
            "scene.json: materials[1].metal: unknown value \"Gold\" (expected one of: gold, "
            "silver, copper, aluminium, chromium, iron, nickel, titanium)");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "roughness": 0.2,
      "metal": 3})"),
            "scene.json: materials[1].metal: must be a string");
}

TEST(SceneErrors, ConductorEtaKRange) {
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "roughness": 0.2,
      "eta": 0, "k": 1})"),
            "scene.json: materials[1].eta: must be in [0.01, 1000]");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "roughness": 0.2,
      "eta": [1, 1, 0.001], "k": 1})"),
            "scene.json: materials[1].eta[2]: must be in [0.01, 1000]");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "roughness": 0.2,
      "eta": 1, "k": [-0.5, 1, 1]})"),
            "scene.json: materials[1].k[0]: must be in [0, 1000]");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "roughness": 0.2,
      "eta": 1, "k": 1e5})"),
            "scene.json: materials[1].k: must be in [0, 1000]");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "conductor", "roughness": 0.2,
      "eta": [1, 1], "k": 1})"),
            "scene.json: materials[1].eta: must be a number or an array of 3 numbers");
}

TEST(SceneErrors, PlasticRanges) {
  EXPECT_EQ(material_error(R"({"name": "m", "type": "plastic", "roughness": 0.2,
      "albedo": [0.5, 1.5, 0]})"),
            "scene.json: materials[1].albedo[1]: must be in [0, 1]");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "plastic", "roughness": 0.2})"),
            "scene.json: materials[1].albedo: required key is missing");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "plastic", "roughness": 0.2,
      "albedo": 0.5, "specular": [1, -1, 1]})"),
            "scene.json: materials[1].specular[1]: must be >= 0");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "plastic", "roughness": 0.2,
      "albedo": 0.5, "ior": 0.9})"),
            "scene.json: materials[1].ior: must be in [1, 10]");
  EXPECT_EQ(material_error(R"({"name": "m", "type": "plastic", "roughness": 0.2,
      "albedo": 0.5, "ior": 11})"),
            "scene.json: materials[1].ior: must be in [1, 10]");
}

TEST(SceneErrors, UnknownMaterialReference) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "box", "min": [0, 0, 0],
                                               "max": [1, 1, 1], "material": "gold"}])")),
            "scene.json: shapes[0].material: unknown material \"gold\"");
}

// ------------------------------------------------------------------------------------ lights

TEST(SceneErrors, NegativeRadius) {
  EXPECT_EQ(light_error(R"({"type": "sphere", "center": [0, 1, 0], "radius": -1, "radiance": 1})"),
            "scene.json: lights[0].radius: must be > 0");
}

TEST(SceneErrors, ZeroRadius) {
  std::string lights = std::string("[") + kPointLight + ", " + kPointLight + ", " + kPointLight +
                       R"(, {"type": "sphere", "center": [0, 1, 0], "radius": 0, "radiance": 1}])";
  EXPECT_EQ(error_of(scene_with("", lights)), "scene.json: lights[3].radius: must be > 0");
}

// Issue 9, finding 7: a light switched off is accepted, skipped and counted.
TEST(SceneErrors, ZeroIntensityLightIsSkipped) {
  Scene s = load_str(
      scene_with("", std::string("[") +
                         R"({"type": "point", "position": [0, 0, 0], "intensity": [0, 0, 0]}, )" +
                         kPointLight + "]"));
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.skipped_lights, 1u);
  EXPECT_EQ(world(s, s.lights[0].p).y, 2.0f); // the one that shines
}

TEST(SceneErrors, NegativeIntensityComponent) {
  EXPECT_EQ(light_error(R"({"type": "point", "position": [0, 0, 0], "intensity": [1, -1, 1]})"),
            "scene.json: lights[0].intensity[1]: must be >= 0");
}

TEST(SceneErrors, ZeroRadianceLightIsSkipped) {
  Scene s = load_str(
      scene_with("", R"([{"type": "sphere", "center": [0, 1, 0], "radius": 1, "radiance": 0},
              {"type": "quad", "corner": [0, 0, 0], "edge1": [1, 0, 0], "edge2": [0, 0, 1],
               "radiance": [0, 0, 0]}])"));
  EXPECT_TRUE(s.lights.empty());
  EXPECT_EQ(s.skipped_lights, 2u);
}

TEST(SceneErrors, ZeroAreaQuadLight) {
  EXPECT_EQ(light_error(R"({"type": "quad", "corner": [0, 0, 0], "edge1": [1, 0, 0],
                             "edge2": [2, 0, 0], "radiance": 1})"),
            "scene.json: lights[0]: area must be > 0 (edge1 and edge2 are parallel or zero)");
}

TEST(SceneErrors, ZeroAreaTriangleLight) {
  EXPECT_EQ(light_error(R"({"type": "triangle", "v0": [0, 0, 0], "v1": [1, 1, 1],
                             "v2": [2, 2, 2], "radiance": 1})"),
            "scene.json: lights[0]: area must be > 0 (the vertices are collinear)");
}

TEST(SceneErrors, SpotZeroDirection) {
  EXPECT_EQ(light_error(R"({"type": "spot", "position": [0, 0, 0], "direction": [0, 0, 0],
                             "intensity": 1, "cone_angle": 30})"),
            "scene.json: lights[0].direction: must not be the zero vector");
}

TEST(SceneErrors, SpotConeZero) {
  EXPECT_EQ(light_error(R"({"type": "spot", "position": [0, 0, 0], "direction": [0, -1, 0],
                             "intensity": 1, "cone_angle": 0})"),
            "scene.json: lights[0].cone_angle: must be in (0, 180]");
}

TEST(SceneErrors, SpotFalloffBeyondCone) {
  EXPECT_EQ(light_error(R"({"type": "spot", "position": [0, 0, 0], "direction": [0, -1, 0],
                             "intensity": 1, "cone_angle": 30, "falloff_start": 30.5})"),
            "scene.json: lights[0].falloff_start: must be in [0, cone_angle]");
}

// Issue 9, finding 7: a scene without emitters loads (the CLI renders it black with a warning).
TEST(SceneErrors, NoEmittersLoads) {
  Scene s = load_str(scene_with(R"("shapes": [{"type": "quad", "corner": [0, 0, 0],
                                               "edge1": [1, 0, 0], "edge2": [0, 0, 1]}])",
                                "[]"));
  EXPECT_TRUE(s.lights.empty());
  EXPECT_EQ(s.skipped_lights, 0u);
  EXPECT_EQ(s.triangle_count(), 2u);
}

// ------------------------------------------------------------------------------------ shapes

TEST(SceneErrors, ZeroAreaQuadShape) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "quad", "corner": [0, 0, 0],
                                               "edge1": [0, 0, 0], "edge2": [0, 1, 0]}])")),
            "scene.json: shapes[0]: area must be > 0 (edge1 and edge2 are parallel or zero)");
}

TEST(SceneErrors, BoxMaxNotAboveMin) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "box", "min": [0, 0, 0],
                                               "max": [1, 0, 1]}])")),
            "scene.json: shapes[0].max: must be > min in every component");
}

TEST(SceneErrors, ZeroEmissionShapeIsNotAnEmitter) {
  Scene s = load_str(scene_with(R"("shapes": [{"type": "box", "min": [0, 0, 0],
                                               "max": [1, 1, 1], "emission": 0}])"));
  EXPECT_EQ(s.triangle_count(), 12u);
  EXPECT_EQ(s.lights.size(), 1u); // the point light only
  for (int32_t l : s.triangle_light)
    EXPECT_EQ(l, -1);
}

TEST(SceneErrors, ZeroScale) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "obj", "file": "triangle.obj",
                                               "transform": {"scale": [1, 0, 1]}}])")),
            "scene.json: shapes[0].transform.scale: must be non-zero");
}

TEST(SceneErrors, RotateZeroAxis) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "obj", "file": "triangle.obj",
               "transform": {"rotate": {"axis": [0, 0, 0], "degrees": 10}}}])")),
            "scene.json: shapes[0].transform.rotate.axis: must not be the zero vector");
}

TEST(SceneErrors, DuplicateShapeName) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [
               {"type": "box", "name": "a", "min": [0, 0, 0], "max": [1, 1, 1]},
               {"type": "box", "name": "a", "min": [0, 0, 0], "max": [1, 1, 1]}])")),
            "scene.json: shapes[1].name: duplicate shape name \"a\"");
}

// ------------------------------------------------------------------------------- OBJ and MTL

TEST(SceneErrors, MissingObj) {
  std::string dir = CANOPY_TEST_DATA_DIR;
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "obj", "file": "nope.obj"}])")),
            "scene.json: shapes[0].file: cannot open OBJ file '" + dir + "/nope.obj'");
}

TEST(SceneErrors, MissingMtl) {
  std::string dir = CANOPY_TEST_DATA_DIR;
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "obj", "file": "missing_mtl.obj"}])")),
            "scene.json: shapes[0].file: missing_mtl.obj: cannot open material library '" + dir +
                "/does_not_exist.mtl'");
}

TEST(SceneErrors, UnknownUsemtl) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "obj", "file": "unknown_usemtl.obj"}])")),
            "scene.json: shapes[0].file: unknown_usemtl.obj: material [ 'nosuchmaterial' ] not "
            "found in .mtl");
}

TEST(SceneErrors, MtlKdAboveOne) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "obj", "file": "bad_kd.obj"}])")),
            "scene.json: shapes[0].file: bad_kd.obj: material 'toobright': Kd must be in [0, 1]");
}

TEST(SceneErrors, MtlKeNegative) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "obj", "file": "bad_ke.obj"}])")),
            "scene.json: shapes[0].file: bad_ke.obj: material 'negative': Ke must be >= 0");
}

namespace {
// The error of an OBJ triangle whose material is `mtl` (the body of an MTL "newmtl m").
std::string mtl_error(const std::string& mtl) {
  std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "canopy_mtl_mapping";
  std::filesystem::create_directories(dir);
  {
    std::ofstream(dir / "m.obj") << "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n";
  }
  { std::ofstream(dir / "m.mtl") << "newmtl m\n" << mtl; }
  try {
    load_scene_from_string(scene_with(R"("shapes": [{"type": "obj", "file": "m.obj"}])"),
                           "scene.json", dir);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}
} // namespace

TEST(SceneErrors, MtlGlossyValues) {
  EXPECT_EQ(mtl_error("Kd 0.5 0.5 0.5\nKs 0.5 -0.1 0.5\nillum 2\n"),
            "scene.json: shapes[0].file: m.obj: material 'm': Ks must be >= 0");
  EXPECT_EQ(mtl_error("Kd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nNs -1\nillum 2\n"),
            "scene.json: shapes[0].file: m.obj: material 'm': Ns must be >= 0");
  EXPECT_EQ(mtl_error("Kd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nNs 10\nNi 12\nillum 2\n"),
            "scene.json: shapes[0].file: m.obj: material 'm': Ni must be <= 10");
  // Ns and Ni matter only for a glossy material: a diffuse one ignores them.
  EXPECT_EQ(mtl_error("Kd 0.5 0.5 0.5\nKs 0 0 0\nNs -1\nNi 12\nillum 2\n"), "(no error)");
  EXPECT_EQ(mtl_error("Kd 0.5 0.5 0.5\nKs 0.5 0.5 0.5\nNs -1\nNi 12\nillum 1\n"), "(no error)");
}

TEST(SceneErrors, ObjNormalIndexOutOfRange) {
  std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "canopy_vn_range";
  std::filesystem::create_directories(dir);
  { std::ofstream(dir / "n.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n"; }
  std::string m;
  try {
    load_scene_from_string(scene_with(R"("shapes": [{"type": "obj", "file": "n.obj"}])"),
                           "scene.json", dir);
  } catch (const SceneError& e) {
    m = e.what();
  }
  EXPECT_EQ(m, "scene.json: shapes[0].file: n.obj: face 1 of '' has a normal index out of range");
}

TEST(SceneErrors, ObjIndexOutOfRange) {
  std::string e = error_of(scene_with(R"("shapes": [{"type": "obj", "file": "bad_index.obj"}])"));
  EXPECT_EQ(e.rfind("scene.json: shapes[0].file: bad_index.obj: ", 0), 0u) << e;
}

TEST(SceneErrors, ObjWithoutFaces) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "obj", "file": "empty.obj"}])")),
            "scene.json: shapes[0].file: empty.obj: contains no faces");
}

// -------------------------------------------------------------------------------- light sets

// Issue 9, finding 7: a light set with count 0 is accepted, for every type (grid used to divide
// by zero).
TEST(SceneErrors, LightSetCountZeroAccepted) {
  Scene s = load_str(scene_with(R"("shapes": [{"type": "quad", "name": "floor",
      "corner": [-1, 0, -1], "edge1": [0, 0, 2], "edge2": [2, 0, 0]}],
      "light_sets": [
      {"type": "grid", "origin": [0, 0, 0], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "count": 0,
       "light": {"type": "point", "intensity": 1}},
      {"type": "random_box", "min": [0, 0, 0], "max": [1, 1, 1], "count": 0,
       "light": {"type": "point", "intensity": 1}},
      {"type": "spiral", "center": [0, 1, 0], "radius": 1, "turns": 2, "count": 0,
       "light": {"type": "point", "intensity": 1}},
      {"type": "mesh_surface", "shape": "floor", "count": 0,
       "light": {"type": "point", "intensity": 1}}])"));
  EXPECT_EQ(s.lights.size(), 1u); // the point light of scene_with
  EXPECT_EQ(s.skipped_lights, 0u);
}

TEST(SceneErrors, LightSetCountTooLarge) {
  EXPECT_EQ(error_of(scene_with(R"("light_sets": [{"type": "random_box", "min": [0, 0, 0],
               "max": [1, 1, 1], "count": 1e8, "light": {"type": "point", "intensity": 1}}])")),
            "scene.json: light_sets[0].count: must be in [0, 50000000]");
}

TEST(SceneErrors, LightSetTemplateError) {
  EXPECT_EQ(error_of(scene_with(R"("light_sets": [{"type": "grid", "origin": [0, 0, 0],
               "edge1": [1, 0, 0], "edge2": [0, 0, 1], "nx": 2, "ny": 2,
               "light": {"type": "sphere", "radius": 0, "radiance": 1}}])")),
            "scene.json: light_sets[0].light.radius: must be > 0");
}

TEST(SceneErrors, GridCountAndNx) {
  EXPECT_EQ(error_of(scene_with(R"("light_sets": [{"type": "grid", "origin": [0, 0, 0],
               "edge1": [1, 0, 0], "edge2": [0, 0, 1], "nx": 2, "ny": 2, "count": 4,
               "light": {"type": "point", "intensity": 1}}])")),
            "scene.json: light_sets[0].count: give either count or nx and ny, not both");
}

TEST(SceneErrors, SpiralInnerRadius) {
  EXPECT_EQ(error_of(scene_with(R"("light_sets": [{"type": "spiral", "center": [0, 0, 0],
               "radius": 1, "inner_radius": 2, "turns": 3, "count": 10,
               "light": {"type": "point", "intensity": 1}}])")),
            "scene.json: light_sets[0].inner_radius: must be < radius");
}

TEST(SceneErrors, MeshSurfaceUnknownShape) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "box", "name": "b", "min": [0, 0, 0],
               "max": [1, 1, 1]}],
               "light_sets": [{"type": "mesh_surface", "shape": "c", "count": 10,
               "light": {"type": "point", "intensity": 1}}])")),
            "scene.json: light_sets[0].shape: no shape named \"c\" (shapes are matched by name)");
}

TEST(SceneErrors, MeshSurfaceShapeIndexOutOfRange) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}],
               "light_sets": [{"type": "mesh_surface", "shape": 1, "count": 10,
               "light": {"type": "point", "intensity": 1}}])")),
            "scene.json: light_sets[0].shape: must be in [0, 0]");
}

TEST(SceneErrors, DiskLight) {
  EXPECT_EQ(light_error(R"({"type": "disk", "center": [0, 1, 0], "normal": [0, -1, 0],
               "radius": 0, "radiance": 1})"),
            "scene.json: lights[0].radius: must be > 0");
  EXPECT_EQ(light_error(R"({"type": "disk", "center": [0, 1, 0], "normal": [0, -1, 0],
               "radius": -2, "radiance": 1})"),
            "scene.json: lights[0].radius: must be > 0");
  EXPECT_EQ(light_error(R"({"type": "disk", "center": [0, 1, 0], "normal": [0, -1, 0],
               "radius": 1e39, "radiance": 1})"),
            "scene.json: lights[0].radius: must be finite");
  // pi r^2 underflows to 0
  EXPECT_EQ(light_error(R"({"type": "disk", "center": [0, 1, 0], "normal": [0, -1, 0],
               "radius": 1e-30, "radiance": 1})"),
            "scene.json: lights[0].radius: area pi r^2 must be a positive finite float");
  EXPECT_EQ(light_error(R"({"type": "disk", "center": [0, 1, 0], "normal": [0, 0, 0],
               "radius": 1, "radiance": 1})"),
            "scene.json: lights[0].normal: must not be the zero vector");
  EXPECT_EQ(light_error(R"({"type": "disk", "center": [0, 1, 0], "normal": [0, 1e39, 0],
               "radius": 1, "radiance": 1})"),
            "scene.json: lights[0].normal[1]: must be finite");
  EXPECT_EQ(light_error(R"({"type": "disk", "center": [0, 1, 0], "normal": [0, 1, 0],
               "radius": 1, "radiance": [1, -1, 1]})"),
            "scene.json: lights[0].radiance[1]: must be >= 0");
  EXPECT_EQ(light_error(R"({"type": "disk", "center": [0, 1, 0], "normal": [0, 1, 0],
               "radius": 1, "radiance": 1e39})"),
            "scene.json: lights[0].radiance: must be finite");
  EXPECT_EQ(light_error(R"({"type": "disk", "normal": [0, 1, 0], "radius": 1, "radiance": 1})"),
            "scene.json: lights[0].center: required key is missing");
  EXPECT_EQ(light_error(R"({"type": "disk", "center": [0, 1, 0], "radius": 1, "radiance": 1})"),
            "scene.json: lights[0].normal: required key is missing");
  EXPECT_EQ(light_error(R"({"type": "disk", "center": [0, 1, 0], "normal": [0, 1, 0],
               "radius": 1, "radiance": 1, "edge1": [1, 0, 0]})"),
            "scene.json: lights[0].edge1: unknown key");
  EXPECT_EQ(light_error(R"({"type": "disk", "center": [0, 1, 0], "normal": [0, 1, 0],
               "radius": 1, "radiance": 1, "two_sided": 1})"),
            "scene.json: lights[0].two_sided: must be true or false");
  // its bounds leave the coordinate range
  std::string e = light_error(R"({"type": "disk", "center": [0, 1, 0], "normal": [0, 1, 0],
               "radius": 2e18, "radiance": 1})");
  EXPECT_EQ(e.rfind("scene.json: lights[0]: its bounds ", 0), 0u) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos);
}

TEST(SceneErrors, AlignToNormalNeedsSpot) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}],
               "light_sets": [{"type": "mesh_surface", "shape": 0, "count": 10,
               "align_to_normal": true, "light": {"type": "point", "intensity": 1}}])")),
            "scene.json: light_sets[0].align_to_normal: applies to spot and disk lights only");
}

TEST(SceneErrors, VariationScaleZero) {
  EXPECT_EQ(error_of(scene_with(R"("light_sets": [{"type": "random_box", "min": [0, 0, 0],
               "max": [1, 1, 1], "count": 5, "light": {"type": "point", "intensity": 1},
               "variation": {"scale": [0, 1]}}])")),
            "scene.json: light_sets[0].variation.scale[0]: must be > 0");
}

// ------------------------------------------------------------------------------------- files

TEST(SceneErrors, MissingSceneFile) {
  try {
    load_scene("no/such/scene.json");
    FAIL() << "no error";
  } catch (const SceneError& e) {
    EXPECT_STREQ(e.what(), "no/such/scene.json: cannot open file");
  }
}

// Every file in tests/data/bad/ starts with a comment "// expect: <message after the file name>"
// ("{dir}" is the file's directory);
// the same files are run through the CLI by tests/cli_tests.cmake.
TEST(SceneErrors, BadFiles) {
  int n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CANOPY_TEST_DATA_DIR "/bad")) {
    if (entry.path().extension() != ".json") continue;
    std::ifstream in(entry.path());
    std::string first;
    std::getline(in, first);
    const std::string tag = "// expect: ";
    ASSERT_EQ(first.rfind(tag, 0), 0u) << entry.path();
    std::string expected = entry.path().string() + ": " + first.substr(tag.size());
    // "{dir}" stands for the directory of the scene file as given.
    if (auto p = expected.find("{dir}"); p != std::string::npos)
      expected.replace(p, 5, entry.path().parent_path().string());
    try {
      load_scene(entry.path());
      ADD_FAILURE() << entry.path() << ": no error";
    } catch (const SceneError& e) {
      EXPECT_EQ(std::string(e.what()), expected);
    }
    ++n;
  }
  EXPECT_GE(n, 5);
}

// ------------------------------------------------------ issue 9, finding 6: derived coordinates
// Inputs that are finite but whose derived vertices, lights or bounds leave the range the float
// pipeline supports (|x| <= kMaxCoordinate, docs/limits.md) are one-line errors naming the entry.

namespace {
const std::string kOutside =
    " is outside the supported coordinate range |x| <= 1e+18 (docs/limits.md)";
} // namespace

TEST(SceneErrors, BoxBeyondCoordinateRange) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "box", "min": [-3e38, -3e38, -3e38],
                                               "max": [3e38, 3e38, 3e38]}])")),
            "scene.json: shapes[0]: vertex 1 after the transform: [-3e+38, -3e+38, -3e+38]" +
                kOutside);
  // The limit itself is inside the range.
  Scene s = load_str(scene_with(R"("shapes": [{"type": "box", "min": [-1e18, -1e18, -1e18],
                                               "max": [1e18, 1e18, 1e18]}])"));
  EXPECT_EQ(s.triangle_count(), 12u);
}

TEST(SceneErrors, TransformScaleBeyondCoordinateRange) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "quad", "corner": [-1, 0, -1],
      "edge1": [0, 0, 2], "edge2": [2, 0, 0], "transform": {"scale": [3e38, 1, 1]}}])")),
            "scene.json: shapes[0]: vertex 1 after the transform: [-3e+38, 0, -1]" + kOutside);
}

TEST(SceneErrors, TransformDeterminantOverflows) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "quad", "corner": [-1, 0, -1],
      "edge1": [0, 0, 2], "edge2": [2, 0, 0], "transform": {"scale": 3e38}}])")),
            "scene.json: shapes[0].transform: is too large (its determinant overflows; "
            "docs/limits.md)");
}

TEST(SceneErrors, LightSetOriginBeyondCoordinateRange) {
  EXPECT_EQ(error_of(scene_with(R"("light_sets": [{"type": "grid", "origin": [3e38, 0, 0],
      "edge1": [1, 0, 0], "edge2": [0, 0, 1], "count": 4,
      "light": {"type": "point", "intensity": 1}}])")),
            "scene.json: light_sets[0]: light 1 (of 4): its position [3e+38, 0, 0.25]" + kOutside);
}

TEST(SceneErrors, LightSetInstanceBeyondCoordinateRange) {
  EXPECT_EQ(error_of(scene_with(R"("light_sets": [{"type": "grid", "origin": [0, 0, 0],
      "edge1": [1, 0, 0], "edge2": [0, 0, 1], "count": 1,
      "light": {"type": "point", "intensity": 1},
      "instance": {"type": "quad", "corner": [0, 0, 0], "edge1": [2e18, 0, 0],
                   "edge2": [0, 0, 1]}}])")),
            "scene.json: light_sets[0]: instance 1 (of 1): vertex 2 after the transform: "
            "[2e+18, 0, 0.5]" +
                kOutside);
}

TEST(SceneErrors, LightBeyondCoordinateRange) {
  EXPECT_EQ(light_error(R"({"type": "point", "position": [0, 2e18, 0], "intensity": 1})"),
            "scene.json: lights[0]: its position [0, 2e+18, 0]" + kOutside);
  // A sphere is checked by its bounds, a quad by its corners.
  EXPECT_EQ(light_error(R"({"type": "sphere", "center": [0, 0, 0], "radius": 3e18,
                            "radiance": 1})"),
            "scene.json: lights[0]: its bounds [3e+18, 3e+18, 3e+18]" + kOutside);
  EXPECT_EQ(light_error(R"({"type": "quad", "corner": [9e17, 0, 0], "edge1": [2e17, 0, 0],
                            "edge2": [0, 0, 1], "radiance": 1})"),
            "scene.json: lights[0]: a corner [1.1e+18, 0, 0]" + kOutside);
}

TEST(SceneErrors, CameraBeyondCoordinateRange) {
  EXPECT_EQ(error_of(R"({"camera": {"position": [0, 0, 1e19], "look_at": [0, 0, 0]},
                         "lights": [{"type": "point", "position": [0, 2, 0], "intensity": 1}]})"),
            "scene.json: camera.position: [0, 0, 1e+19]" + kOutside);
}

// ------------------------------------------------- issue 9, finding 6: echoed strings are escaped

namespace {
// One line, no NUL: what a terminal shows is what the message holds.
void expect_one_line(const std::string& m) {
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  EXPECT_EQ(m.find('\r'), std::string::npos) << m;
  EXPECT_EQ(m.find('\0'), std::string::npos) << m;
}
} // namespace

TEST(SceneErrors, KeyWithNewlineIsEscaped) {
  std::string m = error_of(scene_with(R"("film": {"wid\nth": 4})"));
  EXPECT_EQ(m, "scene.json: film.wid\\nth: unknown key");
  expect_one_line(m);
}

TEST(SceneErrors, KeyWithNulIsEscaped) {
  std::string m = error_of(scene_with(R"("film": {"wid\u0000th": 4})"));
  EXPECT_EQ(m, "scene.json: film.wid\\x00th: unknown key");
  expect_one_line(m);
}

TEST(SceneErrors, DuplicateKeyWithControlCharactersIsEscaped) {
  std::string m = error_of(scene_with(R"("film": {"a\tb": 4, "a\tb": 4})"));
  EXPECT_EQ(m, "scene.json: film.a\\tb: duplicate key");
}

TEST(SceneErrors, LongKeyIsTruncated) {
  std::string key(5000, 'k');
  std::string m = error_of(scene_with("\"film\": {\"" + key + "\": 4}"));
  EXPECT_EQ(m, "scene.json: film." + std::string(64, 'k') + "\u2026: unknown key");
}

TEST(SceneErrors, EnumValueIsEscaped) {
  std::string m = error_of(scene_with(R"("integrator": {"light_sampler": "tree\r\nsplit"})"));
  EXPECT_EQ(m, "scene.json: integrator.light_sampler: unknown value \"tree\\r\\nsplit\" (expected "
               "one of: auto, uniform, power, tree, tree-split, exhaustive, bsdf, brdf-mis, "
               "brdf-oriented)");
}

TEST(SceneErrors, MaterialNameIsEscaped) {
  // U+0085 (NEL) and U+2028 (line separator) are line breaks to some terminals.
  std::string m = error_of(scene_with(R"("shapes": [{"type": "quad", "corner": [0, 0, 0],
      "edge1": [1, 0, 0], "edge2": [0, 0, 1], "material": "m\u0085\u2028\u001bx"}])"));
  EXPECT_EQ(m, "scene.json: shapes[0].material: unknown material \"m\\u0085\\u2028\\x1bx\"");
}

TEST(SceneErrors, InvalidUtf8InTheTextIsEscaped) {
  std::string m = error_of(scene_with("\"film\": {\"w\xff\xfe\": 4}"));
  EXPECT_NE(m.find("\\xff"), std::string::npos) << m;
  expect_one_line(m);
  for (unsigned char c : m)
    EXPECT_LT(c, 0x80) << m; // the bytes 0xff 0xfe are escaped, nothing else is non-ASCII here
}

TEST(SceneErrors, ObjFileNameIsEscaped) {
  std::string m = error_of(scene_with(R"("shapes": [{"type": "obj", "file": "no\nsuch.obj"}])"));
  EXPECT_NE(m.find("no\\nsuch.obj"), std::string::npos) << m;
  expect_one_line(m);
}

TEST(SceneErrors, PrintableKeepsValidTextAndEscapesTheRest) {
  EXPECT_EQ(printable("plain ASCII, caf\xc3\xa9, \xe2\x82\xac"),
            "plain ASCII, caf\xc3\xa9, \xe2\x82\xac");
  EXPECT_EQ(printable(std::string("a\0b", 3)), "a\\x00b");
  EXPECT_EQ(printable("\x7f\x1b"), "\\x7f\\x1b");
  // Overlong encodings, surrogates, truncated sequences and stray continuation bytes.
  EXPECT_EQ(printable("\xc0\xaf"), "\\xc0\\xaf");
  EXPECT_EQ(printable("\xed\xa0\x80"), "\\xed\\xa0\\x80");
  EXPECT_EQ(printable("\xe2\x82"), "\\xe2\\x82");
  EXPECT_EQ(printable("\x80"), "\\x80");
  EXPECT_EQ(printable("abcdef", 3), "abc\u2026");
  EXPECT_EQ(printable("abc", 3), "abc");
}

// ------------------------------------------------------- issue 9, finding 6: OBJ numbers, faces

TEST(SceneErrors, ObjNanVertex) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "obj", "file": "nan_vertex.obj"}])")),
            "scene.json: shapes[0].file: nan_vertex.obj: line 3: 'v': 'nan' is not a finite "
            "number");
}

TEST(SceneErrors, ObjVertexWithOneNumber) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "obj", "file": "short_vertex.obj"}])")),
            "scene.json: shapes[0].file: short_vertex.obj: line 3: 'v' needs 3 numbers, found 1");
}

TEST(SceneErrors, ObjUnparsableNumber) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "obj", "file": "bad_number.obj"}])")),
            "scene.json: shapes[0].file: bad_number.obj: line 4: 'v': '0x1p3' is not a finite "
            "number");
}

TEST(SceneErrors, ObjPolygonAboveTheVertexLimit) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "obj", "file": "huge_polygon.obj"}])")),
            "scene.json: shapes[0].file: huge_polygon.obj: line 1027: a face with 1025 vertices "
            "(the limit is 1024, docs/limits.md)");
  // At the limit, a convex 1024-gon loads as n - 2 triangles, within a time budget far above its
  // measured 15 ms (the limit exists because tinyobjloader's triangulation is quadratic: 10^5
  // vertices took > 60 s).
  std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "canopy_polygon";
  std::filesystem::create_directories(dir);
  {
    std::ofstream obj(dir / "poly.obj");
    const int n = kMaxPolygonVertices;
    for (int i = 0; i < n; ++i)
      obj << "v " << std::cos(6.283185307179586 * i / n) << " 0 "
          << std::sin(6.283185307179586 * i / n) << "\n";
    obj << "f";
    for (int i = 1; i <= n; ++i)
      obj << " " << i;
    obj << "\n";
  }
  auto t0 = std::chrono::steady_clock::now();
  Scene s = load_scene_from_string(scene_with(R"("shapes": [{"type": "obj", "file": "poly.obj"}])"),
                                   "scene.json", dir);
  double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(s.triangle_count(), size_t(kMaxPolygonVertices - 2));
  EXPECT_LT(sec, 2.0);
}

// ------------------------------------------------ issue 9, finding 6: files that are not files

namespace {
std::string load_error(const std::filesystem::path& p) {
  try {
    load_scene(p);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}
} // namespace

TEST(SceneErrors, SceneFifoIsRefusedWithoutBlocking) {
  std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "canopy_fifo";
  std::filesystem::create_directories(dir);
  std::filesystem::path fifo = dir / "scene.json";
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // With no writer, opening a FIFO for reading blocks forever: this returning at all is the test.
  EXPECT_EQ(load_error(fifo),
            fifo.string() + ": cannot open file (it is a FIFO, not a regular file)");
  std::filesystem::remove(fifo);
}

TEST(SceneErrors, SceneDeviceIsRefused) {
  EXPECT_EQ(load_error("/dev/zero"),
            "/dev/zero: cannot open file (it is a character device, not a regular file)");
}

TEST(SceneErrors, SceneDirectoryIsRefused) {
  std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "canopy_dir.json";
  std::filesystem::create_directories(dir);
  EXPECT_EQ(load_error(dir),
            dir.string() + ": cannot open file (it is a directory, not a regular file)");
}

TEST(SceneErrors, SceneFileAboveTheSizeLimit) {
  std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "canopy_large";
  std::filesystem::create_directories(dir);
  std::filesystem::path f = dir / "scene.json";
  { std::ofstream(f) << " "; }
  std::filesystem::resize_file(f, kMaxSceneFileBytes + 1); // sparse: no disk space used
  EXPECT_EQ(load_error(f),
            f.string() + ": file is too large (268435457 bytes, the limit is 256 MiB)");
  std::filesystem::remove(f);
}

TEST(SceneErrors, ObjFifoIsRefusedWithoutBlocking) {
  std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "canopy_obj_fifo";
  std::filesystem::create_directories(dir);
  std::filesystem::path fifo = dir / "mesh.obj";
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string m;
  try {
    load_scene_from_string(scene_with(R"("shapes": [{"type": "obj", "file": "mesh.obj"}])"),
                           "scene.json", dir);
  } catch (const SceneError& e) {
    m = e.what();
  }
  EXPECT_EQ(m, "scene.json: shapes[0].file: mesh.obj: cannot open file (it is a FIFO, not a "
               "regular file)");
  std::filesystem::remove(fifo);
}

TEST(SceneErrors, MtlFifoIsRefusedWithoutBlocking) {
  std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "canopy_mtl_fifo";
  std::filesystem::create_directories(dir);
  { std::ofstream(dir / "mesh.obj") << "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"; }
  std::filesystem::path fifo = dir / "m.mtl";
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string m;
  try {
    load_scene_from_string(scene_with(R"("shapes": [{"type": "obj", "file": "mesh.obj"}])"),
                           "scene.json", dir);
  } catch (const SceneError& e) {
    m = e.what();
  }
  EXPECT_EQ(m, "scene.json: shapes[0].file: mesh.obj: m.mtl: cannot open file (it is a FIFO, not "
               "a regular file)");
  std::filesystem::remove(fifo);
}

// --------------------------------------------------------------------------------- medium

TEST(SceneErrors, MediumValues) {
  auto medium = [](const std::string& body) {
    return error_of(scene_with(R"("medium": {)" + body + "}"));
  };
  EXPECT_EQ(medium(R"("sigma_s": 0.1)"), "scene.json: medium.sigma_a: required key is missing");
  EXPECT_EQ(medium(R"("sigma_a": -0.1, "sigma_s": 0.1)"),
            "scene.json: medium.sigma_a: must be in [0, 1e+20]");
  EXPECT_EQ(medium(R"("sigma_a": 0, "sigma_s": [0.1, -1, 0])"),
            "scene.json: medium.sigma_s[1]: must be in [0, 1e+20]");
  EXPECT_EQ(medium(R"("sigma_a": 0, "sigma_s": 1e21)"),
            "scene.json: medium.sigma_s: must be in [0, 1e+20]");
  EXPECT_EQ(medium(R"("sigma_a": 0, "sigma_s": 0.1, "g": 1)"),
            "scene.json: medium.g: must be in (-1, 1)");
  EXPECT_EQ(medium(R"("sigma_a": 0, "sigma_s": 0.1, "density": 1)"),
            "scene.json: medium.density: unknown key");
  EXPECT_EQ(
      medium(R"("sigma_a": 0, "sigma_s": 0.1, "bounds": {"min": [0, 0, 0], "max": [1, 0, 1]})"),
      "scene.json: medium.bounds.max: must exceed bounds.min in every coordinate");
  EXPECT_EQ(medium(R"("sigma_a": 0, "sigma_s": 0.1, "bounds": {"min": [0, 0, 0]})"),
            "scene.json: medium.bounds.max: required key is missing");
  EXPECT_EQ(
      medium(R"("sigma_a": 0, "sigma_s": 0.1, "bounds": {"min": [0, 0, 0], "max": [1e19, 1, 1]})")
          .rfind("scene.json: medium.bounds.max: ", 0),
      0u);
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"volume_importance": "centre"})")),
            "scene.json: integrator.volume_importance: unknown value \"centre\" (expected one of: "
            "segment, midpoint)");
}
