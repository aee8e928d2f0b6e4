// The "auto" light sampler (render/auto_sampler.h): the exploration renders every candidate, ranks
// them by 1 / (variance per sample x seconds), weights their samples into the image without bias,
// and leaves the renderer set to the chosen one.
#include "render/auto_sampler.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <tuple>

using namespace canopy;

namespace {

// A floor under a 30 x 30 grid of point lights a little above it: every point's light is the few
// lights over it, which power sampling (by power alone: uniform here) almost never picks.
const char* kGridJson = R"({
  "camera": { "position": [0, 6, 6], "look_at": [0, 0, 0], "fov": 40 },
  "film": { "width": 64, "height": 48 },
  "integrator": { "max_depth": 1 },
  "shapes": [ { "type": "quad", "corner": [-10, 0, 10], "edge1": [20, 0, 0], "edge2": [0, 0, -20] } ],
  "light_sets": [ { "type": "grid", "origin": [-10, 0.2, -10], "edge1": [20, 0, 0],
                    "edge2": [0, 0, 20], "nx": 30, "ny": 30,
                    "light": { "type": "point", "intensity": 1 } } ]
})";

// A scene's renderer, built for the first candidate as `canopy render` builds it, and its auto
// renders, the costly candidate's probe counted as free (tests do not time: it is never pruned).
struct AutoRun {
  explicit AutoRun(const std::string& json)
      : scene(load_scene_from_string(json, "scene.json", ".")),
        base(auto_candidates(RendererOptions{}).front().options), renderer(rt, scene, base) {}
  AutoRender render(int spp, uint32_t seed, size_t wave_size = RenderSettings{}.wave_size) {
    RenderSettings rs;
    rs.spp = spp;
    rs.seed = seed;
    rs.wave_size = wave_size;
    return render_auto(renderer, base, rs, 0, 0.0);
  }
  Scene scene;
  ClRuntime rt;
  RendererOptions base;
  Renderer renderer;
};

} // namespace

TEST(AutoSampler, CandidatesArePowerTreeAndTheSplitBrdfMis) {
  RendererOptions base;
  base.max_cut = 32;
  base.split_threshold = 0.9f;
  std::vector<PilotResult> c = auto_candidates(base);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[0].options.light_sampler, "power");
  EXPECT_EQ(c[1].options.light_sampler, "tree");
  EXPECT_EQ(c[2].options.light_sampler, "brdf-mis");
  EXPECT_EQ(c[2].options.split_threshold, LT_DEFAULT_SPLIT_THRESHOLD);
  EXPECT_EQ(c[2].label, "brdf-mis/split=0.25");
  for (const PilotResult& p : c)
    EXPECT_EQ(p.options.max_cut, 32); // the rest of base is kept
}

// The exploration takes at most 60% of the samples and leaves one for the chosen candidate; its
// timed renders fill a wave when there is room, and shrink (to one render, then none) when not.
TEST(AutoSampler, TheExplorationFitsTheSampleBudget) {
  const std::vector<int> waves = {4, 4, 1};
  for (int spp = 1; spp <= 256; ++spp) {
    int renders = -1;
    std::vector<int> p = plan_exploration(spp, waves, &renders);
    if (p.empty()) {
      EXPECT_EQ(renders, 0);
      continue;
    }
    ASSERT_EQ(p.size(), waves.size());
    int explored = int(waves.size());
    for (size_t c = 0; c < p.size(); ++c) {
      EXPECT_GE(p[c], 1);
      EXPECT_LE(p[c], waves[c]);
      explored += renders * p[c];
    }
    EXPECT_LE(explored, std::max(int(0.6 * spp), 2 * int(waves.size()))) << spp;
    EXPECT_LT(explored, spp) << spp;
    if (spp >= 64) { // room for all: a full wave each, timed twice
      EXPECT_EQ(renders, 2);
      EXPECT_EQ(p, waves);
    }
  }
  int renders = 0;
  EXPECT_TRUE(plan_exploration(6, waves, &renders).empty()); // no sample left after 3 + 3
  EXPECT_EQ(plan_exploration(7, waves, &renders), std::vector<int>({1, 1, 1}));
  EXPECT_EQ(renders, 1);
  EXPECT_EQ(plan_exploration(16, waves, &renders), std::vector<int>({1, 1, 1})); // 3 + 2 x 3
  EXPECT_EQ(renders, 2);
}

// Inverse-variance weights relative to the predicted choice, by the typical tile, at most 1; a
// candidate that missed its tail weighs nothing and is not the reference.
// The costly candidates explore one band of 8 rows in every 1 to 4, keeping at least 16,384 pixels
// and a band in each of the film's 8 x 8 tiles.
TEST(AutoSampler, TheExplorationCoversBandsThatKeepEnoughPixels) {
  for (auto [w, h, period] :
       {std::tuple{128, 96, 1}, std::tuple{288, 216, 3}, std::tuple{512, 512, 4},
        std::tuple{1024, 128, 2}, std::tuple{4096, 16, 1}}) {
    const RowBands b = exploration_bands(w, h);
    EXPECT_EQ(b.period, period) << w << "x" << h;
    EXPECT_EQ(b.height, kExploreBandRows);
    EXPECT_EQ(b.first, 0);
    EXPECT_EQ(b.count, 1);
    if (period > 1) {
      EXPECT_GE(w * covered_rows(b.packed(), h), kExploredPixels) << w << "x" << h;
    }
  }
  EXPECT_EQ(exploration_bands(64, 48, 3).period, 3); // as asked
  EXPECT_EQ(exploration_bands(64, 12, 3).period, 1); // too few rows for bands
}

