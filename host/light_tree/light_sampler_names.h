// The names of the light samplers, the one list every mapping derives from: the scene format
// ("light_sampler"), `canopy render --light-sampler`, `canopy converge`, make_light_sampler() and
// make_light_sampler_data(). Indexed by the SAMPLER_* kinds of cl/types.h.
#pragma once

#include "types.h" // cl/types.h: SAMPLER_*

#include <array>
#include <string_view>

namespace canopy {

inline constexpr std::array<std::string_view, 8> kLightSamplerNames = {
    "uniform", "power", "tree", "tree-split", "exhaustive", "bsdf", "brdf-mis", "brdf-oriented"};
static_assert(kLightSamplerNames.size() == SAMPLER_BRDF_ORIENTED + 1,
              "one name per SAMPLER_* kind");
static_assert(kLightSamplerNames[SAMPLER_UNIFORM] == "uniform" &&
              kLightSamplerNames[SAMPLER_POWER] == "power" &&
              kLightSamplerNames[SAMPLER_TREE] == "tree" &&
              kLightSamplerNames[SAMPLER_TREE_SPLIT] == "tree-split" &&
              kLightSamplerNames[SAMPLER_EXHAUSTIVE] == "exhaustive" &&
              kLightSamplerNames[SAMPLER_BSDF] == "bsdf" &&
              kLightSamplerNames[SAMPLER_BRDF_MIS] == "brdf-mis" &&
              kLightSamplerNames[SAMPLER_BRDF_ORIENTED] == "brdf-oriented");

// The names a scene or the command line may give: every sampler, and "auto", which chooses one of
// them per scene by a pilot render (host/render/auto_sampler.h).
inline constexpr std::string_view kAutoLightSampler = "auto";
inline constexpr std::array<std::string_view, 9> kLightSamplerChoices = {
    "auto",       "uniform", "power",    "tree",         "tree-split",
    "exhaustive", "bsdf",    "brdf-mis", "brdf-oriented"};

// The SAMPLER_* kind named `name`, or -1 if no sampler has that name.
constexpr int light_sampler_kind(std::string_view name) {
  for (size_t k = 0; k < kLightSamplerNames.size(); ++k)
    if (kLightSamplerNames[k] == name) return int(k);
  return -1;
}

} // namespace canopy
