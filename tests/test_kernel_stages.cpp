// Every wavefront kernel on PoCL against a host reference on identical inputs: generate,
// shade_surface (+ scatter_shade), light_pick (+ scatter_split) for every light sampler, with and
// without splitting, the BRDF-oriented stages of brdf-mis / brdf-oriented (brdf_cut, brdf_sample,
// scatter_brdf, brdf_trace, brdf_accumulate), accumulate_shadow, accumulate, cut_histogram and the
// scan. The intersect kernels are checked against Embree in test_intersect_embree.cpp.
//
// shade_surface and light_pick run the per-item functions of cl/integrator/ on both sides, so
// these tests prove the device executes them as the host does (address spaces, struct layouts,
// argument order, compiler); their statistical correctness is proven on the host by
// test_light_tree_* and end to end by test_render_analytic. generate and accumulate have
// independent references written here.
#include "accel/bvh.h"
#include "cl/kernel_args.h"
#include "cl/runtime.h"
#include "integrator/brdf_mis.h"
#include "integrator/light_pick.h"
#include "integrator/shade_surface.h"
#include "integrator/shade_volume.h"
#include "render/camera.h"
#include "render/device_scene.h"
#include "render/features.h"
#include "render/light_sampler_data.h"
#include "render/renderer.h"
#include "rng.h"
#include "sampler.h"

#include "support/glossy_points.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

using namespace canopy;

namespace {

// A box room with every material (diffuse; rough and mirror conductors; rough and smooth-coat
// plastics; glass, smooth and rough, and a thin glass sheet; a smooth-shaded OBJ; image textures
// for a diffuse albedo and a plastic's albedo and roughness) lit by every light type: point, spot,
// sphere, quad, triangle, disk (one-sided on the ceiling, two-sided in view of the camera), an
// emissive quad shape (mesh-light triangles) and 300 random points, so the light tree has several
// levels. The coated materials are not in it: their eval and pdf are random estimates seeded from a
// hash of their float inputs (cl/bsdf/layered.h), and the device's and the host's shading frames
// round those an ulp apart now and then, which gives another estimate, not a nearby value.
// test_kernel_bsdf checks them on identical inputs, test_render_coated end to end.
const char* kSceneJson = R"({
  "camera": { "position": [0, 1.5, 5], "look_at": [0, 1, 0], "up": [0, 1, 0], "fov": 50 },
  "film": { "width": 16, "height": 12 },
  "integrator": { "spp": 1, "max_depth": 3 },
  "materials": [ { "name": "white", "albedo": 0.7 }, { "name": "red", "albedo": [0.7, 0.1, 0.1] },
                 { "name": "gold", "type": "conductor", "metal": "gold", "roughness": 0.3 },
                 { "name": "mirror", "type": "conductor", "metal": "silver", "roughness": 0 },
                 { "name": "glossy", "type": "plastic", "albedo": [0.2, 0.3, 0.6], "roughness": 0.1 },
                 { "name": "coat", "type": "plastic", "albedo": [0.5, 0.5, 0.2], "roughness": 0 },
                 { "name": "painted", "albedo": { "texture": "textures/colours.png", "uv_scale": [3, 2] } },
                 { "name": "worn", "type": "plastic", "albedo": { "texture": "textures/colours.png" },
                   "roughness": { "texture": "textures/roughness.png", "wrap": "clamp" } },
                 { "name": "glass", "type": "dielectric", "ior": 1.5 },
                 { "name": "sheet", "type": "dielectric", "ior": 1.5, "thin": true },
                 { "name": "frosted", "type": "dielectric", "ior": 1.5, "roughness": 0.3 } ],
  "shapes": [
    { "type": "box", "material": "white", "min": [-3, 0, -3], "max": [3, 3, 3] },
    { "type": "box", "material": "red", "min": [-0.5, 0, -0.5], "max": [0.5, 1, 0.5], "rotate_y": 30 },
    { "type": "box", "material": "gold", "min": [1.0, 0, -2.0], "max": [2.0, 1.5, -1.0] },
    { "type": "box", "material": "mirror", "min": [-2.9, 0, -2.9], "max": [-1.0, 2.5, -2.8] },
    { "type": "box", "material": "glossy", "min": [-2.0, 0, 1.0], "max": [-1.0, 0.8, 2.0] },
    { "type": "box", "material": "coat", "min": [1.0, 0, 1.5], "max": [2.5, 0.4, 2.5] },
    { "type": "box", "material": "painted", "min": [-2.9, 0, -0.5], "max": [-2.5, 2.0, 0.5] },
    { "type": "box", "material": "worn", "min": [2.5, 0, -0.5], "max": [2.9, 2.0, 1.0] },
    { "type": "box", "material": "glass", "min": [-0.9, 0.9, 1.2], "max": [-0.2, 1.6, 1.9], "rotate_y": 20 },
    { "type": "quad", "material": "sheet", "corner": [0.3, 0.8, 1.5], "edge1": [0.8, 0, 0],
      "edge2": [0, 0.8, 0.2] },
    { "type": "box", "material": "frosted", "min": [0.6, 1.7, 0.8], "max": [1.3, 2.2, 1.4] },
    { "type": "obj", "file": "smooth.obj", "material": "gold",
      "transform": { "scale": 1.5, "translate": [0.5, 1.2, 0.5] } },
    { "type": "quad", "corner": [-1, 2.9, -1], "edge1": [2, 0, 0], "edge2": [0, 0, 0.2],
      "emission": [4, 4, 4] }
  ],
  "lights": [
    { "type": "point", "position": [0, 2.5, 0], "intensity": [5, 5, 5] },
    { "type": "spot", "position": [-2, 2.5, 1], "direction": [1, -1, 0], "intensity": 20,
      "cone_angle": 35, "falloff_start": 25 },
    { "type": "sphere", "center": [2, 0.3, 1], "radius": 0.3, "radiance": [8, 6, 3] },
    { "type": "quad", "corner": [-1, 2.95, 1], "edge1": [2, 0, 0], "edge2": [0, 0, 0.5], "radiance": 3 },
    { "type": "triangle", "v0": [-2.5, 0.01, -2.5], "v1": [-1.5, 0.01, -2.5], "v2": [-2.5, 0.01, -1.5],
      "radiance": [0, 0, 10], "two_sided": true },
    { "type": "disk", "center": [1.5, 2.9, -1], "normal": [0, -1, 0], "radius": 0.4, "radiance": 5 },
    { "type": "disk", "center": [-1.2, 1.2, 0.5], "normal": [1, 0.3, 0.8], "radius": 0.3,
      "radiance": [6, 2, 2], "two_sided": true }
  ],
  "light_sets": [
    { "type": "random_box", "min": [-2.5, 2.0, -2.5], "max": [2.5, 2.8, 2.5], "count": 300, "seed": 3,
      "light": { "type": "point", "intensity": 0.05 } }
  ]
})";

constexpr int kPaths = 4096;

template <class T> cl::Buffer to_device(ClRuntime& rt, const std::vector<T>& v) {
  return upload_buffer(rt.context(), v, CL_MEM_READ_WRITE);
}
template <class T> std::vector<T> from_device(ClRuntime& rt, const cl::Buffer& b, size_t n) {
  std::vector<T> v(n);
  if (n) rt.queue().enqueueReadBuffer(b, CL_TRUE, 0, n * sizeof(T), v.data());
  return v;
}

