// Light-tree benchmarks (host). Families:
//   LightTreeBuild/<N>/<layout>  build time of the tree over N lights; counters bytes_per_emitter
//                                (device buffers / N), nodes, levels
//   TreePick/<N>/<layout>        stochastic tree picks (no splitting) for random shading points on
//                                2 threads; counter picks_per_second
//   TreeSplitPick/<N>/<layout>   the same with adaptive splitting (threshold 0.85, max_cut 64);
//                                counters points_per_second, avg_cut
//   SplitCut/<threshold*100>     spiral scene of the paper's Fig. 11 (10^4 lights): mean cut size
// layout: 0 random points, 1 randomly oriented triangles, 2 city-like layout.
#include "lighttree/light_sampler.h"
#include "lighttree/synthetic_lights.h"

#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <map>
#include <mutex>

using namespace canopy;

namespace {

const std::vector<Light>& lights_for(int n, int layout) {
  static std::mutex mu;
  static std::map<std::pair<int, int>, std::vector<Light>> cache;
  std::lock_guard<std::mutex> lock(mu);
  auto key = std::make_pair(n, layout);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  std::vector<Light> l = layout == 0   ? random_point_lights(n, 7)
                         : layout == 1 ? random_triangle_lights(n, 7)
                                       : city_lights(n, 7);
  return cache.emplace(key, std::move(l)).first->second;
}

const char* layout_name(int layout) {
  return layout == 0 ? "random points" : (layout == 1 ? "random triangles" : "city");
}

struct Shading {
  float3 P, N;
};
// Shading points inside the lights' bounding box with random normals (city: on the ground, up).
std::vector<Shading> shading_points(const std::vector<Light>& lights, int layout, int count) {
  float3 lo = make_float3(FLT_INF, FLT_INF, FLT_INF),
         hi = make_float3(-FLT_INF, -FLT_INF, -FLT_INF);
  for (const Light& l : lights) {
    lo = fmin(lo, xyz_of(l.p));
    hi = fmax(hi, xyz_of(l.p));
  }
  LtRng r = lt_rng_make(11, 5);
  std::vector<Shading> s(count);
  for (Shading& x : s) {
    float3 u = make_float3(lt_rng_next(&r), lt_rng_next(&r), lt_rng_next(&r));
    x.P = lo + (hi - lo) * u;
    if (layout == 2) {
      x.P.y = 0.0f;
      x.N = make_float3(0, 1, 0);
    } else {
      float z = 2.0f * lt_rng_next(&r) - 1.0f, phi = 2.0f * M_PI_F * lt_rng_next(&r);
      float sn = std::sqrt(std::fmax(0.0f, 1.0f - z * z));
      x.N = make_float3(sn * std::cos(phi), sn * std::sin(phi), z);
    }
  }
  return s;
}

void BM_LightTreeBuild(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int layout = static_cast<int>(state.range(1));
  const std::vector<Light>& lights = lights_for(n, layout);
  tbb::task_arena arena(2);
  LightTree tree;
  for (auto _ : state) {
    arena.execute([&] { tree = build_light_tree(lights); });
    benchmark::DoNotOptimize(tree.nodes.data());
  }
  state.SetLabel(layout_name(layout));
  state.counters["bytes_per_emitter"] = double(tree.device_bytes()) / double(n);
  state.counters["nodes"] = double(tree.num_nodes());
  state.counters["levels"] = double(tree.levels);
}

void BM_TreePick(benchmark::State& state, const char* sampler_name) {
  const int n = static_cast<int>(state.range(0));
  const int layout = static_cast<int>(state.range(1));
  const std::vector<Light>& lights = lights_for(n, layout);
  tbb::task_arena arena(2);
  std::unique_ptr<LightSampler> sampler;
  arena.execute([&] { sampler = make_light_sampler(sampler_name, lights); });
  const int kPoints = 1 << 16;
  std::vector<Shading> pts = shading_points(lights, layout, kPoints);
  std::atomic<long long> picks{0};
  uint32_t round = 0;
  for (auto _ : state) {
    ++round;
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, kPoints, 1024),
                        [&](const tbb::blocked_range<int>& r) {
                          std::vector<LightPick> out;
                          long long local = 0;
                          float sink = 0;
                          for (int i = r.begin(); i != r.end(); ++i) {
                            Rng rng = make_rng(round, uint32_t(i));
                            out.clear();
                            sampler->sample(pts[i].P, pts[i].N, rng, out);
                            local += static_cast<long long>(out.size());
                            for (const LightPick& p : out)
                              sink += p.prob;
                          }
                          benchmark::DoNotOptimize(sink);
                          picks += local;
                        });
    });
  }
  state.SetLabel(layout_name(layout));
  state.counters["points_per_second"] =
      benchmark::Counter(double(kPoints), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["picks_per_second"] =
      benchmark::Counter(double(picks.load()), benchmark::Counter::kIsRate);
  state.counters["avg_cut"] = double(picks.load()) / (double(kPoints) * double(state.iterations()));
}

void BM_SplitCut(benchmark::State& state) {
  const float thr = float(state.range(0)) / 100.0f;
  std::vector<Light> lights = spiral_lights(10000);
  LightSamplerOptions opt;
  opt.split_threshold = thr;
  opt.max_cut = 1024;
  auto sampler = make_light_sampler("tree-split", lights, opt);
  // shading points on the ground (y = 0) under the spiral (radius <= 50), normal up
  LtRng r = lt_rng_make(3, 3);
  const int kPoints = 4096;
  double cut = 0;
  for (auto _ : state) {
    std::vector<LightPick> out;
    cut = 0;
    for (int i = 0; i < kPoints; ++i) {
      float3 P =
          make_float3(100.0f * lt_rng_next(&r) - 50.0f, 0.0f, 100.0f * lt_rng_next(&r) - 50.0f);
      Rng rng = make_rng(1, uint32_t(i));
      out.clear();
      sampler->sample(P, make_float3(0, 1, 0), rng, out);
      cut += double(out.size());
    }
  }
  state.counters["avg_cut"] = cut / kPoints;
}

void build_args(benchmark::internal::Benchmark* b) {
  for (int n : {1000, 10000, 100000, 1000000})
    for (int layout = 0; layout < 3; ++layout)
      b->Args({n, layout});
}

} // namespace

BENCHMARK(BM_LightTreeBuild)
    ->Name("LightTreeBuild")
    ->Apply(build_args)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(0.2);
BENCHMARK_CAPTURE(BM_TreePick, tree, "tree")
    ->Name("TreePick")
    ->Apply(build_args)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(0.2);
BENCHMARK_CAPTURE(BM_TreePick, split, "tree-split")
    ->Name("TreeSplitPick")
    ->Apply(build_args)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(0.2);
BENCHMARK(BM_SplitCut)
    ->Name("SplitCut")
    ->Arg(0)
    ->Arg(50)
    ->Arg(85)
    ->Arg(95)
    ->Arg(100)
    ->Iterations(1);
