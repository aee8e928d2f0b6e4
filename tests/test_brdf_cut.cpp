// BRDF-oriented light cuts, picks and pmfs (Liu, Xu & Yan 2019 §4.1; cl/light_tree/brdf_cut.h) on
// trees of mixed lights at random glossy shading points. These are properties of the cut and of
// the sampling that hold for any valid cap integral S_C (cl/bsdf/cap_integral.h): the cut is a
// set of disjoint clusters within capacity whose recorded importances are Eq. 6's, I_B is Eq. 8's
// max S_C; the pick is distributed exactly as lt_brdf_pmf says (which is what MIS needs), every
// light that can light the point has a non-zero probability (what unbiasedness needs), and culled
// lights are never picked.
#include "test_light_tree_util.h"

#include "light_tree/brdf_cut.h"
#include "light_tree/light_tree.h"

#include "support/glossy_points.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <utility>

using namespace canopy;
using namespace canopy::test;

namespace {

Material conductor(float roughness) {
  return gold_conductor(roughness);
}
Material plastic(float roughness) {
  return blue_plastic(roughness);
}

// A glossy shading point: position, geometric normal (= shading normal), wo above the surface,
// material and its cap lobe.
struct GlossyPoint {
  float3 P, N, wo;
  Material m;
  CapLobe lobe;
};
GlossyPoint make_point(float3 P, float3 N, float3 wo, const Material& m) {
  GlossyPoint g{P, N, wo, m, {}};
  Frame fr = frame_from(N);
  g.lobe = cap_lobe_make(&g.m, &fr, wo);
  return g;
}
// Random points in [lo, hi]^3 (the mixed lights fill [0, size]^3: some points are inside the
// bounds, some outside), random normals, wo at least ~3 degrees above the surface, conductor and
// plastic of roughness 0.05..0.8.
std::vector<GlossyPoint> glossy_points(int n, float lo, float hi, uint32_t seed) {
  LtRng r = lt_rng_make(seed, 7);
  std::vector<GlossyPoint> pts;
  for (int i = 0; i < n; ++i) {
    float3 P = make_float3(lo + (hi - lo) * lt_rng_next(&r), lo + (hi - lo) * lt_rng_next(&r),
                           lo + (hi - lo) * lt_rng_next(&r));
    float3 N = random_unit(r);
    float3 wo = random_unit(r);
    while (dot(wo, N) < 0.05f)
      wo = random_unit(r);
    float roughness = 0.05f + 0.75f * lt_rng_next(&r);
    pts.push_back(make_point(P, N, wo, i % 2 ? plastic(roughness) : conductor(roughness)));
  }
  return pts;
}

// The tree's structure on the host: for every code (node, leaf, or a single emitter of a leaf as
// lt_lane_code names it) its parent code and lane, and the lights below it.
struct TreeIndex {
  std::map<int, std::pair<int, int>> parent;
  void build(const LtTree& t, int code) {
    int lanes = code >= 0 ? 4 : lt_leaf_count(code);
    for (int lane = 0; lane < lanes; ++lane) {
      int child = lt_lane_code(&t, code, lane);
      if (child == LT_EMPTY) continue;
      parent[child] = {code, lane};
      if (lt_code_splittable(child)) build(t, child);
    }
  }
};
void lights_below(const LtTree& t, int code, std::vector<int>& out) {
  if (code == LT_EMPTY) return;
  if (code >= 0) {
    for (int lane = 0; lane < 4; ++lane)
      lights_below(t, i4_get(t.children[code], lane), out);
    return;
  }
  for (int j = 0; j < lt_leaf_count(code); ++j)
    out.push_back(t.leaf_lights[lt_leaf_first(code) + j]);
}

// Probability that the descent below `code` reaches a light (rather than a lane-less cluster),
// computed exactly from the same importances.
double descent_success(const LtTree& t, int code, const GlossyPoint& g) {
  float4 S;
  int4 inside;
  float4 imp = lt_brdf_code_importance(&t, code, g.P, g.N, &g.lobe, &S, &inside);
  double p = 0;
  for (int lane = 0; lane < 4; ++lane) {
    double pl = lt_lane_prob(imp, lane);
    if (!(pl > 0)) continue;
    if (code < 0) {
      p += pl;
      continue;
    }
    int child = i4_get(t.children[code], lane);
    if (child != LT_EMPTY) p += pl * descent_success(t, child, g);
  }
  return p;
}

struct Cut {
  std::vector<float2> entries = std::vector<float2>(LT_BRDF_MAX_CUT);
  int n = 0;
  float I_B = 0;
  int code(int j) const { return int(float_as_uint_(entries[size_t(j)].x)); }
};
Cut build_cut(const LtTree& t, const GlossyPoint& g, float delta) {
  Cut c;
  c.n = lt_brdf_cut_build(&t, g.P, g.N, &g.lobe, delta, c.entries.data(), &c.I_B);
  return c;
}

struct Scene {
  std::vector<Light> lights;
  LightTree tree;
  LtTree view;
  TreeIndex index;
};
Scene make_scene(int n, uint32_t seed, bool points_only = false) {
  Scene s;
  s.lights = points_only ? random_point_lights(n, seed, 10.0f) : mixed_lights(n, seed, 10.0f);
  s.tree = build_light_tree(s.lights);
  s.view = s.tree.view(s.lights.data());
  s.index.build(s.view, 0);
  return s;
}

} // namespace

