// The BSDFs of cl/bsdf/ on PoCL against the host: a test kernel runs bsdf_eval, bsdf_pdf,
// bsdf_sample and bsdf_has_smooth_lobe for every material type (diffuse; conductor and plastic
// from a perfect mirror to alpha = 1; glass, smooth and rough, from either side, index-matched,
// and a thin sheet; coated diffuse and coated conductor with smooth and rough coats and bases,
// with and without a scattering slab; grazing and random directions) on inputs the host evaluates
// identically, so the host's statistical tests (test_bsdf*.cpp) cover the device too. The program
// is built with every feature on (the default) and with each material feature alone, which also
// proves the dispatch compiles when GGX code is left out (a diffuse-only kernel).
//
// The coated materials are random walks (cl/bsdf/layered.h) driven by generators seeded from the
// inputs, so the device draws the same numbers; an ulp of difference can still send a walk down
// another branch (a Fresnel choice, a Russian roulette test) now and then. Their probes are
// compared with the same tolerances, the device's sample weight against the host's sample for the
// same u, and at most 0.5% of them may differ (1 in 6144 does).
//
// Tolerances: the device's sqrt, sin, cos and built-in dot/normalize may differ from glibc's by an
// ulp or two. Values without a microfacet peak agree to 2e-5 relative. D(h) amplifies an error
// dh in the half vector by up to ~2 dh / alpha (relative), so glossy values get
// 2e-5 + 8 * 2^-24 / alpha; the sampled direction, which goes through sin and cos, agrees to 2e-5
// absolute, and the device's sample pdf and weight are compared with the host's bsdf_pdf and
// bsdf_eval at the device's direction. Discrete outputs (is_delta, smooth lobe) match exactly.
#include "cl/runtime.h"
#include "render/device_scene.h"
#include "render/features.h"
#include "support/materials.h"
#include "support/probe_program.h"

#include "bsdf/bsdf.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

using namespace canopy;
using namespace canopy::test;

namespace {

const char* kProbeKernel = R"CL(
#include "bsdf/bsdf.h"
// One probe per work item: eval and pdf at (wo, wi), a sample from (wo, u).
__kernel void bsdf_probe(__global const Material* mats, __global const float4* wo,
                         __global const float4* wi, __global const float4* u, int count,
                         __global float4* f_pdf, __global float4* s_wi_pdf,
                         __global float4* s_weight, __global int2* flags) {
  int i = get_global_id(0);
  if (i >= count) return;
  Material m = mats[i];
  float3 o = wo[i].xyz;
  float3 f = bsdf_eval(&m, o, wi[i].xyz);
  f_pdf[i] = (float4)(f, bsdf_pdf(&m, o, wi[i].xyz));
  BsdfSample s = bsdf_sample(&m, o, u[i].xyz);
  s_wi_pdf[i] = (float4)(s.wi, s.pdf);
  s_weight[i] = (float4)(s.weight, 0.0f);
  flags[i] = (int2)(s.is_delta, bsdf_has_smooth_lobe(&m));
}
)CL";

Material conductor(float alpha) { // gold-like
  return make_conductor(make_float3(0.18f, 0.42f, 1.37f), make_float3(3.42f, 2.35f, 1.77f), alpha);
}
Material plastic(float alpha) {
  return make_plastic(make_float3(0.6f, 0.3f, 0.1f), make_float3(1, 0.8f, 0.6f), 1.5f, alpha);
}
Material diffuse() {
  return make_diffuse(make_float3(0.8f, 0.5f, 0.2f));
}

struct Probes {
  std::vector<Material> mats;
  std::vector<float4> wo, wi, u;
};

