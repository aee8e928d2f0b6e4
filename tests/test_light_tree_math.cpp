// Shared light-tree math (cl/light_tree/) on the host: cone union, M_Omega, the stable
// geometric variance, the dimensionless split measure and the importance's scale invariance.
#include "test_light_tree_util.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace canopy;
using namespace canopy::test;

namespace {

// theta_o sampled from the bulk and from both ends (near 0, near pi).
float random_angle(LtRng& r, float max_angle) {
  float u = lt_rng_next(&r);
  float x = lt_rng_next(&r);
  if (u < 0.3f) return max_angle * x;
  if (u < 0.55f) return max_angle * std::pow(10.0f, -7.0f * x); // near 0 (down to 1e-7)
  if (u < 0.8f) return std::fmax(0.0f, max_angle - max_angle * std::pow(10.0f, -7.0f * x));
  return u < 0.9f ? 0.0f : max_angle;
}

// An axis near `a` (or near -a) by a tiny angle, or random.
float3 random_axis_near(LtRng& r, float3 a) {
  float u = lt_rng_next(&r);
  if (u < 0.5f) return random_unit(r);
  float eps = std::pow(10.0f, -1.0f - 7.0f * lt_rng_next(&r));
  float3 p = lt_any_perpendicular(a);
  float3 v = normalize(a + p * eps);
  if (u < 0.6f) return a;
  if (u < 0.8f) return v;
  return make_float3(-v.x, -v.y, -v.z);
}

void expect_covers(const LtCone& u, const LtCone& in, double tol) {
  double need = angle_d(u.axis, in.axis) + double(in.theta_o);
  if (u.theta_o < M_PI_F) {
    EXPECT_LE(need, double(u.theta_o) + tol)
        << "input theta_o " << in.theta_o << " result theta_o " << u.theta_o;
  }
  EXPECT_GE(u.theta_e, in.theta_e);
}

} // namespace

TEST(LightTreeMath, ConeUnionCoversBothInputs) {
  LtRng r = lt_rng_make(2024, 1);
  const int kCases = 100000;
  int failures = 0;
  for (int i = 0; i < kCases && failures < 10; ++i) {
    float3 a_axis = random_unit(r);
    LtCone a = lt_make_cone(a_axis, random_angle(r, M_PI_F), random_angle(r, 0.5f * M_PI_F));
    LtCone b = lt_make_cone(random_axis_near(r, a_axis), random_angle(r, M_PI_F),
                            random_angle(r, 0.5f * M_PI_F));
    LtCone u = lt_cone_union(a, b);
    ASSERT_TRUE(std::isfinite(u.theta_o) && std::isfinite(u.axis.x) && std::isfinite(u.axis.y) &&
                std::isfinite(u.axis.z));
    EXPECT_NEAR(std::sqrt(dot_d(u.axis, u.axis)), 1.0, 1e-5);
    EXPECT_LE(u.theta_o, M_PI_F);
    // Exact coverage (up to double evaluation of the float axes): no tolerance beyond 1e-7 rad.
    expect_covers(u, a, 1e-7);
    expect_covers(u, b, 1e-7);
    if (::testing::Test::HasFailure()) ++failures;
  }
}

TEST(LightTreeMath, ConeUnionIsTight) {
  float3 z = make_float3(0, 0, 1);
  // a covers b: unchanged
  LtCone a = lt_make_cone(z, 0.5f, 0.3f);
  LtCone b = lt_make_cone(normalize(make_float3(0.1f, 0, 1)), 0.1f, 1.0f);
  LtCone u = lt_cone_union(a, b);
  EXPECT_EQ(u.theta_o, 0.5f);
  EXPECT_EQ(u.theta_e, 1.0f);
  // two flat emitters 90 degrees apart: half-angle 45 degrees, axis in between
  LtCone c = lt_cone_union(lt_make_cone(z, 0, 1.5707964f),
                           lt_make_cone(make_float3(1, 0, 0), 0, 1.5707964f));
  EXPECT_NEAR(c.theta_o, M_PI_F / 4, 1e-5);
  EXPECT_NEAR(c.axis.x, std::sqrt(0.5), 1e-5);
  EXPECT_NEAR(c.axis.z, std::sqrt(0.5), 1e-5);
  // opposite flat emitters: a half sphere around some perpendicular axis
  LtCone d = lt_cone_union(lt_make_cone(z, 0, 1.5707964f),
                           lt_make_cone(make_float3(0, 0, -1), 0, 1.5707964f));
  EXPECT_NEAR(d.theta_o, M_PI_F / 2, 1e-5);
  EXPECT_NEAR(d.axis.z, 0.0, 1e-5);
}

