#include "render/texture_data.h"

#include "image/image_io.h"
#include "image/stderr_capture.h"

#include <fmt/format.h>

#include <cmath>
#include <map>
#include <string>
#include <tuple>

namespace canopy {

RenderImage read_render_image(const std::filesystem::path& file, const std::string& what,
                              size_t max_texels, int channels, ImageEncoding encoding, float gamma,
                              const std::string& where) {
  const std::string name = file.string();
  const std::string who = where.empty() ? name : fmt::format("{}: {}", where, name);
  StderrCapture library_output; // what an image library prints on a bad file joins the message
  DecodedImage img;
  try {
    img = read_image_file(file, max_texels);
  } catch (const ImageTooLarge& e) {
    library_output.finish();
    throw SceneError(fmt::format("{}: {}x{} texels is more than a {} may have ({})", who, e.width,
                                 e.height, what, max_texels));
  } catch (const ImageFileError& e) {
    const std::string printed = library_output.finish();
    throw SceneError(fmt::format("{}: cannot read the {} ({})", who, what,
                                 printed.empty() ? std::string(e.what()) : printed));
  }
  library_output.finish();
  const int nc = img.channels;
  const bool integer = !img.floating;
  const bool srgb = encoding == ImageEncoding::Srgb || (encoding == ImageEncoding::Auto && integer);
  auto decode = [&](float v) {
    if (srgb) return srgb_decode(v);
    if (encoding == ImageEncoding::Gamma) return std::pow(std::max(v, 0.0f), gamma);
    return v;
  };
  RenderImage out;
  out.width = img.width;
  out.height = img.height;
  out.channels = channels;
  const size_t n = size_t(img.width) * size_t(img.height);
  out.values.resize(n * size_t(channels));
  const int colour = std::min(nc, 3) == 2 ? 1 : std::min(nc, 3); // grey + alpha: grey
  for (size_t p = 0; p < n; ++p) {
    float c[3];
    for (int k = 0; k < 3; ++k) {
      float v = img.pixels[p * size_t(nc) + size_t(colour == 3 ? k : 0)];
      if (!std::isfinite(v) || v < 0.0f)
        throw SceneError(fmt::format("{}: texel ({}, {}) is {} (a {} must be finite and >= 0)", who,
                                     p % size_t(img.width), p / size_t(img.width), v, what));
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
