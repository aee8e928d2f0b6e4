// Loading pbrt-v4 text in tests: the scene (paths relative to tests/data/pbrt) and the message of
// its SceneError. Shared by the test_scene_pbrt* and test_scene_textures tests.
#pragma once

#include "scene/pbrt_reader.h"
#include "scene/scene.h"

#include <filesystem>
#include <string>

namespace canopy::test {

// A camera whose frames agree with Canopy's (Scale -1 1 1), so the world is kept as written, and
// the start of the world block: scene text after it starts at line 5.
inline const std::string kPbrtHead = "Scale -1 1 1\n"
                                     "LookAt 0 0 5  0 0 0  0 1 0\n"
                                     "Camera \"perspective\"\n"
                                     "WorldBegin\n";
// One triangle, with whatever material is current.
inline const std::string kPbrtTriangle =
    "Shape \"trianglemesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0] \"integer indices\" [0 1 2]\n";

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
