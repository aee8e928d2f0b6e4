// The spp of a render of a target time (render/equal_time.h), against synthetic render times:
// affine ones are solved from two renders, and a time affine only piecewise (auto's: a fixed cost
// of exploring, and another way of exploring from 32 spp) is found within 10% by the checks.
#include "render/equal_time.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace canopy;

TEST(EqualTime, AnAffineRenderTimeIsSolvedFromTwoRenders) {
  int renders = 0;
  auto affine = [&](int spp, uint32_t) {
    ++renders;
    return 0.3 + 0.01 * spp;
  };
  int spp = 0;
  const double spent = spp_for_seconds(affine, 10.0, 16, 1 << 20, 1, &spp, 2);
  EXPECT_EQ(spp, 970); // (10 - 0.3) / 0.01
  // the probe, the second point and one check, which hits within 10%
  EXPECT_EQ(renders, 3);
  EXPECT_NEAR(spent, (0.3 + 0.16) + (0.3 + 0.01 * 174) + 10.0, 1e-9);
}

TEST(EqualTime, APiecewiseRenderTimeIsFoundByTheChecks) {
  // As auto's: below 3 spp no exploration, 0.05 s per sample; up to 31 spp a fixed 0.8 s more
  // (the exploration); from 32 spp a fixed 0.2 s and 0.02 s per sample.
  auto piecewise = [](int spp, uint32_t) {
    return spp < 3 ? 0.05 * spp : spp < 32 ? 0.8 + 0.05 * spp : 0.2 + 0.02 * spp;
  };
  for (double target : {1.0, 3.0, 10.0}) {
    int unchecked = 0, checked = 0;
    spp_for_seconds(piecewise, target, 16, 1 << 20, 1, &unchecked, 0);
    spp_for_seconds(piecewise, target, 16, 1 << 20, 1, &checked, 3);
    EXPECT_LE(std::abs(piecewise(checked, 1) - target), 0.1 * target)
        << target << " s: " << checked << " spp";
    if (target == 1.0) { // the line from 16 spp alone is far off
      EXPECT_GT(std::abs(piecewise(unchecked, 1) - target), 0.1 * target) << unchecked;
    }
  }
}

TEST(EqualTime, TheSppStaysInItsRange) {
  auto slow = [](int n, uint32_t) { return 5.0 + n; };
  int spp = 0;
  spp_for_seconds(slow, 1.0, 16, 1000, 1, &spp, 2);
  EXPECT_EQ(spp, 1);
  auto fast = [](int n, uint32_t) { return 1e-6 * n; };
  spp_for_seconds(fast, 1.0, 16, 1000, 1, &spp, 2);
  EXPECT_EQ(spp, 1000);
}
