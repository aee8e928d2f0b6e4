// The path sampler's Sobol points (cl/sobol.h, cl/sampler.h), on the host:
// - the unscrambled 2D Sobol sequence's first 2^k points are a (0, k, 2)-net in base 2: exactly
//   one point in every elementary interval [a 2^-i, (a+1) 2^-i) x [b 2^-j, (b+1) 2^-j), i + j = k;
// - so are the first 2^k samples of every 2D group of the scrambled, shuffled sampler, for many
//   pixels and dimensions, and each aligned block of 2^k samples after them; a 1D group's first
//   2^k samples fall one in each interval of width 2^-k;
// - scrambled values are uniform over pixels (chi-square, fixed keys) and padded groups of one
//   pixel are independent of each other (chi-square of a joint histogram).
// - a light pick whose first word is the light-selection dimension's (the root pick, sobol) keeps
//   exactly its pmf: over many pixels' samples, each light is picked with the probability the
//   sampler reports (chi-square), for uniform, power and tree.
// The device draws the same numbers (test_kernel_sampler.cpp).
#include "integrator/light_sampler.h"
#include "light_tree/synthetic_lights.h"
#include "render/light_sampler_data.h"
#include "sampler.h"
#include "test_light_tree_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace {

// Whether the points (32-bit fractions) are a (0, k, 2)-net in base 2: 2^k points, one in each
// elementary interval of volume 2^-k. Reports the first failing split.
::testing::AssertionResult is_net(const std::vector<uint32_t>& x, const std::vector<uint32_t>& y,
                                  int k) {
  const size_t n = size_t(1) << k;
  if (x.size() != n || y.size() != n) return ::testing::AssertionFailure() << "size";
  for (int i = 0; i <= k; ++i) {
    const int j = k - i;
    std::vector<int> cell(n, 0);
    for (size_t p = 0; p < n; ++p) {
      uint32_t a = i ? x[p] >> (32 - i) : 0u, b = j ? y[p] >> (32 - j) : 0u;
      size_t c = (size_t(a) << j) | size_t(b);
      if (++cell[c] > 1)
        return ::testing::AssertionFailure() << "2^" << k << " points: two in interval (" << a
                                             << ", " << b << ") of 2^-" << i << " x 2^-" << j;
    }
  }
  return ::testing::AssertionSuccess();
}

// Chi-square statistic of counts against equal expected counts.
double chi_square(const std::vector<long>& counts, double expected) {
  double s = 0.0;
  for (long c : counts)
    s += (double(c) - expected) * (double(c) - expected) / expected;
  return s;
}

// A bound the statistic of `dof` degrees of freedom exceeds with probability ~1e-9 (Wilson-
// Hilferty): fixed inputs make each test deterministic; the bound only says how unlikely a fair
// generator would be to fail it.
double chi_square_bound(double dof) {
  const double z = 6.0, h = 2.0 / (9.0 * dof);
  return dof * std::pow(1.0 - h + z * std::sqrt(h), 3.0);
}

} // namespace

TEST(SobolPoints, UnscrambledSequenceIsANet) {
  for (int k = 0; k <= 14; ++k) {
    std::vector<uint32_t> x, y;
    for (uint32_t i = 0; i < (1u << k); ++i) {
      x.push_back(sobol_dim0(i));
      y.push_back(sobol_dim1(i));
    }
    EXPECT_TRUE(is_net(x, y, k)) << "k = " << k;
  }
  // The second dimension is Sobol's (in index order, not Gray-code order): 0, 1/2, 3/4, 1/4, 5/8,
  // 1/8, 3/8, 7/8.
  const uint32_t first[8] = {0u,          0x80000000u, 0xc0000000u, 0x40000000u,
                             0xa0000000u, 0x20000000u, 0x60000000u, 0xe0000000u};
  for (uint32_t i = 0; i < 8; ++i)
    EXPECT_EQ(sobol_dim1(i), first[i]) << i;
  // The closed form is the XOR of the direction numbers of the index's bits.
  std::mt19937 rng(5);
  for (int t = 0; t < 100000; ++t) {
    const uint32_t i = t < 4096 ? uint32_t(t) : uint32_t(rng());
    uint32_t x = 0u, v = 0x80000000u;
    for (int b = 0; b < 32; ++b, v ^= v >> 1)
      if ((i >> b) & 1u) x ^= v;
    ASSERT_EQ(sobol_dim1(i), x) << i;
  }
  // A pair of van der Corput coordinates is not a net: the check can fail.
  std::vector<uint32_t> x, y;
  for (uint32_t i = 0; i < 16; ++i) {
    x.push_back(sobol_dim0(i));
    y.push_back(sobol_dim0(i));
  }
  EXPECT_FALSE(is_net(x, y, 4));
}

