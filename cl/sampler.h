// The numbers of a camera path, shared by the kernels and the host reference (cl/compat.h). A
// render takes them from one of two samplers (`--sampler`):
// - independent: the path's PCG stream (PathRng, cl/rng.h), seeded from (seed, film pixel, sample
//   index) and advanced in order along the path.
// - sobol: Owen-scrambled Sobol points (cl/sobol.h) indexed by the sample index, one group of one
//   or two dimensions per purpose. Each group shuffles the sample index with its own seed (a hash
//   of the seed, the film pixel and the group's first dimension: Burley 2020's padding), so groups
//   are independent of each other while each is stratified over a pixel's samples: the first 2^k
//   samples of every 2D group form a (0, k, 2)-net. Sample i of a pixel is the same whatever the
//   spp, wave size, window or sample range of the render (the index is the global one).
// Dimensions are assigned by purpose in a fixed layout: the pixel's 2D, then PATH_VERTEX_DIMS
// per vertex (depth d starts at sampler_vertex_base(d)), with the offsets below. Numbers that seed
// the light samplers' counter-based streams (LtRng: split children, leaf lights, BRDF rounds,
// medium segments) are plain hashes of (pixel, sample, dimension): not stratified.
// The path state keeps one uint4 per path (PathBuffers.rng): x: the PCG state (independent) or
// the pixel's scramble key (sobol), y: the sample index bit-reversed (sobol), z: the first
// dimension of the current vertex (sobol), w: the sampler (PATH_SAMPLER_*).
#ifndef CANOPY_CL_SAMPLER_H
#define CANOPY_CL_SAMPLER_H

#include "compat.h"
#include "rng.h"
#include "sobol.h"

#define PATH_SAMPLER_INDEPENDENT 0u
#define PATH_SAMPLER_SOBOL 1u

#define PATH_DIM_PIXEL 0u   // 2D: the film position within the pixel
#define PATH_DIM_VERTEX0 2u // the first vertex's first dimension
#define PATH_VERTEX_DIMS 16u
// Offsets within a vertex's dimensions.
#define PATH_DIM_LIGHT_SELECT 0u    // 1D: the root pick's first word (uniform, power, tree descent)
#define PATH_DIM_LIGHT_POINT 1u     // 2D: the point on the root pick's light
#define PATH_DIM_BSDF 3u            // 2D: the BSDF direction
#define PATH_DIM_LOBE 5u            // 1D: the lobe / layer choice
#define PATH_DIM_RR 6u              // 1D: Russian roulette at a surface
#define PATH_DIM_MEDIUM_DISTANCE 7u // 1D: the free-flight distance
#define PATH_DIM_PHASE 8u           // 2D: the phase-function direction
#define PATH_DIM_MEDIUM_RR 10u      // 1D: Russian roulette at a medium vertex
#define PATH_DIM_LIGHT_SEED 11u     // hash: the shading point's LtRng seed
#define PATH_DIM_SEGMENT_SEED 12u   // hash: the medium segment's LtRng seed

INLINE uint sampler_vertex_base(int depth) {
  return PATH_DIM_VERTEX0 + (uint)depth * PATH_VERTEX_DIMS;
}

// The key of a film pixel's scrambles.
INLINE uint sampler_pixel_key(uint seed, uint pixel) {
  return hash_u32(seed ^ 0x5851f42du ^ hash_u32(pixel * 0x2c1b3c6du + 0x297a2d39u));
}

// The seed of the group that starts at dimension `dim` of a pixel (key: a hash already).
INLINE uint sampler_group_seed(uint key, uint dim) {
  return hash_u32(key ^ (dim * 0x9e3779b9u + 0x68e31da4u));
}
// The seed of component c's scramble in the group of seed g.
INLINE uint sampler_component_seed(uint g, int c) {
  return (g ^ (c ? 0x1b873593u : 0xcc9e2d51u)) * 0x9e3779b9u;
}