// Per material: directions from normal incidence to 89.999 deg and random ones, wi in the lobe
// (the host's own sample), random over the sphere, on the horizon, equal to wo.
Probes make_probes(const std::vector<Material>& materials, uint32_t seed) {
  std::mt19937 rng(seed);
  auto uni = [&] { return float(rng() >> 8) * 5.9604645e-8f; };
  Probes p;
  for (const Material& m : materials)
    for (int i = 0; i < 512; ++i) {
      float3 o;
      if (i < 64) {
        const float deg[] = {0.0f, 30.0f, 60.0f, 80.0f, 89.9f, 89.999f, 45.0f, 10.0f};
        float t = deg[i % 8] * 3.14159265f / 180.0f, phi = 0.3f + float(i);
        o = make_float3(std::sin(t) * std::cos(phi), std::sin(t) * std::sin(phi), std::cos(t));
      } else {
        float r = std::sqrt(uni()), phi = 6.2831853f * uni();
        o = make_float3(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1 - r * r)));
      }
      float3 uu = make_float3(uni(), uni(), uni());
      float3 w;
      int kind = i % 4;
      if (kind == 0) {
        w = bsdf_sample(&m, o, make_float3(uni(), uni(), uni())).wi;
      } else if (kind == 1) {
        float z = 2 * uni() - 1, phi = 6.2831853f * uni(), s = std::sqrt(std::max(0.0f, 1 - z * z));
        w = make_float3(s * std::cos(phi), s * std::sin(phi), z);
      } else if (kind == 2) {
        w = i % 8 == 2 ? o : make_float3(o.y, -o.x, 0.0f);
      } else {
        float r = std::sqrt(uni()), phi = 6.2831853f * uni();
        w = make_float3(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1 - r * r)));
      }
      p.mats.push_back(m);
      p.wo.push_back(f4_from3(o, 0));
      p.wi.push_back(f4_from3(w, 0));
      p.u.push_back(f4_from3(uu, 0));
    }
  return p;
}

bool is_coated(const Material& m) {
  return m.type == MATERIAL_COATED_DIFFUSE || m.type == MATERIAL_COATED_CONDUCTOR;
}

// Relative tolerance of a value of material m (see the header comment).
float tolerance(const Material& m) {
  float tol = 2e-5f;
  if (m.type != MATERIAL_DIFFUSE && m.alpha > 0) tol += 8 * 5.9604645e-8f / m.alpha;
  if (m.type == MATERIAL_COATED_CONDUCTOR && m.base_alpha > 0)
    tol += 8 * 5.9604645e-8f / m.base_alpha;
  return is_coated(m) ? 10 * tol : tol; // a walk compounds a few such values
}

void expect_rel(float dev, float host, float tol, const std::string& what) {
  EXPECT_NEAR(dev, host, tol * std::max({std::fabs(dev), std::fabs(host), 1e-30f})) << what;
}

bool near_rel(float dev, float host, float tol) {
  return std::fabs(dev - host) <= tol * std::max({std::fabs(dev), std::fabs(host), 1e-30f});
}

// A coated material's probe i: the device's values against the host's (see the header comment).
bool coated_probe_matches(const Material& m, const Probes& p, int i, float4 f_pdf, float4 s_wi_pdf,
                          float4 s_weight, int2 flags) {
  float3 o = xyz_of(p.wo[i]), w = xyz_of(p.wi[i]);
  float tol = tolerance(m);
  float3 f = bsdf_eval(&m, o, w);
  bool ok = near_rel(f_pdf.x, f.x, tol) && near_rel(f_pdf.y, f.y, tol) &&
            near_rel(f_pdf.z, f.z, tol) && near_rel(f_pdf.w, bsdf_pdf(&m, o, w), tol);
  BsdfSample s = bsdf_sample(&m, o, xyz_of(p.u[i]));
  float3 dwi = xyz_of(s_wi_pdf);
  EXPECT_EQ(flags.y, bsdf_has_smooth_lobe(&m)); // a property of the material: always equal
  ok = ok && flags.x == s.is_delta && std::fabs(dwi.x - s.wi.x) <= 1e-4f &&
       std::fabs(dwi.y - s.wi.y) <= 1e-4f && std::fabs(dwi.z - s.wi.z) <= 1e-4f;
  ok = ok && near_rel(s_weight.x, s.weight.x, tol) && near_rel(s_weight.z, s.weight.z, tol);
  if (!s.is_delta && max3(s.weight) > 0) ok = ok && near_rel(s_wi_pdf.w, bsdf_pdf(&m, o, dwi), tol);
  EXPECT_TRUE(std::isfinite(f_pdf.x + f_pdf.y + f_pdf.z + f_pdf.w + s_weight.x + s_weight.y +
                            s_weight.z + s_wi_pdf.w));
  return ok;
}