TEST(AutoSampler, ExplorationWeightsAreInverseVarianceToTheChoiceAndDropAMissedTail) {
  std::vector<PilotResult> c(3);
  auto set = [&](size_t i, double v, double mean, double tile_v) {
    c[i].label = "c" + std::to_string(i);
    c[i].stats.variance = v;
    c[i].stats.mean = mean;
    c[i].stats.mean_variance = 1e-6;
    c[i].stats.tile_variance.assign(32, tile_v / 32);
    c[i].pass_seconds = 1.0;
  };
  set(0, 1e-4, 0.5, 1e-4); // low only because it missed its tail: its mean is far too low
  set(1, 2.0, 1.0, 2.0);
  set(2, 8.0, 1.001, 8.0); // 4x in every tile
  std::vector<double> w = exploration_weights(c);
  EXPECT_EQ(w[0], 0.0);
  EXPECT_EQ(w[1], 1.0);
  EXPECT_DOUBLE_EQ(w[2], 0.25);
  // 1.5x as noisy, but all of the excess in one tile: the typical tile is as noisy, weight 1.
  c[2].stats.variance = 3.0;
  c[2].stats.tile_variance.assign(32, 2.0 / 32);
  c[2].stats.tile_variance[5] += 1.0;
  EXPECT_EQ(exploration_weights(c)[2], 1.0);
  // A noisier candidate, 10x cheaper, is the choice: its samples weigh 1, and so do the better
  // samples of the other (at most 1).
  set(2, 8.0, 1.001, 8.0);
  c[2].pass_seconds = 0.1;
  w = exploration_weights(c);
  EXPECT_EQ(w[0], 0.0);
  EXPECT_EQ(w[1], 1.0);
  EXPECT_EQ(w[2], 1.0);
}

// Measured on different rows, two candidates' means differ by what their rows show as well. A
// mean 5 standard errors of the samples below the other's is a missed tail where each candidate's
// own rows agree between every other row and the rows between; where they differ that much (the
// image changes from row to row), it is the rows' structure, and the candidate stays ranked. On
// common pixels the rows' structure takes no part.
TEST(AutoSampler, TheMissedTailTestAllowsForTheStructureOfTheRows) {
  auto missed = [](double split, bool own_rows) {
    std::vector<PilotResult> c(2);
    for (size_t i = 0; i < c.size(); ++i) {
      c[i].label = i == 0 ? "low" : "high";
      c[i].stats.variance = i == 0 ? 1.0 : 2.0;
      c[i].stats.tile_variance.assign(32, c[i].stats.variance / 32);
      c[i].stats.mean = i == 0 ? 0.95 : 1.0;
      c[i].stats.mean_variance = 0.5 * 1e-4; // the difference's standard error: 0.01
      c[i].stats.row_split = split;
      c[i].stats.row_split_variance = 2e-4;
      c[i].stats.own_rows = own_rows;
      c[i].pass_seconds = 1.0;
    }
    std::string reason;
    choose_candidate(c, &reason);
    return c[0].missed_tail;
  };
  EXPECT_TRUE(missed(0.0, true));   // rows that agree: 5 standard errors below
  EXPECT_TRUE(missed(0.014, true)); // the samples' own spread between every other row
  EXPECT_FALSE(missed(0.1, true));  // rows 10% apart: a 5% difference is theirs
  EXPECT_TRUE(missed(0.1, false));  // the same pixels: no structure between them
}

// The most efficient is chosen. A leader whose lead over another is not significant tile by tile
// (its variance is mostly one tile's) gives way to that one's lighter tail, or to a cheaper one
// whose tail is no heavier; a leader that is better in every tile stays, whatever its tail.
TEST(AutoSampler, TheChoiceIsTheMostEfficientUnlessALighterTailOrACheaperIsNotSignificantlyWorse) {
  auto candidate = [](const char* label, std::vector<double> tiles, double tail, double t) {
    PilotResult p;
    p.label = label;
    p.stats.tile_variance = tiles;
    for (double v : tiles)
      p.stats.variance += v;
    p.stats.variance_lo = 0.9 * p.stats.variance;
    p.stats.variance_hi = 1.1 * p.stats.variance;
    p.stats.tail_share = tail;
    p.stats.mean = 1.0;
    p.stats.mean_variance = 1e-6;
    p.pass_seconds = t;
    return p;
  };
  const std::vector<double> even(64, 1.0 / 64.0);
  std::vector<double> one_tile(64, 0.2 / 64.0);
  one_tile[17] = 1.0 - 63 * 0.2 / 64.0;
  std::string reason;
  std::vector<PilotResult> c = {candidate("a", even, 0.01, 1.0), candidate("b", even, 0.01, 0.5),
                                candidate("c", std::vector<double>(64, 4.0 / 64.0), 0.01, 0.5)};
  EXPECT_EQ(choose_candidate(c, &reason), 1u);
  EXPECT_DOUBLE_EQ(c[1].efficiency, 2.0);
  EXPECT_DOUBLE_EQ(c[1].efficiency_lo, 1.0 / (1.1 * 0.5));
  EXPECT_EQ(reason, "the most efficient");
  // b's variance is mostly one tile's: its lead over a is not significant, and a's tail is lighter.
  c[1] = candidate("b", one_tile, 0.6, 0.5);
  EXPECT_EQ(choose_candidate(c, &reason), 0u);
  EXPECT_NE(reason.find("lighter tail"), std::string::npos);
  // The same lead, significant: b stays, whatever its tail.
  c[1] = candidate("b", even, 0.6, 0.5);
  EXPECT_EQ(choose_candidate(c, &reason), 1u);
  // A candidate of half the cost whose loss to the leader is not significant (mostly one tile's)
  // and whose tail is no heavier is taken; with a heavier tail it is not.
  std::vector<double> noisy = one_tile;
  for (double& v : noisy)
    v *= 3.0;
  c = {candidate("x", even, 0.01, 1.0), candidate("y", noisy, 0.01, 0.5)};
  EXPECT_EQ(choose_candidate(c, &reason), 1u);
  EXPECT_GT(c[0].efficiency, c[1].efficiency);
  EXPECT_NE(reason.find("cheaper"), std::string::npos);
  c[1].stats.tail_share = 0.02;
  EXPECT_EQ(choose_candidate(c, &reason), 0u);
  // Less cheap than kCheaperFactor of the choice's time: the more efficient stays.
  c[1].stats.tail_share = 0.01;
  c[1].pass_seconds = 0.8;
  EXPECT_EQ(choose_candidate(c, &reason), 0u);
  // Significantly less efficient: not taken, however cheap.
  c[1] = candidate("y", std::vector<double>(64, 3.0 / 64.0), 0.01, 0.5);
  EXPECT_EQ(choose_candidate(c, &reason), 0u);
}

