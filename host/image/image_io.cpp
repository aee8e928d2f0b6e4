#include "image/image_io.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace canopy {

float srgb_encode(float x) {
  x = std::clamp(x, 0.0f, 1.0f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

namespace {

void write_pixels(const std::filesystem::path& file, const OIIO::ImageSpec& spec,
                  OIIO::TypeDesc type, const void* data) {
  std::filesystem::path parent = file.parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  auto out = OIIO::ImageOutput::create(file.string());
  if (!out)
    throw std::runtime_error(fmt::format("{}: cannot write ({})", file.string(), OIIO::geterror()));
  if (!out->open(file.string(), spec) || !out->write_image(type, data) || !out->close())
    throw std::runtime_error(fmt::format("{}: cannot write ({})", file.string(), out->geterror()));
}

} // namespace

void write_exr(const std::filesystem::path& file, const RgbImage& img,
               const std::vector<std::pair<std::string, std::string>>& metadata) {
  OIIO::ImageSpec spec(img.width, img.height, 3, OIIO::TypeDesc::FLOAT);
  spec.attribute("compression", "zip");
  for (const auto& [k, v] : metadata)
    spec.attribute(k, v);
  write_pixels(file, spec, OIIO::TypeDesc::FLOAT, img.rgb.data());
}

void write_png(const std::filesystem::path& file, const RgbImage& img) {
  std::vector<unsigned char> px(img.rgb.size());
  for (size_t i = 0; i < px.size(); ++i)
    px[i] = (unsigned char)std::lround(255.0f * srgb_encode(img.rgb[i]));
  OIIO::ImageSpec spec(img.width, img.height, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", "sRGB");
  write_pixels(file, spec, OIIO::TypeDesc::UINT8, px.data());
}

RgbImage read_image(const std::filesystem::path& file) {
  auto in = OIIO::ImageInput::open(file.string());
  if (!in)
    throw std::runtime_error(
        fmt::format("{}: cannot read image ({})", file.string(), OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.nchannels < 3)
    throw std::runtime_error(fmt::format("{}: need at least 3 channels", file.string()));
  RgbImage img;
  img.width = spec.width;
  img.height = spec.height;
  std::vector<float> all(size_t(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
    throw std::runtime_error(
        fmt::format("{}: cannot read image ({})", file.string(), in->geterror()));
  img.rgb.resize(size_t(spec.width) * spec.height * 3);
  for (size_t p = 0; p < size_t(spec.width) * spec.height; ++p)
    for (int c = 0; c < 3; ++c)
      img.rgb[3 * p + c] = all[p * spec.nchannels + c];
  return img;
}

} // namespace canopy