void run_probes(ClRuntime& rt, const std::string& options, const std::vector<Material>& materials,
                uint32_t seed) {
  cl::Program program = build_probe_program(rt, kProbeKernel, options);
  if (::testing::Test::HasFailure()) return;
  Probes p = make_probes(materials, seed);
  const int n = int(p.mats.size());
  const cl::Context& ctx = rt.context();
  cl::Buffer mats = upload_buffer(ctx, p.mats), wo = upload_buffer(ctx, p.wo),
             wi = upload_buffer(ctx, p.wi), u = upload_buffer(ctx, p.u);
  cl::Buffer f_pdf(ctx, CL_MEM_WRITE_ONLY, sizeof(float4) * n),
      s_wi_pdf(ctx, CL_MEM_WRITE_ONLY, sizeof(float4) * n),
      s_weight(ctx, CL_MEM_WRITE_ONLY, sizeof(float4) * n),
      flags(ctx, CL_MEM_WRITE_ONLY, sizeof(int2) * n);
  cl::Kernel k(program, "bsdf_probe");
  int a = 0;
  for (const cl::Buffer* b : {&mats, &wo, &wi, &u})
    k.setArg(a++, *b);
  k.setArg(a++, n);
  for (const cl::Buffer* b : {&f_pdf, &s_wi_pdf, &s_weight, &flags})
    k.setArg(a++, *b);
  enqueue_1d(rt.queue(), k, size_t(n));
  std::vector<float4> d_f_pdf(n), d_s_wi_pdf(n), d_s_weight(n);
  std::vector<int2> d_flags(n);
  rt.queue().enqueueReadBuffer(f_pdf, CL_TRUE, 0, sizeof(float4) * n, d_f_pdf.data());
  rt.queue().enqueueReadBuffer(s_wi_pdf, CL_TRUE, 0, sizeof(float4) * n, d_s_wi_pdf.data());
  rt.queue().enqueueReadBuffer(s_weight, CL_TRUE, 0, sizeof(float4) * n, d_s_weight.data());
  rt.queue().enqueueReadBuffer(flags, CL_TRUE, 0, sizeof(int2) * n, d_flags.data());

  int compared_samples = 0, coated = 0, coated_off = 0;
  for (int i = 0; i < n && !::testing::Test::HasFailure(); ++i) {
    const Material& m = p.mats[i];
    if (is_coated(m)) {
      ++coated;
      coated_off +=
          !coated_probe_matches(m, p, i, d_f_pdf[i], d_s_wi_pdf[i], d_s_weight[i], d_flags[i]);
      continue;
    }
    float3 o = xyz_of(p.wo[i]), w = xyz_of(p.wi[i]);
    std::string what = "probe " + std::to_string(i) + " type " + std::to_string(m.type) +
                       " alpha " + std::to_string(m.alpha) + " wo.z " + std::to_string(o.z) +
                       " wi.z " + std::to_string(w.z);
    float tol = tolerance(m);
    float3 f = bsdf_eval(&m, o, w);
    expect_rel(d_f_pdf[i].x, f.x, tol, what + " eval.x");
    expect_rel(d_f_pdf[i].y, f.y, tol, what + " eval.y");
    expect_rel(d_f_pdf[i].z, f.z, tol, what + " eval.z");
    expect_rel(d_f_pdf[i].w, bsdf_pdf(&m, o, w), tol, what + " pdf");

    BsdfSample s = bsdf_sample(&m, o, xyz_of(p.u[i]));
    EXPECT_EQ(d_flags[i].x, s.is_delta) << what;
    EXPECT_EQ(d_flags[i].y, bsdf_has_smooth_lobe(&m)) << what;
    float3 dwi = xyz_of(d_s_wi_pdf[i]);
    EXPECT_NEAR(dwi.x, s.wi.x, 2e-5f) << what;
    EXPECT_NEAR(dwi.y, s.wi.y, 2e-5f) << what;
    EXPECT_NEAR(dwi.z, s.wi.z, 2e-5f) << what;
    float dpdf = d_s_wi_pdf[i].w;
    float3 dweight = xyz_of(d_s_weight[i]);
    if (std::fabs(s.wi.z) < 1e-4f) continue; // at the horizon: absorbed on one side only
    if (s.is_delta) {
      EXPECT_EQ(dpdf, 0.0f) << what;
      expect_rel(dweight.x, s.weight.x, 2e-5f, what + " delta weight");
      expect_rel(dweight.z, s.weight.z, 2e-5f, what + " delta weight");
      ++compared_samples;
      continue;
    }
    if (!(max3(s.weight) > 0) && !(s.pdf > 0)) { // absorbed on the host: so on the device
      EXPECT_EQ(max3(dweight), 0.0f) << what;
      EXPECT_EQ(dpdf, 0.0f) << what;
      continue;
    }
    // The device's pdf and weight against the host's functions at the device's direction.
    float hp = bsdf_pdf(&m, o, dwi);
    expect_rel(dpdf, hp, tol, what + " sample pdf");
    if (hp > 0) {
      float3 hw = bsdf_eval(&m, o, dwi) * (std::fabs(dwi.z) / hp); // (refraction: wi.z < 0)
      expect_rel(dweight.x, hw.x, 2 * tol, what + " sample weight.x");
      expect_rel(dweight.y, hw.y, 2 * tol, what + " sample weight.y");
      expect_rel(dweight.z, hw.z, 2 * tol, what + " sample weight.z");
    } else {
      EXPECT_EQ(dweight.x, 0.0f) << what;
    }
    ++compared_samples;
  }
  if (coated < n) {
    EXPECT_GT(compared_samples, (n - coated) / 2);
  }
  EXPECT_LE(coated_off, coated / 200) << "of " << coated << " coated probes";
}

