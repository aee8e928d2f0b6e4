// BRDF-oriented sampling (brdf-mis, brdf-oriented; cl/kernels/brdf_mis.cl) costs nothing where
// it does not apply: for a scene without glossy materials the program holds none of its kernels
// and brdf-mis renders exactly what tree-split renders (it is tree-split at non-glossy points),
// while a glossy scene's program has all of them. Where it applies, the whole renderer loop
// (cuts, split passes, rounds of BRDF-aware samples, the continuation ray's emission left out at
// glossy points, several bounces) renders the image tree-split renders, within its noise.
#include "render/features.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

using namespace canopy;

namespace {

// A diffuse room: every material Lambertian; lights of several types and a set of points, so
// that the tree splits.
const char* kDiffuseScene = R"({
  "camera": { "position": [0, 1.5, 2.8], "look_at": [0, 1, 0], "up": [0, 1, 0], "fov": 70 },
  "film": { "width": 24, "height": 18 },
  "integrator": { "spp": 1, "max_depth": 3 },
  "materials": [ { "name": "white", "albedo": 0.7 }, { "name": "red", "albedo": [0.7, 0.1, 0.1] } ],
  "shapes": [
    { "type": "box", "material": "white", "min": [-3, 0, -3], "max": [3, 3, 3] },
    { "type": "box", "material": "red", "min": [-0.5, 0, -0.5], "max": [0.5, 1, 0.5], "rotate_y": 30 }
  ],
  "lights": [
    { "type": "point", "position": [0, 2.5, 0], "intensity": [5, 5, 5] },
    { "type": "sphere", "center": [2, 0.3, 1], "radius": 0.3, "radiance": [8, 6, 3] },
    { "type": "quad", "corner": [-1, 2.95, 1], "edge1": [2, 0, 0], "edge2": [0, 0, 0.5], "radiance": 3 }
  ],
  "light_sets": [
    { "type": "random_box", "min": [-2.5, 2.0, -2.5], "max": [2.5, 2.8, 2.5], "count": 80, "seed": 3,
      "light": { "type": "point", "intensity": 0.05 } }
  ]
})";

// The same room with a rough gold box: a glossy material.
std::string glossy_scene() {
  std::string s = kDiffuseScene;
  const std::string materials = R"({ "name": "red", "albedo": [0.7, 0.1, 0.1] } ],)";
  const std::string with_gold =
      R"({ "name": "red", "albedo": [0.7, 0.1, 0.1] },
                 { "name": "gold", "type": "conductor", "metal": "gold", "roughness": 0.3 } ],)";
  s.replace(s.find(materials), materials.size(), with_gold);
  const std::string shapes = R"("rotate_y": 30 })";
  s.replace(
      s.find(shapes), shapes.size(),
      std::string(shapes) +
          R"(, { "type": "box", "material": "gold", "min": [1, 0, -2], "max": [2, 1.5, -1] })");
  return s;
}

// The diffuse room with one box of another material (JSON), named "extra".
std::string room_with(const std::string& material) {
  std::string s = kDiffuseScene;
  const std::string materials = R"({ "name": "red", "albedo": [0.7, 0.1, 0.1] } ],)";
  s.replace(s.find(materials), materials.size(),
            R"({ "name": "red", "albedo": [0.7, 0.1, 0.1] }, )" + material + " ],");
  const std::string shapes = R"("rotate_y": 30 })";
  s.replace(
      s.find(shapes), shapes.size(),
      std::string(shapes) +
          R"(, { "type": "box", "material": "extra", "min": [1, 0, -2], "max": [2, 1.5, -1] })");
  return s;
}
// Glass (rough too) is not a glossy reflector: its program has GGX code but no BRDF stages (whose
// buffers the renderer then does not allocate). A rough-coated material is glossy.
const char* kRoughGlass = R"({ "name": "extra", "type": "dielectric", "roughness": 0.3 })";
const char* kCoated = R"({ "name": "extra", "type": "coated_diffuse", "albedo": [0.2, 0.5, 0.3],
                           "roughness": 0.3 })";

