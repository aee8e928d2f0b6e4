#include "render/renderer.h"

#include "integrator/brdf_mis.h"
#include "integrator/light_pick.h"
#include "render/camera.h"
#include "render/memory_budget.h"
#include "sampler.h"

#include <fmt/format.h>

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace canopy {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

cl::Buffer device_buffer(const cl::Context& ctx, size_t bytes) {
  return cl::Buffer(ctx, CL_MEM_READ_WRITE, std::max<size_t>(bytes, 16));
}

const std::vector<std::string> kKernelFiles = {
    "kernels/compact.cl",          "kernels/generate.cl",      "kernels/intersect_closest.cl",
    "kernels/shade_volume.cl",     "kernels/shade_surface.cl", "kernels/light_pick.cl",
    "kernels/intersect_shadow.cl", "kernels/brdf_mis.cl",      "kernels/accumulate.cl"};

constexpr int kScanBlock = 256;
constexpr int kCutBins = 65;

} // namespace

const std::vector<std::string>& wavefront_kernel_files() {
  return kKernelFiles;
}

uint32_t path_sampler_id(std::string_view name) {
  if (name == kPathSamplerNames[PATH_SAMPLER_INDEPENDENT]) return PATH_SAMPLER_INDEPENDENT;
  if (name == kPathSamplerNames[PATH_SAMPLER_SOBOL]) return PATH_SAMPLER_SOBOL;
  throw std::invalid_argument(fmt::format("unknown path sampler '{}' (independent or sobol)",
                                          std::string(name.substr(0, 256))));
}

int emission_scale_exponent(const std::vector<Light>& lights) {
  float m = 0.0f;
  for (const Light& l : lights)
    for (float c : {l.emission.x, l.emission.y, l.emission.z})
      if (std::isfinite(c)) m = std::max(m, std::fabs(c));
  if (!(m > 0.0f)) return 0;
  // m = f * 2^e with f in [0.5, 1): m * 2^-(e-1) is in [1, 2).
  int e = 0;
  std::frexp(m, &e);
  return e - 1;
}

namespace {

// One channel of a pixel's mean as float32. The mean of finite samples is finite in double; a
// value float cannot hold is written as the largest finite float of its sign, never Inf.
float resolve_channel(double sum, double n, bool* beyond) {
  double x = sum / n;
  if (std::fabs(x) > double(FLT_MAX)) {
    *beyond = true;
    x = std::copysign(double(FLT_MAX), x);
  }
  return float(x);
}

// A render of bands of the window's rows, its rows packed, spread over the window's `rows` rows;
// the rows it did not cover have no samples.
Film spread_rows(Film packed, const RowBands& bands, int rows) {
  const std::vector<double4> sum = std::move(packed.sum), sumsq = std::move(packed.sumsq),
                             counts = std::move(packed.counts);
  Film film = std::move(packed); // its dimensions; the sums are spread below
  film.height = rows;
  const size_t width = size_t(film.width), n = width * size_t(rows);
  film.sum.assign(n, double4{});
  film.sumsq.assign(n, double4{});
  film.counts.assign(n, double4{});
  for (size_t r = 0, from = 0; from < sum.size(); ++r, from += width) {
    const auto to = std::ptrdiff_t(size_t(covered_row(bands.packed(), uint(r))) * width);
    const auto f = std::ptrdiff_t(from), w = std::ptrdiff_t(width);
    std::copy(sum.begin() + f, sum.begin() + f + w, film.sum.begin() + to);
    std::copy(sumsq.begin() + f, sumsq.begin() + f + w, film.sumsq.begin() + to);
    std::copy(counts.begin() + f, counts.begin() + f + w, film.counts.begin() + to);
  }
  return film;
}

} // namespace

