// Light-tree picks for ray segments in a medium (Conty Estevez & Kulla 2018, §5.2, Eq. 4-7;
// cl/light_tree/query.h): the orientation bound theta_min of Eq. 5-6 against a brute-force
// maximum, conservative importance (every light that can light some point of the segment has a
// pmf > 0, with and without splitting), pmf normalisation, sampled pmf == evaluated pmf, chi-square
// fit, unbiased estimators of the single-scattering integral (Eq. 4), and point queries through
// the query functions equal to the (P, N) forms.
#include "test_light_tree_util.h"

#include "integrator/light_sampler.h" // cl/
#include "light_tree/query.h"         // cl/

#include <gtest/gtest.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <cmath>
#include <cstdio>

using namespace canopy;
using namespace canopy::test;

namespace {

// Mixed lights in [0, 10]^3 plus narrow spots (cos_outer in [0.99, 0.9995]).
std::vector<Light> segment_lights(int mixed, int narrow, uint32_t seed) {
  std::vector<Light> lights = mixed_lights(mixed, seed, 10.0f);
  LtRng r = lt_rng_make(seed, 31);
  for (int i = 0; i < narrow; ++i) {
    float3 p =
        make_float3(10.0f * lt_rng_next(&r), 10.0f * lt_rng_next(&r), 10.0f * lt_rng_next(&r));
    float co = 0.99f + 0.0095f * lt_rng_next(&r);
    float3 axis = random_unit(r);
    float e = 0.5f + 4.0f * lt_rng_next(&r);
    lights.push_back(
        make_spot_light(p, axis, co, std::fmin(1.0f, co + 0.0004f), make_float3(e, e, e)));
  }
  return lights;
}

// Random segments of five kinds (k = i % 5): short, long (across the scene), through a light's
// neighbourhood, starting next to a light (inside the clusters around it), zero length.
std::vector<LtQuery> random_segments(const std::vector<Light>& lights, int n, uint32_t seed) {
  LtRng r = lt_rng_make(seed, 77);
  std::vector<LtQuery> q;
  auto u = [&](float lo, float hi) { return lo + (hi - lo) * lt_rng_next(&r); };
  auto box = [&]() { return make_float3(u(-1, 11), u(-1, 11), u(-1, 11)); };
  for (int i = 0; i < n; ++i) {
    float3 c = xyz_of(lights[lt_rng_index(&r, uint32_t(lights.size()))].p);
    switch (i % 5) {
    case 0:
      q.push_back(lt_query_segment(box(), random_unit(r), u(0.01f, 0.5f)));
      break;
    case 1:
      q.push_back(lt_query_segment(box(), random_unit(r), u(5.0f, 25.0f)));
      break;
    case 2: {
      float3 a = c + random_unit(r) * 1.5f;
      float3 d = normalize(c + random_unit(r) * u(0.0f, 0.2f) - a);
      q.push_back(lt_query_segment(a, d, u(2.0f, 4.0f)));
      break;
    }
    case 3:
      q.push_back(
          lt_query_segment(c + random_unit(r) * u(0.05f, 0.3f), random_unit(r), u(0.5f, 5.0f)));
      break;
    default:
      q.push_back(lt_query_segment(box(), random_unit(r), 0.0f));
    }
  }
  return q;
}

float3 seg_point(const LtQuery& q, float t) {
  return q.P + q.N * t;
}

// Whether the light clearly emits towards some of 64 points spread over the segment (ends
// included): clearly_contributes with no receiver normal (a medium point).
bool lights_segment(const Light& l, const LtQuery& q) {
  for (int i = 0; i < 64; ++i)
    if (clearly_contributes(l, seg_point(q, q.len * float(i) / 63.0f), make_float3(0, 0, 0)))
      return true;
  return false;
}

// Four lanes of which only lane 0 has energy: lt_importance_seg_v then returns lane 0's
// orientation factor cos(max(theta_min - theta_o - theta_u, 0)) itself (energy and distance ratios
// are 1, the factor is above the floor).
LtLanes one_lane(float3 c, float r, float3 axis, float cos_o, float cos_e) {
  LtLanes l;
  l.cx = v4_from_f4(make_float4(c.x, 0, 0, 0));
  l.cy = v4_from_f4(make_float4(c.y, 0, 0, 0));
  l.cz = v4_from_f4(make_float4(c.z, 0, 0, 0));
  l.r = v4_from_f4(make_float4(r, 0, 0, 0));
  l.ax = v4_from_f4(make_float4(axis.x, 0, 0, 0));
  l.ay = v4_from_f4(make_float4(axis.y, 0, 0, 0));
  l.az = v4_from_f4(make_float4(axis.z, 0, 0, 0));
  l.cos_o = v4_from_f4(make_float4(cos_o, -1, -1, -1));
  l.cos_e = v4_from_f4(make_float4(cos_e, -1, -1, -1));
  l.energy = v4_from_f4(make_float4(1, 0, 0, 0));
  l.plane_h = v4_splat(LT_PLANE_NONE);
  return l;
}

} // namespace

