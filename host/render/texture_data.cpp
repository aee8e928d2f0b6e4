#include "render/texture_data.h"

#include "image/image_io.h"
#include "image/stderr_capture.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <cmath>
#include <map>
#include <string>
#include <tuple>

namespace canopy {

namespace {

// Why an image could not be read, for the end of Canopy's one-line message: what the image
// library printed (captured, stderr_capture.h), else the first line of OpenImageIO's error;
// empty if neither says anything.
std::string read_failure(const std::string& printed, const std::string& oiio_error) {
  if (!printed.empty()) return printed;
  return oiio_error.substr(0, oiio_error.find('\n'));
}

} // namespace

RenderImage read_render_image(const std::filesystem::path& file, const std::string& what,
                              size_t max_texels, int channels, ImageEncoding encoding, float gamma,
                              const std::string& where) {
  const std::string name = file.string();
  const std::string who = where.empty() ? name : fmt::format("{}: {}", where, name);
  StderrCapture library_output; // a corrupt PNG makes libpng print its own line
  auto in = OIIO::ImageInput::open(name);
  if (!in) {
    std::string why = read_failure(library_output.finish(), OIIO::geterror());
    throw SceneError(fmt::format("{}: cannot read the {}{}", who, what,
                                 why.empty() ? "" : fmt::format(" ({})", why)));
  }
  const OIIO::ImageSpec spec = in->spec();
  const int nc = spec.nchannels;
  if (spec.width < 1 || spec.height < 1 || nc < 1)
    throw SceneError(fmt::format("{}: a {} needs pixels", who, what));
  if (uint64_t(spec.width) * uint64_t(spec.height) > max_texels)
    throw SceneError(fmt::format("{}: {}x{} texels is more than a {} may have ({})", who,
                                 spec.width, spec.height, what, max_texels));
  std::vector<float> all(size_t(spec.width) * size_t(spec.height) * size_t(nc));
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, all.data())) {
    std::string why = read_failure(library_output.finish(), in->geterror());
    throw SceneError(fmt::format("{}: cannot read the {} (truncated or corrupt{})", who, what,
                                 why.empty() ? "" : ": " + why));
  }
  library_output.finish();
  const bool integer = spec.format.basetype != OIIO::TypeDesc::FLOAT &&
                       spec.format.basetype != OIIO::TypeDesc::HALF &&
                       spec.format.basetype != OIIO::TypeDesc::DOUBLE;
  const bool srgb = encoding == ImageEncoding::Srgb || (encoding == ImageEncoding::Auto && integer);
  auto decode = [&](float v) {
    if (srgb) return srgb_decode(v);
    if (encoding == ImageEncoding::Gamma) return std::pow(std::max(v, 0.0f), gamma);
    return v;
  };
  RenderImage out;
  out.width = spec.width;
  out.height = spec.height;
  out.channels = channels;
  const size_t n = size_t(spec.width) * size_t(spec.height);
  out.values.resize(n * size_t(channels));
  const int colour = std::min(nc, 3) == 2 ? 1 : std::min(nc, 3); // grey + alpha: grey
  for (size_t p = 0; p < n; ++p) {
    float c[3];
    for (int k = 0; k < 3; ++k) {
      float v = all[p * size_t(nc) + size_t(colour == 3 ? k : 0)];
      if (!std::isfinite(v) || v < 0.0f)
        throw SceneError(fmt::format("{}: texel ({}, {}) is {} (a {} must be finite and >= 0)", who,
                                     p % size_t(spec.width), p / size_t(spec.width), v, what));
      c[k] = decode(v);
    }
    if (channels == 1)
      out.values[p] = (c[0] + c[1] + c[2]) / 3.0f;
    else
      std::copy(c, c + 3, out.values.begin() + std::ptrdiff_t(3 * p));
  }
  return out;
}

TextureData build_texture_data(const std::vector<TextureDesc>& textures) {
  TextureData d;
  // Images already in `texels`: (file, channels, encoding, gamma) -> their Texture (first, size).
  std::map<std::tuple<std::string, int, int, float>, Texture> loaded;
  for (const TextureDesc& desc : textures) {
    if (desc.kind != TEXTURE_IMAGE) { // an operator or a constant: no texels
      Texture t{};
      t.kind = desc.kind;
      t.nodes = desc.nodes;
      t.scale = make_float4(desc.scale.x, desc.scale.y, desc.scale.z, 0.0f);
      t.uvmap = desc.uvmap;
      t.map = desc.map;
      d.textures.push_back(t);
      continue;
    }
    auto key = std::make_tuple(desc.file.string(), desc.channels, int(desc.encoding),
                               desc.encoding == ImageEncoding::Gamma ? desc.gamma : 1.0f);
    auto it = loaded.find(key);
    if (it == loaded.end()) {
      RenderImage img = read_render_image(desc.file, "texture", kMaxTextureFloats, desc.channels,
                                          desc.encoding, desc.gamma, desc.where);
      if (d.texels.size() + img.values.size() > kMaxTextureFloats)
        throw SceneError(fmt::format("{}: {}: the textures have more than {} texel values together",
                                     desc.where, desc.file.string(), kMaxTextureFloats));
      Texture t{};
      t.first = int(d.texels.size());
      t.width = img.width;
      t.height = img.height;
      t.channels = img.channels;
      d.texels.insert(d.texels.end(), img.values.begin(), img.values.end());
      it = loaded.emplace(key, t).first;
    }
    Texture t = it->second;
    t.scale = make_float4(desc.scale.x, desc.scale.y, desc.scale.z, 0.0f);
    t.uvmap = desc.uvmap;
    t.wrap = desc.wrap;
    t.map = desc.map;
    t.kind = TEXTURE_IMAGE;
    t.nodes = desc.nodes;
    d.textures.push_back(t);
  }
  return d;
}

} // namespace canopy