TEST(LightTreeMath, MOmegaMatchesQuadrature) {
  // M = 2pi [ (1 - cos to) + int_to^tw cos(x - to) sin(x) dx ], tw = min(to + te, pi)
  auto quad = [](double to, double te) {
    double tw = std::min(to + te, M_PI);
    const int n = 4000; // Simpson
    double h = (tw - to) / n, s = 0;
    for (int i = 0; i <= n; ++i) {
      double x = to + i * h;
      double f = std::cos(x - to) * std::sin(x);
      s += f * (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2));
    }
    return 2 * M_PI * ((1 - std::cos(to)) + s * h / 3);
  };
  for (int i = 0; i <= 40; ++i) {
    for (int j = 0; j <= 20; ++j) {
      float to = float(M_PI * i / 40.0);
      float te = float(M_PI / 2 * j / 20.0);
      double ref = quad(to, te);
      EXPECT_NEAR(lt_m_omega(to, te), ref, 2e-5 * 4 * M_PI) << "to=" << to << " te=" << te;
    }
  }
  EXPECT_NEAR(lt_m_omega(0.0f, 0.5f * M_PI_F), M_PI, 1e-5);
  EXPECT_NEAR(lt_m_omega(M_PI_F, 0.5f * M_PI_F), 4 * M_PI, 1e-5);
}

TEST(LightTreeMath, GeometricVarianceStableAgainstLongDouble) {
  // Reference: the definition evaluated in long double, where the cancellation is still small
  // for the relative gaps used here.
  auto ref_var = [](long double a, long double b) {
    long double eg2 = (b * b * b - a * a * a) / (3 * (b - a) * a * a * a * b * b * b);
    long double eg = 1 / (a * b);
    return eg2 - eg * eg;
  };
  for (float b : {1e-3f, 1.0f, 1e3f}) {
    // a -> b
    for (float rel : {1e-1f, 1e-2f, 1e-3f, 1e-4f, 1e-5f}) {
      float a = b * (1.0f - rel);
      long double ref = ref_var((long double)a, (long double)b);
      float v = lt_geom_var(a, b);
      EXPECT_NEAR(v / double(ref), 1.0, 1e-4) << "a=" << a << " b=" << b;
      EXPECT_NEAR(lt_geom_mean(a, b) * double(a) * double(b), 1.0, 1e-6);
      // the cancellation the stable form avoids: the paper's form in float is far off here
      if (rel <= 1e-3f) {
        float eg2 = (b * b * b - a * a * a) / (3 * (b - a) * a * a * a * b * b * b);
        float eg = 1 / (a * b);
        float paper = eg2 - eg * eg;
        EXPECT_GT(std::fabs(paper / double(ref) - 1.0), 1e-2) << "rel=" << rel;
      }
    }
    // a -> 0
    for (float rel : {1e-1f, 1e-3f, 1e-6f, 1e-9f}) {
      float a = b * rel;
      long double ref = ref_var((long double)a, (long double)b);
      float v = lt_geom_var(a, b);
      if (!std::isfinite(double(ref)) || double(ref) > 1e37) continue;
      ASSERT_TRUE(std::isfinite(v));
      EXPECT_NEAR(v / double(ref), 1.0, 1e-4) << "a=" << a << " b=" << b;
    }
  }
  // the dimensionless ratio V/E^2 = (b-a)^2/(3ab)
  EXPECT_NEAR(lt_geom_cv2(1.0f, 3.0f), 4.0 / 9.0, 1e-7);
}

