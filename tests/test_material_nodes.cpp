// The device functions of the mix material, the texture trees and diffuse transmission, run on the
// host (they compile as C++ through cl/compat.h):
// - texture_eval: pbrt-v4's checkerboard, mix and scale against closed-form values at known uv;
// - material_resolve_mix: the material chosen at a point is deterministic, and over many points
//   the second is chosen with probability `amount` (binomial bound), nested mixes multiply;
// - the diffuse-transmission BSDF: f = R / pi and T / pi on the two sides, its pdf integrates to 1
//   over the sphere, its samples' mean weight is the albedo R + T (<= 1: a white furnace loses
//   nothing and gains nothing), and eval / pdf / sample agree.
#include "bsdf/bsdf.h"
#include "material_mix.h"
#include "texture.h"

#include "support/materials.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace {

constexpr double kPi = 3.14159265358979323846;

Texture constant(float3 v) {
  Texture t{};
  t.kind = TEXTURE_CONSTANT;
  t.nodes = 1;
  t.scale = f4_from3(v, 0.0f);
  return t;
}

Texture op(int kind, int nodes, float4 uvmap = make_float4(1, 1, 0, 0)) {
  Texture t{};
  t.kind = kind;
  t.nodes = nodes;
  t.uvmap = uvmap;
  return t;
}

float3 eval(const std::vector<Texture>& t, float u, float v) {
  return texture_eval(t.data(), nullptr, int(t.size()) - 1, make_float2(u, v));
}

Material diffuse(float3 a) {
  Material m{};
  m.type = MATERIAL_DIFFUSE;
  m.albedo = f4_from3(a, 0.0f);
  return m;
}

Material mix(int a, int b, float amount) {
  Material m{};
  m.type = MATERIAL_MIX;
  m.mix_material[0] = a;
  m.mix_material[1] = b;
  m.mix_amount = amount;
  return m;
}

// material_resolve_mix at P, wo without an amount texture (uv and textures unused).
int choose(const std::vector<Material>& mats, int index, float3 P, float3 wo) {
  static const std::vector<float2> uv(3, make_float2(0, 0));
  static const std::vector<Texture> none(1);
  static const float texel = 0.0f;
  return material_resolve_mix(mats.data(), index, P, wo, uv.data(), none.data(), &texel, 0, 0, 0);
}

} // namespace

// ---------------------------------------------------------------- textures
// pbrt-v4's 2D checkerboard without filtering: tex1 where floor(s) + floor(t) is even, tex2 where
// it is odd, (s, t) = (su u + du, sv v + dv).
TEST(TextureNodes, CheckerboardIsTex1OnEvenAndTex2OnOddSquares) {
  const float3 a = make_float3(0.9f, 0.1f, 0.2f), b = make_float3(0.1f, 0.3f, 0.8f);
  std::vector<Texture> t = {constant(a), constant(b),
                            op(TEXTURE_CHECKERBOARD, 3, make_float4(4, 2, 0.5f, 0.25f))};
  std::mt19937 gen(1);
  std::uniform_real_distribution<float> u01(-3.0f, 3.0f);
  for (int i = 0; i < 2000; ++i) {
    float u = u01(gen), v = u01(gen);
    float s = 4.0f * u + 0.5f, tt = 2.0f * v + 0.25f;
    bool odd = ((long long)std::floor(s) + (long long)std::floor(tt)) % 2 != 0;
    float3 got = eval(t, u, v), want = odd ? b : a;
    ASSERT_EQ(got.x, want.x) << u << "," << v;
    ASSERT_EQ(got.z, want.z) << u << "," << v;
  }
  // Known points: (0.1, 0.1): s 0.9, t 0.45 -> even; (0.2, 0.1): s 1.3 -> odd; negative u.
  EXPECT_EQ(eval(t, 0.1f, 0.1f).x, a.x);
  EXPECT_EQ(eval(t, 0.2f, 0.1f).x, b.x);
  EXPECT_EQ(eval(t, -0.2f, 0.1f).x, b.x); // s = -0.3: floor -1, odd
  EXPECT_EQ(eval(t, 0.1f, 0.5f).x, b.x);  // t = 1.25: odd
  // Non-finite coordinates stay finite (the even square).
  EXPECT_EQ(eval(t, NAN, 0.1f).x, a.x);
  EXPECT_EQ(eval(t, 1e30f, 0.1f).x, a.x); // 4e30 + 0.5 is an even integer in float
}