// Eq. 5-6: theta_min is the smallest angle between the cone axis and the directions from the
// centre towards the segment. Against a brute-force maximum of cos(max(theta(x) - theta_o -
// theta_u, 0)) over 4001 points x of the segment (theta_u from the closest point, as Eq. 7): the
// factor is never below it (conservative) and at most 2e-3 above (the discrete maximum misses a
// little), including segments whose best direction is interior (Eq. 6's second case).
TEST(LightTreeSegment, OrientationBoundMatchesBruteForce) {
  LtRng r = lt_rng_make(5, 1);
  auto u = [&](double lo, double hi) { return lo + (hi - lo) * lt_rng_next(&r); };
  int interior = 0, culled = 0, lit = 0;
  for (int k = 0; k < 3000; ++k) {
    float3 c = make_float3(float(u(-1, 1)), float(u(-1, 1)), float(u(-1, 1)));
    float rad = k % 3 == 0 ? 0.0f : float(u(0.0, 0.3));
    float3 axis = random_unit(r);
    // theta_e <= pi/2 as lt_light_bounds makes it (wider spots widen theta_o instead)
    float cos_o = float(u(-0.5, 1.0)), cos_e = float(u(0.0, 0.9));
    float3 a = make_float3(float(u(-4, 4)), float(u(-4, 4)), float(u(-4, 4)));
    float3 d = random_unit(r);
    float len = k % 7 == 0 ? 0.0f : float(u(0.0, 8.0));
    if (k % 2 == 1) { // a narrow cone aimed near the segment's middle: the interior case
      rad = float(u(0.0, 0.05));
      cos_o = float(u(0.98, 1.0));
      cos_e = float(u(0.95, 1.0));
      axis = normalize(a + d * (0.5f * len) - c + random_unit(r) * float(u(0.0, 1.0)));
    }
    LtQuery q = lt_query_segment(a, d, len);
    LtLanes l = one_lane(c, rad, axis, cos_o, cos_e);
    float f = v4_to_f4(lt_importance_seg_v(&l, &q, 0)).x;
    // brute force in double
    double theta_o = std::acos(double(cos_o)), theta_e = std::acos(double(cos_e));
    double best = 1e9, best_t = 0, dist = 1e9;
    for (int i = 0; i <= 4000; ++i) {
      double t = double(len) * i / 4000.0;
      float3 x = a + d * float(t);
      float3 v = x - c;
      double th = angle_d(axis, v);
      if (th < best) best = th, best_t = t;
      dist = std::min(dist, std::sqrt(dot_d(v, v)));
    }
    // the exact closest point (the sampled points may miss it)
    float3 xc = lt_query_closest(&q, c);
    dist = std::min(dist, std::sqrt(dot_d(xc - c, xc - c)));
    double theta_u = dist <= rad ? M_PI : std::asin(std::min(1.0, rad / dist));
    double ang = std::max(best - theta_o - theta_u, 0.0);
    double ref = ang >= theta_e ? 0.0 : std::max(std::cos(ang), 0.0);
    interior += best_t > 1e-3 * len && best_t < len * (1 - 1e-3) && ang > 0;
    culled += ref == 0.0;
    lit += ref > 0.0;
    ASSERT_GE(double(f), ref - 2e-5) << "case " << k;
    // near theta_e the brute force may step past the cut-off the exact angle stays below
    if (ang < theta_e - 1e-2) {
      ASSERT_LE(double(f), ref + 2e-3) << "case " << k;
    }
  }
  EXPECT_GT(interior, 100); // Eq. 6's second case is exercised ...
  EXPECT_GT(culled, 100);   // ... and the bound does cull ...
  EXPECT_GT(lit, 1000);     // ... and keep
}