// Floats that went through device math (sqrt, sin, cos, division may differ by an ulp or two
// from glibc) are compared relatively; everything discrete must match exactly.
void expect_close(float a, float b, const std::string& what) {
  float tol = 2e-5f * std::max({1.0f, std::fabs(a), std::fabs(b)});
  EXPECT_NEAR(a, b, tol) << what;
}
void expect_close4(float4 a, float4 b, const std::string& what) {
  expect_close(a.x, b.x, what + ".x");
  expect_close(a.y, b.y, what + ".y");
  expect_close(a.z, b.z, what + ".z");
  expect_close(a.w, b.w, what + ".w");
}

// Host copies of the path state (every buffer of PATH_STATE_BUFFERS), uploaded identically to
// the device.
using Paths = canopy::test::HostPaths;

class KernelStages : public ::testing::TestWithParam<std::string> {
protected:
  void SetUp() override {
    scene_ = load_scene_from_string(kSceneJson, "kernel-test.json", CANOPY_TEST_DATA_DIR);
    for (const MaterialDesc& m : scene_.materials)
      materials_.push_back(m.gpu);
    geometry_ = build_scene_geometry(scene_, materials_);
    textures_ = build_texture_data(scene_.textures);
    // The loader stores coordinates relative to the camera position (Scene::origin); the points
    // below are chosen in world space and shifted the same way.
    origin_ = make_float3(float(scene_.origin.x), float(scene_.origin.y), float(scene_.origin.z));
    // "<sampler>-noorient": the orientation ablation (importance E / d^2); "brdf-mis-equal":
    // brdf-mis with equal allocation (BrdfSettings::adaptive = false); "-medium": the room half
    // filled with a coloured, forward-scattering medium (shade_volume and segment light picks)
    std::string name = GetParam();
    if (name.ends_with("-medium")) {
      name.resize(name.size() - 7);
      scene_.has_medium = true;
      scene_.medium.sigma_t = make_float4(0.35f, 0.5f, 0.7f, 0.4f);
      scene_.medium.sigma_s = make_float4(0.3f, 0.4f, 0.5f, 1.0f);
      scene_.medium.bmin = f4_from3(make_float3(-3.5f, -0.5f, -3.5f) - origin_, 0.0f);
      scene_.medium.bmax = f4_from3(make_float3(3.5f, 1.6f, 0.5f) - origin_, 0.0f);
    }
    const std::string suffix = "-noorient", equal = "-equal";
    bool orientation = !name.ends_with(suffix);
    if (!orientation) name.resize(name.size() - suffix.size());
    BrdfSettings brdf;
    if (name.ends_with(equal)) {
      brdf.adaptive = false;
      name.resize(name.size() - equal.size());
    }
    sampler_ = make_light_sampler_data(scene_.lights, name, 0.85f, 16, orientation, brdf);
    host_cut_.assign(size_t(kPaths) * LT_BRDF_MAX_CUT, make_float2(0, 0));
    program_ = rt_.build_program(wavefront_kernel_files(),
                                 KernelFeatures::all(sampler_.kind).build_options());
  }

  // Random paths: rays from random points in the room to random directions, their closest hits
  // (host traversal), random throughput and radiance, depth-dependent MIS context.
  Paths make_paths(uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    Paths p;
    for (int i = 0; i < kPaths; ++i) {
      float3 o =
          make_float3(-2.8f + 5.6f * u(rng), 0.1f + 2.8f * u(rng), -2.8f + 5.6f * u(rng)) - origin_;
      float z = 2 * u(rng) - 1, phi = 6.2831853f * u(rng), s = std::sqrt(std::max(0.0f, 1 - z * z));
      float3 d = make_float3(s * std::cos(phi), z, s * std::sin(phi));
      Hit h;
      bvh_intersect(geometry_.bvh.nodes.data(), geometry_.bvh.leaf_blocks.data(),
                    geometry_.prims.data(), o, d, 0.0f, FLT_INF, 0, &h);
      p.ray_o.push_back(f4_from3(o, 0));
      p.ray_d.push_back(f4_from3(d, 0));
      p.hits.push_back(h);
      p.throughput.push_back(make_float4(0.2f + u(rng), 0.2f + u(rng), 0.2f + u(rng), 0));
      p.radiance.push_back(make_float4(u(rng), u(rng), u(rng), 0));
      // Every third path draws from the Sobol sampler (key, sample index; shade_surface and
      // shade_volume set the vertex's dimensions), the others from their PCG state.
      if (i % 3 == 1)
        p.rng.push_back(
            make_uint4(uint32_t(rng()), uint32_t(rng() % 4096), 0u, PATH_SAMPLER_SOBOL));
      else
        p.rng.push_back(make_uint4(uint32_t(rng()), 0u, 0u, PATH_SAMPLER_INDEPENDENT));
      p.light_u.push_back(make_float2(0.0f, 0.0f)); // (shade_surface writes it for sobol)
      // Previous vertex: a point in the room, a normal, and the pdf of the BSDF ray (0: none).
      float3 sp = make_float3(-2 + 4 * u(rng), 0.5f + 2 * u(rng), -2 + 4 * u(rng)) - origin_;
      p.shade_P.push_back(f4_from3(sp, i % 3 == 0 ? 0.0f : u(rng)));
      p.shade_N.push_back(f4_from3(normalize(make_float3(u(rng) - 0.5f, 1.0f, u(rng) - 0.5f)), 0));
      // With a medium, some paths come from a medium vertex (MIS of the emission they find).
      p.shade_f.push_back(
          make_float4(0, 0, 0, scene_.has_medium && i % 4 == 1 ? VOLUME_POINT_FLAG : 0.0f));
      p.shade_wo.push_back(make_float4(0, 0, 0, 0));
      p.shade_Ns.push_back(make_float4(0, 0, 0, 0));
      p.shade_tex.push_back(make_float4(0, 0, 0, 0));
      p.shade_tex_t.push_back(make_float4(0, 0, 0, 0));
      p.shade_back.push_back(make_float4(0, 0, 0, 0)); // previous vertices one-sided
      p.brdf_state.push_back(make_int4(0, 0, 0, 0));
      p.brdf_share.push_back(0.0f);
      p.seg_o.push_back(make_float4(0, 0, 0, -1));
      p.seg_d.push_back(make_float4(0, 0, 0, 0));
      p.seg_beta.push_back(make_float4(0, 0, 0, 0));
      p.seg_phase.push_back(0.0f);
      // The segment of a previous medium vertex (for the MIS of emission found from it).
      float3 so = make_float3(-2 + 4 * u(rng), 0.2f + 1.2f * u(rng), -2 + 4 * u(rng)) - origin_;
      p.scatter_seg_o.push_back(f4_from3(so, 0.5f + 3 * u(rng)));
      p.scatter_seg_d.push_back(
          f4_from3(normalize(make_float3(u(rng) - 0.5f, u(rng) - 0.5f, 1)), 0.5f * u(rng)));
    }
    return p;
  }

