// Random numbers shared by the kernels and the host reference. Two generators, for two jobs:
// - PathRng: each camera path owns one 32-bit PCG state, seeded from (seed, pixel, sample) by a
//   hash and advanced in order along the path, so a path's sequence does not depend on the wave
//   size or on the order work items run in: images are bit-identical from run to run.
// - LtRng: a counter-based stream keyed by (seed, stream). The light samplers derive a fresh,
//   independent stream from what a pick is about (a split-queue entry's bit code, a light index,
//   a BRDF-round slot) instead of threading one state through queues that fan out and compact
//   between kernels; the host reference draws the same streams, so host statistics cover the
//   device. Its discrete choices (index, alias, tree lane) are in light_tree/discrete.h.
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

// A counter-based stream: value i of stream (seed, stream) is a hash of (key, i). Cheap to carry
// in a kernel's private memory; the host sampler interface uses the same struct.
typedef struct LtRng {
  uint key;
  uint ctr;
} LtRng;

// Counter-based stream keyed by hash_u32 (the "lowbias32" finaliser above).
INLINE LtRng lt_rng_make(uint seed, uint stream) {
  LtRng r;
  r.key = hash_u32(hash_u32(seed ^ 0x3c6ef372u) ^ (stream * 0x9e3779b9u + 0x7f4a7c15u));
  r.ctr = 0u;
  return r;
}
INLINE uint lt_rng_next_u32(LtRng* r) {
  uint x = hash_u32(hash_u32(r->ctr * 0x9e3779b9u + r->key) ^ r->key);
  r->ctr += 1u;
  return x;
}
// Uniform in [0, 1) with 24 random bits.
INLINE float lt_rng_next(LtRng* r) {
  return (float)(lt_rng_next_u32(r) >> 8) * (1.0f / 16777216.0f);
}

#endif // CANOPY_CL_RNG_H
