// An image of one value in every pixel and channel, for the image-metric tests.
#pragma once

#include "image/image_io.h"

namespace canopy::test {

inline RgbImage constant_image(int w, int h, float v) {
  RgbImage img;
  img.width = w;
  img.height = h;
  img.rgb.assign(size_t(w) * size_t(h) * 3, v);
  return img;
}

} // namespace canopy::test