// The emitter pixels' variance is pooled over the candidates: two films alike but for one huge
// sample at a pixel whose camera rays saw an emitter measure the same variance with pooling, and
// that variance is the pooled mean of the pixel's two values; without pooling they differ.
TEST(AutoSampler, TheEmitterPixelsVarianceIsPooledOverTheCandidates) {
  auto film = [](double outlier) {
    Film f;
    f.width = f.film_width = 16;
    f.height = f.film_height = 16;
    const size_t n = 16 * 16;
    f.sum.assign(n, double4{2.0, 2.0, 2.0, 2.0});   // two samples of 1 per pixel
    f.sumsq.assign(n, double4{2.5, 2.5, 2.5, 2.0}); // sample variance 0.5
    f.counts.assign(n, double4{});
    f.sum[37] = double4{outlier + 1.0, outlier + 1.0, outlier + 1.0, 2.0};
    f.sumsq[37] =
        double4{outlier * outlier + 1.0, outlier * outlier + 1.0, outlier * outlier + 1.0, 2.0};
    return f;
  };
  const std::vector<Film> films = {film(1000.0), film(3.0)};
  std::vector<uint8_t> in_view(16 * 16, 0);
  in_view[37] = 1;
  const EmitterPool pool = pool_emitters(films, in_view);
  ASSERT_EQ(pool.variance.size(), 64u);
  const int tile = (37 / 16 * 8 / 16) * 8 + (37 % 16) * 8 / 16; // the tile of pixel (5, 2)
  const double va = 999.0 * 999.0 / 2.0, vb = 2.0 * 2.0 / 2.0;
  EXPECT_DOUBLE_EQ(pool.variance[size_t(tile)], 0.5 * (va + vb));
  EXPECT_DOUBLE_EQ(pool.share[size_t(tile)], 0.25); // one of the tile's 2 x 2 pixels
  EXPECT_DOUBLE_EQ(pool.pixels[size_t(tile)], 4.0);
  EXPECT_TRUE(std::isnan(pool.variance[0]));
  const std::vector<uint8_t> off_mean = in_view;
  const ExploreStats a = explore_stats(films[0], off_mean, -1, &in_view, &pool);
  const ExploreStats b = explore_stats(films[1], off_mean, -1, &in_view, &pool);
  EXPECT_DOUBLE_EQ(a.variance, b.variance);
  EXPECT_DOUBLE_EQ(a.variance, (255 * 0.5 + 0.5 * (va + vb)) / 256.0);
  EXPECT_DOUBLE_EQ(a.emitter_variance, 0.5 * (va + vb) / 256.0);
  EXPECT_GT(explore_stats(films[0], off_mean, -1).variance,
            100.0 * explore_stats(films[1], off_mean, -1).variance);
}

// Candidates on interleaved rows see a small emitter in view on unequal numbers of their rows. Two
// films alike (variance 0.5 per pixel) but one on the even rows and one on the odd rows of a 32 x
// 32 film (tiles of 4 x 4 pixels), with pixels in view (variance 400) on rows 0-2: two of the even
// film's rows, one of the odd one's. Each counts the pool's share of them per tile (3/4 in the
// first row of tiles), so both measure the same variance and emitter part, which their own pixels
// would not give.
TEST(AutoSampler, EveryCandidateCountsTheEmittersInViewAlike) {
  const int size = 32;
  auto film = [&](int parity) {
    Film f;
    f.width = f.film_width = f.height = f.film_height = size;
    const size_t n = size_t(size * size);
    f.sum.assign(n, double4{});
    f.sumsq.assign(n, double4{});
    f.counts.assign(n, double4{});
    for (size_t p = 0; p < n; ++p) {
      if (int(p) / size % 2 != parity) continue;
      const bool in_view = p / size_t(size) < 3;
      const double a2 = in_view ? 200.0 : 0.25; // two samples 1 +- a: variance 2 a^2
      f.sum[p] = double4{2.0, 2.0, 2.0, 2.0};
      f.sumsq[p] = double4{2.0 + 2.0 * a2, 2.0 + 2.0 * a2, 2.0 + 2.0 * a2, 2.0};
      f.counts[p].z = in_view ? 2.0 : 0.0;
    }
    return f;
  };
  const std::vector<Film> films = {film(0), film(1)};
  std::vector<uint8_t> in_view(size_t(size * size), 0);
  for (size_t p = 0; p < 3 * size_t(size); ++p)
    in_view[p] = 1;
  const EmitterPool pool = pool_emitters(films, in_view);
  EXPECT_DOUBLE_EQ(pool.variance[0], 400.0);
  EXPECT_DOUBLE_EQ(pool.share[0], 0.75);
  EXPECT_DOUBLE_EQ(pool.pixels[0], 16.0);
  const ExploreStats even = explore_stats(films[0], in_view, -1, &in_view, &pool);
  const ExploreStats odd = explore_stats(films[1], in_view, -1, &in_view, &pool);
  const double first_row = 0.75 * 400.0 + 0.25 * 0.5; // of tiles
  const double expected = (first_row + 7.0 * 0.5) / 8.0;
  EXPECT_NEAR(even.variance, expected, 1e-9 * expected);
  EXPECT_NEAR(odd.variance, expected, 1e-9 * expected);
  EXPECT_NEAR(even.emitter_variance, 0.75 * 400.0 / 8.0, 1e-9);
  EXPECT_NEAR(odd.emitter_variance, 0.75 * 400.0 / 8.0, 1e-9);
  // Each film's own pixels: 2 of the even film's 16 rows are in view, 1 of the odd film's.
  EXPECT_GT(explore_stats(films[0], in_view, -1).variance,
            1.5 * explore_stats(films[1], in_view, -1).variance);
}