RgbImage Film::mean() const {
  RgbImage img;
  img.width = width;
  img.height = height;
  img.rgb.resize(size_t(width) * height * 3);
  bool beyond = false;
  for (size_t p = 0; p < sum.size(); ++p) {
    double n = sum[p].w > 0.0 ? sum[p].w : 1.0;
    img.rgb[3 * p] = resolve_channel(sum[p].x, n, &beyond);
    img.rgb[3 * p + 1] = resolve_channel(sum[p].y, n, &beyond);
    img.rgb[3 * p + 2] = resolve_channel(sum[p].z, n, &beyond);
  }
  return img;
}

uint64_t Film::overflowed_pixels() const {
  uint64_t over = 0;
  for (const double4& s : sum) {
    double n = s.w > 0.0 ? s.w : 1.0;
    bool beyond = false;
    resolve_channel(s.x, n, &beyond);
    resolve_channel(s.y, n, &beyond);
    resolve_channel(s.z, n, &beyond);
    over += beyond ? 1 : 0;
  }
  return over;
}

std::vector<uint8_t> Film::emitter_mask() const {
  std::vector<uint8_t> m(counts.size());
  for (size_t p = 0; p < counts.size(); ++p)
    m[p] = counts[p].z > 0.0 ? 1 : 0;
  return m;
}

RgbImage Film::shadow_ray_heatmap(float max_rays) const {
  RgbImage img;
  img.width = width;
  img.height = height;
  img.rgb.assign(size_t(width) * height * 3, 0.0f);
  std::vector<float> v(counts.size());
  for (size_t p = 0; p < counts.size(); ++p)
    v[p] = counts[p].y > 0 ? float(counts[p].x / counts[p].y) : 0.0f;
  if (max_rays <= 0.0f) max_rays = std::max(1.0f, *std::max_element(v.begin(), v.end()));
  // A perceptually ordered ramp: black -> blue -> magenta -> orange -> yellow -> white.
  const float3 ramp[] = {{0, 0, 0},          {0.1f, 0.1f, 0.6f}, {0.7f, 0.1f, 0.6f},
                         {1.0f, 0.5f, 0.1f}, {1.0f, 0.9f, 0.2f}, {1, 1, 1}};
  for (size_t p = 0; p < v.size(); ++p) {
    float x = std::clamp(v[p] / max_rays, 0.0f, 1.0f) * 5.0f;
    int k = std::min(4, int(x));
    float3 c = mix(ramp[k], ramp[k + 1], x - float(k));
    img.rgb[3 * p] = c.x, img.rgb[3 * p + 1] = c.y, img.rgb[3 * p + 2] = c.z;
  }
  return img;
}

Renderer::Renderer(ClRuntime& rt, Scene& scene, const RendererOptions& options)
    : rt_(rt), scene_(scene), options_(options) {
  // The film is accumulated in double (cl/kernels/accumulate.cl).
  if (rt.device().getInfo<CL_DEVICE_DOUBLE_FP_CONFIG>() == 0)
    throw ClError(fmt::format("device {} has no double precision (cl_khr_fp64), which the film "
                              "accumulation needs; choose another device with --device",
                              rt.device_name()));
  path_sampler_id(options.path_sampler); // a known name
  auto t0 = Clock::now();
  for (const MaterialDesc& m : scene.materials)
    materials_.push_back(m.gpu);
  geometry_ = build_scene_geometry(scene, materials_);
  sampler_ = make_light_sampler_data(scene.lights, options.light_sampler, options.split_threshold,
                                     options.max_cut, options.orientation_term, options.brdf);
  stats_.light_tree_seconds = sampler_.tree_build_seconds;
  stats_.build_seconds = seconds_since(t0);

  t0 = Clock::now();
  const cl::Context& ctx = rt.context();
  // Environment maps are read here (not by the scene loader): the texels go to the device only.
  infinite_ = scene.infinite_lights;
  environment_ = build_environment_data(infinite_, scene.environment_maps);
  // The exponent of the brightest emission of either list (0 for an empty list: not a candidate);
  // a map's radiance is its scale times its brightest texel.
  std::vector<Light> brightest = infinite_;
  for (Light& l : brightest) {
    if (l.type != LIGHT_ENVIRONMENT || l.flags == ENV_CONSTANT) continue;
    float m = 0.0f;
    for (uint32_t k = 0, first = float_as_uint_(l.p.x),
                  n = float_as_uint_(l.p.y) * float_as_uint_(l.p.z);
         k < n; ++k)
      m = std::max(m, max3(xyz_of(environment_.texels[first + k])));
    l.emission = l.emission * m;
  }
  stats_.emission_exponent =
      brightest.empty() ? emission_scale_exponent(scene.lights)
      : scene.lights.empty()
          ? emission_scale_exponent(brightest)
          : std::max(emission_scale_exponent(scene.lights), emission_scale_exponent(brightest));
  // Texture images likewise.
  TextureData textures = build_texture_data(scene.textures);
  device_ = upload_device_scene(ctx, geometry_, materials_, scene.lights, sampler_,
                                stats_.emission_exponent, scene.medium, infinite_, environment_,
                                textures);
  set_film_size(scene.film.width, scene.film.height);
  stats_.upload_seconds = seconds_since(t0);
  compile_kernels();
  stats_.cut_size_histogram.assign(kCutBins, 0);
}

