#include "image/error_stats.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <stdexcept>

namespace canopy {

namespace {

constexpr double kNonfiniteError = 1e30; // as compare_images

// splitmix64: a fixed, platform-independent generator (std::uniform_int_distribution is not the
// same on every standard library, and the intervals must be reproducible).
struct SplitMix64 {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, n): the high bits of a 64 x 64 multiply (bias < n / 2^64).
  size_t below(size_t n) { return size_t((unsigned __int128)next() * n >> 64); }
};

double quantile_sorted(const std::vector<double>& v, double q) {
  if (v.empty()) return NAN;
  double pos = q * double(v.size() - 1);
  size_t i = size_t(pos);
  if (i + 1 >= v.size()) return v.back();
  double f = pos - double(i);
  return (1 - f) * v[i] + f * v[i + 1];
}

Interval bootstrap(size_t n, int resamples, uint64_t seed, double level,
                   const std::function<double(const std::vector<size_t>&)>& statistic) {
  if (n == 0) return {NAN, NAN};
  SplitMix64 rng{seed};
  std::vector<double> stats;
  stats.reserve(size_t(std::max(resamples, 1)));
  std::vector<size_t> idx(n);
  for (int r = 0; r < resamples; ++r) {
    for (size_t& i : idx)
      i = rng.below(n);
    double s = statistic(idx);
    if (std::isfinite(s)) stats.push_back(s);
  }
  if (stats.empty()) return {NAN, NAN};
  std::sort(stats.begin(), stats.end());
  double a = 0.5 * (1.0 - level);
  return {quantile_sorted(stats, a), quantile_sorted(stats, 1.0 - a)};
}

double mean_of(const std::vector<double>& x) {
  return x.empty() ? NAN : std::accumulate(x.begin(), x.end(), 0.0) / double(x.size());
}

} // namespace

PixelErrorStats pixel_error_stats(const RgbImage& test, const RgbImage& reference,
                                  const std::vector<uint8_t>& exclude, double top_fraction) {
  if (test.width != reference.width || test.height != reference.height ||
      test.rgb.size() != reference.rgb.size())
    throw std::invalid_argument(fmt::format("image sizes differ: {}x{} and {}x{}", test.width,
                                            test.height, reference.width, reference.height));
  const size_t npix = test.rgb.size() / 3;
  if (!exclude.empty() && exclude.size() != npix)
    throw std::invalid_argument(
        fmt::format("pixel mask has {} entries for {} pixels", exclude.size(), npix));
  std::vector<double> e;
  e.reserve(npix);
  for (size_t p = 0; p < npix; ++p) {
    if (!exclude.empty() && exclude[p]) continue;
    double s = 0.0;
    for (int c = 0; c < 3; ++c) {
      double a = test.rgb[3 * p + c], r = reference.rgb[3 * p + c];
      double d = std::isfinite(a) ? a - r : kNonfiniteError;
      s += d * d;
    }
    e.push_back(s / 3.0);
  }
  PixelErrorStats st;
  st.pixels = e.size();
  if (e.empty()) return st;
  double total = std::accumulate(e.begin(), e.end(), 0.0);
  st.mse = total / double(e.size());
  st.worst = *std::max_element(e.begin(), e.end());
  size_t k = std::max<size_t>(1, size_t(std::ceil(top_fraction * double(e.size()))));
  k = std::min(k, e.size());
  std::nth_element(e.begin(), e.begin() + std::ptrdiff_t(k - 1), e.end(), std::greater<>());
  double top = std::accumulate(e.begin(), e.begin() + std::ptrdiff_t(k), 0.0);
  st.top_share = total > 0.0 ? top / total : 0.0;
  return st;
}

double reference_floor_mse(const RgbImage& half_a, const RgbImage& half_b,
                           const std::vector<uint8_t>& exclude) {
  return pixel_error_stats(half_a, half_b, exclude).mse / 4.0;
}

Interval bootstrap_mean_interval(const std::vector<double>& x, int resamples, uint64_t seed,
                                 double level) {
  return bootstrap(x.size(), resamples, seed, level, [&](const std::vector<size_t>& idx) {
    double s = 0.0;
    for (size_t i : idx)
      s += x[i];
    return s / double(idx.size());
  });
}

double efficiency(const std::vector<double>& mse, const std::vector<double>& seconds) {
  double m = mean_of(mse), t = mean_of(seconds);
  return m > 0.0 && t > 0.0 ? 1.0 / (m * t) : NAN;
}

Interval bootstrap_efficiency_interval(const std::vector<double>& mse,
                                       const std::vector<double>& seconds, int resamples,
                                       uint64_t seed, double level) {
  if (mse.size() != seconds.size())
    throw std::invalid_argument("bootstrap_efficiency_interval: mse and seconds differ in size");
  return bootstrap(mse.size(), resamples, seed, level, [&](const std::vector<size_t>& idx) {
    double m = 0.0, t = 0.0;
    for (size_t i : idx) {
      m += mse[i];
      t += seconds[i];
    }
    m /= double(idx.size());
    t /= double(idx.size());
    return m > 0.0 && t > 0.0 ? 1.0 / (m * t) : NAN;
  });
}

RgbImage mask_to_image(const std::vector<uint8_t>& mask, int width, int height) {
  RgbImage img;
  img.width = width;
  img.height = height;
  img.rgb.assign(size_t(width) * size_t(height) * 3, 0.0f);
  for (size_t p = 0; p < mask.size() && p < size_t(width) * size_t(height); ++p)
    if (mask[p]) img.rgb[3 * p] = img.rgb[3 * p + 1] = img.rgb[3 * p + 2] = 1.0f;
  return img;
}

std::vector<uint8_t> mask_from_image(const RgbImage& img) {
  std::vector<uint8_t> m(img.rgb.size() / 3);
  for (size_t p = 0; p < m.size(); ++p)
    m[p] = (img.rgb[3 * p] + img.rgb[3 * p + 1] + img.rgb[3 * p + 2]) / 3.0f > 0.5f ? 1 : 0;
  return m;
}

} // namespace canopy
