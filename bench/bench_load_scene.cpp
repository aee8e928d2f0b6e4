// Scene loading benchmark. Family:
//   LoadScene/<N>   load_scene() of a JSON scene with N explicit point lights (a diffuse quad and
//                   a camera, then a "lights" array of N point lights, full float precision: ~100
//                   bytes a light, like a scene exported by a tool). Counters: lights, file_MB,
//                   ns_per_light (wall time of load_scene per light, without the Scene's
//                   destruction that the Time column includes: constant when loading is linear),
//                   and peak_rss_MB (the process's peak resident set; a high-water mark,
//                   so it is meaningful for the largest N run first in a process or alone).
// The files are written to a temporary directory the first time a size is run (not at build
// time) and removed at exit.
#include "scene/scene.h"

#include "temp_dir.h"

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

using namespace canopy;

namespace {

namespace fs = std::filesystem;

// A small LCG: the bench only needs reproducible, spread-out positions.
struct Lcg {
  uint64_t s;
  double next() {
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(s >> 11) * (1.0 / 9007199254740992.0);
  }
};

const fs::path& scene_file(int n) {
  static bench::TempDir tmp("load");
  static std::map<int, fs::path> files;
  auto it = files.find(n);
  if (it != files.end()) return it->second;
  fs::path p = tmp.dir / fmt::format("plane-{}.json", n);
  std::FILE* f = std::fopen(p.c_str(), "w");
  if (!f) throw std::runtime_error("cannot write " + p.string());
  fmt::print(f, "{{\n  \"camera\": {{ \"position\": [0, -2.6, 2.2], \"look_at\": [0, 0, 0], "
                "\"up\": [0, 0, 1], \"fov\": 45 }},\n"
                "  \"film\": {{ \"width\": 256, \"height\": 256 }},\n"
                "  \"materials\": [ {{ \"name\": \"plane\", \"albedo\": 0.5 }} ],\n"
                "  \"shapes\": [ {{ \"type\": \"quad\", \"material\": \"plane\", \"corner\": "
                "[-1, -1, 0], \"edge1\": [2, 0, 0], \"edge2\": [0, 2, 0] }} ],\n"
                "  \"lights\": [\n");
  Lcg rng{uint64_t(n) * 7919u + 1u};
  double intensity = 4.0 / n;
  for (int i = 0; i < n; ++i) {
    double x = 2.0 * rng.next() - 1.0, y = 2.0 * rng.next() - 1.0, z = 0.05 + 0.45 * rng.next();
    fmt::print(f,
               "    {{ \"type\": \"point\", \"position\": [{:.9g}, {:.9g}, {:.9g}], "
               "\"intensity\": [{:.6g}, {:.6g}, {:.6g}] }}{}\n",
               float(x), float(y), float(z), intensity, intensity, intensity, i + 1 < n ? "," : "");
  }
  fmt::print(f, "  ]\n}}\n");
  std::fclose(f);
  return files.emplace(n, p).first->second;
}

double peak_rss_mb() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_maxrss) / 1024.0; // kB on Linux
}

void BM_LoadScene(benchmark::State& state) {
  const int n = int(state.range(0));
  const fs::path& file = scene_file(n);
  size_t lights = 0;
  double seconds = 0.0;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    Scene s = load_scene(file);
    lights = s.lights.size();
    benchmark::DoNotOptimize(s.lights.data());
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  if (lights != size_t(n)) state.SkipWithError("wrong number of lights loaded");
  state.counters["lights"] = double(n);
  state.counters["file_MB"] = double(fs::file_size(file)) / 1e6;
  state.counters["ns_per_light"] = seconds * 1e9 / (double(n) * double(state.iterations()));
  state.counters["peak_rss_MB"] = peak_rss_mb();
}

} // namespace

BENCHMARK(BM_LoadScene)
    ->Name("LoadScene")
    ->Arg(10'000)
    ->Arg(100'000)
    ->Arg(1'000'000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);
