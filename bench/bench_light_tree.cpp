// Light-tree benchmarks (host). Families:
//   LightTreeBuild/<N>/<layout>  build time of the tree over N lights; counters bytes_per_emitter
//                                (device buffers / N), nodes, levels
//   TreePick/<N>/<layout>        stochastic tree picks (no splitting) for random shading points on
//                                2 threads; counter picks_per_second
//   TreeSplitPick/<N>/<layout>   the same with adaptive splitting (threshold 0.85, max_cut 64);
//                                counters points_per_second, avg_cut
//   SplitCut/<threshold*100>     spiral scene of the paper's Fig. 11 (10^4 lights): mean cut size
//   PickCpu/<N>/<sampler>        one light_sampler_pick (the device function) per random shading
//                                point on the host, one thread; counter cpu_ns_per_pick (thread CPU
//                                time, less sensitive to other load than wall time)
//   PickCpuQuery/<N>/<kind>      the same through light_sampler_pick_q (tree): kind 0 point
//                                queries, 1 ray segments in a medium (§5.2)
//   DevicePick/<N>/<sampler>     the same picks in an OpenCL kernel (PoCL); counter
//                                cpu_ns_per_pick = process CPU time (all device threads) per pick
// sampler: 0 uniform, 1 power, 2 tree (random points layout).
// layout: 0 random points, 1 randomly oriented triangles, 2 city-like layout.
#include "cl/runtime.h"
#include "light_tree/light_sampler.h"
#include "light_tree/synthetic_lights.h"
#include "render/device_scene.h"
#include "render/light_sampler_data.h"

#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <sys/resource.h>

#include <atomic>
#include <ctime>
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

double thread_cpu_seconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}
double process_cpu_seconds() {
  rusage u;
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}
const char* kSamplerByIndex[3] = {"uniform", "power", "tree"};

// One pick, not inlined: `valgrind --tool=callgrind --toggle-collect='*pick_one*'` on PickCpu then
// counts the instructions of the picks alone (Ir / calls = instructions per pick, repeatable).
__attribute__((noinline)) int pick_one(const LightSamplerCtx* ls, float3 P, float3 N, LtRng* rng,
                                       float* pmf) {
  return light_sampler_pick(ls, 0, P, N, rng, pmf);
}

void BM_PickCpu(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::vector<Light>& lights = lights_for(n, 0);
  LightSamplerData data = make_light_sampler_data(lights, kSamplerByIndex[state.range(1)], 0.0f, 1);
  LightSamplerCtx ls = data.host_view(lights);
  const int kPoints = 4096, kPicks = 100000;
  std::vector<Shading> pts = shading_points(lights, 0, kPoints);
  double cpu = 0;
  long long picks = 0, sink = 0;
  uint32_t round = 0;
  for (auto _ : state) {
    ++round;
    double t0 = thread_cpu_seconds();
    for (int k = 0; k < kPicks; ++k) {
      LtRng rng = lt_rng_make(round, uint32_t(k));
      float pmf;
      const Shading& x = pts[size_t(k) & (kPoints - 1)];
      sink += pick_one(&ls, x.P, x.N, &rng, &pmf) + (pmf > 0.5f);
    }
    cpu += thread_cpu_seconds() - t0;
    picks += kPicks;
  }
  benchmark::DoNotOptimize(sink);
  state.SetLabel(kSamplerByIndex[state.range(1)]);
  state.counters["cpu_ns_per_pick"] = 1e9 * cpu / double(picks);
}

// The query forms as the integrator calls them: the query's kind is known at run time only, so a
// point query pays the segment test once per node (HAS_MEDIUM is on on the host).
__attribute__((noinline)) int pick_one_q(const LightSamplerCtx* ls, const LtQuery* q, LtRng* rng,
                                         float* pmf) {
  return light_sampler_pick_q(ls, 0, q, rng, pmf);
}