// The emitters' antialiasing error at N samples per pixel, against what their per-sample variance
// predicts (variance / N), is emitter_variance_scale(N): 1 with independent camera samples, N^-1/2
// with the stratified ones, within a factor of 2, at 16 and 64 spp. A sphere light in view over
// black: every pixel is the light's coverage of it. Over 8 seeds, against a 4096-spp render.
TEST(AutoSampler, TheEmittersAntialiasingErrorFallsAsTheVarianceScaleSays) {
  const char* json = R"({
    "camera": { "position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 30 },
    "film": { "width": 32, "height": 24 },
    "integrator": { "max_depth": 1 },
    "lights": [ { "type": "sphere", "center": [0.1, 0, 0], "radius": 0.6,
                  "radiance": [1, 1, 1] } ]
  })";
  Scene scene = load_scene_from_string(json, "edge.json", ".");
  ClRuntime rt;
  auto renderer = [&](const char* path_sampler) {
    RendererOptions o;
    o.light_sampler = "tree";
    o.path_sampler = path_sampler;
    return std::make_unique<Renderer>(rt, scene, o);
  };
  std::unique_ptr<Renderer> sobol = renderer("sobol"), independent = renderer("independent");
  auto render = [](Renderer& r, int spp, uint32_t seed) {
    RenderSettings rs;
    rs.spp = spp;
    rs.seed = seed;
    return r.render(rs);
  };
  const Film ref = render(*sobol, 4096, 1000);
  std::vector<size_t> edge; // pixels that the light covers in part
  for (size_t p = 0; p < ref.sum.size(); ++p) {
    const double m = ref.sum[p].x / ref.sum[p].w;
    if (m > 0.0 && m < 1.0) edge.push_back(p);
  }
  ASSERT_GT(edge.size(), 40u);
  for (int spp : {16, 64}) {
    double predicted = 0.0, mse[2] = {0.0, 0.0};
    for (uint32_t seed = 1; seed <= 8; ++seed) {
      const Film f[2] = {render(*independent, spp, seed), render(*sobol, spp, seed)};
      for (size_t p : edge) {
        const double k = f[0].sum[p].w, s = f[0].sum[p].x, q = f[0].sumsq[p].x;
        predicted += (q - s * s / k) / (k - 1.0) / k;
        for (int i = 0; i < 2; ++i) {
          const double e = f[i].sum[p].x / f[i].sum[p].w - ref.sum[p].x / ref.sum[p].w;
          mse[i] += e * e;
        }
      }
    }
    const double ratio[2] = {mse[0] / predicted, mse[1] / predicted};
    const double scale[2] = {emitter_variance_scale("independent", spp),
                             emitter_variance_scale("sobol", spp)};
    for (int i = 0; i < 2; ++i) {
      EXPECT_GT(ratio[i], 0.5 * scale[i]) << spp << " spp, sampler " << i;
      EXPECT_LT(ratio[i], 2.0 * scale[i]) << spp << " spp, sampler " << i;
    }
  }
}

// Power sampling is hopeless here: the exploration must see it, its samples must weigh little,
// every pixel gets exactly spp samples, and the renderer ends on the chosen candidate.
TEST(AutoSampler, TheExplorationRanksByEfficiencyAndItsSamplesArePartOfTheImage) {
  AutoRun run(kGridJson);
  Renderer& renderer = run.renderer;
  RenderSettings rs;
  // Waves of one pass over the 64 x 48 film (a splitting candidate's: 16,384 paths, 6 passes): at
  // 80 spp the film's exploration, 19 spp, is at most kFilmExplorationShare of them.
  rs.spp = 80;
  AutoRender r = run.render(rs.spp, 7, 64 * 48);
  const AutoChoice& choice = r.choice;
  ASSERT_EQ(choice.candidates.size(), 3u);
  int explored = 0;
  uint64_t extra = 0; // the other candidates' samples
  for (const PilotResult& c : choice.candidates) {
    EXPECT_GT(c.stats.variance, 0.0) << c.label;
    EXPECT_GT(c.pass_seconds, 0.0) << c.label;
    EXPECT_DOUBLE_EQ(c.efficiency, 1.0 / (c.stats.variance * c.pass_seconds)) << c.label;
    EXPECT_LE(c.efficiency_lo, c.efficiency) << c.label;
    EXPECT_GE(c.efficiency_hi, c.efficiency) << c.label;
    EXPECT_EQ(c.first_sample, 0) << c.label; // every candidate explores the first indices
    EXPECT_DOUBLE_EQ(c.explored_share, 1.0) << c.label;
    explored = std::max(explored, c.samples);
    if (c.label != choice.chosen.label) extra += uint64_t(c.samples) * 64 * 48;
  }
  EXPECT_EQ(choice.explored_samples, explored);
  EXPECT_LT(explored, rs.spp);
  // per-sample variance: power's is far above the tree's, so its samples weigh little
  EXPECT_GT(choice.candidates[0].stats.variance, 10.0 * choice.candidates[1].stats.variance);
  for (int h = 0; h < 2; ++h)
    EXPECT_LT(choice.candidates[0].weight[h], 0.1);
  EXPECT_NE(choice.chosen.label, "power");
  EXPECT_EQ(renderer.options().light_sampler, choice.chosen.options.light_sampler);
  EXPECT_EQ(renderer.options().split_threshold, choice.chosen.options.split_threshold);
  EXPECT_NE(describe(choice).find("auto: " + choice.chosen.label), std::string::npos);
  // The chosen candidate rendered every sample index once, the others their exploration.
  EXPECT_EQ(renderer.stats().samples, uint64_t(rs.spp) * 64 * 48 + extra);
  for (int h = 0; h < 2; ++h)
    EXPECT_GE(choice.gain[h], 1.0);
  EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
  ASSERT_EQ(r.film.sum.size(), size_t(64 * 48));
  for (const double4& s : r.film.sum)
    ASSERT_EQ(s.w, double(rs.spp));
}

