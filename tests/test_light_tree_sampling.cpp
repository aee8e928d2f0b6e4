// Light samplers: pmf normalisation, sampled pmf == bit-trail pmf, chi-square fits (including
// paths of more than 24 bits of probability on a 10^6-light tree), conservative importance,
// unbiasedness with and without splitting, scale invariance of the split decisions, zero-energy
// lights.
#include "test_light_tree_util.h"

#include <gtest/gtest.h>

#include <cfloat>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>

using namespace canopy;
using namespace canopy::test;

namespace {

struct Shade {
  float3 P, N;
};
// Random shading points in [lo, hi]^3 with random normals; every 8th has N = 0 (medium).
std::vector<Shade> shading_points(int n, float lo, float hi, uint32_t seed) {
  LtRng r = lt_rng_make(seed, 99);
  std::vector<Shade> s(n);
  for (int i = 0; i < n; ++i) {
    s[i].P = make_float3(lo + (hi - lo) * lt_rng_next(&r), lo + (hi - lo) * lt_rng_next(&r),
                         lo + (hi - lo) * lt_rng_next(&r));
    s[i].N = i % 8 == 7 ? make_float3(0, 0, 0) : random_unit(r);
  }
  return s;
}

// The orientation ablation (importance E / d^2), optionally with a split threshold.
LightSamplerOptions without_orientation(float threshold = LT_DEFAULT_SPLIT_THRESHOLD) {
  LightSamplerOptions o;
  o.orientation = false;
  o.split_threshold = threshold;
  return o;
}

double pmf_sum(const LightSampler& s, float3 P, float3 N) {
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, s.num_lights(), 1024), 0.0,
      [&](const tbb::blocked_range<int>& r, double acc) {
        for (int l = r.begin(); l != r.end(); ++l)
          acc += s.pmf(P, N, l);
        return acc;
      },
      [](double a, double b) { return a + b; });
}

} // namespace

TEST(LightTreeSampling, UnknownSamplerThrows) {
  std::vector<Light> l = random_point_lights(10, 1);
  EXPECT_THROW(make_light_sampler("bogus", l), std::invalid_argument);
  LightSamplerOptions bad;
  bad.split_threshold = 1.5f;
  EXPECT_THROW(make_light_sampler("tree-split", l, bad), std::invalid_argument);
  for (const std::string& name : light_sampler_names()) {
    auto s = make_light_sampler(name, l);
    EXPECT_EQ(name, s->name());
  }
}

TEST(LightTreeSampling, PmfSumsToOne) {
  std::vector<Light> lights = mixed_lights(5000, 11, 10.0f);
  std::vector<Shade> pts = shading_points(40, -2.0f, 12.0f, 1);
  for (const char* name : {"uniform", "power", "tree", "tree-noorient"}) {
    bool ablation = std::string(name) == "tree-noorient";
    auto s = make_light_sampler(ablation ? "tree" : name, lights,
                                ablation ? without_orientation() : LightSamplerOptions{});
    for (const Shade& x : pts) {
      // tree: 1 everywhere (a descent never dead-ends, even where nothing contributes)
      EXPECT_NEAR(pmf_sum(*s, x.P, x.N), 1.0, 1e-4) << name;
    }
  }
}

// The orientation ablation (paper Fig. 15-16): without Eq. 3's orientation terms a cluster's
// importance is E / d^2, so for four spot lights (bounding radius 0, one light per lane or one
// leaf) the pmf is exactly E_l / d_l^2 normalised, whatever the normal and the spots' axes; the
// full measure gives lights that face away or lie behind the horizon probability 0.
TEST(LightTreeSampling, OrientationAblationRanksByEnergyOverDistanceSquared) {
  std::vector<Light> lights = four_spot_lights();
  LightSamplerOptions off;
  off.orientation = false;
  auto ablation = make_light_sampler("tree", lights, off);
  auto full = make_light_sampler("tree", lights);
  const LightTree& t = *ablation->tree();
  ASSERT_EQ(t.num_nodes(), 1);
  for (int lane = 0; lane < 4; ++lane) { // the precondition of the exact E / d^2 ratios
    int code = i4_get(t.children[0], lane);
    ASSERT_TRUE(code == LT_EMPTY ||
                (lt_is_leaf(code) && (lt_leaf_count(code) == 1 || t.children[0].y == LT_EMPTY)));
  }
  const float3 P = make_float3(0.5f, 0, 0);
  double w[4], sum = 0;
  for (int l = 0; l < 4; ++l) {
    float3 d = xyz_of(lights[l].p) - P;
    sum += w[l] = emitter_bounds(lights[l]).energy / dot_d(d, d);
  }
  int differs = 0, culled = 0;
  for (float3 N :
       {make_float3(0, 1, 0), make_float3(0, -1, 0), make_float3(1, 0, 0), make_float3(0, 0, 0)}) {
    for (int l = 0; l < 4; ++l) {
      float p = ablation->pmf(P, N, l);
      EXPECT_NEAR(p, w[l] / sum, 2e-6) << "light " << l;
      differs += std::fabs(full->pmf(P, N, l) - p) > 1e-3f;
      culled += full->pmf(P, N, l) == 0.0f;
    }
  }
  EXPECT_GT(differs, 4); // the switch changes the ranking ...
  EXPECT_GT(culled, 2);  // ... and the full measure culls lights the ablation keeps
}