void Renderer::compile_kernels() {
  auto t0 = Clock::now();
  KernelFeatures features = options_.all_features ? KernelFeatures::all(sampler_.kind)
                                                  : scene_features(scene_, sampler_.kind);
  features.volume_midpoint = scene_.has_medium && scene_.integrator.volume_importance == "midpoint";
  features.mis = options_.mis;
  brdf_stages_ =
      sampler_.brdf_oriented() &&
      (features.material_conductor || features.material_plastic || features.material_coated);
  // Kernels with the medium feature run shade_volume (on a scene without a medium, its record is
  // vacuum: every path passes unchanged, so forcing the feature on changes no image).
  volume_stages_ = features.medium;
  stats_.kernel_options = features.build_options();
  // A sampler switched back to (render_auto) finds its program built: PoCL then also keeps its
  // kernels' work-group functions loaded.
  auto built = programs_.find(stats_.kernel_options);
  if (built == programs_.end()) {
    BuiltProgram p;
    p.program = rt_.build_program(kKernelFiles, stats_.kernel_options, &p.from_cache);
    built = programs_.emplace(stats_.kernel_options, std::move(p)).first;
  }
  program_ = built->second.program;
  stats_.program_from_cache = built->second.from_cache;
  stats_.compile_seconds = seconds_since(t0);
}

size_t Renderer::max_cut_items() const {
  // A cut never holds more items in a pass than its budget, nor more than max_cut (every light, for
  // the exhaustive sampler): a shading point's cut at most max_cut and, with a medium, its
  // segment's at most the segment budget (light_sampler_segment_budget).
  const size_t segment_items =
      std::min<size_t>(sampler_.max_cut, light_sampler_segment_budget(sampler_.root_budget()));
  // A shading point's distant lights (light_pick.h) come on top of its cut.
  return size_t(sampler_.max_cut) + (volume_stages_ ? segment_items : 0u) +
         scene_.infinite_lights.size();
}

size_t Renderer::paths_per_wave(size_t wave_size) const {
  // Waves of split_queue_items / max_cut_items() paths bound the split queue.
  return std::max<size_t>(1, std::min(wave_size, options_.split_queue_items / max_cut_items()));
}

cl::Buffer Renderer::scratch_buffer(const std::string& name, size_t bytes) {
  ScratchBuffer& b = buffers_[name];
  if (b.bytes < bytes || !b.buffer()) {
    b.buffer = cl::Buffer(); // free the smaller one first
    b.buffer = device_buffer(rt_.context(), bytes);
    b.bytes = bytes;
  }
  return b.buffer;
}

void Renderer::set_film_size(int width, int height) {
  if (width < 1 || height < 1)
    throw std::invalid_argument(
        fmt::format("film size {}x{}: must be at least 1x1", width, height));
  film_w_ = width;
  film_h_ = height;
  std::vector<CameraParams> cam = {make_camera_params(scene_.camera, width, height)};
  camera_ = upload_buffer(rt_.context(), cam);
}