// The image made of the chosen candidate's samples and the others' weighted exploration samples is
// unbiased: over 8 seeds its image mean equals the exhaustive estimator's within 5 standard errors
// of the difference; under point lights alone, and with sphere lights in view (near whose pixels
// only the chosen candidate's samples count), with the
// exploration on every row, on bands of them (one in three) for the splitting candidate, and on
// interleaved rows, a third of them each (at 5 spp, below kFilmExplorationMinSpp, two samples each;
// at 48 spp with full waves, where the film's exploration would cost too much, three); and with the
// last candidate timed as if it were 10^4 times costlier, which prunes it: with emitters in view
// before it renders (its pass costs at least tree's, and its variance is at least the emitters'),
// under point lights alone after its probe (the rest of its exploration would cost most of the
// render). (Otherwise the probe counts as free: tests do not time.)
class CombinedImage : public ::testing::TestWithParam<std::tuple<bool, int, bool>> {};

TEST_P(CombinedImage, IsUnbiased) {
  std::string json = kGridJson;
  const auto [emitters, period, costly] = GetParam();
  if (emitters) // emitters in view: near them only the chosen candidate's samples count
    json.replace(json.find("\"light_sets\""), 12,
                 R"("lights": [ { "type": "sphere", "center": [1, 0.6, 0], "radius": 0.4,
                                  "radiance": [30, 30, 30] },
                                { "type": "sphere", "center": [-2, 0.3, 1], "radius": 0.2,
                                  "radiance": [60, 40, 20] } ],
                    "light_sets")");
  Scene scene = load_scene_from_string(json, "grid.json", ".");
  ClRuntime rt;
  auto image_mean = [](const Film& f) {
    double m = 0.0;
    for (const double4& s : f.sum)
      m += (s.x + s.y + s.z) / (3.0 * s.w);
    return m / double(f.sum.size());
  };
  RendererOptions exhaustive;
  exhaustive.light_sampler = "exhaustive";
  Renderer ref(rt, scene, exhaustive);
  RenderSettings rs;
  rs.spp = 8;
  rs.seed = 99;
  Film e = ref.render(rs);
  // The exhaustive image mean's variance from its per-pixel sample variances.
  double ref_var = 0.0;
  for (size_t p = 0; p < e.sum.size(); ++p) {
    const double k = e.sum[p].w;
    const double s = (e.sum[p].x + e.sum[p].y + e.sum[p].z) / 3.0;
    const double q = (e.sumsq[p].x + e.sumsq[p].y + e.sumsq[p].z) / 3.0;
    ref_var += std::max(0.0, (q - s * s / k) / (k - 1.0)) / k;
  }
  ref_var /= double(e.sum.size()) * double(e.sum.size());

  RendererOptions base = auto_candidates(RendererOptions{}).front().options;
  // Waves of 256 paths for the splitting candidate: a pass over its bands (16 of 48 rows) fills
  // one, so it explores on them; power and tree, whose waves hold 2^18 paths, on the film.
  // Waves of one pass on the film (and of 256 paths for the splitting candidate, 1 << 14 items
  // over its cut of 64): at 48 spp the film's exploration, 9 spp, is at most
  // kFilmExplorationShare of them.
  if (period > 0) base.split_queue_items = 1 << 14;
  const bool interleaved = period <= 0;
  Renderer renderer(rt, scene, base);
  std::vector<double> means;
  for (uint32_t seed = 1; seed <= 8; ++seed) {
    rs.spp = period == 0 ? 5 : 48;
    // at 48 spp with waves of 2^18 paths the film's exploration would cost most of the samples
    rs.wave_size = period < 0 ? RenderSettings{}.wave_size : 64 * 48;
    rs.seed = seed;
    AutoRender r = render_auto(renderer, base, rs, period, costly ? 1e4 : 0.0);
    ASSERT_FALSE(r.choice.candidates.empty());
    if (interleaved) { // max(2, spp / 16) each
      EXPECT_EQ(r.choice.explored_samples, period == 0 ? 2 : 3);
    }
    // 10^4 times the cost: with emitters in view it cannot win; without, the rest of its
    // exploration costs more than kCostlyExplorationShare of the render, and on interleaved rows
    // its probe's variance does not show it significantly more efficient.
    const bool pruned = costly, unexplored = costly && emitters;
    for (size_t i = 0; i < 3; ++i) {
      const PilotResult& c = r.choice.candidates[i];
      const double share = interleaved || (period > 1 && i == 2) ? 16.0 / 48.0 : 1.0;
      EXPECT_EQ(c.pruned, pruned && i == 2) << describe(r.choice);
      // a probe: two of kProbeParts bands of its rows (on bands, both of its 2 bands of 8 rows)
      EXPECT_DOUBLE_EQ(c.explored_share, unexplored && c.pruned    ? 0.0
                                         : c.pruned && period <= 1 ? share * 2.0 / kProbeParts
                                                                   : share);
      if (c.pruned) {
        EXPECT_NE(r.choice.chosen.label, c.label);
        // a second sample where it measured a variance
        EXPECT_EQ(c.samples, unexplored ? 0 : interleaved && !emitters ? 2 : 1);
      }
    }
    for (const double4& x : r.film.sum) // every pixel, explored or not, has spp samples
      ASSERT_EQ(x.w, double(rs.spp));
    means.push_back(image_mean(r.film));
  }
  double m = 0.0, v = 0.0;
  for (double x : means)
    m += x / double(means.size());
  for (double x : means)
    v += (x - m) * (x - m) / double(means.size() - 1);
  const double se = std::sqrt(v / double(means.size()) + ref_var);
  EXPECT_LE(std::fabs(m - image_mean(e)), 5.0 * se)
      << "auto " << m << " exhaustive " << image_mean(e) << " se " << se;
  EXPECT_GT(se, 0.0);
}

INSTANTIATE_TEST_SUITE_P(AutoSampler, CombinedImage,
                         ::testing::Combine(::testing::Bool(), ::testing::Values(1, 3, 0, -1),
                                            ::testing::Bool()),
                         [](const auto& p) {
                           const int mode = std::get<1>(p.param);
                           return std::string(std::get<0>(p.param) ? "EmittersInView"
                                                                   : "PointLights") +
                                  (mode == 1   ? ""
                                   : mode == 3 ? "OnBands"
                                   : mode == 0 ? "OnInterleavedRows"
                                               : "OnInterleavedRowsAt48Spp") +
                                  (std::get<2>(p.param) ? "CostlyLast" : "");
                         });

