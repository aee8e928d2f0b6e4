// A reader for pbrt-v4 scene files (https://pbrt.org/fileformat-v4), the first slice: it builds
// the same canopy::Scene as the JSON loader, so every renderer feature works unchanged. What is
// read, how each construct maps and what is warned about: docs/scene-format.md, "pbrt-v4 scenes".
#pragma once

#include "scene/scene.h"

#include <filesystem>
#include <string>

namespace canopy {

// Reads a .pbrt file and the files it Includes/Imports. Constructs Canopy cannot represent are
// skipped or approximated with a one-line warning "<file>:<line>: ... ignored" in
// Scene::warnings (options.strict: a SceneError instead); malformed input is a SceneError naming
// file:line.
Scene load_pbrt_scene(const std::filesystem::path& file, const SceneLoadOptions& options = {});

// Same, from text; `name` is used in messages and `base_dir` resolves Include paths.
Scene load_pbrt_scene_from_string(const std::string& text, const std::string& name,
                                  const std::filesystem::path& base_dir,
                                  const SceneLoadOptions& options = {});

// Linear sRGB (Rec. 709 primaries, D65 white) of pbrt-v4's BlackbodySpectrum at `kelvin`: Planck's
// law normalised to 1 at its peak wavelength, integrated against the CIE 1931 matching functions
// over 360..830 nm and divided by the integral of y-bar (pbrt's SpectrumToXYZ). Negative
// components (out of the sRGB gamut) are clamped to 0.
float3 blackbody_rgb(double kelvin);

} // namespace canopy