TEST(LightTreeSampling, SampledPmfEqualsTrailPmf) {
  std::vector<Light> lights = mixed_lights(20000, 12, 10.0f);
  std::vector<Shade> pts = shading_points(300, -1.0f, 11.0f, 2);
  LightSamplerOptions capped;
  capped.max_cut = 6;
  capped.split_threshold = 0.95f;
  struct Cfg {
    const char* name;
    LightSamplerOptions opt;
  };
  for (const Cfg& cfg :
       {Cfg{"uniform", {}}, Cfg{"power", {}}, Cfg{"tree", {}}, Cfg{"tree-split", {}},
        Cfg{"tree-split", capped}, Cfg{"tree", without_orientation()},
        Cfg{"tree-split", without_orientation()}}) {
    auto s = make_light_sampler(cfg.name, lights, cfg.opt);
    std::vector<LightPick> out;
    int picks = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
      for (int k = 0; k < 20; ++k) {
        Rng rng = make_rng(7, uint32_t(i * 20 + k));
        out.clear();
        s->sample(pts[i].P, pts[i].N, rng, out);
        EXPECT_LE(int(out.size()), std::string(cfg.name) == "tree-split" ? cfg.opt.max_cut : 1);
        for (const LightPick& p : out) {
          ++picks;
          ASSERT_GT(p.prob, 0.0f);
          // bit-identical: the same functions on the same inputs
          ASSERT_EQ(p.prob, s->pmf(pts[i].P, pts[i].N, p.light))
              << cfg.name << " light " << p.light;
        }
      }
    }
    EXPECT_GT(picks, 3000) << cfg.name;
  }
}

TEST(LightTreeSampling, ChiSquarePerLight) {
  // Picks against the pmf, one bin per light (pooled below 5 expected), 1500 mixed lights.
  std::vector<Light> lights = mixed_lights(1500, 13, 10.0f);
  std::vector<Shade> pts = shading_points(4, 2.0f, 8.0f, 3);
  for (const char* name : {"power", "tree"}) {
    auto s = make_light_sampler(name, lights);
    for (size_t i = 0; i < pts.size(); ++i) {
      const int m = 300000;
      std::vector<double> counts(lights.size(), 0), prob(lights.size());
      for (size_t l = 0; l < lights.size(); ++l)
        prob[l] = s->pmf(pts[i].P, pts[i].N, int(l));
      std::vector<LightPick> out;
      int total = 0;
      for (int k = 0; k < m; ++k) {
        Rng rng = make_rng(uint32_t(100 + i), uint32_t(k));
        out.clear();
        s->sample(pts[i].P, pts[i].N, rng, out);
        for (const LightPick& p : out) {
          counts[p.light] += 1;
          ++total;
        }
      }
      if (total == 0) continue;
      int dof;
      double z = chi2_score(counts, prob, total, &dof);
      EXPECT_LT(z, 5.0) << name << " point " << i << " dof " << dof;
      EXPECT_GT(dof, 100);
    }
  }
}

