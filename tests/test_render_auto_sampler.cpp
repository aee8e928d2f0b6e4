// The "auto" light sampler (render/auto_sampler.h): the pilot renders every candidate, ranks them
// by 1 / (variance per sample x seconds), and leaves the renderer set to the winner.
#include "render/auto_sampler.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <algorithm>

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

// Power sampling is hopeless here: the pilot must see it, and the renderer must end on the winner,
// the candidate with the highest measured efficiency.
TEST(AutoSampler, ThePilotRanksByEfficiencyAndLeavesTheWinnerSet) {
  Scene scene = load_scene_from_string(kGridJson, "grid.json", ".");
  ClRuntime rt;
  RendererOptions base = auto_candidates(RendererOptions{}).front().options;
  Renderer renderer(rt, scene, base);
  AutoChoice choice = choose_light_sampler(renderer, base, 7);
  ASSERT_EQ(choice.candidates.size(), 3u);
  for (const PilotResult& c : choice.candidates) {
    EXPECT_GT(c.variance, 0.0) << c.label;
    EXPECT_GT(c.seconds, 0.0) << c.label;
    // the efficiency is that of a pass over the whole film
    EXPECT_GT(c.pass_seconds, 0.0) << c.label;
    EXPECT_DOUBLE_EQ(c.efficiency, 1.0 / (c.variance * c.pass_seconds)) << c.label;
    EXPECT_LE(c.efficiency, choice.chosen.efficiency) << c.label;
  }
  // per-sample variance: power's is far above the tree's (the same order of time per sample)
  EXPECT_GT(choice.candidates[0].variance, 10.0 * choice.candidates[1].variance);
  EXPECT_NE(choice.chosen.label, "power");
  EXPECT_EQ(renderer.options().light_sampler, choice.chosen.options.light_sampler);
  EXPECT_EQ(renderer.options().split_threshold, choice.chosen.options.split_threshold);
  EXPECT_GE(choice.pilot_seconds, choice.candidates[0].seconds);
  EXPECT_NE(describe(choice).find("auto: " + choice.chosen.label), std::string::npos);
  // The pilot's renders are not the render's: its statistics start from zero.
  EXPECT_EQ(renderer.stats().samples, 0u);
  EXPECT_EQ(renderer.stats().render_seconds, 0.0);
  // The renderer renders with it afterwards.
  RenderSettings rs;
  rs.spp = 2;
  Film film = renderer.render(rs);
  EXPECT_EQ(renderer.stats().samples, uint64_t(2 * 64 * 48));
  EXPECT_EQ(renderer.stats().nonfinite_samples, 0u);
  EXPECT_EQ(film.sum.size(), size_t(64 * 48));
}

// Without emitters every candidate's image is black (variance 0): the fastest is taken, and
// nothing divides by zero.
TEST(AutoSampler, ABlackScenePicksTheFastest) {
  std::string json = kGridJson;
  json.replace(json.find("\"intensity\": 1"), 14, "\"intensity\": 0");
  Scene scene = load_scene_from_string(json, "black.json", ".");
  ClRuntime rt;
  RendererOptions base = auto_candidates(RendererOptions{}).front().options;
  Renderer renderer(rt, scene, base);
  AutoChoice choice = choose_light_sampler(renderer, base, 7);
  double fastest = 1e300;
  for (const PilotResult& c : choice.candidates) {
    EXPECT_EQ(c.efficiency, 0.0);
    fastest = std::min(fastest, c.seconds);
  }
  EXPECT_EQ(choice.chosen.seconds, fastest);
}

// One dim light close over the floor outshines 65,536 distant ones there, but holds 6e-9 of the
// power: power sampling picks it about never in a pilot of at most ~5·10^5 samples, so its image
// mean falls far below the others' and its measured variance means nothing. It is not ranked.
TEST(AutoSampler, ACandidateThatMissesItsTailIsNotRanked) {
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
  Scene scene = load_scene_from_string(json, "tail.json", ".");
  ClRuntime rt;
  RendererOptions base = auto_candidates(RendererOptions{}).front().options;
  Renderer renderer(rt, scene, base);
  AutoChoice choice = choose_light_sampler(renderer, base, 11);
  EXPECT_TRUE(choice.candidates[0].missed_tail) << describe(choice);
  EXPECT_FALSE(choice.candidates[1].missed_tail) << describe(choice);
  EXPECT_NE(choice.chosen.label, "power");
  EXPECT_NE(describe(choice).find("missed its tail"), std::string::npos);
}

// The pilot switches samplers on one renderer, and a tree sampler after another keeps the light
// tree (it depends on the lights alone): the image after each switch must be the very image of a
// renderer built for that sampler.
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

// The pilot times renders of one full wave; a wave's paths are bounded by the split queue for a
// splitting sampler (every path's cut must fit: split_queue_items / max_cut) and by the settings'
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
