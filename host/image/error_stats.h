// Per-image error statistics and bootstrap intervals over seeds, for `canopy converge`'s
// yardstick (docs/design.md, "Error against time").
//
// Per pixel p, the squared error is e_p = Σ_c (a − r)² / 3 over the three channels (so the MSE of
// a pixel set is the mean of e_p over it, as compare_images' MSE over every pixel). A pixel set
// is every pixel, or the pixels whose `exclude` entry is 0 (e.g. without the pixels whose camera
// rays hit an emitter directly: their anti-aliasing noise is the emitters' own, not the light
// sampler's). Non-finite test values count as an error of 1e30, as in compare_images.
#pragma once

#include "image/image_io.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace canopy {

struct PixelErrorStats {
  size_t pixels = 0;      // pixels in the set
  double mse = 0.0;       // mean of e_p over the set
  double top_share = 0.0; // share of Σ e_p held by the top_fraction of the set's pixels
  double worst = 0.0;     // max e_p: the worst pixel's squared error
};

constexpr double kTopFraction = 0.001; // fireflies: the top 0.1% of pixels

// `exclude` (empty, or one entry per pixel): pixels with a non-zero entry are left out. The top
// share counts the k = max(1, ceil(top_fraction · pixels)) largest e_p; 0 when Σ e_p = 0.
// Throws std::invalid_argument when the sizes differ.
PixelErrorStats pixel_error_stats(const RgbImage& test, const RgbImage& reference,
                                  const std::vector<uint8_t>& exclude = {},
                                  double top_fraction = kTopFraction);

// The error floor of a reference made as the mean of two independent half renders A and B of
// equal spp: with per-pixel variance σ² per half, E[MSE(A, B)] = 2σ² and the mean (A + B) / 2 has
// variance σ² / 2, so MSE_floor = MSE(A, B) / 4 (over the same pixel set).
double reference_floor_mse(const RgbImage& half_a, const RgbImage& half_b,
                           const std::vector<uint8_t>& exclude = {});

struct Interval {
  double lo = 0.0, hi = 0.0;
};

constexpr int kBootstrapResamples = 2000;
constexpr uint64_t kBootstrapSeed = 0x5EED5EEDull; // fixed: the intervals are reproducible

// Percentile bootstrap interval (level 0.95: the 2.5% and 97.5% quantiles) of the mean of `x`,
// resampling its entries with replacement.
Interval bootstrap_mean_interval(const std::vector<double>& x, int resamples = kBootstrapResamples,
                                 uint64_t seed = kBootstrapSeed, double level = 0.95);

// Efficiency 1 / (mean(mse) · mean(seconds)) and its percentile bootstrap interval: the seeds
// (pairs mse[i], seconds[i]) are resampled together and the ratio recomputed.
double efficiency(const std::vector<double>& mse, const std::vector<double>& seconds);
Interval bootstrap_efficiency_interval(const std::vector<double>& mse,
                                       const std::vector<double>& seconds,
                                       int resamples = kBootstrapResamples,
                                       uint64_t seed = kBootstrapSeed, double level = 0.95);

// Emitter masks as images: 1 → white, 0 → black; back with a threshold of 0.5 on the mean of the
// channels.
RgbImage mask_to_image(const std::vector<uint8_t>& mask, int width, int height);
std::vector<uint8_t> mask_from_image(const RgbImage& img);

} // namespace canopy