TEST(SobolPoints, OwenScrambleKeepsElementaryIntervals) {
  // A scramble maps a 2^-k interval onto a 2^-k interval: the top k bits of the result depend on
  // the top k bits of the input alone, and values within an interval stay in one interval.
  for (uint32_t seed : {1u, 0x9e3779b9u, 0xdeadbeefu})
    for (int k = 1; k <= 12; ++k)
      for (uint32_t a = 0; a < (1u << k); a += 1u + (a >> 3)) {
        uint32_t lo = a << (32 - k), hi = lo | (0xffffffffu >> k);
        EXPECT_EQ(owen_scramble(lo, seed) >> (32 - k), owen_scramble(hi, seed) >> (32 - k))
            << "seed " << seed << " k " << k << " a " << a;
      }
  // ... and it scrambles: the seeds give different values.
  EXPECT_NE(owen_scramble(0x12345678u, 1u), owen_scramble(0x12345678u, 2u));
}

TEST(SobolPoints, SamplerWordsAreBurleysComposition) {
  // Owen scramble of Sobol dimension c at the group's shuffled index, each scramble with its seed.
  std::mt19937 rng(9);
  for (int t = 0; t < 20000; ++t) {
    const uint32_t key = uint32_t(rng()), sample = t % 2 ? uint32_t(rng()) : uint32_t(t),
                   dim = uint32_t(rng() % 200);
    const uint32_t g = sampler_group_seed(key, dim);
    const uint32_t i = owen_scramble(sample, g);
    const uint32_t x = owen_scramble(sobol_dim0(i), sampler_component_seed(g, 0));
    const uint32_t y = owen_scramble(sobol_dim1(i), sampler_component_seed(g, 1));
    ASSERT_EQ(sampler_sobol_word(key, sample, dim, 0), x);
    ASSERT_EQ(sampler_sobol_word(key, sample, dim, 1), y);
    float2 f = sampler_sobol_2d(key, sample, dim);
    ASSERT_EQ(f.x, sobol_to_float(x));
    ASSERT_EQ(f.y, sobol_to_float(y));
  }
}

TEST(SobolPoints, ScrambledGroupsAreNetsInEveryPixelAndBlock) {
  for (uint32_t seed : {1u, 7u})
    for (uint32_t pixel : {0u, 1u, 513u, 99999u})
      for (uint32_t dim : {uint32_t(PATH_DIM_PIXEL), sampler_vertex_base(0) + PATH_DIM_LIGHT_POINT,
                           sampler_vertex_base(0) + PATH_DIM_BSDF, sampler_vertex_base(3) + 8u})
        for (int k : {1, 4, 8, 11})
          for (uint32_t block : {0u, 1u, 5u}) { // samples [block 2^k, (block + 1) 2^k)
            const uint32_t key = sampler_pixel_key(seed, pixel);
            std::vector<uint32_t> x, y, one;
            for (uint32_t i = 0; i < (1u << k); ++i) {
              const uint32_t s = (block << k) + i;
              x.push_back(sampler_sobol_word(key, s, dim, 0));
              y.push_back(sampler_sobol_word(key, s, dim, 1));
              float2 f = sampler_sobol_2d(key, s, dim);
              // The floats are the words' top 24 bits.
              ASSERT_EQ(f.x, float(x.back() >> 8) * 0x1p-24f);
              ASSERT_EQ(f.y, float(y.back() >> 8) * 0x1p-24f);
              one.push_back(sampler_sobol_word(key, s, dim + 1u, 0)); // a 1D group
            }
            EXPECT_TRUE(is_net(x, y, k))
                << "seed " << seed << " pixel " << pixel << " dim " << dim << " block " << block;
            std::vector<int> cell(size_t(1) << k, 0);
            for (uint32_t v : one)
              EXPECT_EQ(++cell[v >> (32 - k)], 1) << "1D group " << dim + 1u << " k " << k;
          }
}

