// Unbiasedness of the per-point direct-light estimator of brdf-mis / brdf-oriented (Liu, Xu & Yan
// 2019 §5; cl/integrator/brdf_mis.h): the wavefront is emulated on the host for one glossy
// shading point with the very per-item functions the kernels run (brdf_cut_item, light_pick_item
// passes with shadow rays, brdf_sample_item / brdf_trace_item / brdf_accumulate_item rounds), over
// a real BVH so that the BSDF probes find the area lights (and an occluder). The mean over many
// runs (independent seeds through shade_N.w) must match
// - for point and spot lights alone, the exact sum_l f(wo, wi_l) cos(theta_l) I_l / d_l^2 V_l;
// - with area lights, the mean of an independent unbiased estimator: light sampling of every
//   light once (the exhaustive sampler) and one BSDF sample, combined by the power heuristic,
// within 5 combined standard errors, for adaptive and equal allocation and brdf-oriented alone, on
// conductor, plastic and coated points of several roughnesses. Every sample must be finite.
#include "accel/bvh.h"
#include "integrator/brdf_mis.h"
#include "integrator/light_pick.h"
#include "integrator/shade_surface.h"
#include "render/light_sampler_data.h"
#include "scene/scene.h"

#include "support/glossy_points.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>

using namespace canopy;
using namespace canopy::test;

namespace {

// An occluder box between the point (at the origin, normal +y) and some of the lights; lights of
// every type around and above it, some culled (below the horizon, facing away). The camera (not
// rendered from) is at 0, so the scene origin is 0 and kP is a world point (Scene::origin).
const char* kAreaScene = R"({
  "camera": { "position": [0, 0, 0], "look_at": [0, -1, -5] },
  "film": { "width": 4, "height": 4 },
  "materials": [ { "name": "white", "albedo": 0.5 } ],
  "shapes": [ { "type": "box", "material": "white", "min": [0.5, 0.6, -0.3], "max": [0.9, 0.7, 0.3] } ],
  "lights": [
    { "type": "point", "position": [1.5, 1.2, 0.2], "intensity": [3, 2, 1] },
    { "type": "point", "position": [0.3, 0.2, -1.0], "intensity": 1 },
    { "type": "point", "position": [0, -1, 0], "intensity": 5 },
    { "type": "spot", "position": [-1, 2, 0.5], "direction": [0.5, -1, -0.2], "intensity": 10,
      "cone_angle": 30, "falloff_start": 20 },
    { "type": "sphere", "center": [-1.2, 0.8, -0.4], "radius": 0.25, "radiance": [4, 3, 2] },
    { "type": "sphere", "center": [1.1, 1.6, 0.0], "radius": 0.2, "radiance": 6 },
    { "type": "quad", "corner": [-0.5, 2.0, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1],
      "radiance": [2, 2, 3] },
    { "type": "quad", "corner": [-2, 1.0, 1.0], "edge1": [0, 0.6, 0], "edge2": [0, 0, 0.6],
      "radiance": 3 },
    { "type": "quad", "corner": [-1, 3.0, -1], "edge1": [0, 0, 2], "edge2": [2, 0, 0], "radiance": 9 },
    { "type": "triangle", "v0": [1.5, 0.3, -1.5], "v1": [2.0, 1.3, -1.0], "v2": [1.0, 1.0, -2.0],
      "radiance": [1, 3, 1], "two_sided": true },
    { "type": "disk", "center": [0.6, 1.5, 1.2], "normal": [-0.3, -1, -0.6], "radius": 0.3,
      "radiance": [5, 4, 4] },
    { "type": "disk", "center": [-0.4, 0.4, 1.3], "normal": [0.2, 0.3, -1], "radius": 0.2,
      "radiance": 4, "two_sided": true }
  ],
  "light_sets": [
    { "type": "random_box", "min": [-2, 0.5, -2], "max": [2, 2.5, 2], "count": 40, "seed": 5,
      "light": { "type": "point", "intensity": 0.1 } }
  ]
})";

