// Agreement of two renders of the same scene by different renderers (Canopy against pbrt-v4,
// docs/pbrt-scenes.md): their noise differs, so the comparison is of means over blocks of pixels
// rather than of pixels. Per block of n x n pixels (the last row and column of blocks may be
// smaller), the mean over its pixels and RGB channels; only blocks whose reference mean exceeds
// `min_fraction` of the reference image's mean count (dark blocks' ratios are noise).
#pragma once

#include "image/image_io.h"

#include <vector>

namespace canopy {

struct BlockAgreement {
  double image_ratio = 0.0;   // test image mean / reference image mean
  double median_ratio = 0.0;  // median over the counted blocks of test / reference block mean
  double within_10 = 0.0;     // share of the counted blocks whose ratio is within 10% of 1
  double within_3 = 0.0;      // ... within 3%
  size_t blocks = 0;          // blocks counted
  size_t all_blocks = 0;      // blocks in the image
  std::vector<double> ratios; // per counted block, in row-major block order
};

// Throws std::invalid_argument when the sizes differ or n < 1.
BlockAgreement block_agreement(const RgbImage& test, const RgbImage& reference, int n,
                               double min_fraction = 0.05);

} // namespace canopy