std::vector<std::string> kernel_names(ClRuntime& rt, const Scene& scene,
                                      const std::string& sampler) {
  KernelFeatures f = scene_features(scene, light_sampler_from_name(sampler));
  cl::Program p = rt.build_program(wavefront_kernel_files(), f.build_options());
  std::stringstream names(p.getInfo<CL_PROGRAM_KERNEL_NAMES>());
  std::vector<std::string> out;
  std::string name;
  while (std::getline(names, name, ';'))
    if (!name.empty()) out.push_back(name);
  return out;
}
bool has_brdf_kernel(const std::vector<std::string>& names) {
  for (const std::string& n : names)
    if (n.rfind("brdf_", 0) == 0 || n == "scatter_brdf") return true;
  return false;
}

} // namespace

TEST(KernelBrdfFeatures, DiffuseScenesCompileNoBrdfOrientedKernels) {
  ClRuntime rt;
  Scene diffuse = load_scene_from_string(kDiffuseScene, "diffuse.json", ".");
  Scene glossy = load_scene_from_string(glossy_scene(), "glossy.json", ".");
  for (const char* sampler : {"brdf-mis", "brdf-oriented"}) {
    SCOPED_TRACE(sampler);
    std::vector<std::string> d = kernel_names(rt, diffuse, sampler);
    EXPECT_FALSE(has_brdf_kernel(d));
    EXPECT_NE(std::find(d.begin(), d.end(), "light_pick"), d.end()); // the program is complete
    std::vector<std::string> g = kernel_names(rt, glossy, sampler);
    for (const char* k :
         {"brdf_cut", "brdf_sample", "scatter_brdf", "brdf_trace", "brdf_accumulate"})
      EXPECT_NE(std::find(g.begin(), g.end(), k), g.end()) << k;
  }
  // Other samplers never have them, glossy or not.
  EXPECT_FALSE(has_brdf_kernel(kernel_names(rt, glossy, "tree-split")));
  Scene glass = load_scene_from_string(room_with(kRoughGlass), "glass.json", ".");
  Scene coated = load_scene_from_string(room_with(kCoated), "coated.json", ".");
  EXPECT_FALSE(has_brdf_kernel(kernel_names(rt, glass, "brdf-mis")));
  std::vector<std::string> c = kernel_names(rt, coated, "brdf-mis");
  EXPECT_NE(std::find(c.begin(), c.end(), "brdf_cut"), c.end());
}

// brdf-mis is tree-split wherever the BRDF is not glossy: on a diffuse scene, the same film (sums
// and per-pixel shadow-ray and shading-point counts) bit for bit with the same seed.
TEST(KernelBrdfFeatures, DiffuseSceneRendersIdenticallyToTreeSplit) {
  auto render = [](const std::string& sampler) {
    ClRuntime rt;
    Scene scene = load_scene_from_string(kDiffuseScene, "diffuse.json", ".");
    RendererOptions opt;
    opt.light_sampler = sampler;
    Renderer r(rt, scene, opt);
    RenderSettings rs;
    rs.spp = 4;
    rs.seed = 9;
    return r.render(rs);
  };
  Film tree = render("tree-split"), brdf = render("brdf-mis");
  ASSERT_EQ(tree.sum.size(), brdf.sum.size());
  int differ = 0;
  double total = 0;
  for (size_t i = 0; i < tree.sum.size(); ++i) {
    const double4 &a = tree.sum[i], &b = brdf.sum[i];
    differ += a.x != b.x || a.y != b.y || a.z != b.z || a.w != b.w;
    differ += tree.counts[i].x != brdf.counts[i].x || tree.counts[i].y != brdf.counts[i].y;
    total += a.x + a.y + a.z;
  }
  EXPECT_EQ(differ, 0);
  EXPECT_GT(total, 0.0); // not black
}

