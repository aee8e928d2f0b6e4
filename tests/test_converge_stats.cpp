// The statistics of `canopy converge`'s yardstick (host/image/error_stats.h): bootstrap intervals,
// the top-0.1% share, the reference floor MSE(A, B) / 4 and masked MSE. Synthetic data, fixed
// seeds.
#include "image/error_stats.h"
#include "support/constant_image.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace canopy;
using namespace canopy::test;

namespace {} // namespace

// Over many independent synthetic experiments of 8 "seeds" each (exponential MSEs, heavy-ish
// tailed as per-seed MSEs are), the 95% percentile interval of the mean covers the true mean in
// most of them (the percentile bootstrap undercovers a little at n = 8, so the bound is loose),
// and both ends bracket the sample mean.
TEST(ConvergeStats, BootstrapIntervalCoversTheTrueMean) {
  std::mt19937_64 rng(12345);
  const double true_mean = 2.0;
  std::exponential_distribution<double> dist(1.0 / true_mean);
  int covered = 0;
  const int experiments = 300;
  for (int e = 0; e < experiments; ++e) {
    std::vector<double> x(8);
    double mean = 0.0;
    for (double& v : x) {
      v = dist(rng);
      mean += v / 8.0;
    }
    Interval ci = bootstrap_mean_interval(x, 2000, 7 + uint64_t(e));
    EXPECT_LE(ci.lo, mean);
    EXPECT_GE(ci.hi, mean);
    if (ci.lo <= true_mean && true_mean <= ci.hi) ++covered;
  }
  double coverage = double(covered) / experiments;
  EXPECT_GT(coverage, 0.80) << coverage;
  EXPECT_LE(coverage, 1.0);
}

TEST(ConvergeStats, BootstrapIsReproducible) {
  std::vector<double> x = {1.0, 3.0, 2.0, 8.0, 0.5, 1.5, 2.5, 4.0};
  Interval a = bootstrap_mean_interval(x), b = bootstrap_mean_interval(x);
  EXPECT_EQ(a.lo, b.lo);
  EXPECT_EQ(a.hi, b.hi);
  std::vector<double> t(8, 2.0);
  Interval e1 = bootstrap_efficiency_interval(x, t), e2 = bootstrap_efficiency_interval(x, t);
  EXPECT_EQ(e1.lo, e2.lo);
  EXPECT_EQ(e1.hi, e2.hi);
}

// Efficiency 1 / (mean MSE x mean seconds); with constant seconds its interval is the mean MSE's,
// inverted and divided by the time (the same resamples: same seed; 2001 resamples put both
// percentiles on order statistics, where inverting commutes with taking the quantile).
TEST(ConvergeStats, EfficiencyInterval) {
  std::vector<double> mse = {1.0, 3.0, 2.0, 8.0, 0.5, 1.5, 2.5, 4.0};
  std::vector<double> secs(mse.size(), 2.0);
  double m = 0.0;
  for (double v : mse)
    m += v / double(mse.size());
  EXPECT_DOUBLE_EQ(efficiency(mse, secs), 1.0 / (m * 2.0));
  Interval mi = bootstrap_mean_interval(mse, 2001, 99);
  Interval ei = bootstrap_efficiency_interval(mse, secs, 2001, 99);
  EXPECT_NEAR(ei.lo, 1.0 / (mi.hi * 2.0), 1e-12);
  EXPECT_NEAR(ei.hi, 1.0 / (mi.lo * 2.0), 1e-12);
  EXPECT_LE(ei.lo, efficiency(mse, secs));
  EXPECT_GE(ei.hi, efficiency(mse, secs));
}

