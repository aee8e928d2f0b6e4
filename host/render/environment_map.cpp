#include "render/environment_map.h"

#include "image/image_io.h"
#include "light_tree/light_sampler.h"
#include "lights/environment.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <cmath>

namespace canopy {

namespace {

constexpr double kPi = 3.14159265358979323846;

// The map as linear rgb radiance, row 0 = the image's top row.
std::vector<float4> read_map(const std::filesystem::path& file, int* width, int* height) {
  const std::string name = file.string();
  auto in = OIIO::ImageInput::open(name);
  if (!in) throw SceneError(fmt::format("{}: cannot read the environment map", name));
  const OIIO::ImageSpec spec = in->spec();
  const int nc = spec.nchannels;
  if (spec.width < 1 || spec.height < 1 || nc < 1)
    throw SceneError(fmt::format("{}: an environment map needs pixels", name));
  if (uint64_t(spec.width) * uint64_t(spec.height) > kMaxEnvironmentTexels)
    throw SceneError(fmt::format("{}: {}x{} texels is more than an environment map may have ({})",
                                 name, spec.width, spec.height, kMaxEnvironmentTexels));
  std::vector<float> all(size_t(spec.width) * size_t(spec.height) * size_t(nc));
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, all.data()))
    throw SceneError(
        fmt::format("{}: cannot read the environment map (truncated or corrupt)", name));
  // Integer images (PNG, JPEG, TGA, ...) hold sRGB-encoded values; float ones (EXR, HDR) linear.
  const bool srgb = spec.format.basetype != OIIO::TypeDesc::FLOAT &&
                    spec.format.basetype != OIIO::TypeDesc::HALF &&
                    spec.format.basetype != OIIO::TypeDesc::DOUBLE;
  std::vector<float4> texels(size_t(spec.width) * size_t(spec.height));
  for (size_t p = 0; p < texels.size(); ++p) {
    float c[3];
    for (int k = 0; k < 3; ++k) {
      float v = all[p * size_t(nc) + size_t(nc >= 3 ? k : 0)]; // grey: one channel for all three
      if (!std::isfinite(v) || v < 0.0f)
        throw SceneError(fmt::format("{}: texel ({}, {}) is {} (radiance must be finite and >= 0)",
                                     name, p % size_t(spec.width), p / size_t(spec.width), v));
      c[k] = srgb ? srgb_decode(v) : v;
    }
    texels[p] = make_float4(c[0], c[1], c[2], 0.0f);
  }
  *width = spec.width;
  *height = spec.height;
  return texels;
}

} // namespace

std::vector<double> environment_texel_weights(const std::vector<float4>& texels, int width,
                                              int height, int projection) {
  std::vector<double> w(texels.size());
  for (int j = 0; j < height; ++j) {
    // The solid angle of a texel of row j: equal-area octahedral 4 pi / n; equirectangular
    // (2 pi / width) (cos theta_top - cos theta_bottom).
    double omega = projection == ENV_OCTAHEDRAL
                       ? 4.0 * kPi / (double(width) * double(height))
                       : 2.0 * kPi / double(width) *
                             (std::cos(kPi * j / height) - std::cos(kPi * (j + 1) / height));
    for (int i = 0; i < width; ++i) {
      const float4& t = texels[size_t(j) * size_t(width) + size_t(i)];
      w[size_t(j) * size_t(width) + size_t(i)] =
          double(luminance3(make_float3(t.x, t.y, t.z))) * std::max(omega, 0.0);
    }
  }
  return w;
}

EnvironmentData build_environment_data(std::vector<Light>& infinite,
                                       const std::vector<EnvironmentMap>& maps) {
  EnvironmentData d;
  for (Light& l : infinite) {
    if (l.type != LIGHT_ENVIRONMENT) continue;
    if (l.pad < 0) {
      l.flags = ENV_CONSTANT;
      continue;
    }
    const EnvironmentMap& map = maps.at(size_t(l.pad));
    int w = 0, h = 0;
    std::vector<float4> texels = read_map(map.file, &w, &h);
    if (map.projection == ENV_OCTAHEDRAL && w != h)
      throw SceneError(fmt::format("{}: the equal-area octahedral projection needs a square map, "
                                   "not {}x{}",
                                   map.file.string(), w, h));
    if (d.texels.size() + texels.size() > kMaxEnvironmentTexels)
      throw SceneError(fmt::format("{}: the environment maps have more than {} texels together",
                                   map.file.string(), kMaxEnvironmentTexels));
    AliasTable table(environment_texel_weights(texels, w, h, map.projection));
    const uint32_t first = uint32_t(d.texels.size());
    l.p = make_float4(uint_as_float_(first), uint_as_float_(uint32_t(w)),
                      uint_as_float_(uint32_t(h)), 0.0f);
    l.flags = map.projection;
    d.texels.insert(d.texels.end(), texels.begin(), texels.end());
    d.pmf.insert(d.pmf.end(), table.pmfs().begin(), table.pmfs().end());
    d.alias_prob.insert(d.alias_prob.end(), table.thresholds().begin(), table.thresholds().end());
    d.alias_index.insert(d.alias_index.end(), table.aliases().begin(), table.aliases().end());
  }
  return d;
}

} // namespace canopy
