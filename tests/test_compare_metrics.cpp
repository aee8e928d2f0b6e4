// Image error metrics of `canopy compare` / `canopy converge` (host/image/image_compare.h) against
// hand-computed values on tiny synthetic images, and against OpenImageIO's ImageBufAlgo::compare.
#include "image/image_compare.h"
#include "image/image_io.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace {

using namespace canopy;

RgbImage make(int w, int h, std::vector<float> rgb) {
  RgbImage img;
  img.width = w;
  img.height = h;
  img.rgb = std::move(rgb);
  return img;
}

TEST(CompareMetrics, HandComputedValues) {
  // Two pixels; the differences are 1 (pixel 0, red, reference 0) and 0.5 (pixel 1, blue,
  // reference 0.5).
  RgbImage a = make(2, 1, {1, 0, 0, 0, 0, 0});
  RgbImage r = make(2, 1, {0, 0, 0, 0, 0, 0.5f});
  ImageMetrics m = compare_images(a, r);
  EXPECT_DOUBLE_EQ(m.mse, 1.25 / 6.0);
  EXPECT_DOUBLE_EQ(m.rmse, std::sqrt(1.25 / 6.0));
  // relMSE = (1 / (0 + 0.01) + 0.25 / (0.25 + 0.01)) / 6
  EXPECT_NEAR(m.relmse, (100.0 + 0.25 / 0.26) / 6.0, 1e-12);
  // peak = max(1, largest value) = 1
  EXPECT_NEAR(m.psnr, 10.0 * std::log10(6.0 / 1.25), 1e-12);
  EXPECT_NEAR(m.psnr, 6.812412, 1e-6);
  EXPECT_DOUBLE_EQ(m.max_abs, 1.0);
  EXPECT_EQ(m.nonfinite, 0u);
}

TEST(CompareMetrics, RelativeEpsilonIsAParameter) {
  RgbImage a = make(1, 1, {2, 2, 2});
  RgbImage r = make(1, 1, {1, 1, 1});
  EXPECT_NEAR(compare_images(a, r).relmse, 1.0 / 1.01, 1e-12);
  EXPECT_NEAR(compare_images(a, r, 0.0).relmse, 1.0, 1e-12);
}

TEST(CompareMetrics, IdenticalImagesHaveZeroErrorAndInfinitePsnr) {
  RgbImage a = make(2, 2, {0.1f, 0.2f, 0.3f, 1, 2, 3, 4, 5, 6, 0, 0, 0});
  ImageMetrics m = compare_images(a, a);
  EXPECT_EQ(m.mse, 0.0);
  EXPECT_EQ(m.rmse, 0.0);
  EXPECT_EQ(m.relmse, 0.0);
  EXPECT_TRUE(std::isinf(m.psnr) && m.psnr > 0);
}

TEST(CompareMetrics, PsnrPeakIsTheLargestValueAsInOpenImageIO) {
  // A constant 0.5 against 0.25 (peak 1): PSNR = 10 log10(1 / 0.0625) = 12.0412 dB.
  RgbImage a = make(1, 1, {0.5f, 0.5f, 0.5f});
  RgbImage r = make(1, 1, {0.25f, 0.25f, 0.25f});
  EXPECT_NEAR(compare_images(a, r).psnr, 12.041199826559248, 1e-9);
  // With values above 1 the peak is the largest value: 4 here.
  RgbImage b = make(2, 1, {4, 0, 0, 0.5f, 0.5f, 0.5f});
  RgbImage s = make(2, 1, {3, 0, 0, 0.25f, 0.25f, 0.25f});
  ImageMetrics m = compare_images(b, s);
  EXPECT_DOUBLE_EQ(m.peak, 4.0);
  EXPECT_NEAR(m.psnr, 10.0 * std::log10(16.0 / m.mse), 1e-12);
}

