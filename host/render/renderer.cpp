#include "render/renderer.h"

#include "render/camera.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace canopy {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// A read-only device copy of a host vector (never zero-sized: OpenCL forbids empty buffers).
template <class T> cl::Buffer upload(const cl::Context& ctx, const std::vector<T>& v) {
  size_t bytes = std::max<size_t>(1, v.size()) * sizeof(T);
  if (v.empty()) return cl::Buffer(ctx, CL_MEM_READ_ONLY, bytes);
  return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes, const_cast<T*>(v.data()));
}

const std::vector<std::string> kKernelFiles = {
    "kernels/generate.cl", "kernels/intersect_closest.cl", "kernels/shade_surface.cl",
    "kernels/intersect_shadow.cl", "kernels/accumulate.cl"};

} // namespace

bool device_supports_light_sampler(const std::string& name) { return name == "uniform"; }

RgbImage Film::mean() const {
  RgbImage img;
  img.width = width;
  img.height = height;
  img.rgb.resize(size_t(width) * height * 3);
  for (size_t p = 0; p < sum.size(); ++p) {
    float n = sum[p].w > 0.0f ? sum[p].w : 1.0f;
    img.rgb[3 * p] = sum[p].x / n;
    img.rgb[3 * p + 1] = sum[p].y / n;
    img.rgb[3 * p + 2] = sum[p].z / n;
  }
  return img;
}

Renderer::Renderer(ClRuntime& rt, Scene& scene) : rt_(rt), scene_(scene) {
  auto t0 = Clock::now();
  for (const MaterialDesc& m : scene.materials) materials_.push_back(m.gpu);
  geometry_ = build_scene_geometry(scene, materials_);
  stats_.build_seconds = seconds_since(t0);

  t0 = Clock::now();
  const cl::Context& ctx = rt.context();
  nodes_ = upload(ctx, geometry_.bvh.nodes);
  prim_index_ = upload(ctx, geometry_.bvh.prim_index);
  prims_ = upload(ctx, geometry_.prims);
  materials_buf_ = upload(ctx, materials_);
  lights_ = upload(ctx, scene.lights);
  std::vector<CameraParams> cam = {
      make_camera_params(scene.camera, scene.film.width, scene.film.height)};
  camera_ = upload(ctx, cam);
  stats_.upload_seconds = seconds_since(t0);

  t0 = Clock::now();
  program_ = rt.build_program(kKernelFiles);
  stats_.compile_seconds = seconds_since(t0);
}