  // The paths' buffers go into `args` under their names; the kernels bind them from there.
  void upload(const Paths& p, KernelArgs& args) {
#define PATH_UPLOAD(T, name) args.set(#name, to_device(rt_, p.name));
    PATH_STATE_BUFFERS(PATH_UPLOAD)
#undef PATH_UPLOAD
  }
  Paths download(const KernelArgs& args) {
    Paths p;
#define PATH_DOWNLOAD(T, name) p.name = from_device<T>(rt_, args.buffer(#name), kPaths);
    PATH_STATE_BUFFERS(PATH_DOWNLOAD)
#undef PATH_DOWNLOAD
    return p;
  }
  void check_brdf_cut(KernelArgs& args, const LightSamplerCtx& ls, const SceneBuffers& sc,
                      Paths& ref, const std::vector<int>& queue);
  void check_brdf_rounds(KernelArgs& args, const LightSamplerCtx& ls, const SceneBuffers& sc,
                         Paths& ref, const std::vector<int>& queue);
  void upload_scene() {
    dev_ = upload_device_scene(rt_.context(), geometry_, materials_, scene_.lights, sampler_, 0,
                               scene_.medium, {}, {}, textures_);
  }
  SceneBuffers host_scene() {
    return SceneBuffers{
        geometry_.bvh.nodes.data(), geometry_.bvh.leaf_blocks.data(), geometry_.prims.data(),
        materials_.data(),          geometry_.shading_normals.data(), &scene_.medium,
        geometry_.texcoords.data(), textures_.textures.data(),        textures_.texels.data()};
  }

  ClRuntime rt_;
  Scene scene_;
  float3 origin_{0, 0, 0}; // scene_.origin in float
  std::vector<Material> materials_;
  SceneGeometry geometry_;
  TextureData textures_; // the two textured materials' images
  LightSamplerData sampler_;
  std::vector<float2> host_cut_; // the host's brdf_cut storage (brdf-mis, brdf-oriented)
  cl::Program program_;
  DeviceScene dev_;
};

void compare_paths(const Paths& dev, const Paths& ref, const std::vector<int>& which) {
  for (int path : which) {
    size_t p = size_t(path);
    std::string at = "path " + std::to_string(path);
    expect_close4(dev.ray_o[p], ref.ray_o[p], at + " ray_o");
    expect_close4(dev.ray_d[p], ref.ray_d[p], at + " ray_d");
    expect_close4(dev.throughput[p], ref.throughput[p], at + " throughput");
    expect_close4(dev.radiance[p], ref.radiance[p], at + " radiance");
    expect_close4(dev.shade_P[p], ref.shade_P[p], at + " shade_P");
    EXPECT_EQ(dev.rng[p], ref.rng[p]) << at;
    EXPECT_EQ(dev.light_u[p].x, ref.light_u[p].x) << at;
    EXPECT_EQ(dev.light_u[p].y, ref.light_u[p].y) << at;
    expect_close(dev.shade_N[p].x, ref.shade_N[p].x, at + " N");
    EXPECT_EQ(float_as_uint_(dev.shade_N[p].w), float_as_uint_(ref.shade_N[p].w)) << at << " seed";
    expect_close4(dev.shade_f[p], ref.shade_f[p], at + " shade_f");
    expect_close4(dev.shade_wo[p], ref.shade_wo[p], at + " shade_wo");
    expect_close(dev.shade_Ns[p].x, ref.shade_Ns[p].x, at + " Ns");
    EXPECT_EQ(float_as_uint_(dev.shade_Ns[p].w), float_as_uint_(ref.shade_Ns[p].w))
        << at << " material";
    expect_close4(dev.shade_tex[p], ref.shade_tex[p], at + " shade_tex");
    if (::testing::Test::HasFailure()) return; // one path's report is enough
  }
}

} // namespace