// Component c (0 or 1) of a sample of the group at `dim`, as a 32-bit fraction: Owen scrambles of
// Sobol dimension c at the group's shuffled index, the nested uniform (Owen) scramble of the
// sample index. The *_r forms take the sample index bit-reversed (as the path state keeps it):
// the scrambles permute bit-reversed values, and reversing the shuffled index is Sobol dimension
// 0, so a component costs two bit reversals.
INLINE uint sampler_sobol_word_r(uint key, uint rsample, uint dim, int c) {
  uint g = sampler_group_seed(key, dim);
  uint i = sobol_reverse_bits(owen_permute_reversed(rsample, g)); // the shuffled index
  uint r = c ? sobol_dim1_reversed(i) : i;                        // the component, bit-reversed
  return sobol_reverse_bits(owen_permute_reversed(r, sampler_component_seed(g, c)));
}
INLINE float2 sampler_sobol_2d_r(uint key, uint rsample, uint dim) {
  uint g = sampler_group_seed(key, dim);
  uint i = sobol_reverse_bits(owen_permute_reversed(rsample, g));
  uint x = sobol_reverse_bits(owen_permute_reversed(i, sampler_component_seed(g, 0)));
  uint y = sobol_reverse_bits(
      owen_permute_reversed(sobol_dim1_reversed(i), sampler_component_seed(g, 1)));
  return make_float2(sobol_to_float(x), sobol_to_float(y));
}
// A plain hash of (pixel, sample, dimension): a seed for counter-based streams.
INLINE uint sampler_hash_word_r(uint key, uint rsample, uint dim) {
  return hash_u32(hash_u32(key ^ rsample) + dim * 0x85ebca6bu);
}
INLINE uint sampler_sobol_word(uint key, uint sample, uint dim, int c) {
  return sampler_sobol_word_r(key, sobol_reverse_bits(sample), dim, c);
}
INLINE float sampler_sobol_1d(uint key, uint sample, uint dim) {
  return sobol_to_float(sampler_sobol_word(key, sample, dim, 0));
}
INLINE float2 sampler_sobol_2d(uint key, uint sample, uint dim) {
  return sampler_sobol_2d_r(key, sobol_reverse_bits(sample), dim);
}
INLINE uint sampler_hash_word(uint key, uint sample, uint dim) {
  return sampler_hash_word_r(key, sobol_reverse_bits(sample), dim);
}

// The state of a new path and its position in the pixel (jitter).
INLINE uint4 path_sampler_start(uint kind, uint seed, uint pixel, uint sample, float2* jitter) {
  if (kind == PATH_SAMPLER_SOBOL) {
    uint key = sampler_pixel_key(seed, pixel);
    uint rsample = sobol_reverse_bits(sample);
    *jitter = sampler_sobol_2d_r(key, rsample, PATH_DIM_PIXEL);
    return make_uint4(key, rsample, PATH_DIM_VERTEX0, kind);
  }
  PathRng r = rng_seed(seed, pixel, sample);
  float jx = rng_next_float(&r);
  float jy = rng_next_float(&r);
  *jitter = make_float2(jx, jy);
  return make_uint4(r.state, 0u, 0u, kind);
}

// The numbers of the vertex whose dimensions start at s.z (sobol only).
INLINE float path_sampler_1d(uint4 s, uint offset) {
  return sobol_to_float(sampler_sobol_word_r(s.x, s.y, s.z + offset, 0));
}
INLINE float2 path_sampler_2d(uint4 s, uint offset) {
  return sampler_sobol_2d_r(s.x, s.y, s.z + offset);
}
INLINE uint path_sampler_word(uint4 s, uint offset) {
  return sampler_sobol_word_r(s.x, s.y, s.z + offset, 0);
}
INLINE uint path_sampler_hash(uint4 s, uint offset) {
  return sampler_hash_word_r(s.x, s.y, s.z + offset);
}

#endif // CANOPY_CL_SAMPLER_H
