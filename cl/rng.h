// Random numbers shared by the kernels and the host reference.
// Each path owns a 32-bit PCG state seeded from (seed, pixel, sample) by a hash, so the random
// sequence of a path does not depend on the wave size or on the order work items run in: images
// are bit-identical from run to run.
#ifndef CANOPY_CL_RNG_H
#define CANOPY_CL_RNG_H

#include "compat.h"

// Chris Wellons' lowbias32 integer hash: a full-avalanche 32-bit mix.
INLINE uint hash_u32(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

typedef struct PathRng {
  uint state;
} PathRng;

INLINE PathRng rng_seed(uint seed, uint pixel, uint sample) {
  PathRng r;
  r.state = hash_u32(seed ^ hash_u32(pixel ^ hash_u32(sample + 0x9e3779b9U)));
  return r;
}

// PCG-RXS-M-XS 32/32 (O'Neill 2014): one LCG step, then an output permutation.
INLINE uint rng_next_u32(PathRng* r) {
  uint s = r->state;
  r->state = s * 747796405U + 2891336453U;
  uint word = ((s >> ((s >> 28U) + 4U)) ^ s) * 277803737U;
  return (word >> 22U) ^ word;
}

// Uniform in [0, 1): the top 24 bits, so the result is exactly representable and never 1.
INLINE float rng_next_float(PathRng* r) {
  return (float)(rng_next_u32(r) >> 8) * (1.0f / 16777216.0f);
}

#endif // CANOPY_CL_RNG_H