TEST_P(KernelStages, ShadeSurfaceAndLightPickMatchTheHost) {
  upload_scene();
  LightSamplerCtx ls = sampler_.host_view(scene_.lights, host_cut_.data());
  SceneBuffers sc = host_scene();
  Paths paths = make_paths(17);
  std::vector<int> queue(kPaths);
  for (int i = 0; i < kPaths; ++i)
    queue[size_t(i)] = (i * 7919) % kPaths; // a permutation
  int hits = 0;
  for (const Hit& h : paths.hits)
    hits += h.prim >= 0;
  ASSERT_GT(hits, kPaths * 9 / 10);
  int textured = 0; // camera-depth hits on a textured material (shade_tex is compared there)
  for (const Hit& h : paths.hits) {
    const Material& m = materials_[size_t(geometry_.prims[size_t(std::max(h.prim, 0))].material)];
    textured += h.prim >= 0 && (m.albedo_texture > 0 || m.alpha_texture > 0);
  }
  ASSERT_GT(textured, kPaths / 50);

  int segments_seen = 0, scattered_seen = 0;
  // max_depth is 3: depth 3 is the rays after the last vertex, which only add emission.
  for (int depth : {0, 1, 2, 3}) {
    SCOPED_TRACE("depth " + std::to_string(depth));
    KernelArgs args;
    dev_.set_args(args);
    if (scene_.has_medium) { // ---- shade_volume: device, host, then both continue from the host's
      upload(paths, args);
      args.set("brdf_cut", to_device(rt_, host_cut_));
      args.set("max_depth", cl_int(3));
      cl::Buffer b_vc = to_device(rt_, std::vector<int>(2, 0));
      args.set("volume_counters", b_vc);
      cl::Buffer b_pcv = to_device(rt_, std::vector<int4>(kPaths, make_int4(0, 0, 0, 0)));
      args.set("path_counts", b_pcv);
      BoundKernel kv(program_, "shade_volume", args);
      enqueue_1d(rt_.queue(),
                 kv.bind({{"depth", depth}, {"queue", to_device(rt_, queue)}, {"count", kPaths}}),
                 kPaths);
      Paths dev = download(args);
      PathBuffers pbv = paths.host();
      int segments = 0;
      std::vector<int4> dpcv = from_device<int4>(rt_, b_pcv, kPaths);
      for (int i = 0; i < kPaths; ++i) {
        int path = queue[size_t(i)];
        // the emitter AOV is read from the hit before shade_volume replaces it
        ASSERT_EQ(dpcv[size_t(path)].z, camera_ray_hits_emitter(depth, pbv.hits[path], &sc))
            << "path " << path;
        segments += shade_volume_item(path, depth, 3, &sc, &pbv, &ls);
      }
      EXPECT_EQ(from_device<int>(rt_, b_vc, 1)[0], segments);
      compare_paths(dev, paths, queue);
      for (int path : queue) {
        size_t p = size_t(path);
        std::string at = "path " + std::to_string(path);
        expect_close4(dev.seg_o[p], paths.seg_o[p], at + " seg_o");
        expect_close4(dev.seg_d[p], paths.seg_d[p], at + " seg_d");
        expect_close4(make_float4(dev.seg_beta[p].x, dev.seg_beta[p].y, dev.seg_beta[p].z, 0),
                      make_float4(paths.seg_beta[p].x, paths.seg_beta[p].y, paths.seg_beta[p].z, 0),
                      at + " seg_beta");
        ASSERT_EQ(float_as_uint_(dev.seg_beta[p].w), float_as_uint_(paths.seg_beta[p].w)) << at;
        ASSERT_EQ(dev.hits[p].prim, paths.hits[p].prim) << at;
        ASSERT_EQ(dev.seg_phase[p], paths.seg_phase[p]) << at;
        expect_close4(dev.scatter_seg_o[p], paths.scatter_seg_o[p], at + " scatter_seg_o");
        expect_close4(dev.scatter_seg_d[p], paths.scatter_seg_d[p], at + " scatter_seg_d");
        scattered_seen += paths.hits[p].prim == HIT_SCATTERED;
      }
      segments_seen += segments;
      if (HasFailure()) return;
    }
    // ---- shade_surface: device
    upload(paths, args);
    // Every kernel with the light sampler's parameters takes the BRDF cut storage (read by the
    // brdf-mis / brdf-oriented stages only; check_brdf_cut fills it).
    args.set("brdf_cut", to_device(rt_, host_cut_));
    cl::Buffer b_counts(rt_.context(), CL_MEM_READ_WRITE, kPaths * sizeof(int2));
    args.set("counts_shade", b_counts);
    cl::Buffer b_path_counts = to_device(rt_, std::vector<int4>(kPaths, make_int4(0, 0, 0, 0)));
    args.set("path_counts", b_path_counts);
    args.set("max_depth", cl_int(3));
    BoundKernel k(program_, "shade_surface", args);
    enqueue_1d(rt_.queue(),
               k.bind({{"depth", depth}, {"queue", to_device(rt_, queue)}, {"count", kPaths}}),
               kPaths);
    std::vector<int2> dev_counts = from_device<int2>(rt_, b_counts, kPaths);
    std::vector<int4> dev_pc = from_device<int4>(rt_, b_path_counts, kPaths);
    Paths dev = download(args);
    // ---- host reference on the same inputs
    Paths ref = paths;
    PathBuffers pb = ref.host();
    int emitter_hits = 0;
    for (int path : queue) {
      int e = camera_ray_hits_emitter(depth, pb.hits[path], &sc);
      ASSERT_EQ(dev_pc[size_t(path)].z, e) << "path " << path;
      emitter_hits += e;
    }
    if (depth == 0) {
      EXPECT_GT(emitter_hits, 0);
    }
    std::vector<int2> ref_counts(kPaths);
    for (int i = 0; i < kPaths; ++i) {
      ref_counts[size_t(i)] = shade_surface_item(queue[size_t(i)], depth, 3, &sc, &pb, &ls);
      if (scene_.has_medium)
        ref_counts[size_t(i)] =
            shade_counts_with_volume(ref_counts[size_t(i)], queue[size_t(i)], &pb);
    }
    int continues = 0, shaded = 0, emission_hits = 0;
    for (int i = 0; i < kPaths; ++i) {
      ASSERT_EQ(dev_counts[size_t(i)].x, ref_counts[size_t(i)].x) << "item " << i;
      ASSERT_EQ(dev_counts[size_t(i)].y, ref_counts[size_t(i)].y) << "item " << i;
      continues += ref_counts[size_t(i)].x;
      shaded += ref_counts[size_t(i)].y;
      emission_hits += paths.hits[size_t(i)].prim >= 0 &&
                       geometry_.prims[size_t(paths.hits[size_t(i)].prim)].light >= 0;
    }
    compare_paths(dev, ref, queue);
    EXPECT_GT(emission_hits, 0); // the MIS-weighted emission path is exercised
    if (depth == 3) { // after the last vertex: emission only, nothing shaded or continued
      EXPECT_EQ(shaded, 0);
      EXPECT_EQ(continues, 0);
      continue;
    }
    EXPECT_GT(shaded, scene_.has_medium ? kPaths / 4 : kPaths / 2);
    if (depth == 2) {
      EXPECT_LT(continues, shaded); // Russian roulette ends some paths
    }

    // ---- light_pick passes on the shaded points: device and host, pass by pass
    // The roots as scatter_shade writes them: a path's segment root first, then its surface point's
    std::vector<SplitItem> items;
    for (int i = 0; i < kPaths; ++i) {
      int path = queue[size_t(i)], roots = ref_counts[size_t(i)].y;
      if (scene_.has_medium && ref.seg_o[size_t(path)].w >= 0.0f) {
        items.push_back(volume_segment_root(&ls, path));
        roots -= 1;
      }
      if (roots) items.push_back(light_sampler_root(&ls, path));
    }
    upload(ref, args); // the shaded state as the next stage sees it
    PathBuffers pb2 = ref.host();
    if (sampler_.brdf_oriented()) {
      check_brdf_cut(args, ls, sc, ref, queue);
      upload(ref, args); // the cut state as the light_pick passes see it
    }
    int passes = 0, shadow_total = 0, split_items = 0;
    while (!items.empty()) {
      ASSERT_LT(passes, 40);
      size_t n = items.size();
      cl::Buffer b_child(rt_.context(), CL_MEM_READ_WRITE, 4 * n * sizeof(SplitItem));
      const size_t slots = LIGHT_PICK_SHADOW_SLOTS; // the program has every feature (media too)
      cl::Buffer b_shadow(rt_.context(), CL_MEM_READ_WRITE, slots * n * sizeof(ShadowItem));
      cl::Buffer b_pc(rt_.context(), CL_MEM_READ_WRITE, n * sizeof(int2));
      std::vector<int> zeros(kPaths, 0);
      cl::Buffer b_cut = to_device(rt_, zeros);
      args.set("child_stage", b_child);
      args.set("shadow_stage", b_shadow);
      args.set("counts_pick", b_pc);
      args.set("cut_size", b_cut);
      args.set("volume_counters", to_device(rt_, std::vector<int>(2, 0)));
      BoundKernel kp(program_, "light_pick", args);
      enqueue_1d(rt_.queue(), kp.bind({{"split_in", to_device(rt_, items)}, {"count", int(n)}}), n);
      std::vector<int2> dc = from_device<int2>(rt_, b_pc, n);
      std::vector<SplitItem> dchild = from_device<SplitItem>(rt_, b_child, 4 * n);
      std::vector<ShadowItem> dshadow = from_device<ShadowItem>(rt_, b_shadow, slots * n);
      std::vector<int> dcut = from_device<int>(rt_, b_cut, kPaths);

      std::vector<SplitItem> hchild(4 * n);
      std::vector<ShadowItem> hshadow(slots * n);
      std::vector<int> hcut(kPaths, 0);
      std::vector<SplitItem> next;
      for (size_t i = 0; i < n; ++i) {
        int4 r = light_pick_item(items[i], &ls, &sc, &pb2, &hchild[4 * i], &hshadow[slots * i]);
        hcut[size_t(items[i].path & ~SPLIT_SEGMENT)] += r.z;
        ASSERT_EQ(dc[i].x, r.x) << "pass " << passes << " item " << i;
        ASSERT_EQ(dc[i].y, r.y) << "pass " << passes << " item " << i;
        for (int j = 0; j < r.x; ++j) {
          const SplitItem &x = dchild[4 * i + size_t(j)], &y = hchild[4 * i + size_t(j)];
          ASSERT_EQ(x.code, y.code);
          ASSERT_EQ(x.path, y.path);
          ASSERT_EQ(x.budget, y.budget);
          expect_close4(x.sphere, y.sphere, "child sphere");
          next.push_back(y);
        }
        for (int j = 0; j < r.y; ++j) {
          const ShadowItem &x = dshadow[slots * i + size_t(j)], &y = hshadow[slots * i + size_t(j)];
          expect_close4(x.origin, y.origin, "shadow origin");
          expect_close(x.dir.x, y.dir.x, "shadow dir");
          EXPECT_EQ(float_as_uint_(x.dir.w), float_as_uint_(y.dir.w)) << "shadow path";
          expect_close4(x.contribution, y.contribution, "shadow contribution");
        }
        split_items += r.x;
        shadow_total += r.y;
      }
      EXPECT_EQ(dcut, hcut);
      items = next;
      ++passes;
    }
    if (sampler_.brdf_oriented()) check_brdf_rounds(args, ls, sc, ref, queue);
    EXPECT_GT(shadow_total, shaded / 8); // enough shadow items to make the comparison meaningful
    if (sampler_.splits()) {
      EXPECT_GT(split_items, 0); // splitting happened
      EXPECT_GT(passes, 1);
    } else {
      EXPECT_EQ(passes, 1);
      EXPECT_EQ(split_items, 0);
    }
    paths = ref; // the next depth starts from the shaded state and the bounce rays' hits
    for (size_t i = 0; i < paths.hits.size(); ++i)
      bvh_intersect(geometry_.bvh.nodes.data(), geometry_.bvh.leaf_blocks.data(),
                    geometry_.prims.data(), xyz_of(paths.ray_o[i]), xyz_of(paths.ray_d[i]),
                    paths.ray_o[i].w, FLT_INF, 0, &paths.hits[i]);
  }
  if (scene_.has_medium) { // segments got light picks and paths scattered in the medium
    EXPECT_GT(segments_seen, kPaths / 4);
    EXPECT_GT(scattered_seen, kPaths / 50);
  }
}

