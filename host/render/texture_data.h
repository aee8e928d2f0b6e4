// Image textures on the device (cl/texture.h): every TextureDesc's image read with OpenImageIO into
// one texel buffer, and the images that the renderer reads for environment lights too.
#pragma once

#include "scene/scene.h"

#include <filesystem>
#include <string>
#include <vector>

namespace canopy {

// An image read for rendering: `channels` linear floats per texel, row-major, row 0 = the image's
// top row.
struct RenderImage {
  int width = 0, height = 0, channels = 3;
  std::vector<float> values;
};

// Reads `file` as `channels` (3: rgb, a grey image's one channel thrice; 1: the mean of its colour
// channels) linear values. `what` names it in messages ("environment map", "texture"), after
// `where` when given. Throws SceneError naming the file when it cannot be read (with the image
// library's reason; what the library prints on stderr meanwhile is captured, not shown), has no
// pixels, more than `max_texels` texels, or a value that is not finite and >= 0 (after decoding).
RenderImage read_render_image(const std::filesystem::path& file, const std::string& what,
                              size_t max_texels, int channels,
                              ImageEncoding encoding = ImageEncoding::Auto, float gamma = 1.0f,
                              const std::string& where = {});

// The kernels' textures and texels buffers (SCENE_BUFFERS): textures[i] is Scene::textures[i];
// an image used by several textures with the same channels and encoding is stored once.
struct TextureData {
  std::vector<Texture> textures;
  std::vector<float> texels;
};

// 2^30 floats (4 GiB) of texels in all: the kernels index them with 32-bit ints.
constexpr size_t kMaxTextureFloats = size_t(1) << 30;

TextureData build_texture_data(const std::vector<TextureDesc>& textures);

} // namespace canopy