// Point and spot lights only (the exact reference), the same occluder.
const char* kDeltaScene = R"({
  "camera": { "position": [0, 0, 0], "look_at": [0, -1, -5] },
  "film": { "width": 4, "height": 4 },
  "materials": [ { "name": "white", "albedo": 0.5 } ],
  "shapes": [ { "type": "box", "material": "white", "min": [0.5, 0.6, -0.3], "max": [0.9, 0.7, 0.3] } ],
  "lights": [
    { "type": "point", "position": [1.5, 1.2, 0.1], "intensity": [3, 2, 1] },
    { "type": "point", "position": [0.3, 0.2, -1.0], "intensity": 1 },
    { "type": "point", "position": [0, -1, 0], "intensity": 5 },
    { "type": "point", "position": [-0.8, 1.0, 0.3], "intensity": 2 },
    { "type": "spot", "position": [-1, 2, 0.5], "direction": [0.5, -1, -0.2], "intensity": 10,
      "cone_angle": 30, "falloff_start": 20 },
    { "type": "spot", "position": [1, 1.5, 1], "direction": [-0.5, -1, -0.5], "intensity": 4,
      "cone_angle": 50, "falloff_start": 10 }
  ],
  "light_sets": [
    { "type": "random_box", "min": [-2, 0.5, -2], "max": [2, 2.5, 2], "count": 60, "seed": 6,
      "light": { "type": "point", "intensity": 0.2 } }
  ]
})";

Material conductor(float roughness) {
  return gold_conductor(roughness);
}
// Coated (cl/bsdf/layered.h): a rough coat over a diffuse base with a scattering slab, and over
// a rough gold base. Their BSDF's eval and pdf are estimates: the estimator stays unbiased.
Material coated_diffuse(float roughness) {
  return make_coated_diffuse(make_float3(0.6f, 0.4f, 0.2f), 1.5f, roughness * roughness,
                             {0.1f, {0.5f, 0.5f, 0.5f}, 0.2f, 10, 1});
}
Material coated_gold(float roughness) {
  return make_coated_conductor(1.5f, roughness * roughness, make_float3(0.18f, 0.42f, 1.37f),
                               make_float3(3.42f, 2.35f, 1.77f), 0.1f);
}
Material plastic(float roughness) {
  return blue_plastic(roughness);
}

using Paths = canopy::test::HostPaths;

const float3 kP = make_float3(0, 0, 0), kN = make_float3(0, 1, 0);

class BrdfMisEstimator : public ::testing::Test {
protected:
  void load(const char* json) {
    scene_ = load_scene_from_string(json, "brdf-estimator.json", ".");
    for (const MaterialDesc& m : scene_.materials)
      materials_.push_back(m.gpu);
    geometry_ = build_scene_geometry(scene_, materials_);
  }
  SceneBuffers scene_buffers() {
    return SceneBuffers{geometry_.bvh.nodes.data(),       geometry_.bvh.leaf_blocks.data(),
                        geometry_.prims.data(),           materials_.data(),
                        geometry_.shading_normals.data(), &scene_.medium}; // vacuum
  }
  bool occluded(float3 o, float3 d, float tmax) {
    Hit h;
    return bvh_intersect(geometry_.bvh.nodes.data(), geometry_.bvh.leaf_blocks.data(),
                         geometry_.prims.data(), o, d, 0.0f, tmax, 1, &h) >= 0;
  }

