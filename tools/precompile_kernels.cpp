// canopy-precompile SCENE...: compiles the programs a plain `canopy render SCENE` builds (for the
// "auto" sampler, one per pilot candidate) into the program cache (host/cl/program_cache.h), so
// that the first render finds them there. The build runs it on scenes/default.json. The cache
// is only an optimisation: a failure is reported and the exit status is still 0 (the render then
// compiles on first use).
#include "cl/program_cache.h"
#include "cl/runtime.h"
#include "light_tree/light_sampler_names.h"
#include "render/auto_sampler.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include <chrono>
#include <cstdio>
#include <exception>
#include <optional>
#include <string>
#include <vector>

using namespace canopy;

namespace {

// The options `canopy render` derives from the scene (host/cli/main.cpp): those the program
// depends on are the sampler, MIS and the BRDF-oriented settings.
RendererOptions scene_options(const Scene& scene) {
  RendererOptions o;
  o.light_sampler = scene.integrator.light_sampler;
  o.split_threshold = scene.integrator.split_threshold;
  o.max_cut = scene.integrator.max_cut;
  o.mis = scene.integrator.mis;
  o.brdf.delta = scene.integrator.brdf_delta;
  o.brdf.n_max = scene.integrator.brdf_n_max;
  o.brdf.lambda = scene.integrator.brdf_lambda;
  o.brdf.adaptive = scene.integrator.brdf_adaptive;
  return o;
}

void precompile(ClRuntime& rt, const char* path) {
  const auto t0 = std::chrono::steady_clock::now();
  Scene scene = load_scene(path);
  RendererOptions base = scene_options(scene);
  std::vector<RendererOptions> variants;
  if (scene.integrator.light_sampler == kAutoLightSampler)
    for (const PilotResult& c : auto_candidates(base))
      variants.push_back(c.options);
  else
    variants.push_back(base);
  std::optional<Renderer> renderer;
  for (const RendererOptions& o : variants)
    if (!renderer)
      renderer.emplace(rt, scene, o); // compiles (or loads) the first program
    else
      renderer->set_light_sampler(o);
  const std::string dir = program_cache_dir().string();
  std::printf("canopy-precompile: %s: %zu programs %s%s (%.1f s)\n", path, variants.size(),
              dir.empty() ? "built, not cached: CANOPY_CACHE_DIR is empty" : "in ", dir.c_str(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

} // namespace

int main(int argc, char** argv) {
  try {
    ClRuntime rt;
    for (int i = 1; i < argc; ++i)
      precompile(rt, argv[i]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "canopy-precompile: warning: %s (the first render compiles instead)\n",
                 e.what());
  }
  return 0;
}
