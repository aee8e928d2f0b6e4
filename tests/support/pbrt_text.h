// Loading pbrt-v4 text in tests: the scene (paths relative to tests/data/pbrt) and the message of
// its SceneError. Shared by the test_scene_pbrt* and test_scene_textures tests.
#pragma once

#include "scene/pbrt_reader.h"
#include "scene/scene.h"

#include <filesystem>
#include <string>

namespace canopy::test {

inline const std::filesystem::path kPbrtData = std::filesystem::path(CANOPY_TEST_DATA_DIR) / "pbrt";

inline Scene load_pbrt(const std::string& text, bool strict = false) {
  return load_pbrt_scene_from_string(text, "t.pbrt", kPbrtData, SceneLoadOptions{strict});
}

// The SceneError message of loading `text` ("" if it loads).
inline std::string pbrt_error_of(const std::string& text, bool strict = false) {
  try {
    load_pbrt(text, strict);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

} // namespace canopy::test
