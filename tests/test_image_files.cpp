// Canopy's own EXR and PNG readers (host/image/exr_file.cpp, png_file.cpp) against OpenImageIO,
// an independent implementation: every channel count and sample type written by OpenImageIO reads
// back as OpenImageIO reads it. Other formats go through the OpenImageIO module and read the same
// too. Canopy's writers round-trip exactly (EXR) or to the nearest 8-bit code (PNG).
#include "image/image_file.h"
#include "image/image_io.h"

#include "support/test_temp_dir.h"
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

using namespace canopy;

namespace {

std::filesystem::path temp_dir() {
  return test::test_temp_dir("img");
}

// Random values in [0, 1] (a few exactly 0 and 1), `n` of them.
std::vector<float> random_values(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<float> v(n);
  for (size_t i = 0; i < n; ++i)
    v[i] = i % 17 == 0 ? float(i % 2) : u(rng);
  return v;
}

RgbImage random_image(int w, int h, uint32_t seed) {
  RgbImage img;
  img.width = w;
  img.height = h;
  img.rgb = random_values(size_t(w) * size_t(h) * 3, seed);
  return img;
}

void write_with_oiio(const std::filesystem::path& file, const OIIO::ImageSpec& spec,
                     const std::vector<float>& values) {
  auto out = OIIO::ImageOutput::create(file.string());
  ASSERT_TRUE(out) << OIIO::geterror();
  ASSERT_TRUE(out->open(file.string(), spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, values.data())) << out->geterror();
  ASSERT_TRUE(out->close());
}

// As stored: OpenImageIO would multiply a PNG's colour by its alpha unless asked not to; Canopy,
// as pbrt-v4, reads the colour as stored.
std::vector<float> read_with_oiio(const std::filesystem::path& file) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(file.string(), &config);
  EXPECT_TRUE(in) << OIIO::geterror();
  if (!in) return {};
  const OIIO::ImageSpec& s = in->spec();
  std::vector<float> v(size_t(s.width) * size_t(s.height) * size_t(s.nchannels));
  EXPECT_TRUE(in->read_image(0, 0, 0, s.nchannels, OIIO::TypeDesc::FLOAT, v.data()));
  return v;
}

void expect_reads_as_oiio(const std::filesystem::path& file, int w, int h, int channels,
                          bool floating) {
  SCOPED_TRACE(file.filename().string());
  const std::vector<float> want = read_with_oiio(file);
  DecodedImage got = read_image_file(file);
  EXPECT_EQ(got.width, w);
  EXPECT_EQ(got.height, h);
  ASSERT_EQ(got.channels, channels);
  EXPECT_EQ(got.floating, floating);
  ASSERT_EQ(got.pixels.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i)
    ASSERT_EQ(got.pixels[i], want[i]) << "value " << i;
}

} // namespace

TEST(ImageFiles, PngOfEveryChannelCountAndDepthReadsAsOpenImageIOReadsIt) {
  const auto dir = temp_dir();
  const int w = 13, h = 7;
  for (int channels : {1, 2, 3, 4})
    for (OIIO::TypeDesc type : {OIIO::TypeDesc::UINT8, OIIO::TypeDesc::UINT16}) {
      const auto file = dir / fmt::format("c{}_{}.png", channels, type.c_str());
      OIIO::ImageSpec spec(w, h, channels, type);
      write_with_oiio(file, spec, random_values(size_t(w * h * channels), uint32_t(channels)));
      expect_reads_as_oiio(file, w, h, channels, false);
    }
}

TEST(ImageFiles, ExrOfHalfAndFloatChannelsReadsAsOpenImageIOReadsIt) {
  const auto dir = temp_dir();
  const int w = 9, h = 5;
  for (int channels : {1, 3, 4})
    for (OIIO::TypeDesc type : {OIIO::TypeDesc::HALF, OIIO::TypeDesc::FLOAT}) {
      const auto file = dir / fmt::format("c{}_{}.exr", channels, type.c_str());
      OIIO::ImageSpec spec(w, h, channels, type);
      std::vector<float> v = random_values(size_t(w * h * channels), uint32_t(10 + channels));
      v[3] = 1e30f; // beyond half: OpenImageIO writes it as inf in a half file
      v[4] = -2.5f;
      write_with_oiio(file, spec, v);
      expect_reads_as_oiio(file, w, h, channels, true);
    }
}

