#include "render/environment_map.h"

#include "light_tree/light_sampler.h"
#include "lights/environment.h"
#include "render/texture_data.h"

#include <fmt/format.h>

#include <cmath>

namespace canopy {

namespace {

constexpr double kPi = 3.14159265358979323846;

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
    const std::string who =
        map.where.empty() ? map.file.string() : fmt::format("{}: {}", map.where, map.file.string());
    RenderImage img = read_render_image(map.file, "environment map", kMaxEnvironmentTexels, 3,
                                        ImageEncoding::Auto, 1.0f, map.where);
    const int w = img.width, h = img.height;
    std::vector<float4> texels(size_t(w) * size_t(h));
    for (size_t p = 0; p < texels.size(); ++p)
      texels[p] =
          make_float4(img.values[3 * p], img.values[3 * p + 1], img.values[3 * p + 2], 0.0f);
    if (map.projection == ENV_OCTAHEDRAL && w != h)
      throw SceneError(fmt::format("{}: the equal-area octahedral projection needs a square map, "
                                   "not {}x{}",
                                   who, w, h));
    if (d.texels.size() + texels.size() > kMaxEnvironmentTexels)
      throw SceneError(fmt::format("{}: the environment maps have more than {} texels together",
                                   who, kMaxEnvironmentTexels));
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
