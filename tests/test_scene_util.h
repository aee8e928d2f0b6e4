// Helpers shared by the test_scene_* tests.
#pragma once

#include "scene/scene.h"

#include <gtest/gtest.h>

#include <string>

namespace canopy::test {

// A camera block that is valid, to build small scenes around.
inline const char* kCamera = R"("camera": {"position": [0, 1, 5], "look_at": [0, 1, 0]})";
inline const char* kPointLight = R"({"type": "point", "position": [0, 2, 0], "intensity": 1})";

// A loaded coordinate in world space: the loader stores coordinates relative to s.origin, the
// camera position (scene.h).
inline float3 world(const Scene& s, float3 p) {
  return make_float3(float(double(p.x) + s.origin.x), float(double(p.y) + s.origin.y),
                     float(double(p.z) + s.origin.z));
}
inline float3 world(const Scene& s, float4 p) {
  return world(s, xyz_of(p));
}

// Loads a scene from a string, named "scene.json", relative paths against tests/data.
inline Scene load_str(const std::string& json) {
  return load_scene_from_string(json, "scene.json", CANOPY_TEST_DATA_DIR);
}

// A scene with the valid camera, the given extra top-level members and, unless `lights` is given,
// one point light.
inline std::string scene_with(const std::string& members,
                              const std::string& lights = std::string("[") + kPointLight + "]") {
  std::string s = std::string("{") + kCamera;
  if (!members.empty()) s += ", " + members;
  if (!lights.empty()) s += ", \"lights\": " + lights;
  return s + "}";
}

// The message of the SceneError thrown by loading `json`, or "(no error)".
inline std::string error_of(const std::string& json) {
  try {
    load_str(json);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "(no error)";
}

} // namespace canopy::test
