// The wavefront renderer: uploads a scene to an OpenCL device and runs
//   generate -> [intersect_closest -> shade_surface -> intersect_shadow] x depth -> accumulate
// over waves of paths (DESIGN.md §1). Each stage is one kernel over a queue; only queue counts come
// back to the host.
#pragma once

#include "accel/bvh.h"
#include "cl/runtime.h"
#include "image/image_io.h"
#include "light_tree/light_tree.h"
#include "render/device_scene.h"
#include "render/features.h"
#include "render/light_sampler_data.h"
#include "row_bands.h"
#include "scene/scene.h"

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace canopy {

struct StageStats {
  double seconds = 0.0; // summed kernel time from profiling events
  uint64_t items = 0;   // work items processed
  uint64_t launches = 0;
};

struct RenderStats {
  double build_seconds = 0.0; // primitives + BVH + light tree
  double light_tree_seconds = 0.0;
  double upload_seconds = 0.0;  // buffers to the device
  double compile_seconds = 0.0; // OpenCL program build
  double render_seconds = 0.0;  // wall time of render()
  uint64_t samples = 0;
  uint64_t shading_points = 0; // surface hits shaded
  // brdf-mis, brdf-oriented: glossy shading points, and the sums over them of the BRDF-oriented
  // cut size and of the BRDF-aware sample count N (Liu et al. 2019, Table 1)
  uint64_t glossy_points = 0, brdf_cut_sum = 0, brdf_samples_sum = 0;
  uint64_t brdf_rays = 0; // rays of the BRDF-aware samples (shadow rays and BSDF probes)
  uint64_t shadow_rays = 0;
  // With a medium: ray segments that got light samples, and their shadow rays (also counted in
  // shadow_rays; the rest are those of surface points)
  uint64_t medium_segments = 0, medium_shadow_rays = 0;
  std::vector<uint64_t> cut_size_histogram; // shading points by number of cut members
  std::string kernel_options;               // the -D options the kernels were compiled with
  // The program was loaded from the program cache (host/cl/program_cache.h), not compiled.
  bool program_from_cache = false;
  uint64_t nonfinite_samples = 0; // samples that were not finite and were recorded as zero
  // Pixels whose resolved value (film mean) lies beyond the float32 range of the output image:
  // Film::mean() writes them as +-FLT_MAX, never as Inf.
  uint64_t overflowed_pixels = 0;
  // The device renders with every light's emission times 2^-emission_exponent (so the largest is
  // in [1, 2)); the film is multiplied by 2^emission_exponent in double when read back.
  int emission_exponent = 0;
  std::map<std::string, StageStats> stages;
};

// The film's double-precision sums (the device's double4/double2 layout).
struct alignas(32) double4 {
  double x, y, z, w;
};
struct alignas(16) double2 {
  double x, y;
};
static_assert(sizeof(double4) == 32 && sizeof(double2) == 16);
static_assert(sizeof(Material) == 128 && sizeof(Light) == 96 && sizeof(Primitive) == 64 &&
              sizeof(Texture) == 64 && sizeof(float2) == 8 && sizeof(Medium) == 64);

// A window [x0, x1) x [y0, y1) of the film's pixels; empty: the whole film.
struct PixelWindow {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  int width() const { return x1 - x0; }
  int height() const { return y1 - y0; }
};

// Per-pixel running sums in double, in the scene's emission units (the device's emission scale
// already undone): sum.xyz = radiance sum, sum.w = sample count, sumsq = second moment. The
// pixels of the rendered window (the whole film unless cropped: RenderSettings::window).
struct Film {
  int width = 0, height = 0; // the window's
  int x0 = 0, y0 = 0;        // the window's first pixel in the film
  int film_width = 0, film_height = 0;
  std::vector<double4> sum, sumsq;
  // Per pixel, summed over samples: (shadow rays, shading points, samples whose camera ray hit an
  // emitter, 0).
  std::vector<double4> counts;
  // Per-pixel means as float32. A value beyond +-FLT_MAX is written as +-FLT_MAX, never Inf.
  RgbImage mean() const;
  // Pixels with a channel whose mean is beyond +-FLT_MAX (written clamped by mean()).
  uint64_t overflowed_pixels() const;
  // Shadow rays per shading point in each pixel, mapped through a false-colour ramp from 0 to
  // `max_rays` (0: the image's maximum) -- Conty Estevez & Kulla 2018, Fig. 18.
  RgbImage shadow_ray_heatmap(float max_rays = 0.0f) const;
  // Per pixel: 1 if any camera ray of the pixel hit an emitter directly, else 0 (an AOV from the
  // renderer, so error metrics can leave out the pixels whose noise is the emitters' own edges).
  std::vector<uint8_t> emitter_mask() const;
};

// Bands of a window's rows that a render covers (cl/row_bands.h): bands of `height` rows repeat
// every `period` bands, and the render covers those whose number mod period is in [first, first +
// count). The film's other rows get no samples. Every row by default.
struct RowBands {
  int height = 1, period = 1, first = 0, count = 1;
  bool all() const { return first == 0 && count >= period; }
  int4 packed() const { return make_int4(height, period, first, count); }
};

struct RenderSettings {
  int spp = 1;
  uint32_t seed = 1;
  // The samples rendered are the indices [first_sample, first_sample + spp) of each pixel of the
  // window (the whole film when empty). A sample's random numbers depend only on (seed, pixel,
  // sample index), so renders of disjoint ranges and windows merge into the full image
  // (`canopy merge`). first_sample + spp <= kMaxSpp.
  int first_sample = 0;
  PixelWindow window;
  RowBands bands;                     // of the window's rows
  size_t wave_size = size_t(1) << 18; // paths per wave (smaller when splitting: see render())
  std::function<void(double fraction)> progress; // optional, called after each wave
};

// The path samplers by their PATH_SAMPLER_* value (cl/sampler.h).
inline constexpr std::array<std::string_view, 2> kPathSamplerNames = {"independent", "sobol"};
inline constexpr std::string_view kDefaultPathSampler = "sobol";
// The PATH_SAMPLER_* value of a name of kPathSamplerNames; throws std::invalid_argument otherwise.
uint32_t path_sampler_id(std::string_view name);

struct RendererOptions {
  // The library's baseline for code that builds a renderer directly (the tests); the product's
  // default is the scene's (IntegratorSettings::light_sampler, "auto": render/auto_sampler.h).
  std::string light_sampler = "tree-split"; // a name of kLightSamplerNames
  float split_threshold = LT_DEFAULT_SPLIT_THRESHOLD;
  int max_cut = kDefaultMaxCut;       // cut size cap per shading point (tree-split)
  bool orientation_term = true;       // tree samplers: false = E / d^2 importance (ablation)
  bool mis = true;                    // false: no MIS (light sampling alone for non-delta bounces)
  BrdfSettings brdf;                  // brdf-mis, brdf-oriented
  bool all_features = false;          // compile every kernel feature (tests)
  size_t split_queue_items = 1 << 20; // split-queue capacity per wave
  // The camera paths' numbers (cl/sampler.h): "independent" (a PCG stream per path) or "sobol"
  // (Owen-scrambled Sobol points per purpose); a name of kPathSamplerNames. The library's
  // baseline; the CLI's default is kDefaultPathSampler.
  std::string path_sampler = "independent";
};

// The kernel sources of the wavefront, in build order.
const std::vector<std::string>& wavefront_kernel_files();

// The power of two k with max_emission * 2^-k in [1, 2), where max_emission is the largest finite
// emission component of `lights` (0 when there is none): the device renders with emissions times
// 2^-k so that emissions from the float maximum down to denormals (1e-40) give finite,
// full-precision per-sample values. Scaling by a power of two is exact.
int emission_scale_exponent(const std::vector<Light>& lights);

class Renderer {
public:
  // Builds the geometry and uploads it; compiles the kernels. `scene` lights get their `prim`
  // fields filled in. Throws ClError if the device has no double precision (the film needs it).
  Renderer(ClRuntime& rt, Scene& scene, const RendererOptions& options);

  Film render(const RenderSettings& settings);
  const RenderStats& stats() const { return stats_; }
  const SceneGeometry& geometry() const { return geometry_; }
  const RendererOptions& options() const { return options_; }
  const Scene& scene() const { return scene_; }
  // Switches to another light sampler (options.light_sampler and its settings; all_features and
  // split_queue_items as before): rebuilds its data and the kernels, keeps the geometry, textures
  // and environment maps (render/auto_sampler.h tries several this way), the device buffers that
  // render() keeps and every program built so far (a switch back to a sampler reuses its own).
  void set_light_sampler(const RendererOptions& options);
  // Zeroes what render() accumulates (time, counts, stage timings, histogram), keeping the build,
  // upload and compile figures: the auto sampler's pilot renders are not the render's.
  void reset_render_stats();
  // The paths a wave of render() holds for this sampler with RenderSettings::wave_size
  // `wave_size`, before the render's own size bounds it: fewer for a splitting sampler, whose wave
  // must fit its cuts in the split queue (RendererOptions::split_queue_items).
  size_t paths_per_wave(size_t wave_size) const;
  // Frees the device buffers that render() keeps for the next render.
  void release_buffers() { buffers_.clear(); }

private:
  void compile_kernels(); // for options_ and sampler_: sets program_, brdf_stages_, volume_stages_
  // The film's size in pixels (the scene's camera and field of view); set once, by the constructor.
  void set_film_size(int width, int height);
  // A device buffer of at least `bytes` under `name`: the one of an earlier render when it is large
  // enough, else a new one. A render's buffers (path state, queues, film) are written before they
  // are read, so they can be reused; reusing them spares a repeated render (the auto pilot,
  // `canopy converge`'s seeds) the first-touch page faults of ~100-500 MB of fresh buffers, which
  // cost 5-15% of a one-wave render on PoCL's CPU device.
  cl::Buffer scratch_buffer(const std::string& name, size_t bytes);
  // The most split-queue items a path holds in one split pass (its cut, a medium segment's cut,
  // the distant lights).
  size_t max_cut_items() const;

  ClRuntime& rt_;
  Scene& scene_;
  SceneGeometry geometry_;
  std::vector<Material> materials_;
  RendererOptions options_;
  LightSamplerData sampler_;
  RenderStats stats_;
  cl::Program program_;
  struct BuiltProgram {
    cl::Program program;
    bool from_cache = false; // RenderStats::program_from_cache
  };
  std::unordered_map<std::string, BuiltProgram> programs_; // by kernel options: compile_kernels()
  bool brdf_stages_ = false;   // brdf-mis / brdf-oriented on a scene with a glossy material
  bool volume_stages_ = false; // kernels with a medium: shade_volume and segment light picks
  DeviceScene device_;
  std::vector<Light> infinite_; // the scene's lights at infinity, as uploaded (maps resolved)
  EnvironmentData environment_;
  cl::Buffer camera_;
  int film_w_ = 0, film_h_ = 0;
  struct ScratchBuffer {
    cl::Buffer buffer;
    size_t bytes = 0;
  };
  std::unordered_map<std::string, ScratchBuffer> buffers_; // scratch_buffer()
};

} // namespace canopy