std::vector<Material> all_materials() {
  std::vector<Material> v = {diffuse(),
                             test::make_diffuse_transmission(make_float3(0.25f, 0.25f, 0.25f),
                                                             make_float3(0.25f, 0.25f, 0.25f)),
                             test::make_diffuse_transmission(make_float3(0.1f, 0.3f, 0.2f),
                                                             make_float3(0.8f, 0.6f, 0.7f))};
  for (float a : {0.0f, 1e-4f, 0.01f, 0.09f, 1.0f}) {
    v.push_back(conductor(a));
    v.push_back(plastic(a));
  }
  // Glass seen from outside, from inside (beyond the critical angle: total internal reflection),
  // index-matched (it passes everything straight on), and a thin sheet.
  for (float ior : {1.5f, 1.0f / 1.5f, 1.0f, 2.4f})
    v.push_back(make_dielectric(ior));
  v.push_back(make_dielectric(1.5f, true));
  // Rough glass, from outside and from inside.
  for (float a : {1e-4f, 0.09f, 1.0f}) {
    v.push_back(make_dielectric(1.5f, false, a));
    v.push_back(make_dielectric(1.0f / 1.5f, false, a));
  }
  // Coated: smooth and rough coats, a scattering slab, conductor bases from a mirror to rough.
  const Layer slab{0.5f, {0.8f, 0.6f, 0.4f}, 0.3f, 10, 2};
  for (float a : {0.0f, 0.01f, 0.3f}) {
    v.push_back(make_coated_diffuse(make_float3(0.8f, 0.5f, 0.2f), 1.5f, a));
    v.push_back(make_coated_diffuse(make_float3(0.8f, 0.5f, 0.2f), 1.5f, a, slab));
    for (float base : {0.0f, 0.09f})
      v.push_back(make_coated_conductor(1.5f, a, make_float3(0.18f, 0.42f, 1.37f),
                                        make_float3(3.42f, 2.35f, 1.77f), base));
  }
  return v;
}

std::string features(bool conductor_on, bool plastic_on, bool dielectric_on = false,
                     bool coated_on = false, bool transmission_on = false) {
  KernelFeatures f;
  f.material_diffuse_transmission = transmission_on;
  f.material_conductor = conductor_on;
  f.material_plastic = plastic_on;
  f.material_dielectric = dielectric_on;
  f.material_coated = coated_on;
  return f.build_options();
}

} // namespace

TEST(KernelBsdf, EveryMaterialMatchesHost) {
  ClRuntime rt;
  run_probes(rt, "", all_materials(), 1); // no CANOPY_FEATURES_SET: everything on
}

// Each material feature alone (the host, compiled with everything on, computes the same values:
// a feature only removes code for types the scene does not have).
TEST(KernelBsdf, SpecialisedKernelsMatchHost) {
  ClRuntime rt;
  std::vector<Material> conductors, plastics, glass, coated, transmitters;
  for (const Material& m : all_materials()) {
    if (m.type == MATERIAL_DIFFUSE_TRANSMISSION) transmitters.push_back(m);
    if (m.type == MATERIAL_CONDUCTOR) conductors.push_back(m);
    if (m.type == MATERIAL_PLASTIC) plastics.push_back(m);
    if (m.type == MATERIAL_DIELECTRIC || m.type == MATERIAL_THIN_DIELECTRIC) glass.push_back(m);
    if (is_coated(m)) coated.push_back(m);
  }
  run_probes(rt, features(false, false), {diffuse()}, 2); // diffuse only: no GGX code
  run_probes(rt, features(true, false), conductors, 3);
  run_probes(rt, features(false, true), plastics, 4);
  run_probes(rt, features(false, false, true), glass, 5);         // glass: no BRDF-glossy code
  run_probes(rt, features(false, false, false, true), coated, 6); // coated alone
  // diffuse transmission alone: no GGX code either
  run_probes(rt, features(false, false, false, false, true), transmitters, 7);
}
