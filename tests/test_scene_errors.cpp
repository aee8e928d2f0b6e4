// Bad input: every case gives one SceneError whose message is exactly
// "<file>: <json path>: <problem>" (or "<file>: line L, column C: <problem>" for JSON syntax).
#include "test_scene_util.h"

#include <fstream>

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
            "sphere, quad, triangle)");
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

TEST(SceneErrors, UnknownLightSampler) {
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"light_sampler": "best"})")),
            "scene.json: integrator.light_sampler: unknown value \"best\" (expected one of: "
            "uniform, power, tree, tree-split, exhaustive)");
}

TEST(SceneErrors, SplitThresholdAboveOne) {
  EXPECT_EQ(error_of(scene_with(R"("integrator": {"split_threshold": 1.5})")),
            "scene.json: integrator.split_threshold: must be in [0, 1]");
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
            "scene.json: materials[0].type: unknown value \"glass\" (expected one of: diffuse)");
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

TEST(SceneErrors, ZeroIntensity) {
  EXPECT_EQ(light_error(R"({"type": "point", "position": [0, 0, 0], "intensity": [0, 0, 0]})"),
            "scene.json: lights[0].intensity: must be > 0");
}

TEST(SceneErrors, NegativeIntensityComponent) {
  EXPECT_EQ(light_error(R"({"type": "point", "position": [0, 0, 0], "intensity": [1, -1, 1]})"),
            "scene.json: lights[0].intensity[1]: must be >= 0");
}

TEST(SceneErrors, ZeroRadiance) {
  EXPECT_EQ(light_error(R"({"type": "sphere", "center": [0, 1, 0], "radius": 1, "radiance": 0})"),
            "scene.json: lights[0].radiance: must be > 0");
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

TEST(SceneErrors, NoEmitters) {
  EXPECT_EQ(error_of(scene_with("", "[]")),
            "scene.json: lights: the scene has no emitters (add lights, light_sets or an emissive "
            "shape)");
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

TEST(SceneErrors, ZeroEmissionShape) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "box", "min": [0, 0, 0],
                                               "max": [1, 1, 1], "emission": 0}])")),
            "scene.json: shapes[0].emission: must be > 0");
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

TEST(SceneErrors, ObjIndexOutOfRange) {
  std::string e = error_of(scene_with(R"("shapes": [{"type": "obj", "file": "bad_index.obj"}])"));
  EXPECT_EQ(e.rfind("scene.json: shapes[0].file: bad_index.obj: ", 0), 0u) << e;
}

TEST(SceneErrors, ObjWithoutFaces) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "obj", "file": "empty.obj"}])")),
            "scene.json: shapes[0].file: empty.obj: contains no faces");
}

// -------------------------------------------------------------------------------- light sets

TEST(SceneErrors, LightSetCountZero) {
  EXPECT_EQ(error_of(scene_with(R"("light_sets": [{"type": "random_box", "min": [0, 0, 0],
               "max": [1, 1, 1], "count": 0, "light": {"type": "point", "intensity": 1}}])")),
            "scene.json: light_sets[0].count: must be in [1, 50000000]");
}

TEST(SceneErrors, LightSetCountTooLarge) {
  EXPECT_EQ(error_of(scene_with(R"("light_sets": [{"type": "random_box", "min": [0, 0, 0],
               "max": [1, 1, 1], "count": 1e8, "light": {"type": "point", "intensity": 1}}])")),
            "scene.json: light_sets[0].count: must be in [1, 50000000]");
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

TEST(SceneErrors, AlignToNormalNeedsSpot) {
  EXPECT_EQ(error_of(scene_with(R"("shapes": [{"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}],
               "light_sets": [{"type": "mesh_surface", "shape": 0, "count": 10,
               "align_to_normal": true, "light": {"type": "point", "intensity": 1}}])")),
            "scene.json: light_sets[0].align_to_normal: applies to spot lights only");
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