Film Renderer::render(const RenderSettings& settings) {
  auto t_start = Clock::now();
  const cl::Context& ctx = rt_.context();
  cl::CommandQueue& q = rt_.queue();
  const int width = scene_.film.width, height = scene_.film.height;
  const int npix = width * height;
  const uint64_t total = uint64_t(npix) * uint64_t(settings.spp);
  const size_t W = size_t(std::min<uint64_t>(total, std::max<size_t>(1, settings.wave_size)));
  const int max_depth = scene_.integrator.max_depth;
  const int light_count = int(scene_.lights.size());

  // Path state (struct of arrays) and queues, sized for one wave.
  cl::Buffer ray_o(ctx, CL_MEM_READ_WRITE, W * sizeof(float4));
  cl::Buffer ray_d(ctx, CL_MEM_READ_WRITE, W * sizeof(float4));
  cl::Buffer throughput(ctx, CL_MEM_READ_WRITE, W * sizeof(float4));
  cl::Buffer radiance(ctx, CL_MEM_READ_WRITE, W * sizeof(float4));
  cl::Buffer rng(ctx, CL_MEM_READ_WRITE, W * sizeof(cl_uint));
  cl::Buffer hits(ctx, CL_MEM_READ_WRITE, W * sizeof(Hit));
  cl::Buffer queue_a(ctx, CL_MEM_READ_WRITE, W * sizeof(cl_int));
  cl::Buffer queue_b(ctx, CL_MEM_READ_WRITE, W * sizeof(cl_int));
  cl::Buffer shadow(ctx, CL_MEM_READ_WRITE, W * sizeof(ShadowItem));
  cl::Buffer counters(ctx, CL_MEM_READ_WRITE, 4 * sizeof(cl_int));
  cl::Buffer nonfinite(ctx, CL_MEM_READ_WRITE, sizeof(cl_int));
  cl::Buffer film_sum(ctx, CL_MEM_READ_WRITE, size_t(npix) * sizeof(float4));
  cl::Buffer film_sumsq(ctx, CL_MEM_READ_WRITE, size_t(npix) * sizeof(float4));
  const float4 zero4 = make_float4(0, 0, 0, 0);
  q.enqueueFillBuffer(film_sum, zero4, 0, size_t(npix) * sizeof(float4));
  q.enqueueFillBuffer(film_sumsq, zero4, 0, size_t(npix) * sizeof(float4));
  q.enqueueFillBuffer(nonfinite, cl_int(0), 0, sizeof(cl_int));

  cl::Kernel k_generate(program_, "generate");
  cl::Kernel k_closest(program_, "intersect_closest");
  cl::Kernel k_shade(program_, "shade_surface");
  cl::Kernel k_shadow(program_, "intersect_shadow");
  cl::Kernel k_accumulate(program_, "accumulate");

  std::vector<std::pair<std::string, cl::Event>> events;
  auto record = [&](const char* stage, const cl::Event& ev, size_t items) {
    events.emplace_back(stage, ev);
    StageStats& s = stats_.stages[stage];
    s.items += items;
    s.launches += 1;
  };

  for (uint64_t base = 0; base < total; base += W) {
    const int count0 = int(std::min<uint64_t>(W, total - base));
    k_generate.setArg(0, camera_);
    k_generate.setArg(1, cl_uint(settings.seed));
    k_generate.setArg(2, cl_ulong(base));
    k_generate.setArg(3, cl_int(count0));
    k_generate.setArg(4, ray_o);
    k_generate.setArg(5, ray_d);
    k_generate.setArg(6, throughput);
    k_generate.setArg(7, radiance);
    k_generate.setArg(8, rng);
    k_generate.setArg(9, queue_a);
    record("generate", enqueue_1d(q, k_generate, size_t(count0)), size_t(count0));

    cl::Buffer* q_in = &queue_a;
    cl::Buffer* q_out = &queue_b;
    int count = count0;
    for (int depth = 0; depth < max_depth && count > 0; ++depth) {
      k_closest.setArg(0, nodes_);
      k_closest.setArg(1, prim_index_);
      k_closest.setArg(2, prims_);
      k_closest.setArg(3, *q_in);
      k_closest.setArg(4, cl_int(count));
      k_closest.setArg(5, ray_o);
      k_closest.setArg(6, ray_d);
      k_closest.setArg(7, hits);
      record("intersect_closest", enqueue_1d(q, k_closest, size_t(count)), size_t(count));

      q.enqueueFillBuffer(counters, cl_int(0), 0, 4 * sizeof(cl_int));
      int a = 0;
      k_shade.setArg(a++, cl_int(depth));
      k_shade.setArg(a++, cl_int(max_depth));
      k_shade.setArg(a++, cl_float(geometry_.ray_eps));
      k_shade.setArg(a++, cl_int(light_count));
      k_shade.setArg(a++, *q_in);
      k_shade.setArg(a++, cl_int(count));
      k_shade.setArg(a++, *q_out);
      k_shade.setArg(a++, counters);
      k_shade.setArg(a++, ray_o);
      k_shade.setArg(a++, ray_d);
      k_shade.setArg(a++, throughput);
      k_shade.setArg(a++, radiance);
      k_shade.setArg(a++, rng);
      k_shade.setArg(a++, hits);
      k_shade.setArg(a++, prims_);
      k_shade.setArg(a++, materials_buf_);
      k_shade.setArg(a++, lights_);
      k_shade.setArg(a++, shadow);
      record("shade_surface", enqueue_1d(q, k_shade, size_t(count)), size_t(count));

      cl_int c[4];
      q.enqueueReadBuffer(counters, CL_TRUE, 0, sizeof(c), c);
      const int next_count = c[0], shadow_count = c[1];
      stats_.shadow_rays += uint64_t(shadow_count);

      k_shadow.setArg(0, nodes_);
      k_shadow.setArg(1, prim_index_);
      k_shadow.setArg(2, prims_);
      k_shadow.setArg(3, shadow);
      k_shadow.setArg(4, cl_int(shadow_count));
      k_shadow.setArg(5, radiance);
      record("intersect_shadow", enqueue_1d(q, k_shadow, size_t(shadow_count)),
             size_t(shadow_count));

      std::swap(q_in, q_out);
      count = next_count;
    }

    k_accumulate.setArg(0, cl_ulong(base));
    k_accumulate.setArg(1, cl_int(count0));
    k_accumulate.setArg(2, cl_int(npix));
    k_accumulate.setArg(3, radiance);
    k_accumulate.setArg(4, film_sum);
    k_accumulate.setArg(5, film_sumsq);
    k_accumulate.setArg(6, nonfinite);
    size_t acc_items = size_t(std::min<int64_t>(npix, count0));
    record("accumulate", enqueue_1d(q, k_accumulate, size_t(npix)), acc_items);
    q.finish();
    for (auto& [stage, ev] : events) stats_.stages[stage].seconds += event_seconds(ev);
    events.clear();
    stats_.samples += uint64_t(count0);
    if (settings.progress) settings.progress(double(base + uint64_t(count0)) / double(total));
  }

  Film film;
  film.width = width;
  film.height = height;
  film.sum.resize(size_t(npix));
  film.sumsq.resize(size_t(npix));
  q.enqueueReadBuffer(film_sum, CL_TRUE, 0, size_t(npix) * sizeof(float4), film.sum.data());
  q.enqueueReadBuffer(film_sumsq, CL_TRUE, 0, size_t(npix) * sizeof(float4), film.sumsq.data());
  cl_int nf = 0;
  q.enqueueReadBuffer(nonfinite, CL_TRUE, 0, sizeof(nf), &nf);
  stats_.nonfinite_samples += uint64_t(nf);
  stats_.render_seconds += seconds_since(t_start);
  return film;
}

} // namespace canopy
