// Conductor presets. The values are measured optical constants n + i k, as tabulated in the
// refractiveindex.info database (CC0), linearly interpolated in wavelength at 650 nm (R), 550 nm
// (G) and 450 nm (B) and rounded to 3 decimals; scripts/metal-presets.py holds the table rows
// used and recomputes every number here. Sources:
//   gold, silver, copper: P. B. Johnson and R. W. Christy, "Optical constants of the noble
//     metals", Phys. Rev. B 6, 4370 (1972).
//   chromium, iron, nickel, titanium: P. B. Johnson and R. W. Christy, "Optical constants of
//     transition metals: Ti, V, Cr, Mn, Fe, Co, Ni, and Pd", Phys. Rev. B 9, 5056 (1974).
//   aluminium: A. D. Rakic, "Algorithm for the determination of intrinsic optical constants of
//     metal films: application to aluminum", Appl. Opt. 34, 4755 (1995).
// A point sample per channel is a simplification (a spectral renderer would integrate the
// spectrum); the resulting normal-incidence reflectances, ((n-1)^2 + k^2) / ((n+1)^2 + k^2),
// are given beside each row.
#include "scene/metal_presets.h"

namespace canopy {

namespace {

// clang-format off
constexpr std::array<MetalPreset, kMetalPresetCount> kPresets = {{
    //               eta R,  G,      B           k R,    G,      B         R(0) R, G, B
    {"gold",      {0.156f, 0.424f, 1.383f}, {3.602f, 2.472f, 1.915f}}, // 0.957 0.792 0.408
    {"silver",    {0.052f, 0.060f, 0.040f}, {4.409f, 3.597f, 2.648f}}, // 0.990 0.983 0.980
    {"copper",    {0.238f, 1.007f, 1.240f}, {3.626f, 2.582f, 2.393f}}, // 0.935 0.624 0.538
    {"aluminium", {1.558f, 1.015f, 0.633f}, {7.712f, 6.627f, 5.454f}}, // 0.906 0.915 0.922
    {"chromium",  {3.107f, 3.181f, 2.323f}, {3.331f, 3.329f, 3.135f}}, // 0.556 0.555 0.555
    {"iron",      {2.911f, 2.950f, 2.584f}, {3.089f, 2.932f, 2.767f}}, // 0.531 0.512 0.496
    {"nickel",    {1.990f, 1.921f, 1.729f}, {4.209f, 3.616f, 2.944f}}, // 0.701 0.644 0.571
    {"titanium",  {2.741f, 2.542f, 2.267f}, {3.814f, 3.435f, 3.038f}}, // 0.616 0.582 0.544
}};
// clang-format on

constexpr std::array<std::string_view, kMetalPresetCount> names_of_presets() {
  std::array<std::string_view, kMetalPresetCount> n{};
  for (size_t i = 0; i < kMetalPresetCount; ++i)
    n[i] = kPresets[i].name;
  return n;
}

constexpr std::array<std::string_view, kMetalPresetCount> kNames = names_of_presets();

} // namespace

const std::array<MetalPreset, kMetalPresetCount>& metal_presets() {
  return kPresets;
}

const std::array<std::string_view, kMetalPresetCount>& metal_preset_names() {
  return kNames;
}

const MetalPreset* find_metal_preset(std::string_view name) {
  for (const MetalPreset& p : kPresets)
    if (p.name == name) return &p;
  return nullptr;
}

} // namespace canopy