// brdf_cut on the device and brdf_cut_item on the host, from the same shaded state: the same
// glossy points, cut sizes, N, cut entries and --stats counters. The host's result (state and
// cuts) is then the input of both sides' next stages.
void KernelStages::check_brdf_cut(KernelArgs& args, const LightSamplerCtx& ls,
                                  const SceneBuffers& sc, Paths& ref,
                                  const std::vector<int>& queue) {
  std::vector<float2> zeros(host_cut_.size(), make_float2(0, 0));
  cl::Buffer b_cut = to_device(rt_, zeros);
  cl::Buffer b_counters = to_device(rt_, std::vector<int>(4, 0));
  args.set("brdf_cut", b_cut);
  args.set("brdf_counters", b_counters);
  BoundKernel k(program_, "brdf_cut", args);
  enqueue_1d(rt_.queue(), k.bind({{"queue", to_device(rt_, queue)}, {"count", kPaths}}), kPaths);
  std::vector<float2> dcut = from_device<float2>(rt_, b_cut, host_cut_.size());
  std::vector<int4> dstate = from_device<int4>(rt_, args.buffer("brdf_state"), kPaths);
  std::vector<float> dshare = from_device<float>(rt_, args.buffer("brdf_share"), kPaths);
  std::vector<int> dcounters = from_device<int>(rt_, b_counters, 4);

  PathBuffers pb = ref.host();
  int glossy = 0, cut_sum = 0, n_sum = 0, n_max = 0;
  for (int path : queue) {
    if (pb.brdf_state[path].y != -1) continue;
    int2 r = brdf_cut_item(path, &ls, &sc, &pb);
    ++glossy, cut_sum += r.x, n_sum += r.y, n_max = std::max(n_max, r.y);
  }
  // (glossy points, sum of cut sizes, sum of N, largest N)
  EXPECT_EQ(dcounters, (std::vector<int>{glossy, cut_sum, n_sum, n_max}));
  for (int path : queue) {
    size_t p = size_t(path);
    int4 d = dstate[p], h = ref.brdf_state[p];
    ASSERT_TRUE(d.x == h.x && d.y == h.y && d.z == h.z && d.w == h.w)
        << "path " << path << ": device (" << d.x << ", " << d.y << ", " << d.z << ", " << d.w
        << ") host (" << h.x << ", " << h.y << ", " << h.z << ", " << h.w << ")";
    expect_close(dshare[p], ref.brdf_share[p], "path " + std::to_string(path) + " share");
    for (int j = 0; j < h.x; ++j) {
      size_t e = p * LT_BRDF_MAX_CUT + size_t(j);
      ASSERT_EQ(float_as_uint_(dcut[e].x), float_as_uint_(host_cut_[e].x))
          << "path " << path << " entry " << j << " code";
      expect_close(dcut[e].y, host_cut_[e].y, "cut importance");
    }
  }
  EXPECT_GT(glossy, kPaths / 20); // the scene's glossy materials are shaded
  EXPECT_GT(cut_sum, glossy);     // cuts of several clusters
  if (sampler_.kind == SAMPLER_BRDF_MIS && sampler_.brdf.adaptive) {
    EXPECT_GT(n_sum, glossy); // adaptive N
  }
  // Both sides continue from the host's cuts.
  args.set("brdf_cut", to_device(rt_, host_cut_));
}