namespace {

// Sum over the pixels of the per-pixel means, and the variance of that sum (per-pixel sample
// variances over the pixel's sample count).
struct ImageTotal {
  double total[3] = {0, 0, 0}, var[3] = {0, 0, 0};
};
ImageTotal image_total(const Film& f) {
  ImageTotal t;
  for (size_t i = 0; i < f.sum.size(); ++i) {
    double n = f.sum[i].w;
    double s[3] = {f.sum[i].x, f.sum[i].y, f.sum[i].z},
           q[3] = {f.sumsq[i].x, f.sumsq[i].y, f.sumsq[i].z};
    for (int c = 0; c < 3; ++c) {
      double mean = s[c] / n;
      t.total[c] += mean;
      t.var[c] += std::max(0.0, q[c] / n - mean * mean) / (n - 1);
    }
  }
  return t;
}

} // namespace

TEST(KernelBrdfFeatures, GlossySceneRendersTheImageOfTreeSplit) {
  auto render = [](const std::string& sampler, bool adaptive) {
    ClRuntime rt;
    Scene scene = load_scene_from_string(glossy_scene(), "glossy.json", ".");
    scene.film.width = 20;
    scene.film.height = 15;
    RendererOptions opt;
    opt.light_sampler = sampler;
    opt.brdf.adaptive = adaptive;
    Renderer r(rt, scene, opt);
    RenderSettings rs;
    rs.spp = 256;
    rs.seed = 21;
    return image_total(r.render(rs));
  };
  ImageTotal ref = render("tree-split", true);
  for (auto [sampler, adaptive] :
       {std::pair{"brdf-mis", true}, {"brdf-mis", false}, {"brdf-oriented", true}}) {
    SCOPED_TRACE(std::string(sampler) + (adaptive ? "" : " (equal allocation)"));
    ImageTotal t = render(sampler, adaptive);
    for (int c = 0; c < 3; ++c) {
      double se = std::sqrt(t.var[c] + ref.var[c]);
      EXPECT_LE(std::fabs(t.total[c] - ref.total[c]), 5 * se)
          << "channel " << c << ": " << t.total[c] << " vs tree-split " << ref.total[c];
      EXPECT_LT(5 * se, 0.05 * ref.total[c]) << "channel " << c; // sharp enough to matter
    }
  }
}

// A rough-coated box (cl/bsdf/layered.h: stochastic eval and pdf, the cap integral's stand-in
// lobe) and a rough glass box: brdf-mis renders tree-split's image over several bounces.
TEST(KernelBrdfFeatures, CoatedAndGlassSceneRendersTheImageOfTreeSplit) {
  std::string json = room_with(kCoated);
  const std::string shapes = R"("max": [2, 1.5, -1] })";
  json.replace(json.find(shapes), shapes.size(),
               std::string(shapes) + R"(, { "type": "box", "material": "frosted",
                   "min": [-1.8, 0.2, -1.5], "max": [-1.0, 1.2, -0.7] })");
  const std::string extra = R"("roughness": 0.3 })";
  json.replace(json.find(extra), extra.size(),
               std::string(extra) +
                   R"(, { "name": "frosted", "type": "dielectric", "roughness": 0.2 })");
  auto render = [&](const std::string& sampler) {
    ClRuntime rt;
    Scene scene = load_scene_from_string(json, "coated.json", ".");
    scene.film.width = 20;
    scene.film.height = 15;
    RendererOptions opt;
    opt.light_sampler = sampler;
    Renderer r(rt, scene, opt);
    RenderSettings rs;
    rs.spp = 256;
    rs.seed = 23;
    Film f = r.render(rs);
    EXPECT_EQ(r.stats().nonfinite_samples, 0u);
    return image_total(f);
  };
  ImageTotal ref = render("tree-split"), t = render("brdf-mis");
  for (int c = 0; c < 3; ++c) {
    double se = std::sqrt(t.var[c] + ref.var[c]);
    EXPECT_LE(std::fabs(t.total[c] - ref.total[c]), 5 * se)
        << "channel " << c << ": " << t.total[c] << " vs tree-split " << ref.total[c];
    EXPECT_LT(5 * se, 0.05 * ref.total[c]) << "channel " << c;
  }
}
