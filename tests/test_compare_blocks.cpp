// Block-mean agreement (image/block_agreement.h) on images whose block means are known by
// construction: a uniform scale, one changed block, dark blocks left out, partial edge blocks.
#include "image/block_agreement.h"
#include "support/constant_image.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

using namespace canopy;
using namespace canopy::test;

namespace {

void fill_block(RgbImage& img, int x0, int y0, int n, float v) {
  for (int y = y0; y < std::min(img.height, y0 + n); ++y)
    for (int x = x0; x < std::min(img.width, x0 + n); ++x)
      for (int c = 0; c < 3; ++c)
        img.rgb[(size_t(y) * size_t(img.width) + size_t(x)) * 3 + size_t(c)] = v;
}

} // namespace

TEST(BlockAgreement, UniformScaleGivesThatRatioEverywhere) {
  RgbImage ref = constant_image(40, 24, 2.0f), test = constant_image(40, 24, 2.1f);
  BlockAgreement a = block_agreement(test, ref, 16);
  EXPECT_EQ(a.all_blocks, 6u); // 3 x 2 blocks, the last column and row partial
  EXPECT_EQ(a.blocks, 6u);
  EXPECT_NEAR(a.image_ratio, 1.05, 1e-6);
  EXPECT_NEAR(a.median_ratio, 1.05, 1e-6);
  EXPECT_DOUBLE_EQ(a.within_10, 1.0);
  EXPECT_DOUBLE_EQ(a.within_3, 0.0);
}

TEST(BlockAgreement, OneBlockOffAndDarkBlocksLeftOut) {
  // 4 x 4 blocks of 8 pixels; one reference block is dark (1% of the others: left out), one test
  // block is 1.5x its reference.
  RgbImage ref = constant_image(32, 32, 1.0f), test = constant_image(32, 32, 1.0f);
  fill_block(ref, 0, 0, 8, 0.01f);
  fill_block(test, 0, 0, 8, 0.01f);
  fill_block(test, 8, 8, 8, 1.5f);
  BlockAgreement a = block_agreement(test, ref, 8);
  EXPECT_EQ(a.all_blocks, 16u);
  EXPECT_EQ(a.blocks, 15u);
  EXPECT_DOUBLE_EQ(a.median_ratio, 1.0);
  EXPECT_NEAR(a.within_10, 14.0 / 15.0, 1e-12);
  // Image means: reference 15 + 0.01 blocks of 1, test 14 + 1.5 + 0.01.
  EXPECT_NEAR(a.image_ratio, 15.51 / 15.01, 1e-6);
}

TEST(BlockAgreement, SizesMustMatch) {
  EXPECT_THROW(block_agreement(constant_image(4, 4, 1), constant_image(4, 5, 1), 2),
               std::invalid_argument);
  EXPECT_THROW(block_agreement(constant_image(4, 4, 1), constant_image(4, 4, 1), 0),
               std::invalid_argument);
}
