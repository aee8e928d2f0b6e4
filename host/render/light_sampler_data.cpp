#include "render/light_sampler_data.h"

#include "light_tree/light_sampler.h"
#include "render/features.h"

#include <algorithm>
#include <chrono>

namespace canopy {

LightSamplerData make_light_sampler_data(const std::vector<Light>& lights, const std::string& name,
                                         float split_threshold, int max_cut, bool orientation_term,
                                         const BrdfSettings& brdf, LightTree* built) {
  LightSamplerData d;
  d.kind = light_sampler_from_name(name);
  d.brdf = brdf;
  d.threshold = split_threshold;
  const uint32_t n = uint32_t(lights.size());
  if (d.kind == SAMPLER_EXHAUSTIVE) {
    d.threshold = 1.0f;                   // split every cluster ...
    d.max_cut = std::max<uint32_t>(1, n); // ... so a cut holds every light (root_budget())
  } else if (d.kind == SAMPLER_TREE_SPLIT || d.kind == SAMPLER_BRDF_MIS ||
             d.kind == SAMPLER_BRDF_ORIENTED) {
    d.max_cut = uint32_t(std::clamp(max_cut, 1, int(std::max<uint32_t>(1, n))));
  }
  if (d.kind == SAMPLER_TREE || d.kind == SAMPLER_TREE_SPLIT || d.kind == SAMPLER_EXHAUSTIVE ||
      d.kind == SAMPLER_BRDF_MIS || d.kind == SAMPLER_BRDF_ORIENTED) {
    auto t0 = std::chrono::steady_clock::now();
    if (built && built->num_lights == int(n) && built->num_nodes() > 0)
      d.tree = std::move(*built);
    else
      d.tree = build_light_tree(lights);
    d.tree.set_orientation_term(orientation_term);
    d.tree_build_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  if (d.kind == SAMPLER_POWER) {
    std::vector<EmitterBounds> eb = emitter_bounds(lights);
    std::vector<double> w(eb.size());
    for (size_t i = 0; i < eb.size(); ++i)
      w[i] = eb[i].energy;
    AliasTable table(w);
    d.power_pmf = table.pmfs();
    d.alias_prob = table.thresholds();
    d.alias_index = table.aliases();
  }
  return d;
}

LightSamplerCtx LightSamplerData::host_view(const std::vector<Light>& lights,
                                            float2* brdf_cut) const {
  LightSamplerCtx ls{};
  ls.kind = kind;
  ls.light_count = int(lights.size());
  ls.lights = lights.data();
  ls.power_pmf = power_pmf.data();
  ls.alias_prob = alias_prob.data();
  ls.alias_index = alias_index.data();
  ls.tree = tree.view(lights.data());
  ls.threshold = threshold;
  ls.max_cut = root_budget();
  ls.brdf_cut = brdf_cut;
  ls.brdf_delta = brdf.delta;
  ls.brdf_lambda = brdf.lambda;
  ls.brdf_nmax = brdf.n_max;
  ls.brdf_adaptive = brdf.adaptive ? 1 : 0;
  return ls;
}

} // namespace canopy