TEST(SobolPoints, ScrambledValuesAreUniformOverPixels) {
  // Sample s of one dimension over 2^16 pixels: 64 bins, and a 16 x 16 joint histogram of a 2D
  // group's components.
  const int pixels = 1 << 16, bins = 64;
  for (uint32_t s : {0u, 1u, 6u, 1000u})
    for (uint32_t dim : {uint32_t(PATH_DIM_PIXEL), sampler_vertex_base(1) + PATH_DIM_BSDF}) {
      std::vector<long> h(bins, 0), joint(256, 0);
      for (int p = 0; p < pixels; ++p) {
        float2 u = sampler_sobol_2d(sampler_pixel_key(3u, uint32_t(p)), s, dim);
        ASSERT_TRUE(u.x >= 0.0f && u.x < 1.0f && u.y >= 0.0f && u.y < 1.0f);
        h[size_t(u.x * float(bins))] += 1;
        joint[size_t(int(u.x * 16.0f) * 16 + int(u.y * 16.0f))] += 1;
      }
      double c1 = chi_square(h, double(pixels) / bins);
      double c2 = chi_square(joint, double(pixels) / 256.0);
      EXPECT_LT(c1, chi_square_bound(bins - 1)) << "sample " << s << " dim " << dim;
      EXPECT_LT(c2, chi_square_bound(255)) << "sample " << s << " dim " << dim;
    }
  // The test can fail: one key for every pixel puts all of them in one bin.
  std::vector<long> h(bins, 0);
  for (int p = 0; p < pixels; ++p)
    h[size_t(sampler_sobol_1d(sampler_pixel_key(3u, 0u), 5u, 2u) * float(bins))] += 1;
  EXPECT_GT(chi_square(h, double(pixels) / bins), chi_square_bound(bins - 1));
}

TEST(SobolPoints, PaddedGroupsAreIndependent) {
  // The first 256 samples of two groups of one pixel, over 256 pixels: the joint histogram of
  // the groups' first components (16 x 16 bins) is uniform. Without padding (one shuffle for
  // every group) the pairs would lie on a few lines.
  const int pixels = 256, samples = 256;
  for (auto [a, b] :
       {std::pair{sampler_vertex_base(0) + PATH_DIM_LIGHT_POINT,
                  sampler_vertex_base(0) + PATH_DIM_BSDF},
        std::pair{uint32_t(PATH_DIM_PIXEL), sampler_vertex_base(0)},
        std::pair{sampler_vertex_base(0) + PATH_DIM_LOBE, sampler_vertex_base(0) + PATH_DIM_RR}}) {
    std::vector<long> joint(256, 0);
    for (int p = 0; p < pixels; ++p) {
      const uint32_t key = sampler_pixel_key(11u, uint32_t(p));
      for (uint32_t s = 0; s < uint32_t(samples); ++s) {
        float u = sampler_sobol_1d(key, s, a), v = sampler_sobol_1d(key, s, b);
        joint[size_t(int(u * 16.0f) * 16 + int(v * 16.0f))] += 1;
      }
    }
    EXPECT_LT(chi_square(joint, double(pixels * samples) / 256.0), chi_square_bound(255))
        << "dims " << a << ", " << b;
  }
  // The test can fail: a group against itself.
  std::vector<long> joint(256, 0);
  for (int p = 0; p < pixels; ++p)
    for (uint32_t s = 0; s < uint32_t(samples); ++s) {
      float u = sampler_sobol_1d(sampler_pixel_key(11u, uint32_t(p)), s, 5u);
      joint[size_t(int(u * 16.0f) * 17)] += 1;
    }
  EXPECT_GT(chi_square(joint, double(pixels * samples) / 256.0), chi_square_bound(255));
}

