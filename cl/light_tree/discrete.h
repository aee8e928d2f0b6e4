// Every discrete choice of the light samplers, made exactly from the counter-based stream LtRng
// (cl/rng.h): a uniform index, the alias method, and the choice of one of four
// lanes (the light-tree descent of Conty Estevez & Kulla 2018, Alg. 2, picks a child with
// probability proportional to its importance, Eq. 3) with the probability lt_lane_prob reports.
// Compiles as OpenCL C and as C++ (cl/compat.h): host and device make the same decisions.
#ifndef CANOPY_LIGHT_TREE_DISCRETE_H
#define CANOPY_LIGHT_TREE_DISCRETE_H

#include "../compat.h"
#include "../rng.h"
#include "../simd4.h"

// Uniform floats from the rng carry 24 random bits (lt_rng_next).
#define LT_XI_RES0 5.9604645e-08f /* 2^-24 */
// 2^32 as a float (exact): scales a probability to the units of one 32-bit random word.
#define LT_TWO_POW_32 4294967296.0f
#define LT_TWO_POW_24 16777216.0f

// ---------------------------------------------------------------- exact discrete choices
// Every discrete choice (uniform index, alias slot and test, tree lane) is made from 32-bit
// random words with exactly the probability the pmf functions report, at any light count and any
// dynamic range (DESIGN §9). A float u in [0, 1) has 24 bits: it cannot index more than 2^24
// items, nor resolve a probability below 2^-24, and a rescaled u loses bits at every decision.

// floor(a * b / 2^32).
INLINE uint lt_mulhi(uint a, uint b) {
#ifdef __OPENCL_C_VERSION__
  return mul_hi(a, b);
#else
  return (uint)(((unsigned long long)a * (unsigned long long)b) >> 32);
#endif
}

// A uniform index in [0, n), n >= 1: floor(W n / 2^64) for a 64-bit random W (two words), with a
// 32 x 32-bit multiply-high per word and no loop (a rejection loop, Lemire 2019, would be exact
// but keeps PoCL from vectorising the kernel across work items: 3x the cost of a uniform pick).
// Every index has floor or ceil of 2^64 / n of the 2^64 values of W: its probability is 1/n to a
// relative n * 2^-64 (< 3e-12 for the format's 5e7 lights, far below the float pmf's own 6e-8).
// A 24-bit float u could not reach more than 2^24 lights, and u32 * n >> 32 alone would be off by
// up to n * 2^-32 (1% at 5e7 lights).
// lt_rng_index_w: W's high word is w1 (a word of the path's sampler, cl/sampler.h), its low word
// from r.
INLINE uint lt_rng_index_w(uint w1, LtRng* r, uint n) {
  uint w0 = lt_rng_next_u32(r);
  uint mid = w1 * n;                              // low half of w1 * n (weight 2^32)
  uint sum = mid + lt_mulhi(w0, n);               // plus the high half of w0 * n
  return lt_mulhi(w1, n) + (sum < mid ? 1u : 0u); // carry into 2^64
}
INLINE uint lt_rng_index(LtRng* r, uint n) {
  uint w1 = lt_rng_next_u32(r); // high word of W
  return lt_rng_index_w(w1, r, n);
}

// One 32-bit word w of a uniform U = 0.w1 w2 w3 ... (binary) against a boundary whose scaled value
// *x = c * 2^32 (or its remainder after the previous words, all equal to the boundary's) is in
// [0, 2^32). Returns 1 if U >= c, 0 if U < c, 2 if w ties with floor(*x) and the boundary has a
// nonzero fraction: then *x becomes that fraction * 2^32 for the next word. x - floor(x) of a
// float is exact, and so is the scaling, so each word compares 32 more bits of the boundary
// exactly: a float boundary in (0, 1) has no bit below 2^-149, so it is resolved after at most 5
// words (LT_MAX_WORDS), and a tie happens with probability 2^-32 per word.
INLINE int lt_word_vs(uint w, float* x) {
  float f = floor(*x);
  uint fi = (uint)f;
  float rest = *x - f;
  if (w != fi || rest == 0.0f) return w >= fi ? 1 : 0;
  *x = rest * LT_TWO_POW_32;
  return 2;
}

// Words of U that can be needed to compare it with a float boundary: its lowest bit is at
// 2^-149 or above, and 5 words hold 160 bits. A fixed count (no data-dependent loop) keeps kernels
// vectorisable; after LT_MAX_WORDS words a tie cannot remain.
#define LT_MAX_WORDS 5

// P(result = 1) = c exactly, for any float c (denormals included; c <= 0 or NaN: never, c >= 1:
// always). w is U's first word; further words are drawn from r only on a tie.
INLINE int lt_u_below(uint w, float c, LtRng* r) {
  if (!(c > 0.0f)) return 0;
  if (c >= 1.0f) return 1;
  float x = c * LT_TWO_POW_32;
  int o = lt_word_vs(w, &x);
  for (int k = 1; k < LT_MAX_WORDS; ++k)
    if (o == 2) o = lt_word_vs(lt_rng_next_u32(r), &x);
  return o == 0;
}

