// The wavefront renderer: uploads a scene to an OpenCL device and runs
//   generate -> [intersect_closest -> shade_surface -> intersect_shadow] x depth -> accumulate
// over waves of paths (DESIGN.md §1). Each stage is one kernel over a queue; only queue counts come
// back to the host.
#pragma once

#include "accel/bvh.h"
#include "cl/runtime.h"
#include "image/image_io.h"
#include "scene/scene.h"

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace canopy {

// Light samplers the device renderer implements.
bool device_supports_light_sampler(const std::string& name);

struct StageStats {
  double seconds = 0.0; // summed kernel time from profiling events
  uint64_t items = 0;   // work items processed
  uint64_t launches = 0;
};

struct RenderStats {
  double build_seconds = 0.0;   // primitives + BVH
  double upload_seconds = 0.0;  // buffers to the device
  double compile_seconds = 0.0; // OpenCL program build
  double render_seconds = 0.0;  // wall time of render()
  uint64_t samples = 0;
  uint64_t shadow_rays = 0;
  uint64_t nonfinite_samples = 0; // samples that were not finite and were recorded as zero
  std::map<std::string, StageStats> stages;
};

// Per-pixel running sums: sum.xyz = radiance sum, sum.w = sample count, sumsq = second moment.
struct Film {
  int width = 0, height = 0;
  std::vector<float4> sum, sumsq;
  RgbImage mean() const;
};

struct RenderSettings {
  int spp = 1;
  uint32_t seed = 1;
  size_t wave_size = size_t(1) << 18; // paths per wave
  std::function<void(double fraction)> progress; // optional, called after each wave
};

class Renderer {
public:
  // Builds the geometry and uploads it; compiles the kernels. `scene` lights get their `prim`
  // fields filled in.
  Renderer(ClRuntime& rt, Scene& scene);

  Film render(const RenderSettings& settings);
  const RenderStats& stats() const { return stats_; }
  const SceneGeometry& geometry() const { return geometry_; }

private:
  ClRuntime& rt_;
  Scene& scene_;
  SceneGeometry geometry_;
  std::vector<Material> materials_;
  RenderStats stats_;
  cl::Program program_;
  cl::Buffer nodes_, prim_index_, prims_, materials_buf_, lights_, camera_;
};

} // namespace canopy
