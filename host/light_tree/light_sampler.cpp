#include "light_tree/light_sampler.h"

#include <cmath>
#include <stdexcept>
#include <string_view>

namespace canopy {

LightSampler::~LightSampler() = default;

AliasTable::AliasTable(const std::vector<double>& weights) {
  const size_t n = weights.size();
  threshold_.assign(n, 1.0f);
  alias_.resize(n);
  pmf_.assign(n, 0.0f);
  if (n == 0) return;
  double total = 0;
  for (double w : weights)
    total += (w > 0 && std::isfinite(w)) ? w : 0.0;
  std::vector<double> scaled(n);
  for (size_t i = 0; i < n; ++i) {
    double w = (weights[i] > 0 && std::isfinite(weights[i])) ? weights[i] : 0.0;
    double p = total > 0 ? w / total : 1.0 / double(n);
    pmf_[i] = static_cast<float>(p);
    scaled[i] = p * double(n);
    alias_[i] = static_cast<int>(i);
  }
  std::vector<int> small, large;
  for (size_t i = 0; i < n; ++i)
    (scaled[i] < 1.0 ? small : large).push_back(static_cast<int>(i));
  while (!small.empty() && !large.empty()) {
    int s = small.back();
    small.pop_back();
    int l = large.back();
    threshold_[s] = static_cast<float>(scaled[s]);
    alias_[s] = l;
    scaled[l] = (scaled[l] + scaled[s]) - 1.0;
    if (scaled[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  for (int i : large)
    threshold_[i] = 1.0f;
  for (int i : small)
    threshold_[i] = 1.0f; // rounding leftovers
}

int AliasTable::sample(Rng& rng) const {
  return lt_alias_pick(threshold_.data(), alias_.data(), uint32_t(pmf_.size()), &rng);
}

namespace {

class UniformSampler final : public LightSampler {
public:
  explicit UniformSampler(const std::vector<Light>& lights) : LightSampler(lights) {}
  const char* name() const override { return "uniform"; }
  void sample(float3, float3, Rng& rng, std::vector<LightPick>& out) const override {
    if (lights_.empty()) return;
    int n = num_lights();
    int i = int(lt_rng_index(&rng, uint32_t(n)));
    out.push_back({i, 1.0f / float(n)});
  }
  float pmf(float3, float3, int) const override {
    return lights_.empty() ? 0.0f : 1.0f / float(num_lights());
  }
};

class PowerSampler final : public LightSampler {
public:
  explicit PowerSampler(const std::vector<Light>& lights) : LightSampler(lights) {
    std::vector<EmitterBounds> eb = emitter_bounds(lights);
    std::vector<double> w(eb.size());
    for (size_t i = 0; i < eb.size(); ++i)
      w[i] = eb[i].energy;
    table_ = AliasTable(w);
  }
  const char* name() const override { return "power"; }
  void sample(float3, float3, Rng& rng, std::vector<LightPick>& out) const override {
    if (lights_.empty()) return;
    int i = table_.sample(rng);
    out.push_back({i, table_.pmf(i)});
  }
  float pmf(float3, float3, int light) const override {
    return lights_.empty() ? 0.0f : table_.pmf(light);
  }

private:
  AliasTable table_;
};

class ExhaustiveSampler final : public LightSampler {
public:
  explicit ExhaustiveSampler(const std::vector<Light>& lights) : LightSampler(lights) {}
  const char* name() const override { return "exhaustive"; }
  void sample(float3, float3, Rng&, std::vector<LightPick>& out) const override {
    for (int i = 0; i < num_lights(); ++i)
      out.push_back({i, 1.0f});
  }
  float pmf(float3, float3, int) const override { return 1.0f; }
};

// BSDF sampling only: no light is ever picked (emission is found by BSDF-sampled rays alone).
class BsdfSampler final : public LightSampler {
public:
  explicit BsdfSampler(const std::vector<Light>& lights) : LightSampler(lights) {}
  const char* name() const override { return "bsdf"; }
  void sample(float3, float3, Rng&, std::vector<LightPick>&) const override {}
  float pmf(float3, float3, int) const override { return 0.0f; }
};

// Tree samplers. If every light has zero energy the tree cannot rank anything: fall back to
// uniform selection (the estimator stays unbiased and finite).
class TreeSamplerBase : public LightSampler {
public:
  TreeSamplerBase(const std::vector<Light>& lights, const LightSamplerOptions& opt)
      : LightSampler(lights), opt_(opt), tree_(build_light_tree(lights, opt.build)) {
    tree_.set_orientation_term(opt.orientation);
  }
  const LightTree* tree() const override { return &tree_; }

protected:
  bool degenerate() const { return lights_.empty() || !(tree_.total_energy() > 0); }
  void sample_uniform(Rng& rng, std::vector<LightPick>& out) const {
    if (lights_.empty()) return;
    int n = num_lights();
    int i = int(lt_rng_index(&rng, uint32_t(n)));
    out.push_back({i, 1.0f / float(n)});
  }
  LtTree view() const { return tree_.view(lights_.data()); }

  LightSamplerOptions opt_;
  LightTree tree_;
};

class TreeSampler final : public TreeSamplerBase {
public:
  using TreeSamplerBase::TreeSamplerBase;
  const char* name() const override { return "tree"; }
  void sample(float3 P, float3 N, Rng& rng, std::vector<LightPick>& out) const override {
    if (degenerate()) return sample_uniform(rng, out);
    LtTree t = view();
    sample_tree(t, P, N, rng, out);
  }
  float pmf(float3 P, float3 N, int light) const override {
    if (lights_.empty()) return 0.0f;
    if (degenerate()) return 1.0f / float(num_lights());
    LtTree t = view();
    return lt_pmf_below(&t, 0, P, N, tree_.trails[light]);
  }
};

// Also brdf-mis and brdf-oriented: this interface knows a point by P and N only, with no BRDF, and
// at points without a glossy BRDF both are tree-split (cl/integrator/brdf_mis.h).
class TreeSplitSampler final : public TreeSamplerBase {
public:
  TreeSplitSampler(const std::vector<Light>& lights, const LightSamplerOptions& opt,
                   const char* name = "tree-split")
      : TreeSamplerBase(lights, opt), name_(name) {}
  const char* name() const override { return name_; }
  void sample(float3 P, float3 N, Rng& rng, std::vector<LightPick>& out) const override {
    if (degenerate()) return sample_uniform(rng, out);
    LtTree t = view();
    sample_tree_split(t, P, N, rng, opt_.split_threshold, opt_.max_cut, out);
  }
  float pmf(float3 P, float3 N, int light) const override {
    if (lights_.empty()) return 0.0f;
    if (degenerate()) return 1.0f / float(num_lights());
    LtTree t = view();
    return lt_pmf_split(&t, P, N, light, opt_.split_threshold, uint(opt_.max_cut));
  }

private:
  const char* name_;
};

} // namespace

void sample_tree_q(const LtTree& t, const LtQuery& q, Rng& rng, std::vector<LightPick>& out) {
  float prob;
  int l = lt_pick_below_q(&t, 0, &q, &rng, &prob);
  if (l >= 0) out.push_back({l, prob});
}

void sample_tree_split_q(const LtTree& t, const LtQuery& q, Rng& rng, float threshold, int max_cut,
                         std::vector<LightPick>& out) {
  struct Item {
    float4 sphere;
    float cv2;
    int code;
    uint budget;
  };
  // Depth-first: each split replaces one item by at most 4, so the stack stays below
  // 3 * levels + 4 items.
  Item stack[4 * LT_MAX_NODE_LEVELS + 8];
  int top = 0;
  stack[top++] = {t.root_sphere, t.root_info.x, 0, uint(max_cut)};
  while (top > 0) {
    Item it = stack[--top];
    if (lt_item_splits_q(&t, it.sphere, it.cv2, it.code, it.budget, &q, threshold)) {
      float4 imp = lt_code_importance_q(&t, it.code, &q);
      if (it.code < 0) {
        int first = lt_leaf_first(it.code);
        for (int j = 0; j < lt_leaf_count(it.code); ++j)
          if (f4_get(imp, j) > 0.0f) out.push_back({t.leaf_lights[first + j], 1.0f});
      } else {
        int4 ch = t.children[it.code];
        int4 budgets = lt_child_budgets_q(&t, it.code, imp, it.budget, &q, threshold);
        for (int lane = 3; lane >= 0; --lane) {
          int c = i4_get(ch, lane);
          if (c == LT_EMPTY || !(f4_get(imp, lane) > 0.0f)) continue;
          stack[top++] = {lt_lane_sphere(&t, it.code, lane), lt_lane_cv2(&t, it.code, lane), c,
                          uint(i4_get(budgets, lane))};
        }
      }
    } else {
      float prob;
      int l = lt_pick_below_q(&t, it.code, &q, &rng, &prob);
      if (l >= 0) out.push_back({l, prob});
    }
  }
}

void sample_tree(const LtTree& t, float3 P, float3 N, Rng& rng, std::vector<LightPick>& out) {
  sample_tree_q(t, lt_query_point(P, N), rng, out);
}

void sample_tree_split(const LtTree& t, float3 P, float3 N, Rng& rng, float threshold, int max_cut,
                       std::vector<LightPick>& out) {
  sample_tree_split_q(t, lt_query_point(P, N), rng, threshold, max_cut, out);
}

const std::vector<std::string>& light_sampler_names() {
  static const std::vector<std::string> names(kLightSamplerNames.begin(), kLightSamplerNames.end());
  return names;
}

std::unique_ptr<LightSampler> make_light_sampler(const std::string& name,
                                                 const std::vector<Light>& lights,
                                                 const LightSamplerOptions& opt) {
  if (!(opt.split_threshold >= 0.0f && opt.split_threshold <= 1.0f))
    throw std::invalid_argument("light sampler: split threshold must be in [0, 1]");
  if (opt.max_cut < 1) throw std::invalid_argument("light sampler: max_cut must be >= 1");
  switch (light_sampler_kind(name)) {
  case SAMPLER_UNIFORM:
    return std::make_unique<UniformSampler>(lights);
  case SAMPLER_POWER:
    return std::make_unique<PowerSampler>(lights);
  case SAMPLER_TREE:
    return std::make_unique<TreeSampler>(lights, opt);
  case SAMPLER_TREE_SPLIT:
    return std::make_unique<TreeSplitSampler>(lights, opt);
  case SAMPLER_EXHAUSTIVE:
    return std::make_unique<ExhaustiveSampler>(lights);
  case SAMPLER_BSDF:
    return std::make_unique<BsdfSampler>(lights);
  case SAMPLER_BRDF_MIS:
  case SAMPLER_BRDF_ORIENTED:
    return std::make_unique<TreeSplitSampler>(lights, opt,
                                              kLightSamplerNames[light_sampler_kind(name)].data());
  default:
    break;
  }
  std::string expected;
  for (std::string_view n : kLightSamplerNames)
    expected += (expected.empty() ? "" : ", ") + std::string(n);
  throw std::invalid_argument("unknown light sampler '" + name + "' (expected " + expected + ")");
}

} // namespace canopy