// Eq. 7 for full-sphere lanes: E / max(d_min, r/2), normalised by the largest energy and the
// smallest clamped distance, d_min the distance from the centre to the segment.
TEST(LightTreeSegment, DistanceFalloffIsInverseLinear) {
  LtRng r = lt_rng_make(6, 1);
  for (int k = 0; k < 500; ++k) {
    LtLanes l;
    float cx[4], cy[4], cz[4], rr[4], en[4];
    for (int j = 0; j < 4; ++j) {
      cx[j] = 4.0f * lt_rng_next(&r);
      cy[j] = 4.0f * lt_rng_next(&r);
      cz[j] = 4.0f * lt_rng_next(&r);
      rr[j] = 0.5f * lt_rng_next(&r);
      en[j] = j == 3 && k % 2 ? 0.0f : 0.1f + lt_rng_next(&r);
    }
    l.cx = v4_from_f4(make_float4(cx[0], cx[1], cx[2], cx[3]));
    l.cy = v4_from_f4(make_float4(cy[0], cy[1], cy[2], cy[3]));
    l.cz = v4_from_f4(make_float4(cz[0], cz[1], cz[2], cz[3]));
    l.r = v4_from_f4(make_float4(rr[0], rr[1], rr[2], rr[3]));
    l.ax = l.ay = l.az = v4_splat(0.0f);
    l.cos_o = v4_splat(-1.0f);
    l.cos_e = v4_splat(-1.0f);
    l.energy = v4_from_f4(make_float4(en[0], en[1], en[2], en[3]));
    l.plane_h = v4_splat(LT_PLANE_NONE);
    LtQuery q = lt_query_segment(make_float3(-1, 2 * lt_rng_next(&r), 2), random_unit(r),
                                 5.0f * lt_rng_next(&r));
    float4 imp = v4_to_f4(lt_importance_seg_v(&l, &q, 1));
    double w[4], wmax = 0;
    for (int j = 0; j < 4; ++j) {
      float3 c = make_float3(cx[j], cy[j], cz[j]);
      float3 x = lt_query_closest(&q, c);
      double dm = std::max(std::sqrt(dot_d(x - c, x - c)), 0.5 * rr[j]);
      w[j] = en[j] / dm;
      wmax = std::max(wmax, w[j]);
    }
    double isum = lt_sum4(imp);
    for (int j = 0; j < 4; ++j)
      EXPECT_NEAR(f4_get(imp, j) / isum, w[j] / (w[0] + w[1] + w[2] + w[3]), 1e-5) << k;
  }
}

// Every light that clearly lights some point of the segment (64 points tested with the light's
// emission cone or plane) has pmf > 0 under the tree pick and under splitting: no cluster holding
// it had importance 0. Some lights are culled (the test has teeth).
TEST(LightTreeSegment, ImportancePositiveForLightsThatLightTheSegment) {
  std::vector<Light> lights = segment_lights(1500, 500, 41);
  LightTree tree = build_light_tree(lights);
  LtTree t = tree.view(lights.data());
  std::vector<LtQuery> segs = random_segments(lights, 100, 42);
  std::vector<int> checked(segs.size(), 0), culled(segs.size(), 0);
  tbb::parallel_for(0, int(segs.size()), [&](int i) {
    const LtQuery& q = segs[size_t(i)];
    for (int l = 0; l < int(lights.size()); ++l) {
      float pt = lt_pmf_below_q(&t, 0, &q, tree.trails[size_t(l)]);
      float ps = lt_pmf_split_q(&t, &q, l, 0.9f, 64u);
      if (!lights_segment(lights[size_t(l)], q)) {
        culled[size_t(i)] += pt == 0.0f;
        continue;
      }
      ++checked[size_t(i)];
      EXPECT_GT(pt, 0.0f) << "segment " << i << " light " << l << " type "
                          << lights[size_t(l)].type;
      EXPECT_GT(ps, 0.0f) << "segment " << i << " light " << l;
    }
  });
  int nchecked = 0, nculled = 0;
  for (size_t i = 0; i < segs.size(); ++i) {
    nchecked += checked[i];
    nculled += culled[i];
  }
  std::printf("checked %d (light, segment) pairs, %d culled\n", nchecked, nculled);
  EXPECT_GT(nchecked, 100000);
  EXPECT_GT(nculled, 5000);
}

