// Closest-hit throughput of the OpenCL intersect kernel against Embree (rtcIntersect1 and
// rtcIntersect8) on the same batch of incoherent rays over the same mesh, and shadow-segment
// throughput of the intersect_shadow kernel against rtcOccluded1, all using every core.
//   canopy_bench --benchmark_filter='Intersect|Occluded'
#include "accel/bvh.h"
#include "cl/runtime.h"
#include "support/closest_hit_kernel.h"
#include "support/procedural_mesh.h"
#include "support/shadow_kernel.h"

#include <benchmark/benchmark.h>
#include <tbb/parallel_for.h>

#include <memory>

using namespace canopy;

namespace {

constexpr int kRayCount = 1 << 20;

struct IntersectFixture {
  std::vector<Primitive> prims = testing::make_mesh(400, 200, 40000); // 200k triangles
  testing::Rays rays = testing::make_rays(prims, kRayCount);
  testing::Rays shadow_rays = testing::make_shadow_rays(prims, kRayCount);
  Bvh bvh = build_bvh(prims);
  EmbreeReference embree{prims};
};

IntersectFixture& fixture() {
  static IntersectFixture f;
  return f;
}

void set_rate(benchmark::State& state, int64_t rays) {
  state.counters["rays_per_second"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
  state.counters["triangles"] = double(fixture().prims.size());
}

// An intersect kernel (tests/support) over the fixture's rays, work-groups of state.range(0).
template <class Kernel>
void run_opencl(benchmark::State& state, const char* source, const testing::Rays& rays) {
  IntersectFixture& f = fixture();
  ClRuntime rt;
  cl::Program program = rt.build_program({source});
  Kernel kernel(rt, program, f.bvh, f.prims, rays);
  for (auto _ : state)
    kernel.run(size_t(state.range(0)));
  set_rate(state, int64_t(state.iterations()) * kRayCount);
}

void Intersect_OpenCL(benchmark::State& state) {
  run_opencl<testing::ClosestHitKernel>(state, "kernels/intersect_closest.cl", fixture().rays);
}

void Intersect_Embree1(benchmark::State& state) {
  IntersectFixture& f = fixture();
  std::vector<int> prim(f.rays.o.size());
  for (auto _ : state) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, f.rays.o.size(), 4096), [&](const auto& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) {
        float t;
        prim[i] = f.embree.intersect(xyz_of(f.rays.o[i]), xyz_of(f.rays.d[i]), 0.0f, FLT_INF, &t);
      }
    });
    benchmark::DoNotOptimize(prim.data());
  }
  set_rate(state, int64_t(state.iterations()) * kRayCount);
}

void Intersect_Embree8(benchmark::State& state) {
  IntersectFixture& f = fixture();
  std::vector<int> prim(f.rays.o.size());
  RTCScene scene = f.embree.scene();
  for (auto _ : state) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, f.rays.o.size() / 8, 512), [&](const auto& r) {
      for (size_t p = r.begin(); p < r.end(); ++p) {
        alignas(32) int valid[8];
        alignas(32) RTCRayHit8 rh;
        for (int j = 0; j < 8; ++j) {
          size_t i = 8 * p + size_t(j);
          valid[j] = -1;
          rh.ray.org_x[j] = f.rays.o[i].x;
          rh.ray.org_y[j] = f.rays.o[i].y;
          rh.ray.org_z[j] = f.rays.o[i].z;
          rh.ray.dir_x[j] = f.rays.d[i].x;
          rh.ray.dir_y[j] = f.rays.d[i].y;
          rh.ray.dir_z[j] = f.rays.d[i].z;
          rh.ray.tnear[j] = 0.0f;
          rh.ray.tfar[j] = FLT_INF;
          rh.ray.mask[j] = ~0u;
          rh.ray.time[j] = 0.0f;
          rh.ray.flags[j] = 0;
          rh.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;
        }
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        rtcIntersect8(valid, scene, &ctx, &rh);
        for (int j = 0; j < 8; ++j)
          prim[8 * p + size_t(j)] =
              rh.hit.geomID[j] == RTC_INVALID_GEOMETRY_ID ? -1 : int(rh.hit.primID[j]);
      }
    });
    benchmark::DoNotOptimize(prim.data());
  }
  set_rate(state, int64_t(state.iterations()) * kRayCount);
}

void Occluded_OpenCL(benchmark::State& state) {
  run_opencl<testing::ShadowKernel>(state, "kernels/intersect_shadow.cl", fixture().shadow_rays);
}

void Occluded_Embree1(benchmark::State& state) {
  IntersectFixture& f = fixture();
  const testing::Rays& rays = f.shadow_rays;
  std::vector<int> occluded(rays.o.size());
  for (auto _ : state) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.o.size(), 4096), [&](const auto& r) {
      for (size_t i = r.begin(); i < r.end(); ++i)
        occluded[i] = f.embree.occluded(xyz_of(rays.o[i]), xyz_of(rays.d[i]), 0.0f, rays.o[i].w);
    });
    benchmark::DoNotOptimize(occluded.data());
  }
  set_rate(state, int64_t(state.iterations()) * kRayCount);
}

} // namespace

BENCHMARK(Intersect_OpenCL)
    ->Arg(64)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime()
    ->MinTime(2.0);
BENCHMARK(Intersect_Embree1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime()
    ->MinTime(2.0);
BENCHMARK(Intersect_Embree8)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime()
    ->MinTime(2.0);
BENCHMARK(Occluded_OpenCL)
    ->Arg(64)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime()
    ->MinTime(2.0);
BENCHMARK(Occluded_Embree1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime()
    ->MinTime(2.0);
