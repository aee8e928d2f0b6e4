// Owen-scrambled Sobol points (Burley 2020, "Practical Hash-based Owen Scrambling"), shared by the
// kernels and the host reference (cl/compat.h). Two dimensions of the Sobol sequence are enough:
// a path draws its numbers in 1D and 2D groups, each group from its own shuffle of the sample
// index (padding, cl/sampler.h), so every group is a (0, 2)-sequence in base 2 of its own.
// - sobol_dim0: van der Corput (the bit-reversed index); sobol_dim1: the second Sobol dimension
//   (primitive polynomial x + 1, direction numbers v_k = v_(k-1) ^ (v_(k-1) >> 1)).
// - owen_scramble: a hash-based Owen scramble of a 32-bit fixed-point value (pbrt-v4's
//   FastOwenScrambler, after Laine & Karras 2011 and Burley): bit k of the result is bit k of the
//   input flipped by a hash of the bits above it, so every elementary interval of a point set is
//   mapped onto an elementary interval of the same size: nets stay nets, and for a random seed
//   each scrambled point is uniform in [0, 1).
// - The same scramble of the sample index (Burley's nested uniform shuffle) permutes each aligned
//   block of 2^k indices within a block of 2^k: the first 2^k samples of a pixel are a whole block
//   of the sequence, so they remain a (0, k, 2)-net, whatever the pixel's shuffle.
#ifndef CANOPY_CL_SOBOL_H
#define CANOPY_CL_SOBOL_H

#include "compat.h"

INLINE uint sobol_reverse_bits(uint v) {
  v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
  v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
  v = ((v >> 4) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4);
  v = ((v >> 8) & 0x00ff00ffu) | ((v & 0x00ff00ffu) << 8);
  return (v >> 16) | (v << 16);
}

// Sample i of Sobol dimension 0 (van der Corput) as a 32-bit fraction.
INLINE uint sobol_dim0(uint i) {
  return sobol_reverse_bits(i);
}

// Sample i of Sobol dimension 1 as a 32-bit fraction. Its generator matrix is Pascal's triangle
// mod 2: bit c of i flips the fraction's bit r (weight 2^-(r+1)) iff the bits of r are a subset of
// those of c (Lucas' theorem; the direction numbers v_c = v_(c-1) ^ (v_(c-1) >> 1)). So bit r of
// the bit-reversed result is the XOR of i's bits c over the supersets c of r: a superset transform
// in five masked shifts, without loops or branches. sobol_dim1_reversed is that transform.
INLINE uint sobol_dim1_reversed(uint i) {
  uint y = i;
  y ^= (y >> 1) & 0x55555555u;
  y ^= (y >> 2) & 0x33333333u;
  y ^= (y >> 4) & 0x0f0f0f0fu;
  y ^= (y >> 8) & 0x00ff00ffu;
  y ^= (y >> 16) & 0x0000ffffu;
  return y;
}
INLINE uint sobol_dim1(uint i) {
  return sobol_reverse_bits(sobol_dim1_reversed(i));
}

// The scramble on bit-reversed values (Laine & Karras 2011's permutation with pbrt-v4's
// constants): bit k of the result is bit k of v flipped by a hash of the bits below k.
INLINE uint owen_permute_reversed(uint v, uint seed) {
  v ^= v * 0x3d20adeau;
  v += seed;
  v *= (seed >> 16) | 1u;
  v ^= v * 0x05526c56u;
  v ^= v * 0x53a22864u;
  return v;
}

// Owen scramble of a 32-bit fraction v (bit 31 is 1/2) with a 32-bit seed.
INLINE uint owen_scramble(uint v, uint seed) {
  return sobol_reverse_bits(owen_permute_reversed(sobol_reverse_bits(v), seed));
}

// A 32-bit fraction as a float in [0, 1): its top 24 bits (exact, never 1).
INLINE float sobol_to_float(uint v) {
  return (float)(v >> 8) * (1.0f / 16777216.0f);
}

#endif // CANOPY_CL_SOBOL_H