// The midpoint ablation (lt_query_midpoint: the surface importance at the segment's midpoint with
// bounds grown by half the segment) is conservative too: every light that lights some point of the
// segment keeps pmf > 0. Without the growth it is not (some such light would be culled).
TEST(LightTreeSegment, MidpointQueryKeepsEveryLightThatLightsTheSegment) {
  std::vector<Light> lights = segment_lights(1500, 500, 41);
  LightTree tree = build_light_tree(lights);
  LtTree t = tree.view(lights.data());
  std::vector<LtQuery> segs = random_segments(lights, 60, 45);
  std::vector<int> checked(segs.size(), 0), lost_plain(segs.size(), 0);
  tbb::parallel_for(0, int(segs.size()), [&](int i) {
    const LtQuery& s = segs[size_t(i)];
    LtQuery q = lt_query_midpoint(s.P, s.N, s.len);
    LtQuery plain = lt_query_point(q.P, make_float3(0, 0, 0));
    for (int l = 0; l < int(lights.size()); ++l) {
      if (!lights_segment(lights[size_t(l)], s)) continue;
      ++checked[size_t(i)];
      EXPECT_GT(lt_pmf_below_q(&t, 0, &q, tree.trails[size_t(l)]), 0.0f)
          << "segment " << i << " light " << l;
      EXPECT_GT(lt_pmf_split_q(&t, &q, l, 0.9f, 64u), 0.0f) << "segment " << i << " light " << l;
      lost_plain[size_t(i)] += lt_pmf_below_q(&t, 0, &plain, tree.trails[size_t(l)]) == 0.0f;
    }
  });
  int nchecked = 0, nlost = 0;
  for (size_t i = 0; i < segs.size(); ++i) {
    nchecked += checked[i];
    nlost += lost_plain[i];
  }
  EXPECT_GT(nchecked, 50000);
  EXPECT_GT(nlost, 0); // the growth is needed
}

// Tree: the pmfs sum to 1. Splitting: they sum to the cut's size (each item not split yields one
// pick, each light of a split leaf is taken with probability 1), every pick's prob equals the
// evaluated pmf bit for bit, under both samplers.
TEST(LightTreeSegment, PmfSumsAndSampledPmfEqualsEvaluated) {
  std::vector<Light> lights = segment_lights(3000, 500, 43);
  LightTree tree = build_light_tree(lights);
  LtTree t = tree.view(lights.data());
  std::vector<LtQuery> segs = random_segments(lights, 40, 44);
  struct Cfg {
    float threshold;
    int max_cut;
  };
  for (size_t i = 0; i < segs.size(); ++i) {
    const LtQuery& q = segs[i];
    double sum = 0;
    for (int l = 0; l < int(lights.size()); ++l)
      sum += lt_pmf_below_q(&t, 0, &q, tree.trails[size_t(l)]);
    EXPECT_NEAR(sum, 1.0, 1e-4) << "segment " << i;
    for (int k = 0; k < 20; ++k) {
      Rng rng = make_rng(9, uint32_t(i * 20 + k));
      std::vector<LightPick> out;
      sample_tree_q(t, q, rng, out);
      ASSERT_EQ(out.size(), 1u);
      ASSERT_EQ(out[0].prob, lt_pmf_below_q(&t, 0, &q, tree.trails[size_t(out[0].light)]));
    }
    for (Cfg cfg : {Cfg{LT_DEFAULT_SPLIT_THRESHOLD, 64}, Cfg{0.9f, 64}, Cfg{0.95f, 6}}) {
      double split_sum = 0;
      for (int l = 0; l < int(lights.size()); ++l)
        split_sum += lt_pmf_split_q(&t, &q, l, cfg.threshold, uint(cfg.max_cut));
      for (int k = 0; k < 5; ++k) {
        Rng rng = make_rng(10, uint32_t(i * 5 + k));
        std::vector<LightPick> out;
        sample_tree_split_q(t, q, rng, cfg.threshold, cfg.max_cut, out);
        ASSERT_LE(int(out.size()), cfg.max_cut);
        EXPECT_NEAR(split_sum, double(out.size()), 1e-4 * double(out.size()))
            << "segment " << i << " threshold " << cfg.threshold;
        for (const LightPick& p : out) {
          ASSERT_GT(p.prob, 0.0f);
          ASSERT_EQ(p.prob, lt_pmf_split_q(&t, &q, p.light, cfg.threshold, uint(cfg.max_cut)))
              << "segment " << i << " light " << p.light;
        }
      }
    }
  }
}