  // `runs` independent estimates of the direct light at kP (material `m`, view direction wo) by
  // `sampler` (brdf_weighted: the point is glossy under a BRDF sampler), one path per run, as
  // the renderer's stages compute them. Returns each run's radiance.
  std::vector<float3> estimate(const std::string& sampler, const BrdfSettings& brdf,
                               const Material& m, float3 wo, int runs, uint32_t seed) {
    std::vector<Material> mats = materials_;
    mats.push_back(m);
    SceneBuffers sc = scene_buffers();
    sc.materials = mats.data();
    LightSamplerData data =
        make_light_sampler_data(scene_.lights, sampler, LT_DEFAULT_SPLIT_THRESHOLD, 8, true, brdf);
    std::vector<float2> cut(size_t(runs) * LT_BRDF_MAX_CUT);
    LightSamplerCtx ls = data.host_view(scene_.lights, cut.data());
    const bool brdf_sampler = data.brdf_oriented();
    Paths p;
#define PATH_RESIZE(T, name) p.name.assign(size_t(runs), T{});
    PATH_STATE_BUFFERS(PATH_RESIZE)
#undef PATH_RESIZE
    const int mat = int(mats.size()) - 1;
    for (int i = 0; i < runs; ++i) { // the shade state as shade_surface_item leaves it
      size_t k = size_t(i);
      LtRng r = lt_rng_make(seed, uint32_t(i));
      uint32_t light_seed = lt_rng_next_u32(&r);
      p.shade_P[k] = f4_from3(kP, 0.0f);
      p.shade_N[k] = f4_from3(kN, uint_as_float_(light_seed));
      p.shade_Ns[k] = f4_from3(kN, uint_as_float_(uint32_t(mat)));
      p.shade_wo[k] = f4_from3(wo, 0.0f);
      // A glossy point of a BRDF sampler; the reference (exhaustive) point with MIS against the
      // BSDF sample added below.
      p.shade_f[k] = make_float4(1, 1, 1, brdf_sampler ? BRDF_POINT_FLAG : 1.0f);
      p.brdf_state[k] = make_int4(0, brdf_sampler ? -1 : 0, 0, 0);
      p.radiance[k] = make_float4(0, 0, 0, 0);
    }
    PathBuffers pb = p.host();
    // brdf_cut
    if (brdf_sampler)
      for (int i = 0; i < runs; ++i)
        brdf_cut_item(i, &ls, &sc, &pb);
    // light_pick passes (brdf-oriented takes no tree light sample at glossy points), shadow rays
    // traced and their contributions added (intersect_shadow, accumulate_shadow)
    std::vector<SplitItem> items;
    if (sampler != "brdf-oriented")
      for (int i = 0; i < runs; ++i)
        items.push_back(light_sampler_root(&ls, i));
    for (int pass = 0; !items.empty(); ++pass) {
      EXPECT_LT(pass, 40);
      std::vector<SplitItem> next;
      for (const SplitItem& it : items) {
        SplitItem children[4];
        ShadowItem shadows[4];
        int4 r = light_pick_item(it, &ls, &sc, &pb, children, shadows);
        for (int j = 0; j < r.x; ++j)
          next.push_back(children[j]);
        for (int j = 0; j < r.y; ++j) {
          const ShadowItem& s = shadows[j];
          if (occluded(xyz_of(s.origin), xyz_of(s.dir), s.origin.w)) continue;
          size_t path = float_as_uint_(s.dir.w);
          p.radiance[path] = p.radiance[path] + s.contribution;
        }
      }
      items.swap(next);
    }
    if (!brdf_sampler) // the reference's BSDF sample, power heuristic against light sampling
      for (int i = 0; i < runs; ++i)
        p.radiance[size_t(i)] =
            p.radiance[size_t(i)] + f4_from3(bsdf_sample_mis(m, wo, seed, i), 0);
    // rounds of BRDF-aware samples
    const int rounds =
        !brdf_sampler
            ? 0
            : brdf_rounds_for(sampler == "brdf-oriented" ? 1 : (brdf.adaptive ? brdf.n_max : 2));
    std::vector<BrdfItem> stage(BRDF_MAX_BATCH), queue;
    for (int round = 0; round < rounds; ++round) {
      queue.clear();
      for (int i = 0; i < runs; ++i) {
        int n = brdf_sample_item(i, round, &ls, &sc, &pb, stage.data());
        EXPECT_LE(n, brdf_round_batch(round));
        queue.insert(queue.end(), stage.begin(), stage.begin() + n);
      }
      for (BrdfItem& it : queue)
        brdf_trace_item(&it, &ls, &sc, &pb);
      int total = 0;
      for (int i = 0; i < int(queue.size()); ++i)
        total += brdf_accumulate_item(i, queue.data(), int(queue.size()), &pb);
      EXPECT_EQ(total, int(queue.size()));
    }
    for (int i = 0; i < runs && brdf_sampler; ++i) // every point drew its N samples
      EXPECT_EQ(p.brdf_state[size_t(i)].z, p.brdf_state[size_t(i)].y) << "run " << i;
    std::vector<float3> out(static_cast<size_t>(runs));
    for (int i = 0; i < runs; ++i)
      out[size_t(i)] = xyz_of(p.radiance[size_t(i)]);
    return out;
  }