TEST(LightTreeMath, SplitMeasureIsDimensionlessAndAlwaysSplitsInside) {
  float4 sphere = make_float4(1, 2, 3, 0.5f);
  // inside or touching: a = 0, always split
  EXPECT_EQ(lt_split_measure(make_float3(1, 2, 3.2f), sphere, 0.3f), 0.0f);
  EXPECT_TRUE(lt_should_split(lt_split_measure(make_float3(1, 2, 3.5f), sphere, 0.0f), 0.01f));
  // threshold 0 never splits, 1 always
  EXPECT_FALSE(lt_should_split(0.0f, 0.0f));
  EXPECT_TRUE(lt_should_split(1.0f, 1.0f));
  LtRng r = lt_rng_make(5, 5);
  for (int i = 0; i < 20000; ++i) {
    float3 c = make_float3(lt_rng_next(&r), lt_rng_next(&r), lt_rng_next(&r));
    float rad = 0.3f * lt_rng_next(&r);
    float3 P = make_float3(lt_rng_next(&r), lt_rng_next(&r), lt_rng_next(&r)) * 3.0f;
    float cv2 = 4.0f * lt_rng_next(&r) * lt_rng_next(&r);
    float m = lt_split_measure(P, f4_from3(c, rad), cv2);
    ASSERT_TRUE(m >= 0.0f && m <= 1.0f);
    for (float s : {1e-3f, 1e3f}) {
      float ms = lt_split_measure(P * s, f4_from3(c * s, rad * s), cv2);
      EXPECT_NEAR(ms, m, 2e-5f * std::fmax(m, 1e-3f) + 1e-6f);
      if (std::fabs(m - 0.85f) > 1e-4f) {
        EXPECT_EQ(lt_should_split(ms, 0.85f), lt_should_split(m, 0.85f));
      }
    }
  }
}

TEST(LightTreeMath, RngIsUniform) {
  LtRng r = lt_rng_make(9, 1);
  std::vector<double> counts(64, 0), prob(64, 1.0 / 64);
  const int n = 640000;
  for (int i = 0; i < n; ++i) {
    float x = lt_rng_next(&r);
    ASSERT_TRUE(x >= 0.0f && x < 1.0f);
    counts[int(x * 64)] += 1;
  }
  EXPECT_LT(chi2_score(counts, prob, n), 5.0);
}

