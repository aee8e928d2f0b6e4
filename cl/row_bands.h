// Which rows of its window a render covers. A render may cover bands of rows instead of every row:
// bands of `height` rows, numbered from the window's top, repeat with a period of `period` bands,
// and the render covers the bands whose number mod `period` is in [first, first + count). The
// estimator choice (host/render/auto_sampler.cpp) explores candidates on such a subset of the film,
// evenly spread over it, so that its cost does not grow with the film. Every row: (1, 1, 0, 1).
// Packed as int4 (height, period, first, count) for the kernel.
#ifndef CANOPY_CL_ROW_BANDS_H
#define CANOPY_CL_ROW_BANDS_H

#include "compat.h"

// The window row of the r-th row the render covers.
INLINE uint covered_row(int4 bands, uint r) {
  uint per_period = (uint)(bands.x * bands.w);
  return (r / per_period) * (uint)(bands.x * bands.y) + (uint)(bands.x * bands.z) + r % per_period;
}

// How many of a window's `rows` rows the render covers.
INLINE int covered_rows(int4 bands, int rows) {
  int period = bands.x * bands.y;
  int in_last = rows % period - bands.x * bands.z;
  return (rows / period) * bands.x * bands.w + min(max(in_last, 0), bands.x * bands.w);
}

#endif // CANOPY_CL_ROW_BANDS_H