// The cut is at most LT_BRDF_MAX_CUT disjoint clusters; each entry carries its Eq. 6 importance
// (positive, finite, exactly what the parent's lanes rank it with); I_B is the max S_C over the
// entries (Eq. 8).
TEST(BrdfCut, EntriesAreDisjointClustersWithTheirImportanceAndIbIsTheMaxCapIntegral) {
  int points_checked = 0, multi_entry_cuts = 0, capacity_cuts = 0;
  for (auto [n_lights, seed] : {std::pair{300, 1u}, {1200, 2u}, {3000, 3u}}) {
    Scene s = make_scene(n_lights, seed);
    const LtTree& t = s.view;
    for (const GlossyPoint& g : glossy_points(300, -3.0f, 13.0f, seed)) {
      for (float delta : {0.5f, 0.05f, 0.005f}) {
        SCOPED_TRACE(::testing::Message() << n_lights << " lights, delta " << delta);
        Cut c = build_cut(t, g, delta);
        ASSERT_GE(c.n, 0);
        ASSERT_LE(c.n, LT_BRDF_MAX_CUT);
        ++points_checked;
        multi_entry_cuts += c.n > 1;
        capacity_cuts += c.n > LT_BRDF_MAX_CUT - 4;
        std::vector<int> covered(s.lights.size(), 0);
        float max_s = 0;
        for (int j = 0; j < c.n; ++j) {
          int code = c.code(j);
          float imp = c.entries[size_t(j)].y;
          ASSERT_TRUE(std::isfinite(imp) && imp > 0) << "entry " << j << " importance " << imp;
          float S;
          if (code == 0) { // the root alone: its own cap
            ASSERT_EQ(c.n, 1);
            float4 rs = t.root_sphere;
            float3 d = xyz_of(rs) - g.P;
            float dd = dot(d, d), id = 1.0f / std::sqrt(dd);
            ASSERT_GT(dd, rs.w * rs.w) << "the root joins the cut only from outside its sphere";
            float mean;
            S = cap_lobe_integral(
                &g.lobe, d * id, std::fmin(rs.w * id, 1.0f),
                std::fmin(std::sqrt(std::fmax(dd - rs.w * rs.w, 0.0f)) * id, 1.0f), &mean);
          } else {
            ASSERT_TRUE(s.index.parent.count(code)) << "entry " << j << " code " << code;
            auto [parent, lane] = s.index.parent[code];
            float4 Sv;
            int4 inside;
            float4 iv = lt_brdf_code_importance(&t, parent, g.P, g.N, &g.lobe, &Sv, &inside);
            EXPECT_EQ(imp, f4_get(iv, lane)) << "entry " << j;
            S = f4_get(Sv, lane);
          }
          max_s = std::fmax(max_s, S);
          std::vector<int> below;
          lights_below(t, code, below);
          ASSERT_FALSE(below.empty());
          for (int l : below)
            ASSERT_EQ(++covered[size_t(l)], 1) << "light " << l << " is in two entries";
        }
        EXPECT_EQ(c.I_B, max_s);
        if (HasFailure()) return;
      }
    }
  }
  // The cases above were all exercised.
  EXPECT_GT(multi_entry_cuts, points_checked / 2);
  EXPECT_GT(capacity_cuts, 0);
}