namespace {
// 4^10 coincident point lights whose energies make every lane probability dyadic:
// at every level the four lanes have probabilities (1/2, 1/4, 1/8, 1/8) and a light's pmf is the
// product over its base-4 digits. A path through many 1/8 lanes has probability down to 2^-30
// (one 24-bit uniform rescaled down the tree could not resolve it; every decision now draws a
// fresh 32-bit word, lt_choose_lane).
constexpr int kDyadicLevels = 10;
constexpr double kLaneP[4] = {0.5, 0.25, 0.125, 0.125};
std::vector<Light> dyadic_lights() {
  const int n = 1 << (2 * kDyadicLevels);
  std::vector<Light> lights(n);
  tbb::parallel_for(0, n, [&](int i) {
    float e = 1.0f;
    for (int d = 0; d < kDyadicLevels; ++d) {
      int digit = (i >> (2 * (kDyadicLevels - 1 - d))) & 3;
      e *= float(kLaneP[digit] * 2.0); // relative to the largest lane: 1, 1/2, 1/4, 1/4
    }
    lights[i] = make_point_light(make_float3(0.5f, -0.25f, 2.0f), make_float3(e, e, e));
  });
  return lights;
}

// Bits of probability taken by the first 8 decisions of light i (-log2 of their probabilities).
int prefix_bits(int i) {
  int bits = 0;
  for (int d = 0; d < kDyadicLevels - 2; ++d) {
    int digit = (i >> (2 * (kDyadicLevels - 1 - d))) & 3;
    bits += digit == 0 ? 1 : (digit == 1 ? 2 : 3);
  }
  return bits;
}

// Chi-square score of picks grouped by the last two decisions (the last node level's lane and the
// index in the leaf), separately for lights whose first 8 decisions consumed more than 20 bits
// (where one rescaled 24-bit uniform would have <= 3 bits left for the last two) and the others.
double dyadic_chi2(const LightSampler& s, int picks, float3 P) {
  std::vector<std::vector<double>> part(2, std::vector<double>(32, 0.0));
  tbb::parallel_for(0, 2, [&](int t) {
    std::vector<LightPick> out;
    for (int k = t; k < picks; k += 2) {
      Rng rng = make_rng(4242, uint32_t(k));
      out.clear();
      s.sample(P, make_float3(0, 0, 0), rng, out);
      for (const LightPick& p : out)
        part[t][(prefix_bits(p.light) > 20 ? 16 : 0) + (p.light & 15)] += 1;
    }
  });
  // P(prefix > 20 bits), exactly, over the 4^8 prefixes
  double deep = 0;
  for (int pre = 0; pre < (1 << 16); ++pre) {
    double pr = 1;
    int bits = 0;
    for (int d = 0; d < 8; ++d) {
      int digit = (pre >> (2 * (7 - d))) & 3;
      pr *= kLaneP[digit];
      bits += digit == 0 ? 1 : (digit == 1 ? 2 : 3);
    }
    if (bits > 20) deep += pr;
  }
  std::vector<double> counts(32), prob(32);
  for (int g = 0; g < 32; ++g) {
    counts[g] = part[0][g] + part[1][g];
    prob[g] = (g >= 16 ? deep : 1.0 - deep) * kLaneP[(g >> 2) & 3] * kLaneP[g & 3];
  }
  return chi2_score(counts, prob, picks);
}
} // namespace

TEST(LightTreeSampling, ChiSquareMillionLightsXiPrecision) {
  std::vector<Light> lights = dyadic_lights();
  const float3 P = make_float3(3, 4, 5);
  auto s = make_light_sampler("tree", lights);
  ASSERT_EQ(s->tree()->levels, kDyadicLevels - 1);
  // the pmf is the analytic product along the digits, exactly
  for (int i : {0, 1, 77, 4095, 123456, (1 << 20) - 1}) {
    double expect = 1;
    for (int d = 0; d < kDyadicLevels; ++d)
      expect *= kLaneP[(i >> (2 * (kDyadicLevels - 1 - d))) & 3];
    EXPECT_EQ(double(s->pmf(P, make_float3(0, 0, 0), i)), expect) << "light " << i;
  }
  double z = dyadic_chi2(*s, 1000000, P);
  EXPECT_LT(z, 5.0);

  std::printf("chi-square normal score: %.2f\n", z);
}

TEST(LightTreeSampling, ImportancePositiveForContributingLights) {
  std::vector<Light> lights = mixed_lights(6000, 14, 10.0f);
  auto tree = make_light_sampler("tree", lights);
  LightSamplerOptions o;
  o.split_threshold = 0.9f;
  auto split = make_light_sampler("tree-split", lights, o);
  std::vector<Shade> pts = shading_points(150, -1.0f, 11.0f, 4);
  int checked = 0;
  for (const Shade& x : pts) {
    for (int l = 0; l < int(lights.size()); ++l) {
      if (!clearly_contributes(lights[l], x.P, x.N) && !(contribution(lights[l], x.P, x.N) > 0))
        continue;
      ++checked;
      ASSERT_GT(tree->pmf(x.P, x.N, l), 0.0f) << "light " << l << " type " << lights[l].type;
      ASSERT_GT(split->pmf(x.P, x.N, l), 0.0f) << "light " << l;
    }
  }
  EXPECT_GT(checked, 100000);
}