  // One BSDF-sampled direction from kP: the emission it finds times f cos / pdf, weighted by the
  // power heuristic against light sampling of every light once (pmf 1, density light_pdf).
  float3 bsdf_sample_mis(const Material& m, float3 wo, uint32_t seed, int run) {
    Frame fr = frame_from(kN);
    LtRng r = lt_rng_make(seed ^ 0x9e3779b9u, uint32_t(run));
    float3 u = make_float3(lt_rng_next(&r), lt_rng_next(&r), lt_rng_next(&r));
    BsdfSample bs = bsdf_sample(&m, frame_to_local(&fr, wo), u);
    float3 zero = make_float3(0, 0, 0);
    float3 wi = normalize(frame_to_world(&fr, bs.wi));
    if (bs.is_delta || !(bs.pdf > 0) || !(dot(wi, kN) > 0)) return zero;
    Hit h;
    if (bvh_intersect(geometry_.bvh.nodes.data(), geometry_.bvh.leaf_blocks.data(),
                      geometry_.prims.data(), kP, wi, 0.0f, FLT_INF, 0, &h) < 0)
      return zero;
    const Primitive* prim = &geometry_.prims[size_t(h.prim)];
    if (prim->light < 0) return zero;
    const Light* l = &scene_.lights[size_t(prim->light)];
    float3 err;
    float3 y = primitive_hit_point(prim, kP, wi, h, &err);
    float3 Le = light_emitted_radiance(l, primitive_normal(prim, y), -wi);
    return bs.weight * Le * power_heuristic(bs.pdf, light_pdf(l, kP, y));
  }

  Scene scene_;
  std::vector<Material> materials_;
  SceneGeometry geometry_;
};

} // namespace

