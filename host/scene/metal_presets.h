// Named conductors for the scene format's "metal" key: the complex index of refraction eta + i k
// per RGB channel, from measured optical constants (metal_presets.cpp says where and how).
#pragma once

#include <array>
#include <string_view>

namespace canopy {

struct MetalPreset {
  std::string_view name;
  float eta[3]; // real part of the index at the R, G, B wavelengths
  float k[3];   // imaginary part (extinction coefficient)
};

inline constexpr size_t kMetalPresetCount = 8;

// Every preset, in the order docs/scene-format.md lists them.
const std::array<MetalPreset, kMetalPresetCount>& metal_presets();
// Their names (for the scene format's enum check and its message).
const std::array<std::string_view, kMetalPresetCount>& metal_preset_names();
// The preset called `name`, or nullptr.
const MetalPreset* find_metal_preset(std::string_view name);

} // namespace canopy
