// Whole-render benchmarks: time per sample and per-stage throughput on the Cornell scenes, the
// gain of kernels compiled for the scene, and render-time scaling from 10^3 to 10^6 lights.
//   canopy_bench --benchmark_filter=Render --benchmark_repetitions=3
// Counters: ms_per_spp (render wall time per sample per pixel), and <stage>_items_per_s from the
// OpenCL profiling events (light_pick, intersect_closest, intersect_shadow, shade_surface).
#include "render/renderer.h"

#include <benchmark/benchmark.h>

#include <map>
#include <memory>

using namespace canopy;

namespace {

Scene& scene(const std::string& name) {
  static std::map<std::string, Scene> cache;
  auto it = cache.find(name);
  if (it == cache.end()) {
    Scene s = load_scene(std::string(CANOPY_SCENES_DIR) + "/" + name + ".json");
    s.film.width = 256;
    s.film.height = 256;
    it = cache.emplace(name, std::move(s)).first;
  }
  return it->second;
}

ClRuntime& runtime() {
  static ClRuntime rt;
  return rt;
}

void render_benchmark(benchmark::State& state, const std::string& scene_name,
                      const std::string& sampler, bool all_features) {
  Scene& s = scene(scene_name);
  RendererOptions opt;
  opt.light_sampler = sampler;
  opt.all_features = all_features;
  Renderer r(runtime(), s, opt);
  RenderSettings rs;
  rs.spp = 4;
  r.render(rs); // warm-up: first launches, page faults
  RenderStats before = r.stats();
  for (auto _ : state)
    r.render(rs);
  const RenderStats& after = r.stats();
  double seconds = after.render_seconds - before.render_seconds;
  state.counters["ms_per_spp"] = 1e3 * seconds / double(state.iterations() * rs.spp);
  for (const char* stage :
       {"light_pick", "intersect_closest", "intersect_shadow", "shade_surface"}) {
    auto a = after.stages.find(stage);
    auto b = before.stages.find(stage);
    if (a == after.stages.end()) continue;
    double items = double(a->second.items - (b == before.stages.end() ? 0 : b->second.items));
    double secs = a->second.seconds - (b == before.stages.end() ? 0 : b->second.seconds);
    state.counters[std::string(stage) + "_items_per_s"] = secs > 0 ? items / secs : 0.0;
  }
  state.counters["lights"] = double(s.lights.size());
}

} // namespace

BENCHMARK_CAPTURE(render_benchmark, Render / default / tree_split, "default", "tree-split", false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK_CAPTURE(render_benchmark, Render / default / tree_split_all_features, "default",
                  "tree-split", true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK_CAPTURE(render_benchmark, Render / cornell_1k / tree, "cornell-1k", "tree", false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK_CAPTURE(render_benchmark, Render / cornell_1m / tree, "cornell-1m", "tree", false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK_CAPTURE(render_benchmark, Render / cornell_1k / tree_split, "cornell-1k", "tree-split",
                  false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
BENCHMARK_CAPTURE(render_benchmark, Render / cornell_1m / tree_split, "cornell-1m", "tree-split",
                  false)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);
