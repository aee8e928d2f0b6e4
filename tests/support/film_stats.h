// The mean over every sample of a film's green channel and its standard error, from the film's
// per-pixel sums of samples and of their squares: for renders of scenes whose pixels all have the
// same expected value (a closed form), the mean over all samples is one estimate of it.
#pragma once

#include "render/renderer.h"

#include <algorithm>
#include <cmath>

namespace canopy::test {

struct SampleStats {
  double mean = 0, se = 0;
};

inline SampleStats film_sample_stats(const Film& film) {
  double n = 0, s = 0, s2 = 0;
  for (size_t p = 0; p < film.sum.size(); ++p) {
    n += film.sum[p].w;
    s += film.sum[p].y;
    s2 += film.sumsq[p].y;
  }
  SampleStats st;
  st.mean = s / n;
  st.se = std::sqrt(std::max(0.0, s2 / n - st.mean * st.mean) / n);
  return st;
}

} // namespace canopy::test