TEST(LightTreeSegment, ChiSquareOfTreePicks) {
  std::vector<Light> lights = segment_lights(1200, 300, 45);
  LightTree tree = build_light_tree(lights);
  LtTree t = tree.view(lights.data());
  std::vector<LtQuery> segs = random_segments(lights, 4, 46); // short, long, through, inside
  for (size_t i = 0; i < segs.size(); ++i) {
    const int m = 200000;
    std::vector<double> prob(lights.size());
    for (size_t l = 0; l < lights.size(); ++l)
      prob[l] = lt_pmf_below_q(&t, 0, &segs[i], tree.trails[l]);
    std::vector<std::vector<double>> part(2, std::vector<double>(lights.size(), 0.0));
    tbb::parallel_for(0, 2, [&](int h) {
      for (int k = h; k < m; k += 2) {
        Rng rng = make_rng(uint32_t(200 + i), uint32_t(k));
        float p;
        int l = lt_pick_below_q(&t, 0, &segs[i], &rng, &p);
        if (l >= 0) part[size_t(h)][size_t(l)] += 1;
      }
    });
    std::vector<double> counts(lights.size());
    for (size_t l = 0; l < lights.size(); ++l)
      counts[l] = part[0][l] + part[1][l];
    int dof;
    double z = chi2_score(counts, prob, m, &dof);
    EXPECT_LT(z, 5.0) << "segment " << i << " dof " << dof;
    EXPECT_GT(dof, 50) << "segment " << i;
  }
}

// A medium segment's cut is capped at LT_SEGMENT_MAX_CUT lights (light_sampler.h): under
// splitting that would take every cluster (threshold 1, max_cut 64), each segment's cut holds at
// most the cap, the light sampler's pmf of a segment query (what MIS of phase-function rays uses)
// is the pmf of the capped cut, and it equals the sampling frequency of each light (chi-square
// over the lights, counts of picks over many cuts against pmf x cuts).
TEST(LightTreeSegment, CappedSegmentCutPmfIsTheSamplingFrequency) {
  std::vector<Light> lights = segment_lights(1200, 300, 51);
  LightTree tree = build_light_tree(lights);
  LtTree t = tree.view(lights.data());
  LightSamplerCtx ls{};
  ls.kind = SAMPLER_TREE_SPLIT;
  ls.light_count = int(lights.size());
  ls.lights = lights.data();
  ls.tree = t;
  ls.threshold = 1.0f;
  ls.max_cut = 64;
  const uint cap = light_sampler_segment_budget(ls.max_cut);
  ASSERT_EQ(cap, LT_SEGMENT_MAX_CUT);
  ASSERT_LT(cap, 64u);
  EXPECT_EQ(light_sampler_segment_budget(2u), 2u); // a smaller max_cut still binds
  EXPECT_EQ(light_sampler_segment_budget(LT_BUDGET_UNLIMITED), LT_BUDGET_UNLIMITED); // exhaustive
  std::vector<LtQuery> segs = random_segments(lights, 4, 52); // short, long, through, inside
  for (size_t i = 0; i < segs.size(); ++i) {
    const LtQuery& q = segs[i];
    std::vector<double> prob(lights.size());
    double cut = 0;
    for (size_t l = 0; l < lights.size(); ++l) {
      prob[l] = light_sampler_pmf_q(&ls, &q, int(l));
      ASSERT_EQ(float(prob[l]), lt_pmf_split_q(&t, &q, int(l), ls.threshold, cap));
      cut += prob[l];
    }
    const int m = 100000;
    std::vector<std::vector<double>> part(2, std::vector<double>(lights.size(), 0.0));
    std::vector<size_t> largest(2, 0);
    tbb::parallel_for(0, 2, [&](int h) {
      std::vector<LightPick> out;
      for (int k = h; k < m; k += 2) {
        Rng rng = make_rng(uint32_t(500 + i), uint32_t(k));
        out.clear();
        sample_tree_split_q(t, q, rng, ls.threshold, int(cap), out);
        largest[size_t(h)] = std::max(largest[size_t(h)], out.size());
        for (const LightPick& p : out)
          part[size_t(h)][size_t(p.light)] += 1;
      }
    });
    EXPECT_LE(std::max(largest[0], largest[1]), size_t(cap)) << "segment " << i;
    EXPECT_GT(cut, 1.5) << "segment " << i; // the cut did split
    std::vector<double> counts(lights.size()), p1(lights.size());
    for (size_t l = 0; l < lights.size(); ++l) {
      counts[l] = part[0][l] + part[1][l];
      p1[l] = prob[l] / cut; // the cut's size is the same for every cut of q
    }
    int dof;
    double z = chi2_score(counts, p1, double(m) * cut, &dof);
    EXPECT_LT(z, 5.0) << "segment " << i << " dof " << dof;
    EXPECT_GT(dof, 50) << "segment " << i;
  }
}