void Renderer::reset_render_stats() {
  RenderStats fresh;
  fresh.build_seconds = stats_.build_seconds;
  fresh.light_tree_seconds = stats_.light_tree_seconds;
  fresh.upload_seconds = stats_.upload_seconds;
  fresh.compile_seconds = stats_.compile_seconds;
  fresh.program_from_cache = stats_.program_from_cache;
  fresh.kernel_options = stats_.kernel_options;
  fresh.emission_exponent = stats_.emission_exponent;
  fresh.cut_size_histogram.assign(kCutBins, 0);
  stats_ = std::move(fresh);
}

void Renderer::set_light_sampler(const RendererOptions& options) {
  auto t0 = Clock::now();
  // The geometry, textures and the rest stay; only the sampler's data and the kernels change.
  path_sampler_id(options.path_sampler); // a known name
  options_ = options;
  // The scratch buffers stay: scratch_buffer() grows one that is too small, and a kept buffer
  // spares the next render its first-touch page faults.
  LightTree previous = std::move(sampler_.tree);
  sampler_ =
      make_light_sampler_data(scene_.lights, options.light_sampler, options.split_threshold,
                              options.max_cut, options.orientation_term, options.brdf, &previous);
  stats_.light_tree_seconds = sampler_.tree_build_seconds;
  stats_.build_seconds = seconds_since(t0);
  t0 = Clock::now();
  upload_light_sampler(rt_.context(), scene_.lights, sampler_, stats_.emission_exponent, device_,
                       infinite_, environment_);
  stats_.upload_seconds = seconds_since(t0);
  compile_kernels();
}

