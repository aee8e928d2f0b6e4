#include "image/block_agreement.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace canopy {

namespace {

// Mean over the pixels of [x0, x1) x [y0, y1) and their three channels (non-finite values count
// as 0: they are reported by compare_images, and one would make every ratio meaningless).
double region_mean(const RgbImage& img, int x0, int y0, int x1, int y1) {
  double s = 0.0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      for (int c = 0; c < 3; ++c) {
        float v = img.rgb[(size_t(y) * size_t(img.width) + size_t(x)) * 3 + size_t(c)];
        if (std::isfinite(v)) s += v;
      }
  return s / (3.0 * double(x1 - x0) * double(y1 - y0));
}

} // namespace

BlockAgreement block_agreement(const RgbImage& test, const RgbImage& reference, int n,
                               double min_fraction) {
  if (test.width != reference.width || test.height != reference.height)
    throw std::invalid_argument("block_agreement: the images differ in size");
  if (n < 1) throw std::invalid_argument("block_agreement: the block size must be >= 1");
  BlockAgreement a;
  const int w = reference.width, h = reference.height;
  if (w == 0 || h == 0) return a;
  const double ref_mean = region_mean(reference, 0, 0, w, h);
  a.image_ratio = ref_mean > 0.0 ? region_mean(test, 0, 0, w, h) / ref_mean : 0.0;
  for (int y = 0; y < h; y += n)
    for (int x = 0; x < w; x += n) {
      ++a.all_blocks;
      const int x1 = std::min(w, x + n), y1 = std::min(h, y + n);
      const double r = region_mean(reference, x, y, x1, y1);
      if (!(r > min_fraction * ref_mean)) continue;
      a.ratios.push_back(region_mean(test, x, y, x1, y1) / r);
    }
  a.blocks = a.ratios.size();
  if (a.blocks == 0) return a;
  std::vector<double> sorted = a.ratios;
  std::sort(sorted.begin(), sorted.end());
  const size_t m = sorted.size();
  a.median_ratio = m % 2 ? sorted[m / 2] : 0.5 * (sorted[m / 2 - 1] + sorted[m / 2]);
  size_t in10 = 0, in3 = 0;
  for (double r : sorted) {
    in10 += std::fabs(r - 1.0) <= 0.10;
    in3 += std::fabs(r - 1.0) <= 0.03;
  }
  a.within_10 = double(in10) / double(m);
  a.within_3 = double(in3) / double(m);
  return a;
}

} // namespace canopy