namespace {
// Mean and standard error of the estimator sum f(l)/prob over `m` independent runs.
void estimate(const LightSampler& s, const std::vector<Light>& lights, float3 P, float3 N, int m,
              uint32_t seed, double* mean, double* stderr_) {
  struct Acc {
    double s = 0, s2 = 0;
  };
  Acc a = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, m, 512), Acc(),
      [&](const tbb::blocked_range<int>& r, Acc acc) {
        std::vector<LightPick> out;
        for (int k = r.begin(); k != r.end(); ++k) {
          Rng rng = make_rng(seed, uint32_t(k));
          out.clear();
          s.sample(P, N, rng, out);
          double est = 0;
          for (const LightPick& p : out)
            est += contribution(lights[p.light], P, N) / p.prob;
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
  *mean = a.s / m;
  double var = std::max(0.0, a.s2 / m - *mean * *mean);
  *stderr_ = std::sqrt(var / m);
}
} // namespace

TEST(LightTreeSampling, EstimatorsAreUnbiased) {
  std::vector<Light> lights = mixed_lights(4000, 15, 10.0f);
  std::vector<Shade> pts = shading_points(6, 1.0f, 9.0f, 5);
  pts.push_back({make_float3(5, 5, 5), make_float3(0, 0, 0)});
  std::vector<std::pair<std::string, LightSamplerOptions>> cfgs;
  cfgs.push_back({"uniform", {}});
  cfgs.push_back({"power", {}});
  cfgs.push_back({"tree", {}});
  cfgs.push_back({"tree", without_orientation()});
  cfgs.push_back({"tree-split", without_orientation(0.85f)});
  for (float thr : {0.5f, 0.85f, 1.0f}) {
    for (int cap : {4, 64}) {
      LightSamplerOptions o;
      o.split_threshold = thr;
      o.max_cut = cap;
      cfgs.push_back({"tree-split", o});
    }
  }
  auto exhaustive = make_light_sampler("exhaustive", lights);
  for (size_t i = 0; i < pts.size(); ++i) {
    double ref = 0;
    for (const Light& l : lights)
      ref += contribution(l, pts[i].P, pts[i].N);
    double em, es;
    estimate(*exhaustive, lights, pts[i].P, pts[i].N, 1, 1, &em, &es);
    EXPECT_NEAR(em, ref, 1e-9 * ref);
    for (const auto& [name, opt] : cfgs) {
      auto s = make_light_sampler(name, lights, opt);
      double mean, se;
      estimate(*s, lights, pts[i].P, pts[i].N, name == "uniform" ? 200000 : 40000, uint32_t(17 + i),
               &mean, &se);
      EXPECT_NEAR(mean, ref, 5.0 * se + 1e-6 * ref)
          << name << " thr " << opt.split_threshold << " cap " << opt.max_cut << " orientation "
          << opt.orientation << " point " << i;
    }
  }
}

// Budgets go where splitting continues (lt_child_budgets): at a shading point next to one of 10^4
// lights, splitting with the paper's threshold and the default cap must reach that light itself
// (pmf 1: it is in the cut), while the cut stays within the cap. An even share of the budget would
// stop three 4-wide levels down, at clusters of ~160 lights.
TEST(LightTreeSampling, SplitBudgetReachesTheNearestLights) {
  // 10^4 point lights on a jittered 100 x 100 grid in a plane (the spiral scene's situation)
  std::vector<Light> lights;
  LtRng jitter = lt_rng_make(21, 0);
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 100; ++x)
      lights.push_back(make_point_light(make_float3(float(x) + 0.5f * lt_rng_next(&jitter), 0.0f,
                                                    float(y) + 0.5f * lt_rng_next(&jitter)),
                                        make_float3(1, 1, 1)));
  LightSamplerOptions o; // the default cap (64) and the paper's threshold, which splits more
  o.split_threshold = 0.85f;
  auto split = make_light_sampler("tree-split", lights, o);
  ASSERT_GE(split->tree()->levels, 6);
  int reached = 0;
  for (int i = 0; i < 50; ++i) {
    int target = i * 197;
    float3 P = xyz_of(lights[size_t(target)].p) + make_float3(0.0f, 0.1f, 0.0f);
    float3 N = make_float3(0, -1, 0);
    reached += split->pmf(P, N, target) == 1.0f;
    Rng rng = make_rng(3, uint32_t(i));
    std::vector<LightPick> out;
    split->sample(P, N, rng, out);
    EXPECT_LE(out.size(), 64u);
    EXPECT_GE(out.size(), 16u); // it did split (leaves and unsplittable items strand some)
    bool in_cut = false;
    for (const LightPick& p : out)
      in_cut |= p.light == target && p.prob == 1.0f;
    EXPECT_EQ(in_cut, split->pmf(P, N, target) == 1.0f) << "light " << target;
  }
  // The even share reaches none of them; importance-weighted budgets reach 46 of 50 (a point whose
  // neighbouring clusters all want to split can still run out of budget one level early).
  EXPECT_GE(reached, 45);
}