TEST(LightTreeMath, FullSphereFastPathMatchesGeneralCode) {
  // lt_importance_v skips the orientation terms when all four lanes have theta_o = pi. Lanes 0-2
  // are full-sphere clusters; lane 3 has no energy (so it changes neither the energy nor the
  // distance normalisation) and either a full-sphere cone (the fast path runs) or a random cone
  // (the general code runs): lanes 0-2 must come out bit for bit the same.
  LtRng r = lt_rng_make(21, 3);
  int differs_from_one = 0;
  for (int i = 0; i < 20000; ++i) {
    float3 P = make_float3(lt_rng_next(&r), lt_rng_next(&r), lt_rng_next(&r)) * 4.0f;
    float3 N = i % 8 == 0 ? make_float3(0, 0, 0) : random_unit(r);
    float c[3][4], ax[3][4];
    for (int k = 0; k < 4; ++k) {
      float3 ck = make_float3(lt_rng_next(&r), lt_rng_next(&r), lt_rng_next(&r)) * 4.0f;
      float3 a = random_unit(r);
      c[0][k] = ck.x, c[1][k] = ck.y, c[2][k] = ck.z;
      ax[0][k] = a.x, ax[1][k] = a.y, ax[2][k] = a.z;
    }
    // radii from 0 (points) to large (P often inside); cos(theta_e) 0 (points, spheres), random,
    // or 1 (theta_e = 0: such a lane cannot contribute)
    float4 rad = make_float4(0.0f, 0.3f * lt_rng_next(&r), 3.0f * lt_rng_next(&r), 1.0f);
    float u = lt_rng_next(&r);
    float4 cos_e = u < 0.5f ? make_float4(0, 0, 0, 0)
                            : make_float4(lt_rng_next(&r), u < 0.7f ? 1.0f : 0.0f, 0.5f, 0.0f);
    float4 energy = make_float4(1.0f + lt_rng_next(&r), 1e-3f * lt_rng_next(&r), 5.0f, 0.0f);
    float4 cx = make_float4(c[0][0], c[0][1], c[0][2], c[0][3]);
    float4 cy = make_float4(c[1][0], c[1][1], c[1][2], c[1][3]);
    float4 cz = make_float4(c[2][0], c[2][1], c[2][2], c[2][3]);
    float4 ax4 = make_float4(ax[0][0], ax[0][1], ax[0][2], ax[0][3]);
    float4 ay4 = make_float4(ax[1][0], ax[1][1], ax[1][2], ax[1][3]);
    float4 az4 = make_float4(ax[2][0], ax[2][1], ax[2][2], ax[2][3]);
    float4 fast = lt_importance4(cx, cy, cz, rad, ax4, ay4, az4, make_float4(-1, -1, -1, -1), cos_e,
                                 energy, P, N);
    float co3 = 2.0f * lt_rng_next(&r) - 0.999f; // > -1: not a full sphere
    float4 general = lt_importance4(cx, cy, cz, rad, ax4, ay4, az4, make_float4(-1, -1, -1, co3),
                                    cos_e, energy, P, N);
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(float_as_uint_(f4_get(fast, k)), float_as_uint_(f4_get(general, k)))
          << "lane " << k << " case " << i << ": " << f4_get(fast, k) << " vs "
          << f4_get(general, k);
      differs_from_one += f4_get(cos_e, k) >= 1.0f && f4_get(energy, k) > 0.0f;
    }
  }
  EXPECT_GT(differs_from_one, 1000); // the theta_e = 0 lanes were exercised
}

TEST(LightTreeMath, ImportanceConservativeForSingleEmitters) {
  // One emitter per lane: importance > 0 whenever any point of the emitter clearly contributes.
  std::vector<Light> lights = mixed_lights(4000, 77, 10.0f);
  LtRng r = lt_rng_make(4, 4);
  int checked = 0;
  for (int i = 0; i < 200; ++i) {
    float3 P = make_float3(lt_rng_next(&r), lt_rng_next(&r), lt_rng_next(&r)) * 10.0f;
    float3 N = i % 10 == 0 ? make_float3(0, 0, 0) : random_unit(r);
    for (int l = 0; l < 4000; l += 7) {
      float3 bmin, bmax, axis;
      float co, ce, e;
      lt_light_bounds(&lights[l], &bmin, &bmax, &axis, &co, &ce, &e);
      float4 s = lt_sphere_of_box(bmin, bmax);
      float4 imp = lt_importance4(make_float4(s.x, 0, 0, 0), make_float4(s.y, 0, 0, 0),
                                  make_float4(s.z, 0, 0, 0), make_float4(s.w, 0, 0, 0),
                                  make_float4(axis.x, 0, 0, 0), make_float4(axis.y, 0, 0, 0),
                                  make_float4(axis.z, 0, 0, 0), make_float4(co, 1, 1, 1),
                                  make_float4(ce, 0, 0, 0), make_float4(e, 0, 0, 0), P, N);
      ASSERT_TRUE(std::isfinite(imp.x));
      EXPECT_EQ(imp.y, 0.0f); // empty lanes
      if (clearly_contributes(lights[l], P, N)) {
        ++checked;
        EXPECT_GT(imp.x, 0.0f) << "light " << l << " type " << lights[l].type;
      }
      if (contribution(lights[l], P, N) > 0) {
        EXPECT_GT(imp.x, 0.0f) << "light " << l;
      }
    }
  }
  EXPECT_GT(checked, 10000);
}
