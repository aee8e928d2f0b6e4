// Light samplers behind one interface (host reference; the kernels use the same cl/ functions):
//   "uniform"     one light, probability 1/N
//   "power"       one light, probability E_l / sum E (alias table); uniform if all E are 0
//   "tree"        one light by stochastic light-tree descent (Conty & Kulla Alg. 2)
//   "tree-split"  adaptive splitting (Alg. 3) with threshold and cut cap, then one light per
//                 cluster of the cut
//   "exhaustive"  every light with probability 1 (the reference)
//   "bsdf"        no light (BSDF sampling only): sample() picks nothing, pmf() is 0
// For every sampler, sum over the picks of f(pick.light) / pick.prob is an unbiased estimator of
// sum over lights of f(light), for any f that is 0 where the sampler's importance is 0 (lights
// behind the shading point's horizon or outside their emission cone: zero contribution).
#pragma once

#include "light_tree/light_sampler_names.h"
#include "light_tree/light_tree.h"
#include "light_tree/pmf.h"      // cl/
#include "light_tree/query.h"    // cl/
#include "light_tree/split.h"    // cl/
#include "light_tree/traverse.h" // cl/

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace canopy {

// Counter-based random stream (cl/rng.h), the same struct in kernels.
using Rng = LtRng;
inline Rng make_rng(uint32_t seed, uint32_t stream) {
  return lt_rng_make(seed, stream);
}
inline float next_float(Rng& rng) {
  return lt_rng_next(&rng);
}
inline uint32_t next_u32(Rng& rng) {
  return lt_rng_next_u32(&rng);
}

struct LightPick {
  int light;  // index into the scene's lights
  float prob; // estimator term: f(light) / prob
};

struct LightSamplerOptions {
  float split_threshold = LT_DEFAULT_SPLIT_THRESHOLD; // tree-split: [0, 1], 0 never splits
  int max_cut = 64; // tree-split: at most this many picks per shading point (>= 1)
  LightTreeBuildOptions build;
  bool orientation = true; // tree samplers: false drops Eq. 3's orientation terms (ablation)
};

class LightSampler {
public:
  virtual ~LightSampler();
  virtual const char* name() const = 0;
  // Appends the picks for shading point P with unit normal N (N == 0: no orientation, e.g. a
  // point in a medium). May append nothing when no light can contribute to P.
  virtual void sample(float3 P, float3 N, Rng& rng, std::vector<LightPick>& out) const = 0;
  // Probability that sample() yields `light` for (P, N) within its single-pick technique, for MIS:
  // uniform 1/N, power E_l/E, tree the product along the bit-trail, tree-split the product below
  // the cluster where the deterministic split stopped, exhaustive 1. 0 if never picked.
  virtual float pmf(float3 P, float3 N, int light) const = 0;
  // The light tree (tree and tree-split), to upload to the device; nullptr for the others.
  virtual const LightTree* tree() const { return nullptr; }
  int num_lights() const { return static_cast<int>(lights_.size()); }
  const std::vector<Light>& lights() const { return lights_; }

protected:
  explicit LightSampler(const std::vector<Light>& lights) : lights_(lights) {}
  std::vector<Light> lights_;
};

// Vose alias table over non-negative weights (built in double); all-zero (or empty) weights give a
// uniform table. Sampling runs lt_alias_pick (cl/light_tree/discrete.h), the device's function.
class AliasTable {
public:
  AliasTable() = default;
  explicit AliasTable(const std::vector<double>& weights);
  int size() const { return static_cast<int>(pmf_.size()); }
  int sample(Rng& rng) const;
  float pmf(int i) const { return pmf_[i]; }
  // The table itself, for upload to the device (slot i keeps i when u < thresholds()[i], else
  // takes aliases()[i]).
  const std::vector<float>& thresholds() const { return threshold_; }
  const std::vector<int>& aliases() const { return alias_; }
  const std::vector<float>& pmfs() const { return pmf_; }

private:
  std::vector<float> threshold_;
  std::vector<int> alias_;
  std::vector<float> pmf_;
};

// The tree techniques over any tree view (LightTree::view), one shading point: the host reference
// of the device's light_pick. sample_tree: Alg. 2 from the root. sample_tree_split: Alg. 3 as a
// depth-first walk over split items (lt_item_splits, budget max_cut), one lt_pick_below per item
// that does not split; every pick's prob equals lt_pmf_split() for its light.
// The _q forms take a query (cl/light_tree/query.h): a shading point (lt_query_point) or a ray
// segment in a medium (lt_query_segment, Conty Estevez & Kulla 2018 §5.2); the (P, N) forms are
// point queries. Every pick's prob equals lt_pmf_below_q / lt_pmf_split_q for the same query.
void sample_tree_q(const LtTree& t, const LtQuery& q, Rng& rng, std::vector<LightPick>& out);
void sample_tree_split_q(const LtTree& t, const LtQuery& q, Rng& rng, float threshold, int max_cut,
                         std::vector<LightPick>& out);
void sample_tree(const LtTree& t, float3 P, float3 N, Rng& rng, std::vector<LightPick>& out);
void sample_tree_split(const LtTree& t, float3 P, float3 N, Rng& rng, float threshold, int max_cut,
                       std::vector<LightPick>& out);

// Throws std::invalid_argument on an unknown name or an invalid option.
std::unique_ptr<LightSampler> make_light_sampler(const std::string& name,
                                                 const std::vector<Light>& lights,
                                                 const LightSamplerOptions& opt = {});
// kLightSamplerNames (light_tree/light_sampler_names.h), in SAMPLER_* order.
const std::vector<std::string>& light_sampler_names();

} // namespace canopy
