// Images in and out: linear float EXR (with metadata) and sRGB 8-bit PNG, written whole or not at
// all; any image read as linear RGB (image_file.h).
#pragma once

#include "image/image_file.h"

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace canopy {

struct RgbImage {
  int width = 0, height = 0;
  std::vector<float> rgb; // row-major, top row first, 3 floats per pixel, linear
};

// Writes a linear float EXR; `metadata` entries become string attributes (e.g.
// "canopy:sampler"); `window`, if given, places the pixels in a larger display window. Throws
// std::runtime_error naming the file on failure.
void write_exr(const std::filesystem::path& file, const RgbImage& img,
               const std::vector<std::pair<std::string, std::string>>& metadata = {},
               const std::optional<ImageWindow>& window = std::nullopt);

// Writes an 8-bit PNG with the sRGB transfer curve (values clamped to [0, 1]).
void write_png(const std::filesystem::path& file, const RgbImage& img);

// Reads an image (image_file.h: EXR, PNG or what OpenImageIO reads) into RGB float: its first
// three channels as stored.
RgbImage read_image(const std::filesystem::path& file);

float srgb_encode(float linear);
// The inverse of srgb_encode: an sRGB-encoded value in [0, 1] to linear.
float srgb_decode(float encoded);

} // namespace canopy