// With delta above any S_C, a point outside the root's sphere keeps the whole tree as one
// cluster (no cap integral exceeds it); lowering delta only ever splits more (mean cut size).
TEST(BrdfCut, DeltaControlsTheCutSize) {
  Scene s = make_scene(2000, 4);
  std::vector<GlossyPoint> pts = glossy_points(400, -3.0f, 13.0f, 4);
  int outside = 0;
  for (const GlossyPoint& g : pts) {
    float4 rs = s.view.root_sphere;
    float3 d = xyz_of(rs) - g.P;
    if (!(dot(d, d) > rs.w * rs.w)) continue;
    ++outside;
    Cut c = build_cut(s.view, g, 1e30f);
    ASSERT_EQ(c.n, 1);
    EXPECT_EQ(c.code(0), 0);
    EXPECT_EQ(c.entries[0].y, 1.0f);
  }
  EXPECT_GT(outside, 50);
  double previous = 0;
  for (float delta : {1e30f, 2.0f, 0.5f, 0.2f, 0.05f, 0.02f, 0.005f, 0.0f}) {
    double sum = 0;
    for (const GlossyPoint& g : pts)
      sum += build_cut(s.view, g, delta).n;
    double mean = sum / double(pts.size());
    EXPECT_GE(mean, previous) << "delta " << delta;
    std::printf("delta %g: mean cut size %.2f\n", double(delta), mean);
    previous = mean;
  }
  EXPECT_GT(previous, 16.0); // delta 0 splits far (up to the capacity)
}

// sum_l pmf(l) is the probability that a pick returns a light: exactly the entries' probabilities
// times the exact success probability of the descent below each (1 where no descent can dead-end,
// and then the sum is 1); the sampled success rate agrees. The pmf a pick reports is lt_brdf_pmf
// of the light it returns. Every light that clearly lights the point's glossy side has pmf > 0
// (a GGX lobe is positive over the whole hemisphere), which brdf-oriented's unbiasedness needs.
TEST(BrdfCut, PmfSumsToThePickSuccessProbabilityAndMatchesThePick) {
  int exact_one = 0, dead_ends = 0, picks_checked = 0;
  for (auto [n_lights, seed] : {std::pair{400, 5u}, {2500, 6u}, {800, 8u}}) {
    // The third: point lights in [0, 10]^3 above points below them facing up, where no cluster
    // is culled, so no descent can dead-end.
    const bool points_above = seed == 8u;
    Scene s = make_scene(n_lights, seed, points_above);
    const LtTree& t = s.view;
    std::vector<GlossyPoint> pts = glossy_points(60, -3.0f, 13.0f, seed);
    if (points_above)
      for (GlossyPoint& g : pts)
        g = make_point(make_float3(g.P.x, -0.5f - 0.1f * g.P.y, g.P.z), make_float3(0, 1, 0),
                       normalize(make_float3(g.wo.x, std::fabs(g.wo.y) + 0.05f, g.wo.z)), g.m);
    for (size_t i = 0; i < pts.size(); ++i) {
      const GlossyPoint& g = pts[i];
      float delta = i % 3 == 0 ? 0.5f : (i % 3 == 1 ? 0.05f : 0.005f);
      SCOPED_TRACE(::testing::Message() << n_lights << " lights, point " << i);
      Cut c = build_cut(t, g, delta);
      double sum = 0;
      std::vector<float> pmf(s.lights.size());
      for (size_t l = 0; l < s.lights.size(); ++l) {
        pmf[l] = lt_brdf_pmf(&t, c.entries.data(), c.n, g.P, g.N, &g.lobe, int(l));
        ASSERT_TRUE(std::isfinite(pmf[l]) && pmf[l] >= 0 && pmf[l] <= 1.0f) << l;
        sum += pmf[l];
        if (clearly_contributes(s.lights[l], g.P, g.N)) {
          EXPECT_GT(pmf[l], 0.0f) << "light " << l << " lights the point but cannot be picked";
        }
      }
      double success = 0;
      bool all_complete = true;
      for (int j = 0; j < c.n; ++j) {
        double below = descent_success(t, c.code(j), g);
        all_complete = all_complete && below > 1.0 - 1e-6;
        success += lt_brdf_entry_prob(c.entries.data(), c.n, j) * below;
      }
      EXPECT_NEAR(sum, success, 1e-4 * std::max(1.0, success));
      if (points_above) {
        EXPECT_TRUE(all_complete);
      }
      if (c.n > 0 && all_complete) {
        EXPECT_NEAR(sum, 1.0, 1e-4);
        ++exact_one;
      } else if (c.n > 0) {
        ++dead_ends;
      }
      // Picks: the reported pmf is the light's lt_brdf_pmf; the success rate is `success`.
      const int M = 4000;
      int returned = 0;
      for (int k = 0; k < M; ++k) {
        LtRng rng = lt_rng_make(1000u + uint32_t(i), uint32_t(k));
        float p;
        int light = lt_brdf_pick(&t, c.entries.data(), c.n, g.P, g.N, &g.lobe, &rng, &p);
        if (light < 0) {
          EXPECT_EQ(p, 0.0f);
          continue;
        }
        ++returned;
        ++picks_checked;
        ASSERT_GT(pmf[size_t(light)], 0.0f) << "picked light " << light << " has pmf 0";
        ASSERT_NEAR(p, pmf[size_t(light)], 1e-5f * pmf[size_t(light)]) << "light " << light;
      }
      // binomial: 5 sigma (+ the float tolerance of `success`)
      double sigma = std::sqrt(std::max(success * (1 - success), 0.0) / M);
      EXPECT_NEAR(double(returned) / M, success, 5 * sigma + 1e-4);
      if (HasFailure()) return;
    }
  }
  std::printf("points with sum 1: %d, with possible dead ends: %d, picks checked: %d\n", exact_one,
              dead_ends, picks_checked);
  EXPECT_GE(exact_one, 60);
  EXPECT_GT(picks_checked, 100000);
}