// One firefly among 1000 pixels: the top 0.1% is exactly that pixel, and its share is its squared
// error over the total.
TEST(ConvergeStats, TopShareOfOneFirefly) {
  const int w = 50, h = 20; // 1000 pixels: k = 1
  RgbImage ref = constant_image(w, h, 1.0f);
  RgbImage test = constant_image(w, h, 1.1f); // e = 0.01 (up to float rounding)
  const size_t firefly = 437;
  for (int c = 0; c < 3; ++c)
    test.rgb[3 * firefly + c] = 51.0f; // e = 2500
  double e_small = 0.0, e_fire = 0.0;
  for (int c = 0; c < 3; ++c) {
    double d = double(test.rgb[c]) - double(ref.rgb[c]);
    e_small += d * d / 3.0;
    double f = double(test.rgb[3 * firefly + c]) - double(ref.rgb[3 * firefly + c]);
    e_fire += f * f / 3.0;
  }
  PixelErrorStats st = pixel_error_stats(test, ref);
  EXPECT_EQ(st.pixels, size_t(w * h));
  double total = e_fire + 999.0 * e_small;
  EXPECT_NEAR(st.top_share, e_fire / total, 1e-12);
  EXPECT_NEAR(st.worst, e_fire, 1e-9);
  EXPECT_NEAR(st.mse, total / 1000.0, 1e-9);
}

// Independent halves A, B = truth + N(0, σ²) per value: the floor MSE(A, B) / 4 estimates the
// MSE of their mean against the truth (σ² / 2), and is exactly a quarter of the halves' MSE.
TEST(ConvergeStats, ReferenceFloorOfIndependentHalves) {
  const int w = 200, h = 150;
  const double sigma = 0.3;
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> noise(0.0, sigma);
  std::uniform_real_distribution<double> value(0.0, 5.0);
  RgbImage truth = constant_image(w, h, 0.0f), a = truth, b = truth, mean = truth;
  for (size_t i = 0; i < truth.rgb.size(); ++i) {
    truth.rgb[i] = float(value(rng));
    a.rgb[i] = float(truth.rgb[i] + noise(rng));
    b.rgb[i] = float(truth.rgb[i] + noise(rng));
    mean.rgb[i] = 0.5f * (a.rgb[i] + b.rgb[i]);
  }
  double floor = reference_floor_mse(a, b);
  EXPECT_DOUBLE_EQ(floor, pixel_error_stats(a, b).mse / 4.0);
  double actual = pixel_error_stats(mean, truth).mse;
  // 90,000 values: the relative standard error of either estimate is about 0.5%.
  EXPECT_NEAR(floor / (sigma * sigma / 2.0), 1.0, 0.03);
  EXPECT_NEAR(floor / actual, 1.0, 0.03);
}

// Masked pixels are left out exactly: a huge error on them changes nothing, and the result equals
// the statistics of the unmasked pixels alone.
TEST(ConvergeStats, MaskedMseIgnoresMaskedPixels) {
  const int w = 16, h = 8;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  RgbImage ref = constant_image(w, h, 0.0f), test = ref;
  for (size_t i = 0; i < ref.rgb.size(); ++i) {
    ref.rgb[i] = u(rng);
    test.rgb[i] = u(rng);
  }
  std::vector<uint8_t> mask(size_t(w * h), 0);
  double se = 0.0;
  size_t n = 0;
  for (size_t p = 0; p < mask.size(); ++p) {
    mask[p] = p % 3 == 0;
    if (mask[p]) continue;
    ++n;
    for (int c = 0; c < 3; ++c) {
      double d = double(test.rgb[3 * p + c]) - double(ref.rgb[3 * p + c]);
      se += d * d / 3.0;
    }
  }
  PixelErrorStats before = pixel_error_stats(test, ref, mask);
  for (size_t p = 0; p < mask.size(); ++p)
    if (mask[p])
      for (int c = 0; c < 3; ++c)
        test.rgb[3 * p + c] = p % 2 ? 1e6f : NAN;
  PixelErrorStats after = pixel_error_stats(test, ref, mask);
  EXPECT_EQ(after.pixels, n);
  EXPECT_DOUBLE_EQ(after.mse, before.mse);
  EXPECT_DOUBLE_EQ(after.worst, before.worst);
  EXPECT_DOUBLE_EQ(after.top_share, before.top_share);
  EXPECT_NEAR(after.mse, se / double(n), 1e-15);
  // Unmasked, the huge errors dominate.
  EXPECT_GT(pixel_error_stats(test, ref).mse, 1e6);
}

TEST(ConvergeStats, MaskRoundTripsThroughAnImage) {
  std::vector<uint8_t> mask = {0, 1, 1, 0, 0, 1};
  EXPECT_EQ(mask_from_image(mask_to_image(mask, 3, 2)), mask);
}