TEST(CompareMetrics, AgreesWithOpenImageIOCompare) {
  const int w = 7, h = 5;
  RgbImage a = make(w, h, std::vector<float>(size_t(w * h * 3)));
  RgbImage r = a;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    a.rgb[i] = float(std::fmod(0.37 * double(i * i) + 0.1, 2.5));
    r.rgb[i] = float(std::fmod(0.11 * double(i) + 0.3, 1.7));
  }
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf A(spec, a.rgb.data()), B(spec, r.rgb.data());
  OIIO::ImageBufAlgo::CompareResults c = OIIO::ImageBufAlgo::compare(A, B, 1e-6f, 1e-6f);
  ImageMetrics m = compare_images(a, r);
  EXPECT_NEAR(m.rmse, c.rms_error, 1e-6 * c.rms_error);
  EXPECT_NEAR(m.psnr, c.PSNR, 1e-4);
  EXPECT_NEAR(m.max_abs, c.maxerror, 1e-6);
}

TEST(CompareMetrics, NonFiniteTestValuesAreHugeErrors) {
  RgbImage a = make(1, 1, {NAN, 0, 0});
  RgbImage r = make(1, 1, {0, 0, 0});
  ImageMetrics m = compare_images(a, r);
  EXPECT_EQ(m.nonfinite, 1u);
  EXPECT_GT(m.rmse, 1e20);
}

TEST(CompareMetrics, SizeMismatchThrows) {
  EXPECT_THROW(compare_images(make(1, 1, {0, 0, 0}), make(1, 2, {0, 0, 0, 0, 0, 0})),
               std::invalid_argument);
}

TEST(CompareMetrics, ClampImage) {
  RgbImage c = clamp_image(make(1, 2, {-1, 0.5f, 7, 1, 2, NAN}), 1.0f);
  EXPECT_EQ(c.rgb[0], 0.0f);
  EXPECT_EQ(c.rgb[1], 0.5f);
  EXPECT_EQ(c.rgb[2], 1.0f);
  EXPECT_EQ(c.rgb[3], 1.0f);
  EXPECT_EQ(c.rgb[4], 1.0f);
  EXPECT_TRUE(std::isnan(c.rgb[5]));
}

TEST(CompareMetrics, ErrorImageScaleAndColours) {
  // Errors 0, 0.1, 0.2, ..., 0.9 in ten pixels (all channels).
  RgbImage a = make(10, 1, std::vector<float>(30));
  RgbImage r = a;
  for (int p = 0; p < 10; ++p)
    for (int c = 0; c < 3; ++c)
      a.rgb[size_t(3 * p + c)] = 0.1f * float(p);
  double scale = 0;
  RgbImage e = error_image(a, r, ErrorMetric::Absolute, 0.0, &scale);
  EXPECT_NEAR(scale, 0.9, 1e-6); // the 99th percentile of ten values is the largest
  float lo[3], hi[3];
  error_colormap(0.0, lo);
  error_colormap(1.0, hi);
  EXPECT_LT(lo[0] + lo[1] + lo[2], 0.1f); // black at zero error
  EXPECT_GT(hi[0] + hi[1] + hi[2], 2.5f); // near white at the scale
  EXPECT_LT(e.rgb[0] + e.rgb[1] + e.rgb[2], 0.01f);
  EXPECT_GT(e.rgb[27] + e.rgb[28] + e.rgb[29], 2.0f); // linear values of near-white
  // Monotone brightness along the map.
  float prev = -1;
  for (int i = 0; i <= 20; ++i) {
    float c[3];
    error_colormap(i / 20.0, c);
    float y = 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
    EXPECT_GT(y, prev);
    prev = y;
  }
  // An explicit scale is used as given.
  error_image(a, r, ErrorMetric::Relative, 2.0, &scale);
  EXPECT_EQ(scale, 2.0);
}

TEST(CompareMetrics, ExrMetadataRoundTrip) {
  std::filesystem::path file =
      std::filesystem::temp_directory_path() / "canopy_test_compare_metadata.exr";
  write_exr(file, make(1, 1, {1, 2, 3}),
            {{"canopy:light_sampler", "exhaustive"}, {"canopy:spp", "1024"}, {"other", "x"}});
  auto attrs = read_image_attributes(file);
  EXPECT_EQ(attrs.size(), 2u);
  EXPECT_EQ(attrs["canopy:light_sampler"], "exhaustive");
  EXPECT_EQ(attrs["canopy:spp"], "1024");
  std::filesystem::remove(file);
  EXPECT_THROW(read_image_attributes(file), std::runtime_error);
}

} // namespace