TEST(PathSampler, IndependentIsThePcgStream) {
  // independent keeps the PCG stream bit for bit: the jitter is its first two numbers and the
  // state the one after them.
  float2 j;
  uint4 s = path_sampler_start(PATH_SAMPLER_INDEPENDENT, 5u, 77u, 9u, &j);
  PathRng r = rng_seed(5u, 77u, 9u);
  EXPECT_EQ(j.x, rng_next_float(&r));
  EXPECT_EQ(j.y, rng_next_float(&r));
  EXPECT_EQ(s.x, r.state);
  EXPECT_EQ(s.w, PATH_SAMPLER_INDEPENDENT);
  // sobol: the pixel's key, the sample index, the first vertex's dimensions; the jitter is the
  // pixel group's point, and the vertex numbers are the groups' at the vertex's dimensions.
  s = path_sampler_start(PATH_SAMPLER_SOBOL, 5u, 77u, 9u, &j);
  float2 p = sampler_sobol_2d(sampler_pixel_key(5u, 77u), 9u, PATH_DIM_PIXEL);
  EXPECT_EQ(j.x, p.x);
  EXPECT_EQ(j.y, p.y);
  EXPECT_EQ(s.x, sampler_pixel_key(5u, 77u));
  EXPECT_EQ(s.y, sobol_reverse_bits(9u)); // the sample index, bit-reversed
  EXPECT_EQ(s.z, uint32_t(PATH_DIM_VERTEX0));
  EXPECT_EQ(s.w, PATH_SAMPLER_SOBOL);
  const uint32_t key = sampler_pixel_key(5u, 77u), base = uint32_t(PATH_DIM_VERTEX0);
  EXPECT_EQ(path_sampler_word(s, 3u), sampler_sobol_word(key, 9u, base + 3u, 0));
  EXPECT_EQ(path_sampler_1d(s, 4u), sampler_sobol_1d(key, 9u, base + 4u));
  float2 a = path_sampler_2d(s, 5u), b = sampler_sobol_2d(key, 9u, base + 5u);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(path_sampler_hash(s, 6u), sampler_hash_word(key, 9u, base + 6u));
}

TEST(PathSampler, PicksWithSobolFirstWordsKeepThePmf) {
  const std::vector<Light> lights = canopy::mixed_lights(400, 13, 10.0f);
  const float3 P = make_float3(1.0f, 2.0f, 0.5f), N = normalize(make_float3(0.2f, 1.0f, -0.3f));
  const LtQuery q = lt_query_point(P, N);
  const uint32_t dim = sampler_vertex_base(0) + PATH_DIM_LIGHT_SELECT;
  for (const char* name : {"uniform", "power", "tree"}) {
    SCOPED_TRACE(name);
    canopy::LightSamplerData data = canopy::make_light_sampler_data(lights, name, 0.0f, 1);
    LightSamplerCtx ls = data.host_view(lights);
    std::vector<double> prob(lights.size()), counts(lights.size(), 0.0);
    for (size_t l = 0; l < lights.size(); ++l)
      prob[l] = light_sampler_pmf_q(&ls, &q, int(l));
    // 64 samples of each of 3125 pixels: the words of one pixel are stratified, the pixels'
    // scrambles independent.
    const int pixels = 3125, spp = 64;
    int total = 0, mismatched = 0;
    for (int p = 0; p < pixels; ++p)
      for (int k = 0; k < spp; ++k) {
        const uint32_t key = sampler_pixel_key(21u, uint32_t(p));
        LtRng rng = lt_rng_make(sampler_hash_word(key, uint32_t(k), dim), 0u);
        float pmf = 0.0f;
        int l = light_sampler_pick_w(&ls, 0, &q, 1, sampler_sobol_word(key, uint32_t(k), dim, 0),
                                     &rng, &pmf);
        if (l < 0) continue;
        counts[size_t(l)] += 1.0;
        ++total;
        mismatched += pmf != float(prob[size_t(l)]);
      }
    EXPECT_EQ(mismatched, 0);
    int dof = 0;
    double z = canopy::test::chi2_score(counts, prob, double(total), &dof);
    EXPECT_LT(z, 5.0) << "dof " << dof;
    EXPECT_GT(dof, 100);
    // The test can fail: a pmf off by a few percent on a tenth of the lights.
    std::vector<double> wrong = prob;
    for (size_t l = 0; l < wrong.size(); l += 10)
      wrong[l] *= 1.2;
    EXPECT_GT(canopy::test::chi2_score(counts, wrong, double(total)), 5.0);
  }
}