// The rounds of BRDF-aware samples (brdf_rounds_for the sampler's largest N), stage by stage,
// each from identical inputs: brdf_sample (item counts and staged items, brdf_state),
// scan + scatter_brdf (compaction in queue order), brdf_trace (each item's value, hit flag),
// brdf_accumulate (radiance, n_hit / n_nohit, path_counts).
void KernelStages::check_brdf_rounds(KernelArgs& args, const LightSamplerCtx& ls,
                                     const SceneBuffers& sc, Paths& ref,
                                     const std::vector<int>& queue) {
  const int rounds = brdf_rounds_for(sampler_.kind == SAMPLER_BRDF_ORIENTED ? 1
                                     : sampler_.brdf.adaptive               ? sampler_.brdf.n_max
                                                                            : 2);
  const int block = 256, nblocks = (kPaths + block - 1) / block;
  int light_items = 0, bsdf_items = 0, bsdf_hits = 0;
  for (int round = 0; round < rounds; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    upload(ref, args);
    // ---- brdf_sample
    const size_t slots = size_t(kPaths) * BRDF_MAX_BATCH;
    cl::Buffer b_stage(rt_.context(), CL_MEM_READ_WRITE, slots * sizeof(BrdfItem));
    cl::Buffer b_counts(rt_.context(), CL_MEM_READ_WRITE, kPaths * sizeof(int2));
    args.set("brdf_stage", b_stage);
    args.set("counts_brdf", b_counts);
    cl::Buffer b_queue = to_device(rt_, queue);
    BoundKernel ks(program_, "brdf_sample", args);
    enqueue_1d(rt_.queue(), ks.bind({{"queue", b_queue}, {"count", kPaths}, {"brdf_round", round}}),
               kPaths);
    std::vector<int2> dcounts = from_device<int2>(rt_, b_counts, kPaths);
    std::vector<BrdfItem> dstage = from_device<BrdfItem>(rt_, b_stage, slots);
    std::vector<int4> dstate = from_device<int4>(rt_, args.buffer("brdf_state"), kPaths);
    PathBuffers pb = ref.host();
    std::vector<BrdfItem> hstage(slots);
    std::vector<int2> hcounts(kPaths);
    std::vector<BrdfItem> compact;
    for (int i = 0; i < kPaths; ++i) {
      int n = brdf_sample_item(queue[size_t(i)], round, &ls, &sc, &pb,
                               &hstage[size_t(i) * BRDF_MAX_BATCH]);
      hcounts[size_t(i)] = make_int2(n, 0);
      ASSERT_EQ(dcounts[size_t(i)].x, n) << "item " << i;
      ASSERT_LE(n, brdf_round_batch(round));
      for (int j = 0; j < n; ++j) {
        const BrdfItem &d = dstage[size_t(i) * BRDF_MAX_BATCH + size_t(j)],
                       &h = hstage[size_t(i) * BRDF_MAX_BATCH + size_t(j)];
        std::string at = "item " + std::to_string(i) + "." + std::to_string(j);
        ASSERT_EQ(d.extra.z, h.extra.z) << at << " technique";
        ASSERT_EQ(float_as_uint_(d.dir.w), float_as_uint_(h.dir.w)) << at << " path";
        // a live probe's tmax is infinite: equal, not close
        expect_close4(make_float4(d.origin.x, d.origin.y, d.origin.z, 0),
                      make_float4(h.origin.x, h.origin.y, h.origin.z, 0), at + " origin");
        if (!(std::isinf(h.origin.w) && d.origin.w == h.origin.w))
          expect_close(d.origin.w, h.origin.w, at + " tmax");
        expect_close4(make_float4(d.dir.x, d.dir.y, d.dir.z, 0),
                      make_float4(h.dir.x, h.dir.y, h.dir.z, 0), at + " dir");
        expect_close4(d.value, h.value, at + " value");
        expect_close4(d.extra, h.extra, at + " extra");
        compact.push_back(h);
        (h.extra.z == float(BRDF_ITEM_LIGHT) ? light_items : bsdf_items) += 1;
      }
    }
    for (int path : queue) {
      int4 d = dstate[size_t(path)], h = ref.brdf_state[size_t(path)];
      ASSERT_TRUE(d.x == h.x && d.y == h.y && d.z == h.z && d.w == h.w) << "path " << path;
    }
    if (HasFailure()) return;
    const int total = int(compact.size());
    if (total == 0) continue;
    // ---- scan + scatter_brdf of the host's staged items
    args.set("brdf_stage", to_device(rt_, hstage));
    args.set("counts", to_device(rt_, hcounts));
    args.set("n", cl_int(kPaths));
    args.set("block", cl_int(block));
    args.set("nblocks", cl_int(nblocks));
    args.set("offsets", cl::Buffer(rt_.context(), CL_MEM_READ_WRITE, kPaths * sizeof(int2)));
    args.set("block_sums",
             cl::Buffer(rt_.context(), CL_MEM_READ_WRITE, size_t(nblocks) * sizeof(int2)));
    args.set("totals", cl::Buffer(rt_.context(), CL_MEM_READ_WRITE, 2 * sizeof(int)));
    cl::Buffer b_items(rt_.context(), CL_MEM_READ_WRITE, size_t(total) * sizeof(BrdfItem));
    args.set("brdf_items", b_items);
    BoundKernel kb(program_, "scan_blocks", args), kt(program_, "scan_block_sums", args),
        kx(program_, "scatter_brdf", args);
    enqueue_1d(rt_.queue(), kb.bind(), size_t(nblocks));
    enqueue_1d(rt_.queue(), kt.bind(), 1);
    EXPECT_EQ(from_device<int>(rt_, args.buffer("totals"), 1)[0], total);
    enqueue_1d(rt_.queue(), kx.bind({{"count", kPaths}}), kPaths);
    std::vector<BrdfItem> ditems = from_device<BrdfItem>(rt_, b_items, size_t(total));
    for (int i = 0; i < total; ++i)
      ASSERT_EQ(std::memcmp(&ditems[size_t(i)], &compact[size_t(i)], sizeof(BrdfItem)), 0)
          << "compacted item " << i;
    // ---- brdf_trace
    upload(ref, args); // brdf_state after sampling
    BoundKernel kr(program_, "brdf_trace", args);
    enqueue_1d(rt_.queue(), kr.bind({{"count", total}}), size_t(total));
    ditems = from_device<BrdfItem>(rt_, b_items, size_t(total));
    for (int i = 0; i < total; ++i) {
      brdf_trace_item(&compact[size_t(i)], &ls, &sc, &pb);
      const BrdfItem &d = ditems[size_t(i)], &h = compact[size_t(i)];
      ASSERT_EQ(d.extra.w, h.extra.w) << "traced item " << i << " hit";
      expect_close4(d.value, h.value, "traced item " + std::to_string(i) + " value");
      bsdf_hits += h.extra.z == float(BRDF_ITEM_BSDF) && h.extra.w > 0;
    }
    if (HasFailure()) return;
    // ---- brdf_accumulate of the host's traced items
    args.set("brdf_items", to_device(rt_, compact));
    std::vector<int4> pc(kPaths, make_int4(0, 0, 0, 0));
    cl::Buffer b_pc = to_device(rt_, pc);
    args.set("path_counts", b_pc);
    BoundKernel ka(program_, "brdf_accumulate", args);
    enqueue_1d(rt_.queue(), ka.bind({{"count", total}}), size_t(total));
    Paths dev = download(args);
    std::vector<int4> dpc = from_device<int4>(rt_, b_pc, kPaths);
    for (int i = 0; i < total; ++i) {
      int n = brdf_accumulate_item(i, compact.data(), total, &pb);
      if (n > 0) pc[float_as_uint_(compact[size_t(i)].dir.w)].x += n;
    }
    for (int path : queue) {
      size_t p = size_t(path);
      int4 d = dev.brdf_state[p], h = ref.brdf_state[p];
      ASSERT_TRUE(d.x == h.x && d.y == h.y && d.z == h.z && d.w == h.w) << "path " << path;
      expect_close4(dev.radiance[p], ref.radiance[p], "path " + std::to_string(path) + " radiance");
      ASSERT_EQ(dpc[p].x, pc[p].x) << "path " << path;
    }
    if (HasFailure()) return;
  }
  // Every point drew its N samples; both techniques ran and probes found emitters.
  for (int path : queue) {
    const int4& st = ref.brdf_state[size_t(path)];
    ASSERT_EQ(st.z, std::max(st.y, 0)) << "path " << path;
  }
  EXPECT_GT(light_items, 0);
  if (sampler_.kind == SAMPLER_BRDF_MIS) {
    EXPECT_GT(bsdf_items, 0);
    EXPECT_GT(bsdf_hits, 0);
  } else {
    EXPECT_EQ(bsdf_items, 0); // brdf-oriented: light samples only
  }
}

INSTANTIATE_TEST_SUITE_P(Samplers, KernelStages,
                         ::testing::Values("uniform", "power", "tree", "tree-split", "exhaustive",
                                           "tree-noorient", "tree-split-noorient", "brdf-mis",
                                           "brdf-mis-equal", "brdf-oriented", "power-medium",
                                           "tree-split-medium", "brdf-mis-medium"),
                         [](const auto& p) {
                           std::string s = p.param;
                           for (char& c : s)
                             if (c == '-') c = '_';
                           return s;
                         });

// ---------------------------------------------------------------- generate, accumulate, scans

class KernelUtilities : public ::testing::Test {
protected:
  void SetUp() override {
    program_ = rt_.build_program(wavefront_kernel_files(),
                                 KernelFeatures::all(SAMPLER_UNIFORM).build_options());
  }
  void check_accumulate(int npix, int wave, uint64_t base);
  void check_generate(int4 window, uint32_t first_pass, uint32_t path_sampler, RowBands bands = {});
  ClRuntime rt_;
  cl::Program program_;
};

// The whole film from pass 0, and a window of it from pass 17 (a crop of a sample range), and
// bands of rows of either: the film pixel and the pass of each path, and so its random numbers,
// are those of the full render.
TEST_F(KernelUtilities, GenerateMatchesAPinholeCamera) {
  for (int4 window : {make_int4(0, 0, 37, 23), make_int4(5, 3, 11, 7)}) {
    const uint32_t first_pass = window.z == 37 ? 0 : 17;
    for (uint32_t ps : {PATH_SAMPLER_INDEPENDENT, PATH_SAMPLER_SOBOL}) {
      check_generate(window, first_pass, ps);
      check_generate(window, first_pass, ps, RowBands{2, 3, 1, 2});
      check_generate(window, first_pass, ps, RowBands{4, 2, 0, 1});
    }
  }
}