// A scene built to defeat a ranking by few samples (as Veach's MIS scene): a tiny, very bright
// sphere light out of view, seen in a near-mirror floor, and a dim wall lit by a grid of point
// lights. Light samples that land in the mirror's narrow lobe are rare and huge. Over 20 seeds, the
// candidate chosen from an exploration's sample (3 spp each over a 128 x 96 film) at equal cost per
// pass (tests do not time) has a long-run variance (32 spp, another seed) within 10% of the least:
// the rare large samples must not fool the choice. (On a 48 x 32 film, 3 of 20 seeds chose wrong:
// the exploration must hold enough samples, which a film of 10^4 pixels or more gives it.)
TEST(AutoSampler, AHeavyTailSceneIsRankedCorrectly) {
  const char* json = R"({
    "camera": { "position": [0, 2, 3], "look_at": [0, 0, 0], "fov": 50 },
    "film": { "width": 128, "height": 96 },
    "integrator": { "max_depth": 1 },
    "materials": [ { "name": "mirror", "type": "conductor", "metal": "silver", "roughness": 0.12 } ],
    "shapes": [
      { "type": "quad", "material": "mirror", "corner": [-3, 0, 3], "edge1": [6, 0, 0],
        "edge2": [0, 0, -6] },
      { "type": "quad", "corner": [-3, 0, -2.5], "edge1": [6, 0, 0], "edge2": [0, 3, 0] } ],
    "lights": [ { "type": "sphere", "center": [0.3, 3, -1.5], "radius": 0.02,
                  "radiance": [20000, 20000, 20000] } ],
    "light_sets": [ { "type": "grid", "origin": [-3, 2.5, 0], "edge1": [6, 0, 0],
                      "edge2": [0, 0, -1.5], "nx": 8, "ny": 4,
                      "light": { "type": "point", "intensity": 0.5 } } ]
  })";
  Scene scene = load_scene_from_string(json, "heavy.json", ".");
  ClRuntime rt;
  std::vector<PilotResult> cand = auto_candidates(RendererOptions{});
  std::vector<std::unique_ptr<Renderer>> r;
  for (const PilotResult& c : cand)
    r.push_back(std::make_unique<Renderer>(rt, scene, c.options));
  auto variance = [&](size_t c, int spp, uint32_t seed) {
    RenderSettings rs;
    rs.spp = spp;
    rs.seed = seed;
    Film f = r[c]->render(rs);
    return explore_stats(f, f.emitter_mask(), -1);
  };
  std::vector<double> truth;
  for (size_t c = 0; c < cand.size(); ++c)
    truth.push_back(variance(c, 32, 1000).variance);
  const double least = *std::min_element(truth.begin(), truth.end());
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    std::vector<PilotResult> c = cand;
    for (size_t i = 0; i < c.size(); ++i) {
      c[i].stats = variance(i, 3, seed);
      c[i].pass_seconds = 1.0;
    }
    std::string reason;
    const size_t k = choose_candidate(c, &reason);
    EXPECT_LE(truth[k], 1.1 * least) << "seed " << seed << ": " << c[k].label << " (" << reason
                                     << ") true variance " << truth[k] << ", least " << least;
  }
}

// A candidate explored on bands of rows is compared with the others over its rows only: on the
// default scene (the ceiling's lights in the top rows, a dim floor below) its image mean over its
// bands is far from the film's, and the missed-tail test must not take that for a missed tail.
TEST(AutoSampler, ACandidateOnBandsIsComparedOverItsRows) {
  Scene scene = load_scene(std::string(CANOPY_SCENES_DIR) + "/default.json");
  scene.film.width = 128;
  scene.film.height = 128;
  scene.integrator.max_depth = 1;
  ClRuntime rt;
  RendererOptions base = auto_candidates(RendererOptions{}).front().options;
  base.split_queue_items = 1 << 14; // waves of 256 paths: the splitting candidate explores bands
  Renderer renderer(rt, scene, base);
  for (uint32_t seed = 1; seed <= 3; ++seed) {
    RenderSettings rs;
    rs.spp = 48; // waves of one pass: the film's exploration is 9 spp
    rs.wave_size = 128 * 128;
    rs.seed = seed;
    AutoRender r = render_auto(renderer, base, rs, 4, 0.0); // a free probe: it explores
    ASSERT_EQ(r.choice.candidates.size(), 3u);
    const PilotResult& banded = r.choice.candidates[2];
    ASSERT_DOUBLE_EQ(banded.explored_share, 0.25);
    EXPECT_FALSE(banded.missed_tail) << describe(r.choice);
    EXPECT_GT(banded.weight[0] + banded.weight[1], 0.0) << describe(r.choice);
  }
}