TEST(TextureNodes, MixLerpsAndScaleMultiplies) {
  const float3 a = make_float3(0.2f, 0.4f, 0.6f), b = make_float3(1.0f, 0.5f, 0.0f);
  std::vector<Texture> m = {constant(a), constant(b), constant(make_float3(0.25f, 0.25f, 0.25f)),
                            op(TEXTURE_MIX, 4)};
  float3 v = eval(m, 0.3f, 0.7f);
  EXPECT_FLOAT_EQ(v.x, 0.75f * 0.2f + 0.25f * 1.0f);
  EXPECT_FLOAT_EQ(v.y, 0.75f * 0.4f + 0.25f * 0.5f);
  EXPECT_FLOAT_EQ(v.z, 0.75f * 0.6f);
  std::vector<Texture> s = {constant(a), constant(make_float3(3, 3, 3)), op(TEXTURE_SCALE, 3)};
  EXPECT_FLOAT_EQ(eval(s, 0, 0).y, 1.2f);
  // A tree: scale(mix(checkerboard(a, b), b, checkerboard amount 0 / 1), 0.5). On an even square
  // the amount is 0: a * 0.5; on an odd one 1: b * 0.5.
  std::vector<Texture> tree = {constant(a),
                               constant(b),
                               op(TEXTURE_CHECKERBOARD, 3),
                               constant(b),
                               constant(make_float3(0, 0, 0)),
                               constant(make_float3(1, 1, 1)),
                               op(TEXTURE_CHECKERBOARD, 3),
                               op(TEXTURE_MIX, 8),
                               constant(make_float3(0.5f, 0.5f, 0.5f)),
                               op(TEXTURE_SCALE, 10)};
  EXPECT_FLOAT_EQ(eval(tree, 0.5f, 0.5f).x, 0.1f); // even: a.x / 2
  EXPECT_FLOAT_EQ(eval(tree, 1.5f, 0.5f).x, 0.5f); // odd: b.x / 2
  EXPECT_FLOAT_EQ(eval(tree, 1.5f, 0.5f).z, 0.0f);
  // A material's reflectance from a tree is clamped to [0, 1].
  std::vector<Texture> big = {constant(a), constant(make_float3(4, 4, 4)), op(TEXTURE_SCALE, 3)};
  std::vector<float2> uv(3, make_float2(0.5f, 0.5f));
  Material mt = diffuse(make_float3(0, 0, 0));
  mt.albedo_texture = 3;
  material_apply_textures(&mt, uv.data(), big.data(), nullptr, 0, 0.2f, 0.3f);
  EXPECT_FLOAT_EQ(mt.albedo.x, 0.8f);
  EXPECT_FLOAT_EQ(mt.albedo.y, 1.0f);
  // The transmittance texture replaces `specular`.
  Material dt =
      canopy::test::make_diffuse_transmission(make_float3(0.1f, 0.1f, 0.1f), make_float3(0, 0, 0));
  dt.transmittance_texture = 3;
  material_apply_textures(&dt, uv.data(), s.data(), nullptr, 0, 0.2f, 0.3f);
  EXPECT_FLOAT_EQ(dt.specular.x, 0.6f);
  EXPECT_FLOAT_EQ(dt.albedo.x, 0.1f);
}

// ---------------------------------------------------------------- mix
// The choice is a function of (P, wo, mix): the same at a point every time. Over many points the
// second material is chosen with probability `amount`: the count stays within 5 binomial standard
// deviations of n amount. Amounts on the 2^-24 grid are exact, 0 and 1 never choose the other.
TEST(MixMaterial, ChoosesTheSecondWithProbabilityAmount) {
  std::mt19937 gen(7);
  std::uniform_real_distribution<float> u(-10.0f, 10.0f);
  const int n = 200000;
  for (float amount : {0.0f, 0.1f, 0.25f, 0.5f, 0.9f, 1.0f}) {
    std::vector<Material> mats = {diffuse(make_float3(0.1f, 0.1f, 0.1f)),
                                  diffuse(make_float3(0.9f, 0.9f, 0.9f)), mix(0, 1, amount)};
    int second = 0;
    for (int i = 0; i < n; ++i) {
      float3 P = make_float3(u(gen), u(gen), u(gen));
      float3 wo = normalize(make_float3(u(gen), u(gen), u(gen)));
      int c = choose(mats, 2, P, wo);
      ASSERT_TRUE(c == 0 || c == 1);
      ASSERT_EQ(c, choose(mats, 2, P, wo));
      second += c;
    }
    const double sd = std::sqrt(n * double(amount) * (1.0 - double(amount)));
    EXPECT_NEAR(second, n * double(amount), 5.0 * sd + 0.5) << "amount " << amount;
  }
  // A non-mix resolves to itself.
  std::vector<Material> one = {diffuse(make_float3(0.5f, 0.5f, 0.5f))};
  EXPECT_EQ(choose(one, 0, make_float3(1, 2, 3), make_float3(0, 0, 1)), 0);
}

