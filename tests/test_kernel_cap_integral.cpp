// cl/bsdf/cap_integral.h compiled as OpenCL C on PoCL against the host (C++) build of the same
// header: a probe kernel runs cap_lobe_make, cap_lobe_integral and cap_lobe_is_glossy for every
// material type (the coated ones through their stand-in lobes) and a spread of caps (tiny to the
// whole sphere, straddling the horizon), with every feature on and with each material feature alone
// (diffuse-only: no GGX code, so the SPTD table is not even included). The accuracy tests are
// host-side (test_cap_integral.cpp).
//
// Tolerance: the device's sqrt, sin, cos, acos and atan2 may differ from glibc's by an ulp or
// two; a few ulps in the pivot's position move a sharp lobe's (alpha = 0.01) cap integrals by up
// to ~1e-3 relative where a cap edge cuts the lobe's peak (the lobe's value changes by 2 / alpha
// per radian of its position), so the results agree to 2e-3 relative. The cap-cap intersection
// sums terms up to 4 pi, so its rounding is a few ulps of 4 pi, ~3e-6 sr, times the lobe's
// scale albedo / |P(H)| (P(H) the pivot image of the hemisphere, larger than a hemisphere for a
// pivot above the horizon, as every fitted one is): an absolute 2e-6 for albedos < 1, and that
// over the cap's solid angle for the mean. The glossy flag matches exactly.
#include "cl/runtime.h"
#include "render/device_scene.h"
#include "render/features.h"
#include "support/materials.h"
#include "support/probe_program.h"

#include "bsdf/cap_integral.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

using namespace canopy;
using namespace canopy::test;

namespace {

const char* kProbeKernel = R"CL(
#include "bsdf/cap_integral.h"
__kernel void cap_probe(__global const Material* mats, __global const float4* normal,
                        __global const float4* wo, __global const float4* cap, int count,
                        __global float4* out) {
  int i = get_global_id(0);
  if (i >= count) return;
  Material m = mats[i];
  Frame fr = frame_from(normal[i].xyz);
  CapLobe l = cap_lobe_make(&m, &fr, wo[i].xyz);
  float mean;
  float s = cap_lobe_integral(&l, cap[i].xyz, sin(cap[i].w), cos(cap[i].w), &mean);
  out[i] = (float4)(s, mean, (float)cap_lobe_is_glossy(&l), (float)sizeof(CapLobe));
}
)CL";

struct Probes {
  std::vector<Material> mats;
  std::vector<float4> normal, wo, cap;
};

Probes make_probes(const std::vector<Material>& materials, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  auto unit = [&] {
    float z = 2 * u(rng) - 1, phi = 6.2831853f * u(rng), s = std::sqrt(std::max(0.0f, 1 - z * z));
    return make_float3(s * std::cos(phi), s * std::sin(phi), z);
  };
  Probes p;
  const float sizes[] = {1e-6f, 1e-4f, 0.01f, 0.1f, 0.5f, 1.0f, 2.0f, 3.14159265f};
  for (const Material& m : materials)
    for (int i = 0; i < 256; ++i) {
      float3 n = unit();
      Frame fr = frame_from(n);
      float th = (i % 8) * 0.2f; // up to 80 degrees
      float phi = 6.2831853f * u(rng);
      float3 wl =
          make_float3(std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi), std::cos(th));
      float3 c = i % 3 == 0 ? frame_to_world(&fr, make_float3(-wl.x, -wl.y, wl.z)) : unit();
      p.mats.push_back(m);
      p.normal.push_back(f4_from3(n, 0));
      p.wo.push_back(f4_from3(frame_to_world(&fr, wl), 0));
      p.cap.push_back(f4_from3(c, sizes[(i / 3) % 8]));
    }
  return p;
}