// Too few samples to explore (1 or 2 spp): tree renders it all, bit for bit its own render.
// The chosen candidate's stratification gain from two parts of each pixel's set: about 1 where
// the samples are independent, large where the parts' means agree far better than independent
// samples' would; the pixels marked near an emitter do not count, and each half of the film is
// measured on its own.
TEST(AutoSampler, TheStratificationGainComparesTheSetsErrorToIndependentSamples) {
  const int w = 64, h = 64, n = 8;
  auto film = [&] {
    Film f;
    f.width = f.film_width = w;
    f.height = f.film_height = h;
    f.sum.assign(size_t(w * h), double4{});
    f.sumsq = f.counts = f.sum;
    return f;
  };
  Film a = film(), b = film();
  std::vector<uint8_t> odd_rows(size_t(w * h)), none(size_t(w * h), 0);
  uint64_t state = 12345;
  auto normal = [&] { // Box-Muller on a 64-bit LCG
    auto u = [&] {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      return (double(state >> 11) + 0.5) / 9007199254740992.0;
    };
    return std::sqrt(-2.0 * std::log(u())) * std::cos(6.283185307179586 * u());
  };
  for (size_t p = 0; p < odd_rows.size(); ++p) {
    odd_rows[p] = (p / size_t(w)) % 2;
    for (Film* f : {&a, &b})
      for (int k = 0; k < n; ++k) {
        // Even rows: independent samples. Odd rows: a stratified set, where each part holds the
        // same values but for a small independent error.
        const double x = odd_rows[p] ? (k % 2 ? 1.0 : -1.0) + 0.01 * normal() : normal();
        double4 &sum = f->sum[p], &sq = f->sumsq[p];
        sum.x += x, sum.y += x, sum.z += x, sum.w += 1.0;
        sq.x += x * x, sq.y += x * x, sq.z += x * x, sq.w += 1.0;
      }
  }
  std::vector<uint8_t> even_rows = odd_rows;
  for (uint8_t& r : even_rows)
    r = !r;
  for (int half = 0; half < 2; ++half) {
    // 1024 independent pixels: the ratio of the two estimates is within a few percent of 1.
    const double independent = stratification_gain(a, b, odd_rows, half);
    EXPECT_GE(independent, 1.0);
    EXPECT_LE(independent, 1.15);
    // Sample variance about 1, the parts' means differ by about 0.01 / sqrt(8) x sqrt(2): a gain
    // of about 1 / 8 / (0.01^2 / 4 x 2 / 4) = 10^4.
    EXPECT_GT(stratification_gain(a, b, even_rows, half), 2000.0);
    // Both kinds: the stratified pixels' error is nothing beside the independent ones'.
    const double both = stratification_gain(a, b, none, half);
    EXPECT_GT(both, 1.5);
    EXPECT_LT(both, 2.5);
  }
  // No pixel with samples in both parts: no measurement, gain 1.
  EXPECT_EQ(stratification_gain(a, film(), none, 0), 1.0);
}

// A stratified render's error falls faster than independent samples': where another candidate's
// samples took a few of the chosen one's sample indices, that cancellation was lost (on
// cornell-1k's direct light the image had 1.8x the error of the chosen candidate's own render).
// The chosen candidate renders every index of every pixel: its samples in the image are exactly
// its own render's. The others' samples are extra, weighted by its measured gain: over 4 seeds the
// image's error is within 15% of the chosen candidate's own render of the same seed (a square
// light and a point light over a floor, direct light, 64 spp, against a 4096-spp render).
TEST(AutoSampler, TheChosenCandidatesStratifiedSetStaysWhole) {
  const char* json = R"({
    "camera": { "position": [0, 4, 5], "look_at": [0, 0, 0], "fov": 45 },
    "film": { "width": 64, "height": 48 },
    "integrator": { "max_depth": 1 },
    "shapes": [ { "type": "quad", "corner": [-6, 0, 6], "edge1": [12, 0, 0],
                  "edge2": [0, 0, -12] } ],
    "lights": [ { "type": "quad", "corner": [-1, 2, 1], "edge1": [0, 0, -2], "edge2": [2, 0, 0],
                  "radiance": 5 },
                { "type": "point", "position": [3, 1, -2], "intensity": 2 } ]
  })";
  AutoRun run(json);
  auto mse = [](const Film& f, const Film& ref) {
    double e = 0.0;
    for (size_t p = 0; p < f.sum.size(); ++p) {
      const double d[3] = {f.sum[p].x / f.sum[p].w - ref.sum[p].x / ref.sum[p].w,
                           f.sum[p].y / f.sum[p].w - ref.sum[p].y / ref.sum[p].w,
                           f.sum[p].z / f.sum[p].w - ref.sum[p].z / ref.sum[p].w};
      e += (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / 3.0;
    }
    return e / double(f.sum.size());
  };
  // Every candidate is unbiased: one reference for all.
  RendererOptions tree;
  tree.light_sampler = "tree";
  RenderSettings rs;
  rs.spp = 4096;
  rs.seed = 1000;
  const Film ref = Renderer(run.rt, run.scene, tree).render(rs);
  double auto_error = 0.0, own_error = 0.0;
  for (uint32_t seed = 1; seed <= 4; ++seed) {
    RenderSettings as = rs;
    as.spp = 64;
    as.seed = seed;
    as.wave_size = 64 * 48;
    Film chosen;
    AutoRender r = render_auto(run.renderer, run.base, as, 0, 0.0, &chosen);
    ASSERT_FALSE(r.choice.candidates.empty());
    Renderer alone(run.rt, run.scene, r.choice.chosen.options);
    rs.spp = 64;
    rs.seed = seed;
    const Film mine = alone.render(rs);
    // The chosen candidate's samples in the image are its render of the same seed: every index
    // of every pixel, the same samples (summed in another order).
    for (size_t p = 0; p < mine.sum.size(); ++p) {
      ASSERT_EQ(chosen.sum[p].w, 64.0) << p;
      ASSERT_NEAR(chosen.sum[p].x, mine.sum[p].x, 1e-9 * (1.0 + std::fabs(mine.sum[p].x))) << p;
      ASSERT_NEAR(chosen.sum[p].y, mine.sum[p].y, 1e-9 * (1.0 + std::fabs(mine.sum[p].y))) << p;
      ASSERT_NEAR(chosen.sum[p].z, mine.sum[p].z, 1e-9 * (1.0 + std::fabs(mine.sum[p].z))) << p;
    }
    auto_error += mse(r.film, ref);
    own_error += mse(mine, ref);
  }
  EXPECT_LE(auto_error, 1.15 * own_error) << "auto " << auto_error << " own " << own_error;
  EXPECT_GT(own_error, 0.0);
}

TEST(AutoSampler, WithoutRoomToExploreTreeRenders) {
  AutoRun run(kGridJson);
  AutoRender r = run.render(kInterleavedMinSpp - 1, 3);
  const RendererOptions& base = run.base;
  EXPECT_TRUE(r.choice.candidates.empty());
  EXPECT_EQ(r.choice.chosen.label, "tree");
  RendererOptions last = auto_candidates(base)[kFewSamplesCandidate].options;
  Renderer fresh(run.rt, run.scene, last);
  RenderSettings rs;
  rs.spp = kInterleavedMinSpp - 1;
  rs.seed = 3;
  Film f = fresh.render(rs);
  for (size_t p = 0; p < f.sum.size(); ++p)
    ASSERT_EQ(f.sum[p].x, r.film.sum[p].x) << p;
}