// The rows that bands cover, counted and listed by cl/row_bands.h, against a direct enumeration.
TEST(RowBands, CoveredRowsAreTheBandsInThePeriod) {
  for (int height : {1, 3, 8})
    for (int period : {1, 2, 3, 4})
      for (int first = 0; first < period; ++first)
        for (int count = 1; first + count <= period; ++count)
          for (int rows : {1, 7, 8, 23, 24, 25, 216}) {
            const RowBands b{height, period, first, count};
            std::vector<uint32_t> want;
            for (int y = 0; y < rows; ++y)
              if ((y / height) % period >= first && (y / height) % period < first + count)
                want.push_back(uint32_t(y));
            ASSERT_EQ(covered_rows(b.packed(), rows), int(want.size()));
            for (size_t r = 0; r < want.size(); ++r)
              ASSERT_EQ(covered_row(b.packed(), uint32_t(r)), want[r]);
          }
}

void KernelUtilities::check_generate(int4 window, uint32_t first_pass, uint32_t path_sampler,
                                     RowBands bands) {
  SCOPED_TRACE(::testing::Message()
               << "path sampler " << path_sampler << " bands " << bands.height << " "
               << bands.period << " " << bands.first << " " << bands.count);
  window.w = covered_rows(bands.packed(), window.w); // the rows the render covers
  Camera cam;
  cam.position = make_float3(1, 2, 3);
  cam.look_at = make_float3(0, 0.5f, -1);
  cam.fov_y_deg = 40;
  const int w = 37, h = 23, n = 3000;
  const uint64_t base = 123457; // a wave that starts mid-image, in a later pass
  std::vector<CameraParams> cp = {make_camera_params(cam, w, h)};
  KernelArgs args;
  args.set("cam", to_device(rt_, cp));
  args.set("seed", cl_uint(99));
  args.set("path_sampler", cl_uint(path_sampler));
  args.set("window", window);
  args.set("bands", bands.packed());
  args.set("first_pass", cl_uint(first_pass));
  args.set("wave_base", cl_ulong(base));
  args.set("count", cl_int(n));
  for (const char* name : {"ray_o", "ray_d", "throughput", "radiance"})
    args.set(name, cl::Buffer(rt_.context(), CL_MEM_READ_WRITE, n * sizeof(float4)));
  args.set("rng", cl::Buffer(rt_.context(), CL_MEM_READ_WRITE, n * sizeof(uint4)));
  args.set("ray_queue", cl::Buffer(rt_.context(), CL_MEM_READ_WRITE, n * sizeof(int)));
  args.set("path_counts", cl::Buffer(rt_.context(), CL_MEM_READ_WRITE, n * sizeof(int4)));
  BoundKernel k(program_, "generate", args);
  enqueue_1d(rt_.queue(), k.bind(), n);
  auto o = from_device<float4>(rt_, args.buffer("ray_o"), n);
  auto d = from_device<float4>(rt_, args.buffer("ray_d"), n);
  auto rng = from_device<uint4>(rt_, args.buffer("rng"), n);
  auto queue = from_device<int>(rt_, args.buffer("ray_queue"), n);
  // Independent reference: the pixel's jittered point on the image plane, from the camera basis.
  float3 fwd = normalize(cam.look_at - cam.position), right = normalize(cross(fwd, cam.up));
  float3 up = cross(right, fwd);
  float th = std::tan(0.5f * 40.0f * float(M_PI) / 180.0f), tw = th * float(w) / float(h);
  const uint64_t nwin = uint64_t(window.z) * uint64_t(window.w);
  for (int i = 0; i < n; ++i) {
    uint64_t g = base + uint64_t(i);
    uint32_t in_win = uint32_t(g % nwin), pass = first_pass + uint32_t(g / nwin);
    // the covered row: the (in_win / width)-th window row whose band is in [first, first + count)
    auto covered = [&](int y) {
      const int band = (y / bands.height) % bands.period;
      return band >= bands.first && band < bands.first + bands.count;
    };
    int row = 0;
    for (int left = int(in_win) / window.z; !(covered(row) && left-- == 0);)
      ++row;
    uint32_t pixel = uint32_t((window.y + row) * w + window.x + int(in_win) % window.z);
    float2 j;
    uint4 state = path_sampler_start(path_sampler, 99, pixel, pass, &j);
    if (path_sampler == PATH_SAMPLER_INDEPENDENT) { // the PCG stream's first two numbers
      PathRng r = rng_seed(99, pixel, pass);
      ASSERT_EQ(j.x, rng_next_float(&r));
      ASSERT_EQ(j.y, rng_next_float(&r));
      ASSERT_EQ(state.x, r.state);
    }
    float sx = (float(pixel % w) + j.x) / float(w), sy = (float(pixel / w) + j.y) / float(h);
    float3 dir = normalize(fwd + right * ((2 * sx - 1) * tw) + up * ((1 - 2 * sy) * th));
    ASSERT_NEAR(d[size_t(i)].x, dir.x, 1e-5f) << i;
    ASSERT_NEAR(d[size_t(i)].y, dir.y, 1e-5f) << i;
    ASSERT_NEAR(d[size_t(i)].z, dir.z, 1e-5f) << i;
    ASSERT_EQ(o[size_t(i)].x, 1.0f);
    ASSERT_EQ(rng[size_t(i)], state) << i;
    ASSERT_EQ(queue[size_t(i)], i);
  }
}

TEST_F(KernelUtilities, AccumulateSumsEachPixelsSamplesInOrderAndDropsNonFinite) {
  // Several samples of some pixels in one wave, then a wave smaller than the film (one work item
  // per pixel the wave touches; the other pixels must keep their values).
  check_accumulate(50, 173, 1234);
  check_accumulate(50, 137, 1234);
  check_accumulate(50, 37, 1234);
  check_accumulate(50, 37, 30);
}