namespace {
// The single-scattering integral of a light over the segment, without transmittance: for a point
// light of intensity I exactly I * (theta_b - theta_a) / D (Eq. 4, D the distance from the light
// to the segment's line); for a spot the integral of I / |x - p|^2 over the part of the segment
// inside its outer cone (midpoint rule: any deterministic f that is 0 where the light cannot
// reach the segment keeps the estimator's expectation equal to the sum of f).
double scatter_integral(const Light& l, const LtQuery& q) {
  double I = emitter_bounds(l).energy;
  float3 p = xyz_of(l.p);
  if (l.type == LIGHT_POINT) {
    float3 e = q.P - p;
    double sa = dot_d(e, q.N), sb = sa + q.len;
    double w2 = std::max(dot_d(e, e) - sa * sa, 0.0);
    double D = std::sqrt(w2);
    if (!(D > 1e-9)) return 0.0;
    return I * (std::atan(sb / D) - std::atan(sa / D)) / D;
  }
  const int n = 2000;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    float3 x = seg_point(q, q.len * (float(i) + 0.5f) / float(n));
    float3 v = x - p;
    double d2 = dot_d(v, v);
    if (dot_d(v, xyz_of(l.e1)) > double(l.e1.w) * std::sqrt(d2)) sum += I / d2;
  }
  return sum * q.len / n;
}
} // namespace

