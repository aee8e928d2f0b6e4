// Image error metrics against a reference (DESIGN.md §8) and a false-colour error image, for
// `canopy compare` and `canopy converge`.
//
// Definitions (over every pixel p and colour channel c, N = 3 · pixels, a = test, r = reference):
//   MSE    = Σ (a − r)² / N                       RMSE = √MSE
//   relMSE = Σ (a − r)² / (r² + ε) / N           ε = 0.01 (as in Rousselle et al. 2011), so
//                                                 dark pixels do not dominate
//   PSNR   = 10 · log10(peak² / MSE)            peak = max(1, largest finite value in either
//                                                 image): OpenImageIO's ImageBufAlgo::compare /
//                                                 `idiff` convention; +inf for identical images
// The sums run in double precision. Non-finite test pixels count as an error of 1e30.
#pragma once

#include "image/image_io.h"

#include <filesystem>
#include <map>
#include <string>

namespace canopy {

struct ImageMetrics {
  double mse = 0.0;
  double rmse = 0.0;
  double relmse = 0.0;
  double psnr = 0.0; // dB
  double peak = 1.0; // the PSNR's peak value
  double max_abs = 0.0;
  size_t nonfinite = 0; // non-finite values in the test image
};

constexpr double kRelMseEpsilon = 0.01;

// Throws std::invalid_argument when the sizes differ.
ImageMetrics compare_images(const RgbImage& test, const RgbImage& reference,
                            double rel_epsilon = kRelMseEpsilon);

// String attributes of an image file whose names start with `prefix` (e.g. "canopy:"), by name.
// Throws std::runtime_error naming the file when it cannot be opened.
std::map<std::string, std::string> read_image_attributes(const std::filesystem::path& file,
                                                         const std::string& prefix = "canopy:");

// A copy with every value clamped to [0, max] (display-referred comparison: directly visible
// emitters and fireflies then weigh no more than a white pixel). Non-finite values stay.
RgbImage clamp_image(const RgbImage& img, float max);

enum class ErrorMetric { Absolute, Relative };

// A false-colour (perceptually ordered "inferno"-like map, black → red → yellow → white) image of
// the per-pixel error, averaged over the three channels: |a − r| or |a − r| / √(r² + ε). Values
// are divided by `scale` and clamped to [0, 1]; scale <= 0 picks the 99th percentile of the
// error (returned in `used_scale`). The result is display-referred: write it with write_png
// after no further transfer (the colours are already sRGB-encoded, so it is returned linearised).
RgbImage error_image(const RgbImage& test, const RgbImage& reference, ErrorMetric metric,
                     double scale, double* used_scale = nullptr);

// The colour map of error_image at t in [0, 1], as sRGB-encoded values in [0, 1].
void error_colormap(double t, float rgb[3]);

} // namespace canopy