// The sampled light frequencies follow lt_brdf_pmf (chi-square at significance 1e-6, fine bins of
// expected count >= 20 and the group totals; a failed pick is its own outcome).
TEST(BrdfCut, ChiSquareOfPickedLightsAgainstThePmf) {
  Scene s = make_scene(1500, 7);
  const LtTree& t = s.view;
  std::vector<GlossyPoint> pts = glossy_points(6, 0.0f, 10.0f, 7);
  for (size_t i = 0; i < pts.size(); ++i) {
    const GlossyPoint& g = pts[i];
    SCOPED_TRACE(::testing::Message() << "point " << i);
    Cut c = build_cut(t, g, i % 2 ? 0.05f : 0.01f);
    ASSERT_GT(c.n, 1);
    size_t L = s.lights.size();
    std::vector<double> prob(L + 1), counts(L + 1, 0.0);
    std::vector<int> group(L + 1, 0);
    double sum = 0;
    for (size_t l = 0; l < L; ++l)
      sum += prob[l] = lt_brdf_pmf(&t, c.entries.data(), c.n, g.P, g.N, &g.lobe, int(l));
    prob[L] = std::max(0.0, 1.0 - sum); // no light (a dead end)
    group[L] = 1;
    const int M = 300000;
    for (int k = 0; k < M; ++k) {
      LtRng rng = lt_rng_make(77u + uint32_t(i), uint32_t(k));
      float p;
      int light = lt_brdf_pick(&t, c.entries.data(), c.n, g.P, g.N, &g.lobe, &rng, &p);
      counts[light < 0 ? L : size_t(light)] += 1;
    }
    PickFit f = pick_fit(counts, prob, group, M);
    EXPECT_TRUE(f.pass()) << "chi2 " << f.chi2 << " (quantile " << f.quantile << ", dof " << f.dof
                          << "), groups " << f.group_chi2 << " (" << f.group_quantile << ") "
                          << f.failures;
    EXPECT_GT(f.dof, 50); // enough bins to see a wrong distribution
  }
}

