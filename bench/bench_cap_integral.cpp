// cap_lobe_integral (cl/bsdf/cap_integral.h) on the host, one thread: the cost of one BRDF cap
// integral, evaluated ~4 times per light-tree node a BRDF-aware traversal visits.
//   CapIntegral/<material>   material 0 diffuse, 1 conductor (gold, roughness 0.3), 2 plastic
//                            (roughness 0.3); counter ns_per_call (CPU time) over 4096
//                            precomputed random caps reaching above the horizon (sizes log-uniform
//                            in 1e-4..pi, centres uniform on the sphere), wo at 30 degrees
//   CapLobeMake/<material>   the per-shading-point set-up; counter ns_per_call (CPU time)
#include "bsdf/cap_integral.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

namespace {

Material bench_material(int kind) {
  Material m{};
  m.alpha = 0.09f;
  if (kind == 0) {
    m.albedo = make_float4(0.8f, 0.5f, 0.2f, 0);
    m.type = MATERIAL_DIFFUSE;
  } else if (kind == 1) {
    m.specular = make_float4(0.18f, 0.42f, 1.37f, 0);
    m.k = make_float4(3.42f, 2.35f, 1.77f, 0);
    m.type = MATERIAL_CONDUCTOR;
  } else {
    m.albedo = make_float4(0.5f, 0.3f, 0.1f, 0);
    m.specular = make_float4(1, 1, 1, 0);
    m.ior = 1.5f;
    m.type = MATERIAL_PLASTIC;
  }
  return m;
}

struct Cap {
  float3 c;
  float s, co;
};

std::vector<Cap> random_caps(int n) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Cap> caps;
  for (int i = 0; i < n; ++i) {
    float z = 2 * u(rng) - 1, phi = 6.2831853f * u(rng), sz = std::sqrt(1 - z * z);
    float r = std::exp(std::log(1e-4f) + (std::log(3.14159f) - std::log(1e-4f)) * u(rng));
    if (!(z > -std::sin(r) || r > 1.5708f)) { // below the horizon: an early exit, not timed
      --i;
      continue;
    }
    caps.push_back(
        {make_float3(sz * std::cos(phi), sz * std::sin(phi), z), std::sin(r), std::cos(r)});
  }
  return caps;
}

void BM_CapIntegral(benchmark::State& state) {
  Material m = bench_material(int(state.range(0)));
  Frame fr = frame_from(make_float3(0, 0, 1));
  CapLobe l = cap_lobe_make(&m, &fr, make_float3(0.5f, 0.0f, 0.8660254f));
  std::vector<Cap> caps = random_caps(4096);
  float sum = 0;
  for (auto _ : state) {
    for (const Cap& c : caps) {
      float mean;
      sum += cap_lobe_integral(&l, c.c, c.s, c.co, &mean) + mean;
    }
  }
  benchmark::DoNotOptimize(sum);
  // A rate of (calls x 1e-9) per second, inverted: nanoseconds (CPU time) per call.
  state.counters["ns_per_call"] =
      benchmark::Counter(double(state.iterations()) * double(caps.size()) * 1e-9,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CapIntegral)->Name("CapIntegral")->Arg(0)->Arg(1)->Arg(2);

void BM_CapLobeMake(benchmark::State& state) {
  Material m = bench_material(int(state.range(0)));
  Frame fr = frame_from(make_float3(0, 0, 1));
  std::vector<Cap> dirs = random_caps(1024);
  float sum = 0;
  for (auto _ : state) {
    for (const Cap& d : dirs) {
      float3 wo = make_float3(d.c.x, d.c.y, std::fabs(d.c.z));
      CapLobe l = cap_lobe_make(&m, &fr, wo);
      sum += l.amp + l.n.w;
    }
  }
  benchmark::DoNotOptimize(sum);
  // A rate of (calls x 1e-9) per second, inverted: nanoseconds (CPU time) per call.
  state.counters["ns_per_call"] =
      benchmark::Counter(double(state.iterations()) * double(dirs.size()) * 1e-9,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CapLobeMake)->Name("CapLobeMake")->Arg(0)->Arg(1)->Arg(2);

} // namespace
