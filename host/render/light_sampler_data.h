// The data behind the device light samplers (cl/integrator/light_sampler.h): the light tree for
// tree / tree-split / exhaustive, the alias table for power. The renderer uploads it; tests use
// host_view() to run the very same sampling code on the host.
#pragma once

#include "integrator/light_sampler.h"
#include "light_tree/brdf_cut.h"
#include "light_tree/light_tree.h"

#include <string>
#include <vector>

namespace canopy {

// Parameters of brdf-mis / brdf-oriented (Liu et al. 2019; cl/integrator/brdf_mis.h).
struct BrdfSettings {
  float delta = LT_BRDF_DEFAULT_DELTA; // split a cluster while S_C > delta (Eq. 5)
  int n_max = 50;                      // BRDF-aware samples per point: ceil(n_max I_B) (Eq. 9)
  float lambda = 10.0f;                // allocation p = n_nohit / (n_nohit + lambda n_hit) (Eq. 7)
  bool adaptive = true;                // false: one sample of each technique (Fig. 8 ablation)
};

struct LightSamplerData {
  int kind = SAMPLER_UNIFORM;
  float threshold = LT_DEFAULT_SPLIT_THRESHOLD;
  uint32_t max_cut = 1; // cut cap per shading point (1 without splitting; every light: exhaustive)
  LightTree tree;
  std::vector<float> power_pmf, alias_prob;
  std::vector<int> alias_index;
  BrdfSettings brdf;
  double tree_build_seconds = 0.0;

  bool splits() const {
    return kind == SAMPLER_TREE_SPLIT || kind == SAMPLER_EXHAUSTIVE || brdf_oriented();
  }
  bool brdf_oriented() const { return kind == SAMPLER_BRDF_MIS || kind == SAMPLER_BRDF_ORIENTED; }
  // The root item's cut budget in the kernels: max_cut, or for the exhaustive sampler one that
  // never binds (its cuts still hold at most max_cut = N items, which sizes the queues).
  uint32_t root_budget() const {
    return kind == SAMPLER_EXHAUSTIVE ? LT_BUDGET_UNLIMITED : max_cut;
  }
  // The sampler over these host arrays and `lights` (which must outlive the view); brdf_cut: the
  // cut storage of brdf-mis / brdf-oriented (LT_BRDF_MAX_CUT entries per path), or null.
  LightSamplerCtx host_view(const std::vector<Light>& lights, float2* brdf_cut = nullptr) const;
};

// Throws SceneError for an unknown sampler name. `built`: a light tree already built for `lights`
// (it depends on them alone), moved from if this sampler needs one instead of building it again
// (Renderer::set_light_sampler, when the auto pilot goes from one tree sampler to another).
LightSamplerData make_light_sampler_data(const std::vector<Light>& lights, const std::string& name,
                                         float split_threshold, int max_cut,
                                         bool orientation_term = true,
                                         const BrdfSettings& brdf = BrdfSettings(),
                                         LightTree* built = nullptr);

} // namespace canopy