void run(ClRuntime& rt, const std::string& options, const std::vector<Material>& materials,
         uint32_t seed) {
  cl::Program program = build_probe_program(rt, kProbeKernel, options);
  if (::testing::Test::HasFailure()) return;
  Probes p = make_probes(materials, seed);
  const int n = int(p.mats.size());
  const cl::Context& ctx = rt.context();
  cl::Buffer mats = upload_buffer(ctx, p.mats), normal = upload_buffer(ctx, p.normal),
             wo = upload_buffer(ctx, p.wo), cap = upload_buffer(ctx, p.cap);
  cl::Buffer out(ctx, CL_MEM_WRITE_ONLY, sizeof(float4) * n);
  cl::Kernel k(program, "cap_probe");
  int a = 0;
  for (const cl::Buffer* b : {&mats, &normal, &wo, &cap})
    k.setArg(a++, *b);
  k.setArg(a++, n);
  k.setArg(a++, out);
  enqueue_1d(rt.queue(), k, size_t(n));
  std::vector<float4> d(n);
  rt.queue().enqueueReadBuffer(out, CL_TRUE, 0, sizeof(float4) * n, d.data());
  int positive = 0;
  for (int i = 0; i < n && !::testing::Test::HasFailure(); ++i) {
    const Material& m = p.mats[i];
    Frame fr = frame_from(xyz_of(p.normal[i]));
    CapLobe l = cap_lobe_make(&m, &fr, xyz_of(p.wo[i]));
    float r = p.cap[i].w, mean;
    float s = cap_lobe_integral(&l, xyz_of(p.cap[i]), std::sin(r), std::cos(r), &mean);
    std::string what = "probe " + std::to_string(i) + " type " + std::to_string(m.type) +
                       " alpha " + std::to_string(m.alpha) + " r " + std::to_string(r);
    EXPECT_NEAR(d[i].x, s, 2e-3f * std::fabs(s) + 2e-6f) << what;
    EXPECT_NEAR(d[i].y, mean, 2e-3f * std::fabs(mean) + 2e-6f / (1 - std::cos(r) + 1e-30f)) << what;
    EXPECT_EQ(int(d[i].z), cap_lobe_is_glossy(&l)) << what;
    EXPECT_EQ(int(d[i].w), 96) << "sizeof(CapLobe) on the device";
    positive += s > 1e-20f;
  }
  EXPECT_GT(positive, n / 8); // not all caps below the horizon
}

Material diffuse() {
  return make_diffuse(make_float3(0.8f, 0.5f, 0.2f));
}
// Coated materials get a stand-in plastic or conductor lobe (cap_coated_proxy).
std::vector<Material> coated() {
  std::vector<Material> v;
  for (float a : {0.0f, 0.09f}) {
    v.push_back(make_coated_diffuse(make_float3(0.6f, 0.3f, 0.1f), 1.5f, a));
    v.push_back(make_coated_conductor(1.5f, a, make_float3(0.18f, 0.42f, 1.37f),
                                      make_float3(3.42f, 2.35f, 1.77f), 0.01f));
  }
  return v;
}
Material conductor(float alpha) { // gold-like
  return make_conductor(make_float3(0.18f, 0.42f, 1.37f), make_float3(3.42f, 2.35f, 1.77f), alpha);
}
Material plastic(float alpha) {
  return make_plastic(make_float3(0.6f, 0.3f, 0.1f), make_float3(1, 0.8f, 0.6f), 1.5f, alpha);
}

} // namespace

static_assert(sizeof(CapLobe) == 96, "CapLobe is 96 bytes (the device checks its own size)");

TEST(KernelCapIntegral, MatchesHost) {
  ClRuntime rt;
  std::vector<Material> mats = {diffuse()};
  for (float a : {0.0f, 0.01f, 0.09f, 0.5f, 1.0f}) {
    mats.push_back(conductor(a));
    mats.push_back(plastic(a));
  }
  for (const Material& m : coated())
    mats.push_back(m);
  run(rt, "", mats, 1);
}

std::string features(bool conductor_on, bool plastic_on, bool coated_on = false) {
  KernelFeatures f;
  f.material_conductor = conductor_on;
  f.material_plastic = plastic_on;
  f.material_coated = coated_on;
  return f.build_options();
}

// Each material feature alone (the host, compiled with everything on, computes the same values:
// a feature only removes code for types the scene does not have).
TEST(KernelCapIntegral, SpecialisedKernelsMatchHost) {
  ClRuntime rt;
  run(rt, features(false, false), {diffuse()}, 2); // diffuse only: no GGX code, no table
  run(rt, features(true, false), {diffuse(), conductor(0.01f), conductor(0.5f)}, 3);
  run(rt, features(false, true), {diffuse(), plastic(0.0f), plastic(0.09f)}, 4);
  std::vector<Material> mats = coated();
  mats.push_back(diffuse());
  run(rt, features(false, false, true), mats, 5); // coated alone: its stand-in lobes
}