// sum over picks of f(l) / prob, averaged over many trials, equals sum over lights of f(l) (point
// lights and narrow spots, f the single-scattering integral over the segment), with the tree pick
// and with splitting, within 5 standard errors of the sample variance.
TEST(LightTreeSegment, EstimatorsAreUnbiased) {
  std::vector<Light> lights;
  LtRng r = lt_rng_make(47, 0);
  for (int i = 0; i < 1200; ++i) {
    float3 p =
        make_float3(10.0f * lt_rng_next(&r), 10.0f * lt_rng_next(&r), 10.0f * lt_rng_next(&r));
    float e = 0.2f + 3.0f * lt_rng_next(&r);
    if (i % 3 == 0) {
      float co = 0.9f + 0.099f * lt_rng_next(&r);
      lights.push_back(make_spot_light(p, random_unit(r), co, co, make_float3(e, e, e)));
    } else {
      lights.push_back(make_point_light(p, make_float3(e, e, e)));
    }
  }
  LightTree tree = build_light_tree(lights);
  LtTree t = tree.view(lights.data());
  std::vector<LtQuery> segs = {
      lt_query_segment(make_float3(-2, 5, 5), make_float3(1, 0, 0), 14.0f),             // across
      lt_query_segment(make_float3(5, 5, 5), normalize(make_float3(1, 2, 3)), 1.0f),    // inside
      lt_query_segment(make_float3(12, 12, 12), normalize(make_float3(1, 1, 0)), 3.0f), // far
      lt_query_segment(make_float3(2, 8, 3), normalize(make_float3(0, -1, 0.2f)), 6.0f)};
  struct Cfg {
    float threshold; // < 0: the tree pick
    int max_cut;
  };
  for (size_t i = 0; i < segs.size(); ++i) {
    const LtQuery& q = segs[i];
    std::vector<double> f(lights.size());
    tbb::parallel_for(0, int(lights.size()),
                      [&](int l) { f[size_t(l)] = scatter_integral(lights[size_t(l)], q); });
    double ref = 0;
    for (double x : f)
      ref += x;
    for (Cfg cfg : {Cfg{-1.0f, 0}, Cfg{0.5f, 8}, Cfg{0.9f, 64}, Cfg{1.0f, 16}}) {
      const int m = 30000;
      struct Acc {
        double s = 0, s2 = 0;
      };
      Acc a = tbb::parallel_reduce(
          tbb::blocked_range<int>(0, m, 512), Acc(),
          [&](const tbb::blocked_range<int>& rg, Acc acc) {
            std::vector<LightPick> out;
            for (int k = rg.begin(); k != rg.end(); ++k) {
              Rng rng = make_rng(uint32_t(300 + i), uint32_t(k));
              out.clear();
              if (cfg.threshold < 0)
                sample_tree_q(t, q, rng, out);
              else
                sample_tree_split_q(t, q, rng, cfg.threshold, cfg.max_cut, out);
              double est = 0;
              for (const LightPick& p : out)
                est += f[size_t(p.light)] / p.prob;
              acc.s += est;
              acc.s2 += est * est;
            }
            return acc;
          },
          [](Acc x, const Acc& y) {
            x.s += y.s;
            x.s2 += y.s2;
            return x;
          });
      double mean = a.s / m;
      double se = std::sqrt(std::max(0.0, a.s2 / m - mean * mean) / m);
      EXPECT_NEAR(mean, ref, 5.0 * se + 1e-6 * ref)
          << "segment " << i << " threshold " << cfg.threshold << " cap " << cfg.max_cut;
      EXPECT_LT(se, 0.2 * ref) << "segment " << i; // the test can see a bias of a few percent
    }
  }
}