void KernelUtilities::check_accumulate(int npix, int wave, uint64_t base) {
  SCOPED_TRACE(::testing::Message() << "npix " << npix << " wave " << wave << " base " << base);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0, 10);
  std::vector<float4> radiance(wave);
  std::vector<int4> counts(wave);
  for (int i = 0; i < wave; ++i) {
    radiance[size_t(i)] = make_float4(u(rng), u(rng), u(rng), 0);
    counts[size_t(i)] = make_int4(i % 5, 1, i % 3 == 0, 0);
  }
  radiance[7].y = std::numeric_limits<float>::quiet_NaN();
  radiance[size_t(wave) / 2].z = std::numeric_limits<float>::infinity();
  std::vector<double4> sum(size_t(npix), double4{1, 1, 1, 2}),
      sumsq(size_t(npix), double4{0.5, 0.5, 0.5, 0});
  std::vector<double4> fc(size_t(npix), double4{0, 0, 0, 0});
  std::vector<int> nonfinite = {0};
  cl::Buffer b_r = to_device(rt_, radiance), b_s = to_device(rt_, sum), b_q = to_device(rt_, sumsq),
             b_n = to_device(rt_, nonfinite), b_c = to_device(rt_, counts),
             b_fc = to_device(rt_, fc);
  KernelArgs args;
  args.set("wave_base", cl_ulong(base));
  args.set("wave_size", cl_int(wave));
  args.set("npix", cl_int(npix));
  args.set("radiance", b_r);
  args.set("film_sum", b_s);
  args.set("film_sumsq", b_q);
  args.set("nonfinite", b_n);
  args.set("path_counts", b_c);
  args.set("film_counts", b_fc);
  BoundKernel k(program_, "accumulate", args);
  enqueue_1d(rt_.queue(), k.bind(), size_t(std::min(npix, wave)));
  auto dsum = from_device<double4>(rt_, b_s, npix), dsq = from_device<double4>(rt_, b_q, npix);
  auto dfc = from_device<double4>(rt_, b_fc, npix);
  EXPECT_EQ(from_device<int>(rt_, b_n, 1)[0], 2);
  // Reference: visit paths in order, add into their pixel (g mod npix).
  for (int i = 0; i < wave; ++i) {
    size_t p = size_t((base + uint64_t(i)) % npix);
    float4 L = radiance[size_t(i)];
    if (!std::isfinite(L.x) || !std::isfinite(L.y) || !std::isfinite(L.z))
      L = make_float4(0, 0, 0, 0);
    // The film sums in double: each float sample and its square exactly converted.
    double x = L.x, y = L.y, z = L.z;
    sum[p] = double4{sum[p].x + x, sum[p].y + y, sum[p].z + z, sum[p].w + 1};
    sumsq[p] = double4{sumsq[p].x + x * x, sumsq[p].y + y * y, sumsq[p].z + z * z, 0};
    fc[p].x += double(counts[size_t(i)].x);
    fc[p].y += double(counts[size_t(i)].y);
    fc[p].z += double(counts[size_t(i)].z);
  }
  for (int p = 0; p < npix; ++p) {
    EXPECT_EQ(dsum[size_t(p)].x, sum[size_t(p)].x) << p; // same order of additions: bit-identical
    EXPECT_EQ(dsum[size_t(p)].y, sum[size_t(p)].y) << p;
    EXPECT_EQ(dsum[size_t(p)].z, sum[size_t(p)].z) << p;
    EXPECT_EQ(dsum[size_t(p)].w, sum[size_t(p)].w) << p;
    EXPECT_EQ(dsq[size_t(p)].y, sumsq[size_t(p)].y) << p;
    EXPECT_EQ(dfc[size_t(p)].x, fc[size_t(p)].x) << p;
    EXPECT_EQ(dfc[size_t(p)].y, fc[size_t(p)].y) << p;
    EXPECT_EQ(dfc[size_t(p)].z, fc[size_t(p)].z) << p;
  }
}

TEST_F(KernelUtilities, ScanScatterAndShadowSumsMatchTheHost) {
  // Random per-item counts -> exclusive scan (scan_blocks + scan_block_sums) -> scatter_split.
  const int n = 5000, block = 256;
  std::mt19937 rng(8);
  std::vector<int2> counts(n);
  // The program has every feature (media too): LIGHT_PICK_SHADOW_SLOTS shadow slots per item.
  const int slots = LIGHT_PICK_SHADOW_SLOTS;
  std::vector<SplitItem> child(4 * n);
  std::vector<ShadowItem> shadow(size_t(slots) * n);
  for (int i = 0; i < n; ++i) {
    int c = int(rng() % 5), s = c ? 0 : int(rng() % (slots + 1));
    counts[size_t(i)] = make_int2(c, s);
    for (int j = 0; j < 4; ++j)
      child[size_t(4 * i + j)] = SplitItem{make_float4(0, 0, 0, 1), i / 3, 10 * i + j, 1u, 0.0f};
    for (int j = 0; j < slots; ++j) {
      shadow[size_t(slots * i + j)].dir = make_float4(0, 0, 1, uint_as_float_(uint(i / 3)));
      shadow[size_t(slots * i + j)].contribution = make_float4(float(i), float(j), 1, 0);
    }
  }
  int blocks = (n + block - 1) / block;
  cl::Buffer b_c = to_device(rt_, counts),
             b_off(rt_.context(), CL_MEM_READ_WRITE, n * sizeof(int2)),
             b_bs(rt_.context(), CL_MEM_READ_WRITE, size_t(blocks) * sizeof(int2)),
             b_tot(rt_.context(), CL_MEM_READ_WRITE, 2 * sizeof(int));
  KernelArgs args;
  args.set("counts", b_c);
  args.set("n", cl_int(n));
  args.set("count", cl_int(n));
  args.set("block", cl_int(block));
  args.set("offsets", b_off);
  args.set("block_sums", b_bs);
  args.set("nblocks", cl_int(blocks));
  args.set("totals", b_tot);
  BoundKernel ks(program_, "scan_blocks", args), kb(program_, "scan_block_sums", args),
      kx(program_, "scatter_split", args);
  enqueue_1d(rt_.queue(), ks.bind(), size_t(blocks));
  enqueue_1d(rt_.queue(), kb.bind(), 1);
  auto tot = from_device<int>(rt_, b_tot, 2);
  std::vector<SplitItem> ref_split;
  std::vector<ShadowItem> ref_shadow;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < counts[size_t(i)].x; ++j)
      ref_split.push_back(child[size_t(4 * i + j)]);
    for (int j = 0; j < counts[size_t(i)].y; ++j)
      ref_shadow.push_back(shadow[size_t(slots * i + j)]);
  }
  ASSERT_EQ(tot[0], int(ref_split.size()));
  ASSERT_EQ(tot[1], int(ref_shadow.size()));
  cl::Buffer b_child = to_device(rt_, child), b_shadow = to_device(rt_, shadow),
             b_so(rt_.context(), CL_MEM_READ_WRITE, ref_split.size() * sizeof(SplitItem)),
             b_sh(rt_.context(), CL_MEM_READ_WRITE, ref_shadow.size() * sizeof(ShadowItem));
  args.set("child_stage", b_child);
  args.set("shadow_stage", b_shadow);
  args.set("split_out", b_so);
  args.set("shadow_items", b_sh);
  enqueue_1d(rt_.queue(), kx.bind(), size_t(n));
  auto so = from_device<SplitItem>(rt_, b_so, ref_split.size());
  auto sh = from_device<ShadowItem>(rt_, b_sh, ref_shadow.size());
  for (size_t i = 0; i < so.size(); ++i)
    ASSERT_EQ(so[i].code, ref_split[i].code) << i;
  for (size_t i = 0; i < sh.size(); ++i)
    ASSERT_EQ(sh[i].contribution.x, ref_shadow[i].contribution.x) << i;

  // accumulate_shadow: each path's run of items is summed in order into its radiance.
  const int paths = n / 3 + 1;
  std::vector<float4> radiance(size_t(paths), make_float4(0.5f, 0, 0, 0));
  std::vector<int4> pc(size_t(paths), make_int4(0, 0, 0, 0));
  cl::Buffer b_rad = to_device(rt_, radiance), b_pc = to_device(rt_, pc);
  args.set("radiance", b_rad);
  args.set("path_counts", b_pc);
  BoundKernel ka(program_, "accumulate_shadow", args);
  enqueue_1d(rt_.queue(), ka.bind({{"count", int(sh.size())}}), sh.size());
  auto drad = from_device<float4>(rt_, b_rad, size_t(paths));
  auto dpc = from_device<int4>(rt_, b_pc, size_t(paths));
  std::vector<float> run_sum(size_t(paths), 0.0f);
  std::vector<int> run_count(size_t(paths), 0);
  for (const ShadowItem& s : ref_shadow) {
    size_t p = float_as_uint_(s.dir.w);
    run_sum[p] += s.contribution.x;
    run_count[p] += 1;
  }
  for (int p = 0; p < paths; ++p) {
    EXPECT_EQ(drad[size_t(p)].x, 0.5f + run_sum[size_t(p)]) << p;
    EXPECT_EQ(dpc[size_t(p)].x, run_count[size_t(p)]) << p;
  }
}