// The device's exhaustive sampler is tree splitting with threshold 1 and LT_BUDGET_UNLIMITED: its
// cut must hold every light with importance > 0, each once with probability 1, and lt_pmf_split
// must say 1 for each (a budget of N lights, shared down the tree, binds in unbalanced subtrees).
TEST(LightTreeSampling, UnlimitedBudgetCutHoldsEveryContributingLight) {
  std::vector<Light> lights = mixed_lights(3000, 23, 10.0f);
  LightTree tree = build_light_tree(lights);
  LtTree t = tree.view(lights.data());
  std::vector<Shade> pts = shading_points(20, -1.0f, 11.0f, 6);
  for (const Shade& x : pts) {
    Rng rng = make_rng(5, 0);
    std::vector<LightPick> out;
    sample_tree_split(t, x.P, x.N, rng, 1.0f, int(LT_BUDGET_UNLIMITED), out);
    std::vector<int> seen(lights.size(), 0);
    for (const LightPick& p : out) {
      ASSERT_EQ(p.prob, 1.0f);
      ASSERT_EQ(seen[size_t(p.light)]++, 0) << "light " << p.light << " twice";
    }
    for (int l = 0; l < int(lights.size()); ++l) {
      float pmf = lt_pmf_split(&t, x.P, x.N, l, 1.0f, LT_BUDGET_UNLIMITED);
      ASSERT_EQ(pmf, seen[size_t(l)] ? 1.0f : 0.0f) << "light " << l;
      if (clearly_contributes(lights[size_t(l)], x.P, x.N)) {
        ASSERT_TRUE(seen[size_t(l)]) << l;
      }
    }
  }
}

TEST(LightTreeSampling, SplitDecisionsInvariantToSceneScale) {
  // Scale the lights by 10^-3 / 10^3 in size and 10^-6 / 10^6 in energy (tree built from the
  // scaled lights): the same shading points (scaled) get the same cuts and the same picks.
  std::vector<Light> base = mixed_lights(3000, 16, 10.0f);
  std::vector<Shade> pts = shading_points(300, -1.0f, 11.0f, 6);
  LightSamplerOptions o;
  o.split_threshold = 0.85f;
  auto ref = make_light_sampler("tree-split", base, o);
  // Scale factors that are powers of two keep every float operation exact, so the trees and all
  // decisions must match bit for bit; decimal factors are checked up to rounding.
  for (auto [size, energy] :
       {std::pair{1024.0f, 1.0f / 1048576.0f}, std::pair{1e-3f, 1e6f}, std::pair{1e3f, 1e-6f},
        std::pair{1e-3f, 1e-6f}, std::pair{1e3f, 1e6f}}) {
    std::vector<Light> l = base;
    for (Light& x : l) {
      x.p = make_float4(x.p.x * size, x.p.y * size, x.p.z * size, x.p.w * size);
      if (x.type == LIGHT_QUAD || x.type == LIGHT_TRIANGLE) {
        x.e1 = x.e1 * size;
        x.e2 = x.e2 * size;
        x.n.w *= size * size;
      }
      if (x.type == LIGHT_DISK) x.n.w *= size * size; // radius in p.w, a unit frame
      // area lights: radiance scaled so the energy (L * A) scales by `energy`
      float k = (x.type == LIGHT_POINT || x.type == LIGHT_SPOT) ? energy : energy / (size * size);
      x.emission = x.emission * k;
    }
    auto s = make_light_sampler("tree-split", l, o);
    bool exact = size == 1024.0f;
    int same = 0, total = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
      std::vector<LightPick> a, b;
      Rng r1 = make_rng(3, uint32_t(i)), r2 = make_rng(3, uint32_t(i));
      ref->sample(pts[i].P, pts[i].N, r1, a);
      s->sample(pts[i].P * size, pts[i].N, r2, b);
      ++total;
      if (exact) {
        ASSERT_EQ(a.size(), b.size()) << "point " << i;
        for (size_t k = 0; k < a.size(); ++k) {
          EXPECT_EQ(a[k].light, b[k].light);
          EXPECT_EQ(a[k].prob, b[k].prob);
        }
        ++same;
      } else if (a.size() == b.size()) {
        ++same;
      }
    }
    // decimal scalings: rounding may move a bin boundary in the build or a pick at a lane
    // boundary, but cut sizes agree almost everywhere
    EXPECT_GE(same, exact ? total : total * 95 / 100) << "size " << size << " energy " << energy;
  }
}

