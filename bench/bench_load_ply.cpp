// pbrt scene loading with PLY meshes (issue 22, part 5). Families:
//   LoadPly/<T>          load_scene() of a pbrt-v4 file whose one Shape "plymesh" is a binary
//                        little-endian PLY of T triangles (a grid of (x, y, z) floats with
//                        per-vertex normals): the PLY check, Assimp's import, the transform and
//                        the scene's triangle soup. Target: 10^6 triangles in <= 2 s.
//   EmissivePlyTree/<T>  the same mesh under AreaLightSource "diffuse": load_scene() (every
//                        triangle an emitter) plus the light tree over them
//                        (make_light_sampler_data, "tree"). Target: 10^5 triangles in <= 1 s.
// Counters: triangles, file_MB, seconds (wall, one iteration). Files are written to a temporary
// directory the first time a size runs and removed at exit.
#include "render/light_sampler_data.h"
#include "scene/scene.h"

#include "temp_dir.h"

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

using namespace canopy;

namespace {

namespace fs = std::filesystem;

// A wavy grid of about `triangles` triangles (2 per cell) as a binary little-endian PLY, and a
// pbrt file that loads it (emissive or not).
fs::path scene_file(int triangles, bool emissive) {
  static bench::TempDir tmp("ply");
  static std::map<std::pair<int, bool>, fs::path> files;
  auto key = std::make_pair(triangles, emissive);
  if (auto it = files.find(key); it != files.end()) return it->second;
  const int n = int(std::ceil(std::sqrt(triangles / 2.0))); // cells per side
  const fs::path ply = tmp.dir / fmt::format("grid-{}.ply", triangles);
  if (!fs::exists(ply)) {
    std::FILE* f = std::fopen(ply.c_str(), "wb");
    if (!f) throw std::runtime_error("cannot write " + ply.string());
    const int nv = (n + 1) * (n + 1), nf = 2 * n * n;
    fmt::print(f,
               "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\n"
               "property float y\nproperty float z\nproperty float nx\nproperty float ny\n"
               "property float nz\nelement face {}\nproperty list uchar int vertex_indices\n"
               "end_header\n",
               nv, nf);
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        float x = float(i) / float(n), y = float(j) / float(n);
        float v[6] = {x, y, 0.02f * std::sin(20.0f * x) * std::cos(17.0f * y), 0.0f, 0.0f, 1.0f};
        std::fwrite(v, sizeof(float), 6, f);
      }
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
        for (int t : {0, 1}) {
          unsigned char three = 3;
          int idx[3] = {a, t == 0 ? b : d, t == 0 ? d : c};
          std::fwrite(&three, 1, 1, f);
          std::fwrite(idx, sizeof(int), 3, f);
        }
      }
    std::fclose(f);
  }
  const fs::path pbrt = tmp.dir / fmt::format("grid-{}-{}.pbrt", triangles, int(emissive));
  std::FILE* f = std::fopen(pbrt.c_str(), "w");
  if (!f) throw std::runtime_error("cannot write " + pbrt.string());
  fmt::print(f,
             "LookAt 0.5 0.5 2  0.5 0.5 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n{}"
             "Shape \"plymesh\" \"string filename\" \"{}\"\n",
             emissive ? "AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n" : "",
             ply.filename().string());
  std::fclose(f);
  return files.emplace(key, pbrt).first->second;
}

void BM_LoadPly(benchmark::State& state) {
  const int t = int(state.range(0));
  const fs::path file = scene_file(t, false);
  size_t tris = 0;
  double seconds = 0.0;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    Scene s = load_scene(file);
    tris = s.triangle_count();
    benchmark::DoNotOptimize(s.vertices.data());
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  state.counters["triangles"] = double(tris);
  state.counters["file_MB"] =
      double(fs::file_size(file.parent_path() / fmt::format("grid-{}.ply", t))) / 1e6;
  state.counters["seconds"] = seconds / double(state.iterations());
}

void BM_EmissivePlyTree(benchmark::State& state) {
  const int t = int(state.range(0));
  const fs::path file = scene_file(t, true);
  size_t lights = 0;
  double seconds = 0.0;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    Scene s = load_scene(file);
    LightSamplerData d = make_light_sampler_data(s.lights, "tree", 0.0f, 1, true, BrdfSettings{});
    lights = s.lights.size();
    benchmark::DoNotOptimize(d.tree.nodes.data());
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  state.counters["emitters"] = double(lights);
  state.counters["seconds"] = seconds / double(state.iterations());
}

} // namespace

BENCHMARK(BM_LoadPly)
    ->Name("LoadPly")
    ->Arg(100'000)
    ->Arg(1'000'000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);
BENCHMARK(BM_EmissivePlyTree)
    ->Name("EmissivePlyTree")
    ->Arg(100'000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);