// range(1): 0 point queries (compare PickCpu/<N>/2), 1 segments of length 0.1 of the lights'
// extent from the same points in random directions.
void BM_PickCpuQuery(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::vector<Light>& lights = lights_for(n, 0);
  LightSamplerData data = make_light_sampler_data(lights, "tree", 0.0f, 1);
  LightSamplerCtx ls = data.host_view(lights);
  const int kPoints = 4096, kPicks = 100000;
  std::vector<Shading> pts = shading_points(lights, 0, kPoints);
  std::vector<LtQuery> qs(kPoints);
  for (int i = 0; i < kPoints; ++i) {
    const Shading& x = pts[size_t(i)];
    // N is a random unit vector: the segment's direction
    qs[size_t(i)] = state.range(1) == 0 ? lt_query_point(x.P, x.N)
                                        : lt_query_segment(x.P, x.N, 10.0f); // lights in 100^3
  }
  double cpu = 0;
  long long picks = 0, sink = 0;
  uint32_t round = 0;
  for (auto _ : state) {
    ++round;
    double t0 = thread_cpu_seconds();
    for (int k = 0; k < kPicks; ++k) {
      LtRng rng = lt_rng_make(round, uint32_t(k));
      float pmf;
      sink += pick_one_q(&ls, &qs[size_t(k) & (kPoints - 1)], &rng, &pmf) + (pmf > 0.5f);
    }
    cpu += thread_cpu_seconds() - t0;
    picks += kPicks;
  }
  benchmark::DoNotOptimize(sink);
  state.SetLabel(state.range(1) == 0 ? "tree, point query" : "tree, segment query");
  state.counters["cpu_ns_per_pick"] = 1e9 * cpu / double(picks);
}

const char* kDevicePickKernel = R"CL(
#include "kernels/params.h"
__kernel void pick_bench(LIGHT_SAMPLER_PARAMS __global const float4* P, __global const float4* N,
                         uint seed, int count, __global int* out) {
  int i = get_global_id(0);
  if (i >= count) return;
  LIGHT_SAMPLER_ASSEMBLE(ls);
  LtRng rng = lt_rng_make(seed, (uint)i);
  float pmf;
  int l = light_sampler_pick(&ls, 0, xyz_of(P[i & 4095]), xyz_of(N[i & 4095]), &rng, &pmf);
  out[i] = l + (pmf > 0.5f);
}
)CL";

void BM_DevicePick(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::vector<Light>& lights = lights_for(n, 0);
  LightSamplerData data = make_light_sampler_data(lights, kSamplerByIndex[state.range(1)], 0.0f, 1);
  const int kPoints = 4096, kPicks = 1 << 20;
  std::vector<Shading> pts = shading_points(lights, 0, kPoints);
  std::vector<float4> P(kPoints), N(kPoints);
  for (int i = 0; i < kPoints; ++i) {
    P[i] = f4_from3(pts[i].P, 0.0f);
    N[i] = f4_from3(pts[i].N, 0.0f);
  }
  ClRuntime rt;
  cl::Program program = rt.build_program_source(kDevicePickKernel, "-DCANOPY_LIGHT_SAMPLER=" +
                                                                       std::to_string(data.kind));
  const cl::Context& ctx = rt.context();
  DeviceScene d;
  upload_light_sampler(ctx, lights, data, 0, d);
  KernelArgs args;
  d.set_args(args);
  args.set("P", upload_buffer(ctx, P));
  args.set("N", upload_buffer(ctx, N));
  args.set("count", cl_int(kPicks));
  args.set("out", cl::Buffer(ctx, CL_MEM_WRITE_ONLY, sizeof(int) * kPicks));
  // The BRDF-oriented cut's per-path scratch (LIGHT_SAMPLER_PARAMS); the tree samplers never read
  // it.
  args.set("brdf_cut", cl::Buffer(ctx, CL_MEM_READ_WRITE, sizeof(cl_float2)));
  BoundKernel k(program, "pick_bench", args);
  // Warm-up (and PoCL's work-group compile).
  enqueue_1d(rt.queue(), k.bind({{"seed", cl_uint(0)}}), kPicks);
  rt.queue().finish();
  double cpu = 0;
  long long picks = 0;
  uint32_t round = 0;
  for (auto _ : state) {
    const cl::Kernel& kernel = k.bind({{"seed", cl_uint(++round)}});
    double t0 = process_cpu_seconds();
    enqueue_1d(rt.queue(), kernel, kPicks);
    rt.queue().finish();
    cpu += process_cpu_seconds() - t0;
    picks += kPicks;
  }
  state.SetLabel(kSamplerByIndex[state.range(1)]);
  state.counters["cpu_ns_per_pick"] = 1e9 * cpu / double(picks);
  state.counters["picks_per_second"] =
      benchmark::Counter(double(picks), benchmark::Counter::kIsRate);
}

void pick_args(benchmark::internal::Benchmark* b) {
  for (int n : {10000, 1000000})
    for (int s = 0; s < 3; ++s)
      b->Args({n, s});
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
BENCHMARK(BM_PickCpu)
    ->Name("PickCpu")
    ->Apply(pick_args)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);
BENCHMARK(BM_PickCpuQuery)
    ->Name("PickCpuQuery")
    ->ArgsProduct({{10000, 1000000}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);
BENCHMARK(BM_DevicePick)
    ->Name("DevicePick")
    ->Apply(pick_args)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);