TEST(LightTreeSampling, SplitMeasureOfTreeNodesInvariantToScale) {
  // Node by node: the split measure of every cluster from random points is unchanged when
  // positions and radii are scaled by 10^+-3 and energies by 10^+-6 (CV^2 is dimensionless).
  std::vector<Light> lights = mixed_lights(5000, 17, 10.0f);
  LightTree t = build_light_tree(lights);
  std::vector<Shade> pts = shading_points(50, -1.0f, 11.0f, 7);
  int decisions = 0;
  for (const Shade& x : pts) {
    for (int node = 0; node < t.num_nodes(); ++node) {
      for (int lane = 0; lane < 4; ++lane) {
        if (i4_get(t.children[node], lane) == LT_EMPTY) continue;
        LtTree v = t.view(lights.data());
        float4 sp = lt_lane_sphere(&v, node, lane);
        float cv2 = lt_lane_cv2(&v, node, lane);
        float m = lt_split_measure(x.P, sp, cv2);
        float3 dv = x.P - xyz_of(sp);
        double d = std::sqrt(dot_d(dv, dv));
        // On the sphere a = d - r is ill-conditioned: scaling rounds P, the centre and r, so a
        // carries an absolute error of a few ulps of |P| + |c| + r, not of r alone.
        const double mag = std::sqrt(dot_d(x.P, x.P)) + std::sqrt(dot_d(xyz_of(sp), xyz_of(sp)));
        if (std::fabs(d - sp.w) < 1e-3 * (sp.w + mag)) continue;
        for (float s : {1e-3f, 1e3f}) {
          float ms = lt_split_measure(x.P * s, sp * s, cv2);
          ASSERT_NEAR(ms, m, 1e-5f * std::fmax(m, 1e-2f) + 1e-7f);
          if (std::fabs(m - 0.85f) > 1e-5f) {
            ++decisions;
            ASSERT_EQ(lt_should_split(ms, 0.85f), lt_should_split(m, 0.85f));
          }
        }
      }
    }
  }
  EXPECT_GT(decisions, 10000);
}

TEST(LightTreeSampling, ZeroEnergyLights) {
  std::vector<Light> lights = mixed_lights(2000, 18, 10.0f);
  for (size_t i = 0; i < lights.size(); i += 2)
    lights[i].emission = make_float4(0, 0, 0, 0);
  std::vector<Shade> pts = shading_points(20, 1.0f, 9.0f, 8);
  for (const char* name : {"power", "tree", "tree-split"}) {
    auto s = make_light_sampler(name, lights);
    for (const Shade& x : pts) {
      for (size_t i = 0; i < lights.size(); i += 2)
        ASSERT_EQ(s->pmf(x.P, x.N, int(i)), 0.0f);
      std::vector<LightPick> out;
      Rng rng = make_rng(1, 2);
      s->sample(x.P, x.N, rng, out);
      for (const LightPick& p : out) {
        EXPECT_EQ(p.light % 2, 1);
        EXPECT_TRUE(std::isfinite(p.prob) && p.prob > 0);
      }
      if (std::string(name) != "tree-split" && !out.empty()) {
        EXPECT_NEAR(pmf_sum(*s, x.P, x.N), 1.0, 1e-4);
      }
    }
  }
  // all lights black: fall back to uniform, finite, sums to 1
  for (Light& l : lights)
    l.emission = make_float4(0, 0, 0, 0);
  for (const char* name : {"uniform", "power", "tree", "tree-split"}) {
    auto s = make_light_sampler(name, lights);
    std::vector<LightPick> out;
    Rng rng = make_rng(1, 3);
    s->sample(make_float3(1, 1, 1), make_float3(0, 0, 1), rng, out);
    ASSERT_EQ(out.size(), 1u) << name;
    EXPECT_TRUE(std::isfinite(out[0].prob) && out[0].prob > 0) << name;
    EXPECT_NEAR(pmf_sum(*s, make_float3(1, 1, 1), make_float3(0, 0, 1)), 1.0, 1e-4) << name;
  }
  // no lights at all
  for (const std::string& name : light_sampler_names()) {
    auto s = make_light_sampler(name, {});
    std::vector<LightPick> out;
    Rng rng = make_rng(1, 4);
    s->sample(make_float3(0, 0, 0), make_float3(0, 0, 1), rng, out);
    EXPECT_TRUE(out.empty()) << name;
  }
}

