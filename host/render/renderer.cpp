#include "render/renderer.h"

#include "render/camera.h"
#include "render/memory_budget.h"

#include <fmt/format.h>

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>
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
    "kernels/compact.cl",       "kernels/generate.cl",   "kernels/intersect_closest.cl",
    "kernels/shade_surface.cl", "kernels/light_pick.cl", "kernels/intersect_shadow.cl",
    "kernels/accumulate.cl"};

constexpr int kScanBlock = 256;
constexpr int kCutBins = 65;

} // namespace

const std::vector<std::string>& wavefront_kernel_files() {
  return kKernelFiles;
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
  auto t0 = Clock::now();
  for (const MaterialDesc& m : scene.materials)
    materials_.push_back(m.gpu);
  geometry_ = build_scene_geometry(scene, materials_);
  sampler_ = make_light_sampler_data(scene.lights, options.light_sampler, options.split_threshold,
                                     options.max_cut, options.orientation_term);
  stats_.light_tree_seconds = sampler_.tree_build_seconds;
  stats_.build_seconds = seconds_since(t0);

  t0 = Clock::now();
  const cl::Context& ctx = rt.context();
  stats_.emission_exponent = emission_scale_exponent(scene.lights);
  device_ = upload_device_scene(ctx, geometry_, materials_, scene.lights, sampler_,
                                stats_.emission_exponent);
  std::vector<CameraParams> cam = {
      make_camera_params(scene.camera, scene.film.width, scene.film.height)};
  camera_ = upload_buffer(ctx, cam);
  stats_.upload_seconds = seconds_since(t0);

  t0 = Clock::now();
  KernelFeatures features = options.all_features ? KernelFeatures::all(sampler_.kind)
                                                 : scene_features(scene, sampler_.kind);
  features.mis = options.mis;
  stats_.kernel_options = features.build_options();
  program_ = rt.build_program(kKernelFiles, stats_.kernel_options);
  stats_.compile_seconds = seconds_since(t0);
  stats_.cut_size_histogram.assign(kCutBins, 0);
}