// A window of a larger film with string attributes, as `canopy render --crop` writes it: read by
// Canopy's reader and by OpenImageIO, the same window and attributes.
TEST(ImageFiles, ExrWindowAndAttributesRoundTrip) {
  const auto file = temp_dir() / "crop.exr";
  RgbImage img = random_image(6, 4, 3);
  img.rgb[5] = 1e-40f; // a denormal survives
  write_exr(file, img, {{"canopy:samples", "0:16"}, {"canopy:scene", "a b.json"}},
            ImageWindow{10, 20, 64, 48});
  DecodedImage got = read_image_file(file);
  EXPECT_EQ(got.width, 6);
  EXPECT_EQ(got.height, 4);
  EXPECT_EQ(got.channels, 3);
  EXPECT_EQ(got.window.x, 10);
  EXPECT_EQ(got.window.y, 20);
  EXPECT_EQ(got.window.full_width, 64);
  EXPECT_EQ(got.window.full_height, 48);
  EXPECT_EQ(got.pixels, img.rgb);
  auto attr = [&](const std::string& k) {
    for (const auto& [name, value] : got.attributes)
      if (name == k) return value;
    return std::string("(none)");
  };
  EXPECT_EQ(attr("canopy:samples"), "0:16");
  EXPECT_EQ(attr("canopy:scene"), "a b.json");
  auto in = OIIO::ImageInput::open(file.string());
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().x, 10);
  EXPECT_EQ(in->spec().y, 20);
  EXPECT_EQ(in->spec().full_width, 64);
  EXPECT_EQ(in->spec().get_string_attribute("canopy:samples"), "0:16");
  EXPECT_EQ(read_with_oiio(file), img.rgb);
}

// The PNG writer stores the sRGB encoding of each value to the nearest 8-bit code.
TEST(ImageFiles, PngWritesTheNearestSrgbCode) {
  const auto file = temp_dir() / "out.png";
  RgbImage img = random_image(5, 3, 4);
  img.rgb[0] = 2.0f;  // clamped to 1
  img.rgb[1] = -1.0f; // clamped to 0
  write_png(file, img);
  DecodedImage got = read_image_file(file);
  ASSERT_EQ(got.channels, 3);
  EXPECT_FALSE(got.floating);
  for (size_t i = 0; i < img.rgb.size(); ++i)
    ASSERT_EQ(std::lround(255.0f * got.pixels[i]), std::lround(255.0f * srgb_encode(img.rgb[i])))
        << i;
  EXPECT_EQ(read_with_oiio(file), got.pixels);
}

// Other formats are read by OpenImageIO, through the module.
TEST(ImageFiles, OtherFormatsReadThroughTheModule) {
  const auto dir = temp_dir();
  for (const char* name : {"a.tga", "a.tif", "a.hdr"}) {
    const auto file = dir / name;
    const bool hdr = std::string(name) == "a.hdr";
    OIIO::ImageSpec spec(4, 3, 3, hdr ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
    write_with_oiio(file, spec, random_values(4 * 3 * 3, 5));
    expect_reads_as_oiio(file, 4, 3, 3, hdr);
  }
}

// Too many pixels is found from the header, before any pixel is decoded; a file that is not the
// format its name says, or is cut short, is an error with a reason.
TEST(ImageFiles, TooLargeAndBadFilesAreErrors) {
  const auto dir = temp_dir();
  RgbImage img;
  img.width = 3;
  img.height = 2;
  img.rgb.assign(18, 0.5f);
  for (const char* name : {"big.exr", "big.png"}) {
    const auto file = dir / name;
    if (std::string(name) == "big.exr")
      write_exr(file, img);
    else
      write_png(file, img);
    try {
      read_image_file(file, 5);
      ADD_FAILURE() << name << ": no error";
    } catch (const ImageTooLarge& e) {
      EXPECT_EQ(e.width, 3);
      EXPECT_EQ(e.height, 2);
    }
    EXPECT_EQ(read_image_file(file, 6).width, 3);
    // Cut short.
    std::ifstream whole(file, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(whole)), std::istreambuf_iterator<char>());
    const auto cut = dir / fmt::format("cut_{}", name);
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    EXPECT_THROW(read_image_file(cut), ImageFileError) << name;
  }
  std::ofstream(dir / "text.exr") << "not an image";
  EXPECT_THROW(read_image_file(dir / "text.exr"), ImageFileError);
  EXPECT_THROW(read_image_file(dir / "missing.png"), ImageFileError);
}
