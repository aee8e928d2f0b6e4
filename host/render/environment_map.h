// Environment maps on the device: each environment light's image read with OpenImageIO, and its
// sampling distribution (cl/lights/environment.h): one alias table per map over its texels, with
// probability proportional to luminance times the texel's solid angle.
#pragma once

#include "scene/scene.h"

#include <vector>

namespace canopy {

// The environment buffers of the kernels (EnvBuffers), every map concatenated: texel k of the map
// starting at `first` is texels[first + k] (row-major, row 0 = the image's top row); pmf[first + k]
// is its probability; alias_prob / alias_index are the map's alias table (indices within the map).
struct EnvironmentData {
  std::vector<float4> texels;
  std::vector<float> pmf, alias_prob;
  std::vector<int> alias_index;
};

// Reads the map of every environment light in `infinite` (Light::pad indexes `maps`; -1: a constant
// environment), appends it to the returned buffers and writes its first texel, width and height
// into the light (Light::p, cl/types.h LIGHT_ENVIRONMENT) and its projection into Light::flags.
// 8-bit images (PNG, JPEG, ...) are sRGB-decoded; HDR and EXR are taken as linear. Throws
// SceneError naming the file when it cannot be read, has non-finite or negative values, is not
// square for the octahedral projection, or has more than kMaxEnvironmentTexels texels.
EnvironmentData build_environment_data(std::vector<Light>& infinite,
                                       const std::vector<EnvironmentMap>& maps);

// 2^26 texels (an 8192 x 8192 map): 16 bytes + 12 bytes of sampling data each, ~1.9 GB.
constexpr size_t kMaxEnvironmentTexels = size_t(1) << 26;

// Texel weights of a map for its alias table: luminance times the texel's solid angle (exported
// for the tests).
std::vector<double> environment_texel_weights(const std::vector<float4>& texels, int width,
                                              int height, int projection);

} // namespace canopy
