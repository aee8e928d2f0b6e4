#include "image/image_compare.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace canopy {

namespace {

constexpr double kNonfiniteError = 1e30;

void check_sizes(const RgbImage& a, const RgbImage& b) {
  if (a.width != b.width || a.height != b.height || a.rgb.size() != b.rgb.size())
    throw std::invalid_argument(
        fmt::format("image sizes differ: {}x{} and {}x{}", a.width, a.height, b.width, b.height));
}

} // namespace

ImageMetrics compare_images(const RgbImage& test, const RgbImage& reference, double rel_epsilon) {
  check_sizes(test, reference);
  ImageMetrics m;
  const size_t n = test.rgb.size();
  if (n == 0) return m;
  double se = 0.0, rel = 0.0;
  for (size_t i = 0; i < n; ++i) {
    double a = test.rgb[i], r = reference.rgb[i];
    double d = std::isfinite(a) ? std::abs(a - r) : kNonfiniteError;
    if (!std::isfinite(a)) ++m.nonfinite;
    se += d * d;
    rel += d * d / (r * r + rel_epsilon);
    m.max_abs = std::max(m.max_abs, d);
    if (std::isfinite(a)) m.peak = std::max(m.peak, a);
    if (std::isfinite(r)) m.peak = std::max(m.peak, r);
  }
  m.mse = se / double(n);
  m.rmse = std::sqrt(m.mse);
  m.relmse = rel / double(n);
  m.psnr = m.mse > 0.0 ? 10.0 * std::log10(m.peak * m.peak / m.mse) : INFINITY;
  return m;
}

RgbImage clamp_image(const RgbImage& img, float max) {
  RgbImage out = img;
  for (float& v : out.rgb)
    if (std::isfinite(v)) v = std::clamp(v, 0.0f, max);
  return out;
}

std::map<std::string, std::string> read_image_attributes(const std::filesystem::path& file,
                                                         const std::string& prefix) {
  DecodedImage img;
  try {
    img = read_image_file(file);
  } catch (const ImageFileError& e) {
    throw std::runtime_error(fmt::format("{}: cannot read image ({})", file.string(), e.what()));
  }
  std::map<std::string, std::string> out;
  for (const auto& [name, value] : img.attributes)
    if (name.compare(0, prefix.size(), prefix) == 0) out[name] = value;
  return out;
}

void error_colormap(double t, float rgb[3]) {
  // "inferno" (matplotlib, CC0) sampled at 9 points, sRGB 0..255.
  static const float kMap[9][3] = {{0, 0, 4},      {31, 12, 72},   {85, 15, 109},
                                   {136, 34, 106}, {186, 54, 85},  {227, 89, 51},
                                   {249, 140, 10}, {249, 201, 50}, {252, 255, 164}};
  if (!std::isfinite(t)) t = 1.0;
  t = std::clamp(t, 0.0, 1.0) * 8.0;
  int i = std::min(int(t), 7);
  float f = float(t - i);
  for (int c = 0; c < 3; ++c)
    rgb[c] = ((1.0f - f) * kMap[i][c] + f * kMap[i + 1][c]) / 255.0f;
}

RgbImage error_image(const RgbImage& test, const RgbImage& reference, ErrorMetric metric,
                     double scale, double* used_scale) {
  check_sizes(test, reference);
  const size_t npix = size_t(test.width) * size_t(test.height);
  std::vector<double> err(npix);
  for (size_t p = 0; p < npix; ++p) {
    double e = 0.0;
    for (int c = 0; c < 3; ++c) {
      double a = test.rgb[3 * p + c], r = reference.rgb[3 * p + c];
      double d = std::isfinite(a) ? std::abs(a - r) : kNonfiniteError;
      if (metric == ErrorMetric::Relative) d /= std::sqrt(r * r + kRelMseEpsilon);
      e += d / 3.0;
    }
    err[p] = e;
  }
  if (!(scale > 0.0)) {
    std::vector<double> sorted = err;
    if (!sorted.empty()) {
      size_t k = std::min(sorted.size() - 1, size_t(0.99 * double(sorted.size())));
      std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(k), sorted.end());
      scale = sorted[k];
    }
    if (!(scale > 0.0)) scale = 1.0; // identical images
  }
  if (used_scale) *used_scale = scale;
  RgbImage out;
  out.width = test.width;
  out.height = test.height;
  out.rgb.resize(npix * 3);
  for (size_t p = 0; p < npix; ++p) {
    float c[3];
    error_colormap(err[p] / scale, c);
    for (int k = 0; k < 3; ++k)
      out.rgb[3 * p + k] = srgb_decode(c[k]);
  }
  return out;
}

} // namespace canopy