// Lights that cannot reach the point's glossy side: one-sided quads facing away from it and
// lights below its horizon. Their clusters are culled: pmf 0, and never picked.
TEST(BrdfCut, CulledLightsHavePmfZeroAndAreNeverPicked) {
  std::vector<Light> lights;
  LtRng r = lt_rng_make(9, 1);
  // Culled: quads at y = 4 facing up (-> away from P below them), points below the plane y = 0.
  for (int i = 0; i < 120; ++i) {
    float x = -4 + 8 * lt_rng_next(&r), z = -4 + 8 * lt_rng_next(&r);
    lights.push_back(make_quad_light(make_float3(x, 4.0f, z), make_float3(0, 0, 0.3f),
                                     make_float3(0.3f, 0, 0), make_float3(5, 5, 5)));
    float3 below = make_float3(-4 + 8 * lt_rng_next(&r), -1.0f - 3 * lt_rng_next(&r),
                               -4 + 8 * lt_rng_next(&r));
    lights.push_back(make_point_light(below, make_float3(2, 2, 2)));
  }
  const size_t culled = lights.size();
  // Visible: quads at y = 3 facing down, spheres and points above the surface.
  for (int i = 0; i < 60; ++i) {
    float x = -4 + 8 * lt_rng_next(&r), z = -4 + 8 * lt_rng_next(&r);
    lights.push_back(make_quad_light(make_float3(x, 3.0f, z), make_float3(0.3f, 0, 0),
                                     make_float3(0, 0, 0.3f), make_float3(5, 5, 5)));
    lights.push_back(make_sphere_light(make_float3(x, 1.0f + lt_rng_next(&r), z + 0.5f), 0.1f,
                                       make_float3(3, 3, 3)));
  }
  // The quads' orientation is what culls them: check the construction.
  for (size_t l = 0; l < culled; l += 2)
    ASSERT_GT(emitter_bounds(lights[l]).cone.axis.y, 0.99f) << "quad " << l << " faces up";
  for (size_t l = culled; l < lights.size(); l += 2)
    ASSERT_LT(emitter_bounds(lights[l]).cone.axis.y, -0.99f) << "quad " << l << " faces down";

  LightTree tree = build_light_tree(lights);
  LtTree t = tree.view(lights.data());
  std::vector<GlossyPoint> pts;
  for (int i = 0; i < 8; ++i) {
    float3 wo = normalize(
        make_float3(-1 + 2 * lt_rng_next(&r), 0.3f + lt_rng_next(&r), -1 + 2 * lt_rng_next(&r)));
    float rough = 0.1f + 0.6f * lt_rng_next(&r);
    pts.push_back(make_point(make_float3(-2 + 4 * lt_rng_next(&r), 0.0f, -2 + 4 * lt_rng_next(&r)),
                             make_float3(0, 1, 0), wo, i % 2 ? plastic(rough) : conductor(rough)));
  }
  for (size_t i = 0; i < pts.size(); ++i) {
    const GlossyPoint& g = pts[i];
    SCOPED_TRACE(::testing::Message() << "point " << i);
    for (float delta : {0.5f, 0.01f}) {
      Cut c = build_cut(t, g, delta);
      ASSERT_GT(c.n, 0);
      double visible_sum = 0;
      for (size_t l = 0; l < lights.size(); ++l) {
        float p = lt_brdf_pmf(&t, c.entries.data(), c.n, g.P, g.N, &g.lobe, int(l));
        if (l < culled)
          EXPECT_EQ(p, 0.0f) << "culled light " << l;
        else
          visible_sum += p;
      }
      EXPECT_GT(visible_sum, 0.5); // the visible lights are picked
      for (int k = 0; k < 20000; ++k) {
        LtRng rng = lt_rng_make(31u + uint32_t(i), uint32_t(k));
        float p;
        int light = lt_brdf_pick(&t, c.entries.data(), c.n, g.P, g.N, &g.lobe, &rng, &p);
        ASSERT_TRUE(light < 0 || size_t(light) >= culled) << "picked culled light " << light;
      }
    }
  }
}