Film Renderer::render(const RenderSettings& settings) {
  auto t_start = Clock::now();
  cl::CommandQueue& q = rt_.queue();
  // The window of the film and the sample range rendered (generate.cl).
  const int film_w = film_w_, film_h = film_h_;
  const PixelWindow win =
      settings.window.empty() ? PixelWindow{0, 0, film_w, film_h} : settings.window;
  if (win.x0 < 0 || win.y0 < 0 || win.x1 > film_w || win.y1 > film_h)
    throw std::invalid_argument(fmt::format("render window [{}, {}) x [{}, {}) is outside the "
                                            "{}x{} film",
                                            win.x0, win.x1, win.y0, win.y1, film_w, film_h));
  if (settings.spp < 1 || settings.first_sample < 0 ||
      int64_t(settings.first_sample) + settings.spp > kMaxSpp)
    throw std::invalid_argument(
        fmt::format("render samples [{}, {}) are outside [0, {}]", settings.first_sample,
                    int64_t(settings.first_sample) + settings.spp, kMaxSpp));
  const RowBands& bands = settings.bands;
  if (bands.height < 1 || bands.period < 1 || bands.first < 0 || bands.count < 1 ||
      bands.first + bands.count > bands.period)
    throw std::invalid_argument(fmt::format("render row bands (height {}, period {}, bands [{}, "
                                            "{})) are not a subset of the period",
                                            bands.height, bands.period, bands.first,
                                            bands.first + bands.count));
  // The render's pixels: the window's rows that the bands cover, packed (generate.cl).
  const int width = win.width(), height = covered_rows(bands.packed(), win.height());
  if (height == 0)
    throw std::invalid_argument(
        fmt::format("render row bands cover none of the window's {} rows", win.height()));
  const int npix = width * height;
  const uint64_t total = uint64_t(npix) * uint64_t(settings.spp);
  const bool medium = volume_stages_;
  const size_t shadow_slots = LIGHT_PICK_SHADOW_SLOTS;
  const size_t cut_items = max_cut_items();
  const size_t W = size_t(std::min<uint64_t>(total, paths_per_wave(settings.wave_size)));
  const size_t split_cap = W * cut_items;
  const int max_depth = scene_.integrator.max_depth;
  // Fail before any work if the film or the wave does not fit (docs/limits.md).
  check_memory(rt_.device(),
               {{"film_sum", uint64_t(npix) * sizeof(double4)},
                {"film_sumsq", uint64_t(npix) * sizeof(double4)},
                {"film_counts", uint64_t(npix) * sizeof(double4)},
                {"shadow_stage", shadow_slots * uint64_t(split_cap) * sizeof(ShadowItem)},
                {"shadow_items", uint64_t(split_cap) * sizeof(ShadowItem)},
                {"child_stage", 4 * uint64_t(split_cap) * sizeof(SplitItem)},
                {"brdf_stage", uint64_t(brdf_stages_ ? W : 1) * BRDF_MAX_BATCH * sizeof(BrdfItem)}},
               {{"film (host copy)", uint64_t(npix) * 3 * sizeof(double4)},
                {"image", uint64_t(npix) * 3 * sizeof(float)}},
               printable(scene_.path.string(), 1024));

  // Every kernel argument by name (host/cl/kernel_args.h); the names are the kernels' parameter
  // names. Values that change from launch to launch (count, queue, depth, ...) are given to each
  // launch and never stored here, so a launch cannot pick up a stale one.
  KernelArgs args;
  auto buffer = [&](const char* name, size_t bytes) {
    cl::Buffer b = scratch_buffer(name, bytes);
    args.set(name, b);
    return b;
  };
  device_.set_args(args);
  args.set("cam", camera_);
  args.set("seed", cl_uint(settings.seed));
  args.set("path_sampler", cl_uint(path_sampler_id(options_.path_sampler)));
  args.set("window", make_int4(win.x0, win.y0, width, height));
  args.set("bands", bands.packed());
  args.set("first_pass", cl_uint(settings.first_sample));
  args.set("max_depth", cl_int(max_depth));
  args.set("npix", cl_int(npix));
  args.set("block", cl_int(kScanBlock));
  args.set("bins", cl_int(kCutBins));
  // Path state (struct of arrays, cl/integrator/path_state.h) and queues, sized for one wave.
#define CANOPY_PATH_BUFFER(T, name) buffer(#name, W * sizeof(T));
  PATH_STATE_BUFFERS(CANOPY_PATH_BUFFER)
#undef CANOPY_PATH_BUFFER
  cl::Buffer queue_a = buffer("ray_queue", W * sizeof(cl_int)); // generate's output
  cl::Buffer queue_b = scratch_buffer("ray_queue_out", W * sizeof(cl_int));
  cl::Buffer counts_shade = buffer("counts_shade", W * sizeof(cl_int2));
  cl::Buffer cut_size = buffer("cut_size", W * sizeof(cl_int));
  cl::Buffer split_a = scratch_buffer("split_a", split_cap * sizeof(SplitItem));
  cl::Buffer split_b = scratch_buffer("split_b", split_cap * sizeof(SplitItem));
  buffer("child_stage", 4 * split_cap * sizeof(SplitItem));
  buffer("shadow_stage", shadow_slots * split_cap * sizeof(ShadowItem));
  // A pass's shadow queue: at most one item per light in the cuts (at most split_cap of them).
  buffer("shadow_items", split_cap * sizeof(ShadowItem));
  cl::Buffer counts_pick = buffer("counts_pick", split_cap * sizeof(cl_int2));
  // BRDF-oriented sampling (brdf_mis.cl): each path's cut, one round's staged and compacted items.
  const size_t brdf_paths = brdf_stages_ ? W : 1;
  buffer("brdf_cut", brdf_paths * LT_BRDF_MAX_CUT * sizeof(float2));
  buffer("brdf_stage", brdf_paths * BRDF_MAX_BATCH * sizeof(BrdfItem));
  buffer("brdf_items", brdf_paths * BRDF_MAX_BATCH * sizeof(BrdfItem));
  cl::Buffer counts_brdf = buffer("counts_brdf", brdf_paths * sizeof(cl_int2));
  cl::Buffer brdf_counters = buffer("brdf_counters", 4 * sizeof(cl_int));
  // shade_volume / light_pick: segments with light samples and their shadow rays (per wave)
  cl::Buffer volume_counters = buffer("volume_counters", 2 * sizeof(cl_int));
  buffer("offsets", split_cap * sizeof(cl_int2));
  buffer("block_sums", (split_cap / kScanBlock + 2) * sizeof(cl_int2));
  cl::Buffer totals = buffer("totals", 2 * sizeof(cl_int));
  cl::Buffer histogram = buffer("histogram", kCutBins * sizeof(cl_int));
  cl::Buffer nonfinite = buffer("nonfinite", sizeof(cl_int));
  cl::Buffer film_sum = buffer("film_sum", size_t(npix) * sizeof(double4));
  cl::Buffer film_sumsq = buffer("film_sumsq", size_t(npix) * sizeof(double4));
  cl::Buffer film_counts = buffer("film_counts", size_t(npix) * sizeof(double4));
  buffer("path_counts", W * sizeof(cl_int4));
  q.enqueueFillBuffer(film_sum, cl_double(0), 0, size_t(npix) * sizeof(double4));
  q.enqueueFillBuffer(film_sumsq, cl_double(0), 0, size_t(npix) * sizeof(double4));
  q.enqueueFillBuffer(film_counts, cl_double(0), 0, size_t(npix) * sizeof(double4));
  // The 32-bit device counters (non-finite samples, cut-size histogram) count one wave at a time
  // (at most W * max_depth events) and are added into the 64-bit stats after each wave: a whole
  // render at 2^24 spp has more than 2^31 samples.
  auto reset_counters = [&] {
    q.enqueueFillBuffer(brdf_counters, cl_int(0), 0, 4 * sizeof(cl_int));
    q.enqueueFillBuffer(volume_counters, cl_int(0), 0, 2 * sizeof(cl_int));
    q.enqueueFillBuffer(nonfinite, cl_int(0), 0, sizeof(cl_int));
    q.enqueueFillBuffer(histogram, cl_int(0), 0, kCutBins * sizeof(cl_int));
  };
  reset_counters();
  std::vector<cl_int> hist(kCutBins);

  BoundKernel k_generate(program_, "generate", args);
  BoundKernel k_closest(program_, "intersect_closest", args);
  BoundKernel k_shade(program_, "shade_surface", args);
  BoundKernel k_scatter_shade(program_, "scatter_shade", args);
  BoundKernel k_pick(program_, "light_pick", args);
  BoundKernel k_scatter_split(program_, "scatter_split", args);
  BoundKernel k_histogram(program_, "cut_histogram", args);
  BoundKernel k_shadow(program_, "intersect_shadow", args);
  BoundKernel k_shadow_sum(program_, "accumulate_shadow", args);
  BoundKernel k_accumulate(program_, "accumulate", args);
  BoundKernel k_scan_blocks(program_, "scan_blocks", args);
  BoundKernel k_scan_sums(program_, "scan_block_sums", args);
  std::optional<BoundKernel> k_volume;
  if (medium) k_volume.emplace(program_, "shade_volume", args);
  std::optional<BoundKernel> k_brdf_cut, k_brdf_sample, k_brdf_scatter, k_brdf_trace, k_brdf_sum;
  if (brdf_stages_) {
    k_brdf_cut.emplace(program_, "brdf_cut", args);
    k_brdf_sample.emplace(program_, "brdf_sample", args);
    k_brdf_scatter.emplace(program_, "scatter_brdf", args);
    k_brdf_trace.emplace(program_, "brdf_trace", args);
    k_brdf_sum.emplace(program_, "brdf_accumulate", args);
  }

  std::vector<std::pair<const char*, cl::Event>> events;
  // Arguments are bound (and checked) even when there is no work.
  auto run = [&](const char* stage, const cl::Kernel& k, size_t n) {
    if (n == 0) return;
    events.emplace_back(stage, enqueue_1d(q, k, n));
    StageStats& s = stats_.stages[stage];
    s.items += n;
    s.launches += 1;
  };
  // Exclusive scan of the count pairs in `c` (n items); returns the two totals.
  auto scan = [&](const cl::Buffer& c, int n) {
    int blocks = (n + kScanBlock - 1) / kScanBlock;
    run("scan", k_scan_blocks.bind({{"counts", c}, {"n", n}}), size_t(blocks));
    run("scan", k_scan_sums.bind({{"nblocks", blocks}}), 1);
    cl_int t[2];
    q.enqueueReadBuffer(totals, CL_TRUE, 0, sizeof(t), t);
    return std::pair<int, int>(t[0], t[1]);
  };

  for (uint64_t base = 0; base < total; base += W) {
    const int count0 = int(std::min<uint64_t>(W, total - base));
    run("generate", k_generate.bind({{"wave_base", cl_ulong(base)}, {"count", count0}}),
        size_t(count0));

    cl::Buffer* q_in = &queue_a;
    cl::Buffer* q_out = &queue_b;
    int count = count0;
    // max_depth vertices sample lights; the rays leaving the last of them (depth == max_depth) only
    // look for emission (cl/integrator/shade_surface.h): no light picks or BRDF rounds for them.
    for (int depth = 0; depth <= max_depth && count > 0; ++depth) {
      const bool emission_only = depth == max_depth;
      run("intersect_closest", k_closest.bind({{"queue", *q_in}, {"count", count}}), size_t(count));
      if (medium)
        run("shade_volume", k_volume->bind({{"depth", depth}, {"queue", *q_in}, {"count", count}}),
            size_t(count));
      run("shade_surface", k_shade.bind({{"depth", depth}, {"queue", *q_in}, {"count", count}}),
          size_t(count));

      auto [next_count, shade_count] = scan(counts_shade, count);
      run("scatter",
          k_scatter_shade.bind({{"queue", *q_in},
                                {"count", count},
                                {"counts", counts_shade},
                                {"queue_out", *q_out},
                                {"split_out", split_a}}),
          size_t(count));
      stats_.shading_points += uint64_t(shade_count); // segments subtracted after the wave
      q.enqueueFillBuffer(cut_size, cl_int(0), 0, W * sizeof(cl_int));
      // The BRDF-oriented cuts first: tree light samples at glossy points are weighted with them.
      int brdf_rounds = 0; // enough for the bounce's largest N (brdf_mis.h)
      if (brdf_stages_ && !emission_only) {
        q.enqueueFillBuffer(brdf_counters, cl_int(0), 3 * sizeof(cl_int), sizeof(cl_int));
        run("brdf_cut", k_brdf_cut->bind({{"queue", *q_in}, {"count", count}}), size_t(count));
        cl_int max_n = 0;
        q.enqueueReadBuffer(brdf_counters, CL_TRUE, 3 * sizeof(cl_int), sizeof(cl_int), &max_n);
        brdf_rounds = brdf_rounds_for(max_n);
      }

      // Split passes: each pass consumes one level of the cut (DESIGN §4).
      cl::Buffer* s_in = &split_a;
      cl::Buffer* s_out = &split_b;
      int n = shade_count;
      while (n > 0) {
        run("light_pick", k_pick.bind({{"split_in", *s_in}, {"count", n}}), size_t(n));
        auto [n_children, n_shadow] = scan(counts_pick, n);
        run("scatter",
            k_scatter_split.bind({{"count", n}, {"counts", counts_pick}, {"split_out", *s_out}}),
            size_t(n));
        run("intersect_shadow", k_shadow.bind({{"count", n_shadow}}), size_t(n_shadow));
        run("accumulate_shadow", k_shadow_sum.bind({{"count", n_shadow}}), size_t(n_shadow));
        stats_.shadow_rays += uint64_t(n_shadow);
        std::swap(s_in, s_out);
        n = n_children;
      }
      // Rounds of BRDF-aware samples at glossy points (Alg. 1 in batches, brdf_mis.h).
      for (int round = 0; round < brdf_rounds; ++round) {
        run("brdf_sample",
            k_brdf_sample->bind({{"queue", *q_in}, {"count", count}, {"brdf_round", round}}),
            size_t(count));
        auto [n_items, unused] = scan(counts_brdf, count);
        (void)unused;
        if (n_items == 0) continue;
        run("scatter", k_brdf_scatter->bind({{"count", count}, {"counts", counts_brdf}}),
            size_t(count));
        run("brdf_trace", k_brdf_trace->bind({{"count", n_items}}), size_t(n_items));
        run("brdf_accumulate", k_brdf_sum->bind({{"count", n_items}}), size_t(n_items));
        stats_.brdf_rays += uint64_t(n_items);
      }
      if (!emission_only)
        run("cut_histogram", k_histogram.bind({{"queue", *q_in}, {"count", count}}), size_t(count));

      std::swap(q_in, q_out);
      count = next_count;
    }

    run("accumulate", k_accumulate.bind({{"wave_base", cl_ulong(base)}, {"wave_size", count0}}),
        size_t(std::min(count0, npix)));
    q.finish();
    for (auto& [stage, ev] : events)
      stats_.stages[stage].seconds += event_seconds(ev);
    events.clear();
    cl_int nf = 0;
    q.enqueueReadBuffer(nonfinite, CL_FALSE, 0, sizeof(nf), &nf);
    q.enqueueReadBuffer(histogram, CL_TRUE, 0, kCutBins * sizeof(cl_int), hist.data());
    stats_.nonfinite_samples += uint64_t(uint32_t(nf));
    if (medium) {
      cl_int vc[2];
      q.enqueueReadBuffer(volume_counters, CL_TRUE, 0, sizeof(vc), vc);
      stats_.medium_segments += uint64_t(uint32_t(vc[0]));
      stats_.medium_shadow_rays += uint64_t(uint32_t(vc[1]));
      stats_.shading_points -= uint64_t(uint32_t(vc[0]));
    }
    if (brdf_stages_) {
      cl_int bc[3]; // the wave's totals (brdf_counters[3] is per bounce)
      q.enqueueReadBuffer(brdf_counters, CL_TRUE, 0, sizeof(bc), bc);
      stats_.glossy_points += uint64_t(uint32_t(bc[0]));
      stats_.brdf_cut_sum += uint64_t(uint32_t(bc[1]));
      stats_.brdf_samples_sum += uint64_t(uint32_t(bc[2]));
    }
    for (int k = 0; k < kCutBins; ++k)
      stats_.cut_size_histogram[size_t(k)] += uint64_t(uint32_t(hist[size_t(k)]));
    reset_counters();
    stats_.samples += uint64_t(count0);
    if (settings.progress) settings.progress(double(base + uint64_t(count0)) / double(total));
  }

  Film film;
  film.width = width;
  film.height = height;
  film.x0 = win.x0;
  film.y0 = win.y0;
  film.film_width = film_w;
  film.film_height = film_h;
  film.sum.resize(size_t(npix));
  film.sumsq.resize(size_t(npix));
  film.counts.resize(size_t(npix));
  q.enqueueReadBuffer(film_counts, CL_TRUE, 0, size_t(npix) * sizeof(double4), film.counts.data());
  q.enqueueReadBuffer(film_sum, CL_TRUE, 0, size_t(npix) * sizeof(double4), film.sum.data());
  q.enqueueReadBuffer(film_sumsq, CL_TRUE, 0, size_t(npix) * sizeof(double4), film.sumsq.data());
  // Undo the device's emission scale 2^-k: exact in double (a power of two; the sums of float
  // samples times 2^k, |k| <= 149 + 128, stay far inside double's range).
  const double scale = std::ldexp(1.0, stats_.emission_exponent), scale2 = scale * scale;
  for (size_t p = 0; p < size_t(npix); ++p) {
    double4& s = film.sum[p];
    double4& q2 = film.sumsq[p];
    s.x *= scale, s.y *= scale, s.z *= scale;
    q2.x *= scale2, q2.y *= scale2, q2.z *= scale2;
  }
  if (!bands.all()) film = spread_rows(std::move(film), bands, win.height());
  stats_.overflowed_pixels += film.overflowed_pixels();
  stats_.render_seconds += seconds_since(t_start);
  return film;
}

} // namespace canopy