Film Renderer::render(const RenderSettings& settings) {
  auto t_start = Clock::now();
  const cl::Context& ctx = rt_.context();
  cl::CommandQueue& q = rt_.queue();
  const int width = scene_.film.width, height = scene_.film.height;
  const int npix = width * height;
  const uint64_t total = uint64_t(npix) * uint64_t(settings.spp);
  // Every path's cut has at most max_cut items in any pass, so waves of
  // split_queue_items / max_cut paths bound the split queue.
  size_t wave = std::max<size_t>(
      1, std::min(settings.wave_size, options_.split_queue_items / sampler_.max_cut));
  const size_t W = size_t(std::min<uint64_t>(total, wave));
  const size_t split_cap = W * sampler_.max_cut;
  const int max_depth = scene_.integrator.max_depth;
  // Fail before any work if the film or the wave does not fit (docs/limits.md).
  check_memory(rt_.device(),
               {{"film_sum", uint64_t(npix) * sizeof(double4)},
                {"film_sumsq", uint64_t(npix) * sizeof(double4)},
                {"film_counts", uint64_t(npix) * sizeof(double2)},
                {"shadow_stage", 4 * uint64_t(split_cap) * sizeof(ShadowItem)},
                {"child_stage", 4 * uint64_t(split_cap) * sizeof(SplitItem)}},
               {{"film (host copy)", uint64_t(npix) * (2 * sizeof(double4) + sizeof(double2))},
                {"image", uint64_t(npix) * 3 * sizeof(float)}},
               printable(scene_.path.string(), 1024));

  // Path state (struct of arrays) and queues, sized for one wave.
  cl::Buffer ray_o = device_buffer(ctx, W * sizeof(float4));
  cl::Buffer ray_d = device_buffer(ctx, W * sizeof(float4));
  cl::Buffer throughput = device_buffer(ctx, W * sizeof(float4));
  cl::Buffer radiance = device_buffer(ctx, W * sizeof(float4));
  cl::Buffer rng = device_buffer(ctx, W * sizeof(cl_uint));
  cl::Buffer hits = device_buffer(ctx, W * sizeof(Hit));
  cl::Buffer shade_P = device_buffer(ctx, W * sizeof(float4));
  cl::Buffer shade_N = device_buffer(ctx, W * sizeof(float4));
  cl::Buffer shade_f = device_buffer(ctx, W * sizeof(float4));
  cl::Buffer shade_wo = device_buffer(ctx, W * sizeof(float4));
  cl::Buffer shade_Ns = device_buffer(ctx, W * sizeof(float4));
  cl::Buffer queue_a = device_buffer(ctx, W * sizeof(cl_int));
  cl::Buffer queue_b = device_buffer(ctx, W * sizeof(cl_int));
  cl::Buffer counts_shade = device_buffer(ctx, W * sizeof(cl_int2));
  cl::Buffer cut_size = device_buffer(ctx, W * sizeof(cl_int));
  cl::Buffer split_a = device_buffer(ctx, split_cap * sizeof(SplitItem));
  cl::Buffer split_b = device_buffer(ctx, split_cap * sizeof(SplitItem));
  cl::Buffer child_stage = device_buffer(ctx, 4 * split_cap * sizeof(SplitItem));
  cl::Buffer shadow_stage = device_buffer(ctx, 4 * split_cap * sizeof(ShadowItem));
  cl::Buffer shadow = device_buffer(ctx, split_cap * sizeof(ShadowItem));
  cl::Buffer counts = device_buffer(ctx, split_cap * sizeof(cl_int2));
  cl::Buffer offsets = device_buffer(ctx, split_cap * sizeof(cl_int2));
  cl::Buffer block_sums = device_buffer(ctx, (split_cap / kScanBlock + 2) * sizeof(cl_int2));
  cl::Buffer totals = device_buffer(ctx, 2 * sizeof(cl_int));
  cl::Buffer histogram = device_buffer(ctx, kCutBins * sizeof(cl_int));
  cl::Buffer nonfinite = device_buffer(ctx, sizeof(cl_int));
  cl::Buffer film_sum = device_buffer(ctx, size_t(npix) * sizeof(double4));
  cl::Buffer film_sumsq = device_buffer(ctx, size_t(npix) * sizeof(double4));
  cl::Buffer film_counts = device_buffer(ctx, size_t(npix) * sizeof(double2));
  cl::Buffer path_counts = device_buffer(ctx, W * sizeof(cl_int2));
  q.enqueueFillBuffer(film_sum, cl_double(0), 0, size_t(npix) * sizeof(double4));
  q.enqueueFillBuffer(film_sumsq, cl_double(0), 0, size_t(npix) * sizeof(double4));
  q.enqueueFillBuffer(film_counts, cl_double(0), 0, size_t(npix) * sizeof(double2));
  // The 32-bit device counters (non-finite samples, cut-size histogram) count one wave at a time
  // (at most W * max_depth events) and are added into the 64-bit stats after each wave: a whole
  // render at 2^24 spp has more than 2^31 samples.
  auto reset_counters = [&] {
    q.enqueueFillBuffer(nonfinite, cl_int(0), 0, sizeof(cl_int));
    q.enqueueFillBuffer(histogram, cl_int(0), 0, kCutBins * sizeof(cl_int));
  };
  reset_counters();
  std::vector<cl_int> hist(kCutBins);

  cl::Kernel k_generate(program_, "generate");
  cl::Kernel k_closest(program_, "intersect_closest");
  cl::Kernel k_shade(program_, "shade_surface");
  cl::Kernel k_scatter_shade(program_, "scatter_shade");
  cl::Kernel k_pick(program_, "light_pick");
  cl::Kernel k_scatter_split(program_, "scatter_split");
  cl::Kernel k_histogram(program_, "cut_histogram");
  cl::Kernel k_shadow(program_, "intersect_shadow");
  cl::Kernel k_shadow_sum(program_, "accumulate_shadow");
  cl::Kernel k_accumulate(program_, "accumulate");
  cl::Kernel k_scan_blocks(program_, "scan_blocks");
  cl::Kernel k_scan_sums(program_, "scan_block_sums");

  std::vector<std::pair<const char*, cl::Event>> events;
  auto run = [&](const char* stage, cl::Kernel& k, size_t n) {
    if (n == 0) return;
    events.emplace_back(stage, enqueue_1d(q, k, n));
    StageStats& s = stats_.stages[stage];
    s.items += n;
    s.launches += 1;
  };
  auto path_args = [&](cl::Kernel& k, int i) {
    for (cl::Buffer* b : {&ray_o, &ray_d, &throughput, &radiance, &rng, &hits, &shade_P, &shade_N,
                          &shade_f, &shade_wo, &shade_Ns})
      k.setArg(i++, *b);
    return i;
  };
  // Exclusive scan of the count pairs in `c` (n items); returns the two totals.
  auto scan = [&](const cl::Buffer& c, int n) {
    int blocks = (n + kScanBlock - 1) / kScanBlock;
    k_scan_blocks.setArg(0, c);
    k_scan_blocks.setArg(1, cl_int(n));
    k_scan_blocks.setArg(2, cl_int(kScanBlock));
    k_scan_blocks.setArg(3, offsets);
    k_scan_blocks.setArg(4, block_sums);
    run("scan", k_scan_blocks, size_t(blocks));
    k_scan_sums.setArg(0, block_sums);
    k_scan_sums.setArg(1, cl_int(blocks));
    k_scan_sums.setArg(2, totals);
    run("scan", k_scan_sums, 1);
    cl_int t[2];
    q.enqueueReadBuffer(totals, CL_TRUE, 0, sizeof(t), t);
    return std::pair<int, int>(t[0], t[1]);
  };
  auto scan_args = [&](cl::Kernel& k, int i, const cl::Buffer& c) {
    k.setArg(i++, c);
    k.setArg(i++, offsets);
    k.setArg(i++, block_sums);
    k.setArg(i++, cl_int(kScanBlock));
    return i;
  };

  for (uint64_t base = 0; base < total; base += W) {
    const int count0 = int(std::min<uint64_t>(W, total - base));
    int a = 0;
    k_generate.setArg(a++, camera_);
    k_generate.setArg(a++, cl_uint(settings.seed));
    k_generate.setArg(a++, cl_ulong(base));
    k_generate.setArg(a++, cl_int(count0));
    k_generate.setArg(a++, ray_o);
    k_generate.setArg(a++, ray_d);
    k_generate.setArg(a++, throughput);
    k_generate.setArg(a++, radiance);
    k_generate.setArg(a++, rng);
    k_generate.setArg(a++, queue_a);
    k_generate.setArg(a++, path_counts);
    run("generate", k_generate, size_t(count0));

    cl::Buffer* q_in = &queue_a;
    cl::Buffer* q_out = &queue_b;
    int count = count0;
    for (int depth = 0; depth < max_depth && count > 0; ++depth) {
      a = 0;
      a = device_.set_bvh_args(k_closest, a);
      k_closest.setArg(a++, *q_in);
      k_closest.setArg(a++, cl_int(count));
      k_closest.setArg(a++, ray_o);
      k_closest.setArg(a++, ray_d);
      k_closest.setArg(a++, hits);
      run("intersect_closest", k_closest, size_t(count));

      a = 0;
      k_shade.setArg(a++, cl_int(depth));
      k_shade.setArg(a++, cl_int(max_depth));
      k_shade.setArg(a++, *q_in);
      k_shade.setArg(a++, cl_int(count));
      a = path_args(k_shade, a);
      a = device_.set_scene_args(k_shade, a);
      a = device_.set_light_sampler_args(k_shade, a);
      k_shade.setArg(a++, counts_shade);
      run("shade_surface", k_shade, size_t(count));

      auto [next_count, shade_count] = scan(counts_shade, count);
      a = 0;
      k_scatter_shade.setArg(a++, *q_in);
      k_scatter_shade.setArg(a++, cl_int(count));
      a = scan_args(k_scatter_shade, a, counts_shade);
      k_scatter_shade.setArg(a++, *q_out);
      k_scatter_shade.setArg(a++, split_a);
      k_scatter_shade.setArg(a++, sampler_.tree.root_sphere);
      k_scatter_shade.setArg(a++, cl_float(sampler_.tree.root_info.x));
      k_scatter_shade.setArg(a++, cl_uint(sampler_.root_budget()));
      k_scatter_shade.setArg(a++, path_counts);
      run("scatter", k_scatter_shade, size_t(count));
      stats_.shading_points += uint64_t(shade_count);
      q.enqueueFillBuffer(cut_size, cl_int(0), 0, W * sizeof(cl_int));

      // Split passes: each pass consumes one level of the cut (DESIGN §4).
      cl::Buffer* s_in = &split_a;
      cl::Buffer* s_out = &split_b;
      int n = shade_count;
      while (n > 0) {
        a = 0;
        k_pick.setArg(a++, *s_in);
        k_pick.setArg(a++, cl_int(n));
        a = path_args(k_pick, a);
        a = device_.set_scene_args(k_pick, a);
        a = device_.set_light_sampler_args(k_pick, a);
        k_pick.setArg(a++, child_stage);
        k_pick.setArg(a++, shadow_stage);
        k_pick.setArg(a++, counts);
        k_pick.setArg(a++, cut_size);
        run("light_pick", k_pick, size_t(n));
        auto [n_children, n_shadow] = scan(counts, n);
        a = 0;
        k_scatter_split.setArg(a++, cl_int(n));
        a = scan_args(k_scatter_split, a, counts);
        k_scatter_split.setArg(a++, child_stage);
        k_scatter_split.setArg(a++, shadow_stage);
        k_scatter_split.setArg(a++, *s_out);
        k_scatter_split.setArg(a++, shadow);
        run("scatter", k_scatter_split, size_t(n));

        a = 0;
        a = device_.set_bvh_args(k_shadow, a);
        k_shadow.setArg(a++, shadow);
        k_shadow.setArg(a++, cl_int(n_shadow));
        run("intersect_shadow", k_shadow, size_t(n_shadow));
        k_shadow_sum.setArg(0, shadow);
        k_shadow_sum.setArg(1, cl_int(n_shadow));
        k_shadow_sum.setArg(2, radiance);
        k_shadow_sum.setArg(3, path_counts);
        run("accumulate_shadow", k_shadow_sum, size_t(n_shadow));
        stats_.shadow_rays += uint64_t(n_shadow);
        std::swap(s_in, s_out);
        n = n_children;
      }
      a = 0;
      k_histogram.setArg(a++, *q_in);
      k_histogram.setArg(a++, cl_int(count));
      k_histogram.setArg(a++, counts_shade);
      k_histogram.setArg(a++, cut_size);
      k_histogram.setArg(a++, histogram);
      k_histogram.setArg(a++, cl_int(kCutBins));
      run("cut_histogram", k_histogram, size_t(count));

      std::swap(q_in, q_out);
      count = next_count;
    }

    a = 0;
    k_accumulate.setArg(a++, cl_ulong(base));
    k_accumulate.setArg(a++, cl_int(count0));
    k_accumulate.setArg(a++, cl_int(npix));
    k_accumulate.setArg(a++, radiance);
    k_accumulate.setArg(a++, film_sum);
    k_accumulate.setArg(a++, film_sumsq);
    k_accumulate.setArg(a++, nonfinite);
    k_accumulate.setArg(a++, path_counts);
    k_accumulate.setArg(a++, film_counts);
    run("accumulate", k_accumulate, size_t(std::min(count0, npix)));
    q.finish();
    for (auto& [stage, ev] : events)
      stats_.stages[stage].seconds += event_seconds(ev);
    events.clear();
    cl_int nf = 0;
    q.enqueueReadBuffer(nonfinite, CL_FALSE, 0, sizeof(nf), &nf);
    q.enqueueReadBuffer(histogram, CL_TRUE, 0, kCutBins * sizeof(cl_int), hist.data());
    stats_.nonfinite_samples += uint64_t(uint32_t(nf));
    for (int k = 0; k < kCutBins; ++k)
      stats_.cut_size_histogram[size_t(k)] += uint64_t(uint32_t(hist[size_t(k)]));
    reset_counters();
    stats_.samples += uint64_t(count0);
    if (settings.progress) settings.progress(double(base + uint64_t(count0)) / double(total));
  }

  Film film;
  film.width = width;
  film.height = height;
  film.sum.resize(size_t(npix));
  film.sumsq.resize(size_t(npix));
  film.counts.resize(size_t(npix));
  q.enqueueReadBuffer(film_counts, CL_TRUE, 0, size_t(npix) * sizeof(double2), film.counts.data());
  q.enqueueReadBuffer(film_sum, CL_TRUE, 0, size_t(npix) * sizeof(double4), film.sum.data());
  q.enqueueReadBuffer(film_sumsq, CL_TRUE, 0, size_t(npix) * sizeof(double4), film.sumsq.data());
  // Undo the device's emission scale 2^-k: exact in double (a power of two; the sums of float
  // samples times 2^k, |k| <= 149 + 128, stay far inside double's range).
  const int k = stats_.emission_exponent;
  for (size_t p = 0; p < size_t(npix); ++p) {
    double4& s = film.sum[p];
    double4& q2 = film.sumsq[p];
    s.x = std::ldexp(s.x, k), s.y = std::ldexp(s.y, k), s.z = std::ldexp(s.z, k);
    q2.x = std::ldexp(q2.x, 2 * k), q2.y = std::ldexp(q2.y, 2 * k), q2.z = std::ldexp(q2.z, 2 * k);
  }
  stats_.overflowed_pixels += film.overflowed_pixels();
  stats_.render_seconds += seconds_since(t_start);
  return film;
}

} // namespace canopy