TEST(LightTreeSampling, ShadingPointInsideClusters) {
  // Points inside the bounding spheres of whole subtrees (theta_u = pi) and exactly at a light.
  std::vector<Light> lights = random_point_lights(3000, 19, 1.0f);
  auto s = make_light_sampler("tree", lights);
  for (float3 P :
       {make_float3(0.5f, 0.5f, 0.5f), xyz_of(lights[10].p), make_float3(0.01f, 0.2f, 0.9f)}) {
    for (float3 N : {make_float3(0, 0, 0), make_float3(0, 1, 0)}) {
      double sum = pmf_sum(*s, P, N);
      EXPECT_NEAR(sum, 1.0, 1e-4);
    }
  }
}

TEST(LightTreeSampling, EmissionScaleDoesNotChangeThePmf) {
  // Emission anywhere from float's denormal range (2^-140 ~ 7e-43) to near its maximum (2^110 ~
  // 1e33, times 100) gives the same tree and power pmfs, bit for bit: the energies are computed in
  // double and normalised by a power of two (normalize_emitter_energies), so a common power-of-two
  // factor changes nothing. Before, 1e-40 emission made the tree's importances 0 / NaN (black).
  std::vector<Light> base = mixed_lights(300, 21, 10.0f);
  LtRng r = lt_rng_make(5, 5);
  for (Light& l : base) {
    float k = float(1 + int(lt_rng_next(&r) * 100.0f));
    l.emission = make_float4(k, k, k, 0.0f);
  }
  std::vector<Shade> pts = shading_points(20, -1.0f, 11.0f, 9);
  for (const char* name : {"tree", "tree-split", "power"}) {
    auto ref = make_light_sampler(name, base);
    for (int e : {-140, 110}) {
      std::vector<Light> scaled = base;
      for (Light& l : scaled) {
        l.emission.x = std::ldexp(l.emission.x, e);
        l.emission.y = std::ldexp(l.emission.y, e);
        l.emission.z = std::ldexp(l.emission.z, e);
      }
      auto s = make_light_sampler(name, scaled);
      for (const Shade& x : pts)
        for (int l = 0; l < int(base.size()); ++l)
          ASSERT_EQ(s->pmf(x.P, x.N, l), ref->pmf(x.P, x.N, l))
              << name << " scale 2^" << e << " light " << l;
      if (const LightTree* t = s->tree()) {
        // node lane energies and emitter record energies: 0 (empty lane) or normal and finite
        auto ok = [](float x) { return x == 0.0f || (x >= FLT_MIN && std::isfinite(x)); };
        for (int n = 0; n < t->num_nodes(); ++n) {
          float4 v = t->nodes[size_t(n) * LT_NODE_F4 + LT_ENERGY];
          ASSERT_TRUE(ok(v.x) && ok(v.y) && ok(v.z) && ok(v.w)) << name << " node " << n;
        }
        for (size_t i = size_t(t->num_nodes()) * LT_NODE_F4 + 1; i < t->nodes.size();
             i += LT_EMITTER_F4)
          ASSERT_TRUE(t->nodes[i].z >= FLT_MIN && std::isfinite(t->nodes[i].z)) << name;
        EXPECT_EQ(t->energy_scale, std::ldexp(ref->tree()->energy_scale, -e));
      }
    }
  }
}
