// The data behind the device light samplers (cl/integrator/light_sampler.h): the light tree for
// tree / tree-split / exhaustive, the alias table for power. The renderer uploads it; tests use
// host_view() to run the very same sampling code on the host.
#pragma once

#include "integrator/light_sampler.h"
#include "lighttree/light_tree.h"

#include <string>
#include <vector>

namespace canopy {

struct LightSamplerData {
  int kind = SAMPLER_UNIFORM;
  float threshold = LT_DEFAULT_SPLIT_THRESHOLD;
  uint32_t max_cut = 1; // cut cap per shading point (1 without splitting; every light: exhaustive)
  LightTree tree;
  std::vector<float> power_pmf, alias_prob;
  std::vector<int> alias_index;
  double tree_build_seconds = 0.0;

  bool splits() const { return kind == SAMPLER_TREE_SPLIT || kind == SAMPLER_EXHAUSTIVE; }
  // The root item's cut budget in the kernels: max_cut, or for the exhaustive sampler one that
  // never binds (its cuts still hold at most max_cut = N items, which sizes the queues).
  uint32_t root_budget() const {
    return kind == SAMPLER_EXHAUSTIVE ? LT_BUDGET_UNLIMITED : max_cut;
  }
  // The sampler over these host arrays and `lights` (which must outlive the view).
  LightSamplerCtx host_view(const std::vector<Light>& lights) const;
};

// Throws SceneError for an unknown sampler name.
LightSamplerData make_light_sampler_data(const std::vector<Light>& lights, const std::string& name,
                                         float split_threshold, int max_cut,
                                         bool orientation_term = true);

} // namespace canopy