// Alias method (Walker 1977; table by Vose 1991): slot i in [0, n) uniformly, then i itself when
// U < threshold[i], else alias[i]; the slot and U come from independent words.
// lt_alias_pick_w: the slot's first word is w1 (lt_rng_index_w).
INLINE int lt_alias_pick_w(GLOBAL const float* threshold, GLOBAL const int* alias, uint n, uint w1,
                           LtRng* r) {
  uint slot = lt_rng_index_w(w1, r, n);
  uint w = lt_rng_next_u32(r);
  return lt_u_below(w, threshold[slot], r) ? (int)slot : alias[slot];
}
INLINE int lt_alias_pick(GLOBAL const float* threshold, GLOBAL const int* alias, uint n, LtRng* r) {
  uint w1 = lt_rng_next_u32(r);
  return lt_alias_pick_w(threshold, alias, n, w1, r);
}

// Probability of lane k: I_k / (sum of the four). 0 if nothing contributes.
LT_HOT float lt_lane_prob(float4 imp, int k) {
  float s = lt_sum4(imp);
  float ik = f4_get(imp, k);
  return (s > 0.0f && ik > 0.0f) ? ik / s : 0.0f;
}

// Compare-and-swap of a sorting network on (value, lane) pairs, ascending; branch-free (selects),
// since the order of the importances is data dependent and unpredictable.
#define LT_CSWAP(va, ia, vb, ib)                                                                   \
  do {                                                                                             \
    int sw_ = vb < va;                                                                             \
    float lo_ = sw_ ? vb : va, hi_ = sw_ ? va : vb;                                                \
    int il_ = sw_ ? ib : ia, ih_ = sw_ ? ia : ib;                                                  \
    va = lo_;                                                                                      \
    vb = hi_;                                                                                      \
    ia = il_;                                                                                      \
    ib = ih_;                                                                                      \
  } while (0)

// Chooses lane k with probability I_k / sum (what lt_lane_prob reports) from fresh 32-bit words
// of r; -1 if no lane contributes. The lanes are sorted by ascending importance (a 4-input sorting
// network) and U in [0, 1) picks the lane whose interval [c_j, c_j+1) holds it, c_j = (sum of
// the j smallest) / sum: summing from the small end keeps a tiny lane beside a big one, and every
// boundary below a lane is at most 3 times that lane's own probability, so each lane's interval
// has the lane's probability to a few float roundings (relative, < 1e-6) however small it is. The
// comparisons of U with the boundaries are exact (lt_word_vs: one word, more only on a tie), so
// no probability is lost to the resolution of U. A lane of importance 0 has an empty interval.
// With use_w, U's first word is w (a word of the path's sampler, cl/sampler.h) instead of r's
// next; the words that resolve a tie still come from r, so U stays uniform to all its bits.
LT_HOT int lt_choose_lane_w(float4 imp, int use_w, uint w0, LtRng* r) {
  float s = lt_sum4(imp);
  if (!(s > 0.0f) || !is_finite_f(s)) return -1;
  float v0 = imp.x, v1 = imp.y, v2 = imp.z, v3 = imp.w;
  int i0 = 0, i1 = 1, i2 = 2, i3 = 3;
  LT_CSWAP(v0, i0, v1, i1);
  LT_CSWAP(v2, i2, v3, i3);
  LT_CSWAP(v0, i0, v2, i2);
  LT_CSWAP(v1, i1, v3, i3);
  LT_CSWAP(v1, i1, v2, i2);
  float t2 = v0 + v1;
  float t3 = t2 + v2;
  uint w = use_w ? w0 : lt_rng_next_u32(r);
  // Fast path: U's top 24 bits a (exact as a float) against y_j = c_j * 2^24 (exact scaling of
  // the boundary): U >= c_j if a >= y_j, U < c_j if a + 1 <= y_j; only a boundary strictly
  // inside (a, a + 1) needs the exact 32-bit comparison (probability < 3 * 2^-24 per decision).
  float k = LT_TWO_POW_24 / s; // c_3 <= 3/4 < 1: the largest lane has at least a quarter
  float y1 = v0 * k, y2 = t2 * k, y3 = t3 * k;
  float a = (float)(w >> 8);
  float a1 = a + 1.0f;
  int pos = (a >= y1) + (a >= y2) + (a >= y3); // boundaries at or below U
  if ((y1 > a && y1 < a1) || (y2 > a && y2 < a1) || (y3 > a && y3 < a1)) {
    float x1 = y1 * 256.0f, x2 = y2 * 256.0f, x3 = y3 * 256.0f; // c_j * 2^32, exact
    int o1 = lt_word_vs(w, &x1), o2 = lt_word_vs(w, &x2), o3 = lt_word_vs(w, &x3);
    for (int n = 1; n < LT_MAX_WORDS; ++n) { // tied boundaries compare with U's next word
      if (o1 != 2 && o2 != 2 && o3 != 2) break;
      w = lt_rng_next_u32(r);
      if (o1 == 2) o1 = lt_word_vs(w, &x1);
      if (o2 == 2) o2 = lt_word_vs(w, &x2);
      if (o3 == 2) o3 = lt_word_vs(w, &x3);
    }
    pos = (o1 == 1) + (o2 == 1) + (o3 == 1);
  }
  return pos == 0 ? i0 : (pos == 1 ? i1 : (pos == 2 ? i2 : i3));
}
LT_HOT int lt_choose_lane(float4 imp, LtRng* r) {
  return lt_choose_lane_w(imp, 0, 0u, r);
}

#endif // CANOPY_LIGHT_TREE_DISCRETE_H