// Point queries through the query functions give exactly the (P, N) forms' results: importances,
// picks, pmfs, split decisions and the light_sampler interface; and uniform / power ignore the
// query's kind.
TEST(LightTreeSegment, PointQueriesEqualPointForms) {
  std::vector<Light> lights = segment_lights(2000, 100, 48);
  LightTree tree = build_light_tree(lights);
  LtTree t = tree.view(lights.data());
  LtRng r = lt_rng_make(49, 0);
  LightSamplerCtx ls{};
  ls.light_count = int(lights.size());
  ls.lights = lights.data();
  ls.tree = t;
  ls.threshold = LT_DEFAULT_SPLIT_THRESHOLD;
  ls.max_cut = 64;
  for (int k = 0; k < 200; ++k) {
    float3 P = make_float3(-1 + 12 * lt_rng_next(&r), -1 + 12 * lt_rng_next(&r),
                           -1 + 12 * lt_rng_next(&r));
    float3 N = k % 4 == 3 ? make_float3(0, 0, 0) : random_unit(r);
    LtQuery q = lt_query_point(P, N);
    for (int node = 0; node < std::min(tree.num_nodes(), 20); ++node) {
      float4 a = lt_node_importance(&t, node, P, N), b = lt_node_importance_q(&t, node, &q, 1);
      for (int j = 0; j < 4; ++j)
        ASSERT_EQ(f4_get(a, j), f4_get(b, j));
      float4 c = lt_code_importance(&t, node, P, N), d = lt_code_importance_q(&t, node, &q);
      for (int j = 0; j < 4; ++j)
        ASSERT_EQ(f4_get(c, j), f4_get(d, j));
    }
    for (int kind : {SAMPLER_TREE, SAMPLER_TREE_SPLIT}) {
      ls.kind = kind;
      Rng r1 = make_rng(50, uint32_t(k)), r2 = r1;
      float p1, p2;
      int l1 = light_sampler_pick(&ls, 0, P, N, &r1, &p1);
      int l2 = light_sampler_pick_q(&ls, 0, &q, &r2, &p2);
      ASSERT_EQ(l1, l2);
      ASSERT_EQ(p1, p2);
      for (int l = k; l < int(lights.size()); l += 97)
        ASSERT_EQ(light_sampler_pmf(&ls, P, N, l), light_sampler_pmf_q(&ls, &q, l));
    }
    std::vector<LightPick> o1, o2;
    Rng r1 = make_rng(51, uint32_t(k)), r2 = r1;
    sample_tree_split(t, P, N, r1, 0.9f, 16, o1);
    sample_tree_split_q(t, q, r2, 0.9f, 16, o2);
    ASSERT_EQ(o1.size(), o2.size());
    for (size_t j = 0; j < o1.size(); ++j) {
      ASSERT_EQ(o1[j].light, o2[j].light);
      ASSERT_EQ(o1[j].prob, o2[j].prob);
    }
    // a segment query through the uniform sampler: the same pick and pmf as a point query
    ls.kind = SAMPLER_UNIFORM;
    LtQuery s = lt_query_segment(P, random_unit(r), 3.0f);
    Rng r3 = make_rng(52, uint32_t(k)), r4 = r3;
    float p3, p4;
    ASSERT_EQ(light_sampler_pick_q(&ls, 0, &s, &r3, &p3),
              light_sampler_pick_q(&ls, 0, &q, &r4, &p4));
    ASSERT_EQ(p3, p4);
  }
}

// The orientation ablation (LT_TERMS_DISTANCE) drops the cones but keeps the segment: four spot
// lights (radius 0, one per lane of the root) get pmf E_l / d_l normalised, d_l the distance from
// light l to the segment, whatever their axes; the full measure culls the spots facing away.
TEST(LightTreeSegment, OrientationAblationRanksByEnergyOverDistance) {
  std::vector<Light> lights = four_spot_lights();
  LightTree ablation = build_light_tree(lights), full = build_light_tree(lights);
  ablation.set_orientation_term(false);
  ASSERT_EQ(ablation.num_nodes(), 1);
  for (int lane = 0; lane < 4; ++lane) { // one light per lane, or one leaf: exact ratios
    int code = i4_get(ablation.children[0], lane);
    ASSERT_TRUE(code == LT_EMPTY || (lt_is_leaf(code) && (lt_leaf_count(code) == 1 ||
                                                          ablation.children[0].y == LT_EMPTY)));
  }
  LtTree ta = ablation.view(lights.data()), tf = full.view(lights.data());
  int culled = 0;
  for (LtQuery q : {lt_query_segment(make_float3(0.5f, 0, 0), make_float3(0, 0, 1), 2.0f),
                    lt_query_segment(make_float3(-3, 0, 0), make_float3(1, 0, 0), 6.0f),
                    lt_query_segment(make_float3(0, 5, 0), normalize(make_float3(1, -1, 1)), 1.0f),
                    lt_query_segment(make_float3(2, 2, 2), make_float3(0, 1, 0), 0.0f)}) {
    double w[4], sum = 0;
    for (int l = 0; l < 4; ++l) {
      float3 c = xyz_of(lights[size_t(l)].p);
      float3 x = lt_query_closest(&q, c);
      sum += w[l] = emitter_bounds(lights[size_t(l)]).energy / std::sqrt(dot_d(x - c, x - c));
    }
    for (int l = 0; l < 4; ++l) {
      EXPECT_NEAR(lt_pmf_below_q(&ta, 0, &q, ablation.trails[size_t(l)]), w[l] / sum, 2e-6)
          << "light " << l;
      culled += lt_pmf_below_q(&tf, 0, &q, full.trails[size_t(l)]) == 0.0f;
    }
  }
  EXPECT_GT(culled, 2);
}