// Nested mixes choose independently: mix(mix(A, B, 0.5), C, 0.3) gives A 0.35, B 0.35, C 0.3.
// Near points (a ray's hits along a surface) are as good as random ones.
TEST(MixMaterial, NestedMixesMultiplyAndNeighbouringPointsDecorrelate) {
  std::vector<Material> mats = {diffuse(make_float3(0.1f, 0, 0)), diffuse(make_float3(0, 0.1f, 0)),
                                diffuse(make_float3(0, 0, 0.1f)), mix(0, 1, 0.5f), mix(3, 2, 0.3f)};
  int count[3] = {0, 0, 0};
  const int n = 300000;
  for (int i = 0; i < n; ++i) {
    // a grid of points 1e-3 apart on a plane, one viewing direction
    float3 P = make_float3(float(i % 600) * 1e-3f, float(i / 600) * 1e-3f, 0.0f);
    int c = choose(mats, 4, P, make_float3(0, 0.6f, 0.8f));
    ASSERT_TRUE(c >= 0 && c <= 2);
    ++count[c];
  }
  const double p[3] = {0.35, 0.35, 0.3};
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(count[k], n * p[k], 5.0 * std::sqrt(n * p[k] * (1 - p[k]))) << k;
}

// A textured amount: the checkerboard's 0 / 1 picks the first material on even squares and the
// second on odd ones, everywhere.
TEST(MixMaterial, TexturedAmountIsReadAtTheHit) {
  std::vector<Texture> t = {constant(make_float3(0, 0, 0)), constant(make_float3(1, 1, 1)),
                            op(TEXTURE_CHECKERBOARD, 3, make_float4(2, 2, 0, 0))};
  std::vector<Material> mats = {diffuse(make_float3(0.1f, 0.1f, 0.1f)),
                                diffuse(make_float3(0.9f, 0.9f, 0.9f)), mix(0, 1, 0.5f)};
  mats[2].mix_amount_texture = 3;
  std::vector<float2> uv = {make_float2(0, 0), make_float2(1, 0), make_float2(0, 1)};
  std::mt19937 gen(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    float bu = u(gen), bv = u(gen) * (1.0f - bu);
    float3 P = make_float3(u(gen), u(gen), u(gen));
    int c = material_resolve_mix(mats.data(), 2, P, make_float3(0, 0, 1), uv.data(), t.data(),
                                 nullptr, 0, bu, bv);
    int odd = (int(std::floor(2.0f * bu)) + int(std::floor(2.0f * bv))) & 1;
    ASSERT_EQ(c, odd) << bu << "," << bv;
  }
}

// ---------------------------------------------------------------- diffuse transmission
TEST(DiffuseTransmission, EvalIsRoverPiAboveAndToverPiBelow) {
  Material m = canopy::test::make_diffuse_transmission(make_float3(0.3f, 0.2f, 0.1f),
                                                       make_float3(0.5f, 0.6f, 0.7f));
  float3 wo = normalize(make_float3(0.3f, -0.2f, 0.9f));
  float3 up = normalize(make_float3(-0.5f, 0.1f, 0.4f)), down = make_float3(up.x, up.y, -up.z);
  float3 r = bsdf_eval(&m, wo, up), t = bsdf_eval(&m, wo, down);
  EXPECT_FLOAT_EQ(r.x, 0.3f / float(kPi));
  EXPECT_FLOAT_EQ(r.z, 0.1f / float(kPi));
  EXPECT_FLOAT_EQ(t.x, 0.5f / float(kPi));
  EXPECT_FLOAT_EQ(t.z, 0.7f / float(kPi));
  EXPECT_TRUE(bsdf_two_sided(&m));
  EXPECT_TRUE(bsdf_has_smooth_lobe(&m));
  Material d = diffuse(make_float3(0.5f, 0.5f, 0.5f));
  EXPECT_FALSE(bsdf_two_sided(&d));
  // pbrt-v4's lobe choice: max R : max T = 0.3 : 0.7
  EXPECT_FLOAT_EQ(bsdf_pdf(&m, wo, up), 0.3f * up.z / float(kPi));
  EXPECT_FLOAT_EQ(bsdf_pdf(&m, wo, down), 0.7f * up.z / float(kPi));
}