namespace {

struct Stats {
  double mean[3] = {0, 0, 0}, var[3] = {0, 0, 0}; // sample mean and variance per channel
  bool finite = true;
};
Stats stats(const std::vector<float3>& v) {
  Stats s;
  double n = double(v.size());
  for (const float3& x : v) {
    s.finite = s.finite && std::isfinite(x.x) && std::isfinite(x.y) && std::isfinite(x.z);
    s.mean[0] += x.x / n, s.mean[1] += x.y / n, s.mean[2] += x.z / n;
  }
  for (const float3& x : v) {
    double d[3] = {x.x - s.mean[0], x.y - s.mean[1], x.z - s.mean[2]};
    for (int c = 0; c < 3; ++c)
      s.var[c] += d[c] * d[c] / (n - 1);
  }
  return s;
}

struct Config {
  const char* sampler;
  BrdfSettings brdf;
  const char* label;
};
std::vector<Config> configs() {
  BrdfSettings adaptive, small, equal;
  small.n_max = 6; // few samples: N = ceil(6 I_B) varies from point to point
  equal.adaptive = false;
  return {{"brdf-mis", adaptive, "brdf-mis adaptive (N_max 50)"},
          {"brdf-mis", small, "brdf-mis adaptive (N_max 6)"},
          {"brdf-mis", equal, "brdf-mis equal allocation"},
          {"brdf-oriented", adaptive, "brdf-oriented"}};
}
struct Surface {
  Material m;
  float3 wo;
  const char* label;
};
// Conductor and plastic points of several roughnesses; wo such that the mirror direction meets
// the ceiling quad, the sphere at (1.1, 1.6, 0), the side of the room or nothing.
std::vector<Surface> surfaces() {
  return {{conductor(0.08f), normalize(make_float3(-0.1f, 1.0f, -0.1f)), "conductor 0.08"},
          {conductor(0.3f), normalize(make_float3(-1.1f, 1.6f, 0.0f)), "conductor 0.3"},
          {conductor(0.8f), normalize(make_float3(0.7f, 0.4f, 0.5f)), "conductor 0.8"},
          {plastic(0.15f), normalize(make_float3(-1.1f, 1.6f, 0.0f)), "plastic 0.15"},
          {plastic(0.5f), normalize(make_float3(0.2f, 0.3f, -0.9f)), "plastic 0.5"},
          {coated_diffuse(0.3f), normalize(make_float3(-1.1f, 1.6f, 0.0f)), "coated diffuse 0.3"},
          {coated_gold(0.2f), normalize(make_float3(-0.1f, 1.0f, -0.1f)), "coated conductor 0.2"}};
}

double elapsed(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace

// Point and spot lights: the exact direct light sum_l f cos I / d^2 V (sample_light gives a delta
// light's exact Li; visibility by an independent shadow ray to the light's position).
TEST_F(BrdfMisEstimator, UnbiasedForPointAndSpotLightsAgainstTheExactSum) {
  load(kDeltaScene);
  auto t0 = std::chrono::steady_clock::now();
  const int runs = 3000;
  int checked = 0;
  for (const Surface& srf : surfaces()) {
    Frame fr = frame_from(kN);
    float3 wo_local = frame_to_local(&fr, srf.wo);
    double exact[3] = {0, 0, 0};
    int visible = 0;
    for (const Light& l : scene_.lights) {
      LightSample s = sample_light(&l, kP, 0.5f, 0.5f);
      ASSERT_TRUE(s.is_delta);
      if (!(s.pdf > 0) || !(dot(kN, s.wi) > 0) || !(max3(s.Li) > 0)) continue;
      float dist = length(s.x - kP);
      if (occluded(kP, s.wi, dist * (1 - 1e-4f))) continue;
      ++visible;
      float3 wi = frame_to_local(&fr, s.wi);
      float3 f = bsdf_eval(&srf.m, wo_local, wi) * wi.z * s.Li / s.pdf;
      exact[0] += f.x, exact[1] += f.y, exact[2] += f.z;
    }
    ASSERT_GT(visible, 20);
    ASSERT_LT(visible, int(scene_.lights.size())); // one is below the horizon
    for (const Config& cfg : configs()) {
      SCOPED_TRACE(std::string(cfg.label) + ", " + srf.label);
      Stats s =
          stats(estimate(cfg.sampler, cfg.brdf, srf.m, srf.wo, runs, 11u + uint32_t(checked)));
      ASSERT_TRUE(s.finite);
      for (int c = 0; c < 3; ++c) {
        double se = std::sqrt(s.var[c] / runs);
        EXPECT_TRUE(std::isfinite(s.var[c]));
        EXPECT_LE(std::fabs(s.mean[c] - exact[c]), 5 * se + 1e-6 * exact[c])
            << "channel " << c << ": mean " << s.mean[c] << " exact " << exact[c] << " (se " << se
            << ")";
      }
      ++checked;
    }
  }
  std::printf("delta lights: %d configurations, %.1f s\n", checked, elapsed(t0));
}

// Every light type, an occluder and culled lights: against light sampling of every light
// (exhaustive sampler) + a BSDF sample with the power heuristic, an independent unbiased estimator
// of the same integral.
TEST_F(BrdfMisEstimator, UnbiasedForAreaLightsAgainstLightSampling) {
  load(kAreaScene);
  auto t0 = std::chrono::steady_clock::now();
  const int runs = 3000, ref_runs = 20000;
  int checked = 0;
  for (const Surface& srf : surfaces()) {
    Stats ref = stats(estimate("exhaustive", BrdfSettings(), srf.m, srf.wo, ref_runs, 7));
    ASSERT_TRUE(ref.finite);
    for (const Config& cfg : configs()) {
      SCOPED_TRACE(std::string(cfg.label) + ", " + srf.label);
      Stats s =
          stats(estimate(cfg.sampler, cfg.brdf, srf.m, srf.wo, runs, 101u + uint32_t(checked)));
      ASSERT_TRUE(s.finite);
      for (int c = 0; c < 3; ++c) {
        double se = std::sqrt(s.var[c] / runs + ref.var[c] / ref_runs);
        EXPECT_TRUE(std::isfinite(s.var[c]));
        EXPECT_LE(std::fabs(s.mean[c] - ref.mean[c]), 5 * se)
            << "channel " << c << ": mean " << s.mean[c] << " reference " << ref.mean[c]
            << " (combined se " << se << ")";
        // The comparison is sharp enough to see a missing light or technique (brdf-oriented
        // alone, one light sample per point, is far noisier on sharp lobes; a coated point's
        // BSDF values are themselves estimates, which adds their noise).
        const bool coated =
            srf.m.type == MATERIAL_COATED_DIFFUSE || srf.m.type == MATERIAL_COATED_CONDUCTOR;
        if (std::string(cfg.sampler) == "brdf-mis") {
          EXPECT_LT(5 * se, (coated ? 0.3 : 0.1) * ref.mean[c]) << "channel " << c;
        }
      }
      ++checked;
    }
  }
  std::printf("area lights: %d configurations, %.1f s\n", checked, elapsed(t0));
}

// A single point light over a glossy plane: tree-split takes the light with probability 1 and its
// Li exactly, so its estimate has no variance. brdf-mis must not add any: the power heuristic
// against the BRDF-aware samples (p_L = 1 against N s p_B) gave them a share of the light, and
// their number of light samples is random (each is BRDF-oriented with Alg. 1's p_i, scaled by
// 1 / p_i): runs 8.2% above the exact value with adaptive allocation (N = 1, p_0 = 1 / 11). The
// tree keeps an exact estimate's whole weight (brdf_weight_tree). Every run must be the
// exact sum up to float rounding, for each allocation, on plastic, conductor and coated points of
// several roughnesses, with the light above the point, near the mirror direction and near the
// horizon.
TEST_F(BrdfMisEstimator, PointLightAloneAddsNoVarianceToTheExactTreeEstimate) {
  int checked = 0;
  for (const char* light : {"[0.3, 1.0, -0.5]", "[0.6, 1.0, 0.3]", "[-1.5, 0.1, 0.4]"}) {
    scene_ = Scene();
    materials_.clear();
    load((std::string(R"({ "camera": { "position": [0, 0, 0], "look_at": [0, -1, -5] },
      "film": { "width": 4, "height": 4 },
      "lights": [ { "type": "point", "position": )") +
          light + R"(, "intensity": [3, 2, 1] } ] })")
             .c_str());
    for (const Surface& srf : surfaces()) {
      Frame fr = frame_from(kN);
      LightSample ls = sample_light(&scene_.lights[0], kP, 0.5f, 0.5f);
      float3 wi = frame_to_local(&fr, ls.wi);
      float3 f = bsdf_eval(&srf.m, frame_to_local(&fr, srf.wo), wi) * wi.z * ls.Li;
      double exact[3] = {f.x, f.y, f.z};
      for (const char* sampler : {"tree-split", "brdf-mis"})
        for (const Config& cfg : configs()) {
          if (std::string(cfg.sampler) != "brdf-mis") continue;
          SCOPED_TRACE(std::string(sampler) + ", " + cfg.label + ", " + srf.label + ", light at " +
                       light);
          std::vector<float3> runs = estimate(sampler, cfg.brdf, srf.m, srf.wo, 2000, 5u);
          double worst = 0;
          for (const float3& x : runs) {
            const float v[3] = {x.x, x.y, x.z};
            for (int c = 0; c < 3; ++c)
              worst = std::max(worst, std::fabs(v[c] - exact[c]) / std::max(exact[c], 1e-30));
          }
          // float rounding of the estimate's few products (the weight is 1 and pmf 1 exactly)
          EXPECT_LE(worst, 1e-5) << "largest relative deviation of a run from the exact value";
          ++checked;
        }
    }
  }
  EXPECT_EQ(checked, 3 * 7 * 2 * 3);
}

// A path whose ray escapes has no shading point: whatever its brdf_state held before (the
// previous wave's path in the same slot, or a buffer never written: the renderer does not clear
// it), the bounce's stages must do nothing for it. Stale state (cut of 3 clusters, N = 5, none
// drawn yet) made brdf_sample draw from a cut that is not this path's.
TEST_F(BrdfMisEstimator, EscapedPathDrawsNoBrdfSamplesWhateverItsStaleState) {
  load(kAreaScene);
  std::vector<Material> mats = materials_;
  mats.push_back(conductor(0.3f));
  SceneBuffers sc = scene_buffers();
  sc.materials = mats.data();
  for (const char* sampler : {"brdf-mis", "brdf-oriented"}) {
    SCOPED_TRACE(sampler);
    LightSamplerData data =
        make_light_sampler_data(scene_.lights, sampler, LT_DEFAULT_SPLIT_THRESHOLD, 8, true);
    std::vector<float2> cut(LT_BRDF_MAX_CUT, make_float2(uint_as_float_(0u), 1.0f));
    LightSamplerCtx ls = data.host_view(scene_.lights, cut.data());
    Paths p;
#define PATH_RESIZE(T, name) p.name.assign(1, T{});
    PATH_STATE_BUFFERS(PATH_RESIZE)
#undef PATH_RESIZE
    // The previous bounce's glossy point, its cut and state as a previous wave left them.
    p.shade_P[0] = f4_from3(kP, 0.0f);
    p.shade_N[0] = f4_from3(kN, uint_as_float_(12345u));
    p.shade_Ns[0] = f4_from3(kN, uint_as_float_(uint32_t(mats.size() - 1)));
    p.shade_wo[0] = f4_from3(normalize(make_float3(0.3f, 1, 0)), 0.0f);
    p.shade_f[0] = make_float4(1, 1, 1, BRDF_POINT_FLAG);
    p.brdf_state[0] = make_int4(3, 5, 0, 1 | (1 << 16));
    p.hits[0].prim = -1; // this bounce's ray escaped
    p.ray_d[0] = make_float4(0, 1, 0, 0);
    PathBuffers pb = p.host();
    int2 shaded = shade_surface_item(0, 1, 3, &sc, &pb, &ls);
    EXPECT_EQ(shaded.x, 0);
    EXPECT_EQ(shaded.y, 0);
    int2 c = brdf_cut_item(0, &ls, &sc, &pb);
    EXPECT_EQ(c.x, 0);
    std::vector<BrdfItem> stage(BRDF_MAX_BATCH);
    for (int round = 0; round < brdf_rounds_for(50); ++round)
      EXPECT_EQ(brdf_sample_item(0, round, &ls, &sc, &pb, stage.data()), 0) << "round " << round;
    EXPECT_EQ(p.radiance[0].x, 0.0f);
  }
}