// Without emitters every candidate's image is black (variance 0): the fastest is taken, and
// nothing divides by zero.
TEST(AutoSampler, ABlackScenePicksTheFastest) {
  std::string json = kGridJson;
  json.replace(json.find("\"intensity\": 1"), 14, "\"intensity\": 0");
  AutoRun run(json);
  AutoRender r = run.render(16, 7);
  const AutoChoice& choice = r.choice;
  ASSERT_EQ(choice.candidates.size(), 3u);
  double fastest = 1e300;
  for (const PilotResult& c : choice.candidates) {
    EXPECT_EQ(c.efficiency, 0.0);
    fastest = std::min(fastest, c.pass_seconds);
  }
  EXPECT_EQ(choice.chosen.pass_seconds, fastest);
  for (const double4& s : r.film.sum)
    ASSERT_TRUE(s.x == 0.0 && std::isfinite(s.w));
}

// One dim light close over the floor outshines 65,536 distant ones there, but holds 6e-9 of the
// power: power sampling picks it about never in an exploration of 10^3-10^4 samples, so its image
// mean falls far below the others' and its measured variance means nothing. It is not ranked, and
// its samples weigh nothing: on interleaved rows (32 spp, 2 samples each on a third of the rows)
// and on the film (80 spp, waves of one pass).
TEST(AutoSampler, ACandidateThatMissesItsTailIsNotRankedNorWeighted) {
  const char* json = R"({
    "camera": { "position": [0, 3, 3], "look_at": [0, 0, 0], "fov": 50 },
    "film": { "width": 64, "height": 48 },
    "integrator": { "max_depth": 1 },
    "shapes": [ { "type": "quad", "corner": [-2, 0, 2], "edge1": [4, 0, 0], "edge2": [0, 0, -4] } ],
    "lights": [ { "type": "point", "position": [0, 0.5, 0], "intensity": 0.04 } ],
    "light_sets": [ { "type": "grid", "origin": [-10000, 10000, -10000], "edge1": [20000, 0, 0],
                      "edge2": [0, 0, 20000], "nx": 256, "ny": 256,
                      "light": { "type": "point", "intensity": 100 } } ]
  })";
  AutoRun run(json);
  for (int spp : {32, 80}) {
    AutoChoice choice =
        run.render(spp, 11, spp == 80 ? 64 * 48 : RenderSettings{}.wave_size).choice;
    EXPECT_TRUE(choice.candidates[0].missed_tail) << spp << " spp: " << describe(choice);
    EXPECT_FALSE(choice.candidates[1].missed_tail) << spp << " spp: " << describe(choice);
    EXPECT_NE(choice.chosen.label, "power");
    EXPECT_NE(describe(choice).find("missed its tail"), std::string::npos);
    EXPECT_EQ(choice.candidates[0].weight[0], 0.0);
    EXPECT_EQ(choice.candidates[0].weight[1], 0.0);
  }
}

// The exploration switches samplers on one renderer, and a tree sampler after another keeps the
// light tree (it depends on the lights alone): the image after each switch must be the very image
// of a renderer built for that sampler.
TEST(AutoSampler, ASwitchedRendererRendersAsAFreshOne) {
  Scene scene = load_scene_from_string(kGridJson, "grid.json", ".");
  ClRuntime rt;
  RendererOptions tree;
  tree.light_sampler = "tree";
  RendererOptions split = auto_candidates(RendererOptions{}).back().options; // brdf-mis/split
  RendererOptions power = auto_candidates(RendererOptions{}).front().options;
  RenderSettings rs;
  rs.spp = 3;
  rs.seed = 5;
  auto expect_same = [&](const Film& a, const Film& b, const char* what) {
    ASSERT_EQ(a.sum.size(), b.sum.size());
    for (size_t i = 0; i < a.sum.size(); ++i) {
      ASSERT_EQ(a.sum[i].x, b.sum[i].x) << what << " pixel " << i;
      ASSERT_EQ(a.sum[i].y, b.sum[i].y) << what << " pixel " << i;
      ASSERT_EQ(a.sum[i].z, b.sum[i].z) << what << " pixel " << i;
      ASSERT_EQ(a.sumsq[i].x, b.sumsq[i].x) << what << " pixel " << i;
    }
  };
  Renderer switched(rt, scene, tree);
  switched.set_light_sampler(split); // keeps the tree
  Film a = switched.render(rs);
  Renderer fresh_split(rt, scene, split);
  expect_same(a, fresh_split.render(rs), "tree -> brdf-mis/split");
  switched.set_light_sampler(power); // drops it
  switched.set_light_sampler(tree);  // builds it again
  Film b = switched.render(rs);
  Renderer fresh_tree(rt, scene, tree);
  expect_same(b, fresh_tree.render(rs), "-> power -> tree");
}

// The exploration times renders of one full wave; a wave's paths are bounded by the split queue for
// a splitting sampler (every path's cut must fit: split_queue_items / max_cut) and by the settings'
// wave size otherwise.
TEST(AutoSampler, AWaveHoldsAsManyPathsAsTheSplitQueueAllows) {
  Scene scene = load_scene_from_string(kGridJson, "grid.json", ".");
  ClRuntime rt;
  RendererOptions opt;
  opt.light_sampler = "tree";
  Renderer renderer(rt, scene, opt);
  EXPECT_EQ(renderer.paths_per_wave(size_t(1) << 18), size_t(1) << 18);
  EXPECT_EQ(renderer.paths_per_wave(1000), 1000u);
  opt.light_sampler = "tree-split";
  opt.max_cut = 64;
  renderer.set_light_sampler(opt);
  EXPECT_EQ(renderer.paths_per_wave(size_t(1) << 18), opt.split_queue_items / 64);
  opt.max_cut = 2;
  renderer.set_light_sampler(opt);
  EXPECT_EQ(renderer.paths_per_wave(size_t(1) << 18), size_t(1) << 18);
}