// Samples: pdf and weight agree with eval / pdf; the transmitted share is max T / (max R + max T);
// the mean weight is R + T per channel (the directional albedo; a white furnace with R + T = 1
// returns exactly what it receives); the pdf integrates to 1 over the sphere (uniform directions).
TEST(DiffuseTransmission, SamplingMatchesEvalAndConservesEnergy) {
  const float3 R = make_float3(0.3f, 0.5f, 0.1f), T = make_float3(0.7f, 0.2f, 0.4f);
  Material m = canopy::test::make_diffuse_transmission(R, T);
  std::mt19937 gen(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int n = 400000;
  const float3 wo = normalize(make_float3(0.2f, 0.1f, 0.7f));
  double sum[3] = {0, 0, 0};
  int below = 0;
  for (int i = 0; i < n; ++i) {
    BsdfSample s = bsdf_sample(&m, wo, make_float3(u(gen), u(gen), u(gen)));
    ASSERT_GT(s.pdf, 0.0f);
    ASSERT_FALSE(s.is_delta);
    ASSERT_NEAR(s.pdf, bsdf_pdf(&m, wo, s.wi), 1e-6f * s.pdf);
    float3 f = bsdf_eval(&m, wo, s.wi);
    ASSERT_NEAR(s.weight.x, f.x * std::fabs(s.wi.z) / s.pdf, 1e-5f);
    below += s.wi.z < 0.0f;
    sum[0] += s.weight.x;
    sum[1] += s.weight.y;
    sum[2] += s.weight.z;
  }
  const double pt = 0.7 / (0.5 + 0.7);
  EXPECT_NEAR(below, n * pt, 5.0 * std::sqrt(n * pt * (1 - pt)));
  // Weights take two values per channel (R / pr or T / pt): the mean's error is binomial.
  const double albedo[3] = {0.3 + 0.7, 0.5 + 0.2, 0.1 + 0.4};
  const double rw[3] = {0.3 / (1 - pt), 0.5 / (1 - pt), 0.1 / (1 - pt)},
               tw[3] = {0.7 / pt, 0.2 / pt, 0.4 / pt};
  for (int k = 0; k < 3; ++k) {
    double sd = std::fabs(rw[k] - tw[k]) * std::sqrt(pt * (1 - pt) / n);
    EXPECT_NEAR(sum[k] / n, albedo[k], 5.0 * sd + 1e-6) << k;
    EXPECT_LE(albedo[k], 1.0 + 1e-12);
  }
  // The pdf over the sphere: the mean of pdf / (1 / 4 pi) over uniform directions.
  double integral = 0.0;
  const int m_dirs = 200000;
  for (int i = 0; i < m_dirs; ++i) {
    float z = 1.0f - 2.0f * u(gen), phi = 2.0f * float(kPi) * u(gen);
    float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    integral += double(bsdf_pdf(&m, wo, make_float3(r * std::cos(phi), r * std::sin(phi), z)));
  }
  EXPECT_NEAR(integral * 4.0 * kPi / m_dirs, 1.0, 0.01);
  // Black: nothing sampled, nothing evaluated.
  Material black =
      canopy::test::make_diffuse_transmission(make_float3(0, 0, 0), make_float3(0, 0, 0));
  BsdfSample s = bsdf_sample(&black, wo, make_float3(0.3f, 0.4f, 0.5f));
  EXPECT_EQ(s.weight.x, 0.0f);
  EXPECT_EQ(bsdf_pdf(&black, wo, make_float3(0, 0, 1)), 0.0f);
}
