// Helpers shared by the light-tree tests.
#pragma once

#include "light_tree/light_sampler.h"
#include "light_tree/synthetic_lights.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

namespace canopy::test {

inline double dot_d(float3 a, float3 b) {
  return double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z;
}
inline double angle_d(float3 a, float3 b) { // accurate angle between (not necessarily unit) vectors
  double cx = double(a.y) * b.z - double(a.z) * b.y;
  double cy = double(a.z) * b.x - double(a.x) * b.z;
  double cz = double(a.x) * b.y - double(a.y) * b.x;
  return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), dot_d(a, b));
}

inline float3 random_unit(LtRng& r) {
  float z = 2.0f * lt_rng_next(&r) - 1.0f;
  float phi = 2.0f * M_PI_F * lt_rng_next(&r);
  float s = std::sqrt(std::fmax(0.0f, 1.0f - z * z));
  return make_float3(s * std::cos(phi), s * std::sin(phi), z);
}

// Points on (or at) a light: the reference points of the test contribution.
inline std::vector<float3> light_points(const Light& l) {
  float3 p = xyz_of(l.p);
  std::vector<float3> pts;
  if (l.type == LIGHT_QUAD) {
    float3 a = xyz_of(l.e1), b = xyz_of(l.e2);
    for (float u : {0.02f, 0.5f, 0.98f})
      for (float v : {0.02f, 0.5f, 0.98f})
        pts.push_back(p + a * u + b * v);
  } else if (l.type == LIGHT_TRIANGLE) {
    float3 a = xyz_of(l.e1), b = xyz_of(l.e2);
    for (float u : {0.02f, 0.33f, 0.96f})
      for (float v : {0.02f, 0.33f})
        pts.push_back(p + a * u + b * (v * (1.0f - u)));
  } else if (l.type == LIGHT_DISK) {
    // the centre (the middle entry: contribution()'s point) and a ring at 0.98 r
    float3 a = xyz_of(l.e1), b = xyz_of(l.e2);
    float r = 0.98f * l.p.w;
    for (int k = 0; k < 8; ++k) {
      if (k == 4) pts.push_back(p);
      float phi = float(k) * 0.25f * M_PI_F;
      pts.push_back(p + a * (r * std::cos(phi)) + b * (r * std::sin(phi)));
    }
  } else {
    pts.push_back(p);
  }
  return pts;
}

// A deterministic stand-in for a light's unoccluded contribution at (P, N): energy times the
// emitter and receiver cosines over d^2 at the light's centroid (a sphere: its centre, facing P).
// It is 0 exactly where the light cannot contribute (behind P's horizon, outside its emission).
inline double contribution(const Light& l, float3 P, float3 N) {
  EmitterBounds b = emitter_bounds(l);
  std::vector<float3> pts = light_points(l);
  float3 y = pts[pts.size() / 2];
  double dx = double(y.x) - P.x, dy = double(y.y) - P.y, dz = double(y.z) - P.z;
  double d2 = dx * dx + dy * dy + dz * dz;
  if (!(d2 > 1e-12)) return 0.0;
  double d = std::sqrt(d2);
  double ux = dx / d, uy = dy / d, uz = dz / d; // P -> light
  double cos_i = 1.0;
  if (N.x != 0 || N.y != 0 || N.z != 0) cos_i = std::max(0.0, ux * N.x + uy * N.y + uz * N.z);
  double cos_l = 1.0;
  if (l.type == LIGHT_SPOT) {
    double c = -(ux * l.e1.x + uy * l.e1.y + uz * l.e1.z);
    cos_l = c >= l.e1.w ? 1.0 : 0.0;
  } else if (l.type == LIGHT_QUAD || l.type == LIGHT_TRIANGLE || l.type == LIGHT_DISK) {
    double c = -(ux * b.cone.axis.x + uy * b.cone.axis.y + uz * b.cone.axis.z);
    cos_l = (l.flags & LIGHT_FLAG_TWO_SIDED) ? std::fabs(c) : std::max(0.0, c);
  }
  return double(b.energy) * cos_i * cos_l / d2;
}

// Whether some point of the light is clearly visible from P's hemisphere and emits towards P
// (both cosines above 1e-3): such a light must get a non-zero pmf.
inline bool clearly_contributes(const Light& l, float3 P, float3 N) {
  EmitterBounds b = emitter_bounds(l);
  if (!(b.energy > 0)) return false;
  for (float3 y : light_points(l)) {
    double dx = double(y.x) - P.x, dy = double(y.y) - P.y, dz = double(y.z) - P.z;
    double d = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (!(d > 1e-6)) continue;
    double ux = dx / d, uy = dy / d, uz = dz / d;
    double cos_i = (N.x != 0 || N.y != 0 || N.z != 0) ? ux * N.x + uy * N.y + uz * N.z : 1.0;
    double cos_l = 1.0;
    if (l.type == LIGHT_SPOT) {
      double c = -(ux * l.e1.x + uy * l.e1.y + uz * l.e1.z);
      cos_l = c - l.e1.w; // inside the aperture by a margin
    } else if (l.type == LIGHT_QUAD || l.type == LIGHT_TRIANGLE || l.type == LIGHT_DISK) {
      double c = -(ux * b.cone.axis.x + uy * b.cone.axis.y + uz * b.cone.axis.z);
      cos_l = (l.flags & LIGHT_FLAG_TWO_SIDED) ? std::fabs(c) : c;
    }
    if (cos_i > 1e-3 && cos_l > 1e-3) return true;
  }
  return false;
}

// Wilson-Hilferty normal score of a chi-square statistic with k degrees of freedom.
inline double chi2_z(double chi2, double k) {
  double h = 2.0 / (9.0 * k);
  return (std::cbrt(chi2 / k) - (1.0 - h)) / std::sqrt(h);
}

// Chi-square of observed counts against expected probabilities (bins with expected count < 5 are
// pooled). Returns the normal score; *dof the degrees of freedom.
inline double chi2_score(const std::vector<double>& observed, const std::vector<double>& prob,
                         double total, int* dof = nullptr) {
  double chi2 = 0, pool_o = 0, pool_e = 0;
  int bins = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    double e = prob[i] * total;
    if (e < 5.0) {
      pool_o += observed[i];
      pool_e += e;
      continue;
    }
    chi2 += (observed[i] - e) * (observed[i] - e) / e;
    ++bins;
  }
  if (pool_e >= 5.0) {
    chi2 += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
    ++bins;
  } else if (pool_o > 10.0) {
    chi2 += 1e9; // many picks where almost none are expected
  }
  int k = std::max(1, bins - 1);
  if (dof) *dof = k;
  return chi2_z(chi2, k);
}

// Goodness of fit of pick counts against the probabilities the sampler reports, at significance
// alpha = 1e-6 (fixed seeds: a correct sampler fails with probability 1e-6, never in practice).
// Lights are split by `group` (bins never mix groups, so a small population is judged on its
// own), sorted by probability within a group and merged into bins of expected count >=
// min_expected (a trailing remainder joins the group's last bin). The chi-square over all bins is
// compared with its 1 - alpha quantile (Wilson-Hilferty); so is a second, coarse chi-square over
// the group totals, which sees a whole group's deficit that the many fine bins dilute. A group
// whose whole expected count is below min_expected cannot form a bin: its observed count must lie
// within the two-sided Poisson alpha bounds of its expectation. A pick of a light of probability
// 0 always fails.
struct PickFit {
  double chi2 = 0, quantile = 0;             // fine bins
  double group_chi2 = 0, group_quantile = 0; // group totals
  int dof = 0, group_dof = 0;
  std::string failures; // rare groups outside their bounds, impossible picks
  bool pass() const { return failures.empty() && chi2 <= quantile && group_chi2 <= group_quantile; }
};
inline double chi2_quantile(int dof, double z) { // Wilson-Hilferty
  double k = dof, h = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - h + z * std::sqrt(h), 3.0);
}
inline double poisson_lower(double lambda, double alpha) { // largest q with P(X < q) <= alpha
  double term = std::exp(-lambda), cdf = 0;
  int q = 0;
  while (cdf + term <= alpha && q < 100000) {
    cdf += term;
    ++q;
    term *= lambda / q;
  }
  return q;
}
inline double poisson_upper(double lambda, double alpha) { // smallest q with P(X > q) <= alpha
  double term = std::exp(-lambda), cdf = term;
  int q = 0;
  while (1.0 - cdf > alpha && q < 100000) {
    ++q;
    term *= lambda / q;
    cdf += term;
  }
  return q;
}
inline PickFit pick_fit(const std::vector<double>& counts, const std::vector<double>& prob,
                        const std::vector<int>& group, double total, double min_expected = 20.0) {
  const double z = 4.753424; // standard normal 1 - 1e-6 quantile
  PickFit f;
  std::vector<int> order(counts.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return group[a] != group[b] ? group[a] < group[b] : prob[a] < prob[b];
  });
  std::vector<double> bo, be; // observed, expected per bin
  size_t i = 0;
  int bins = 0;
  while (i < order.size()) {
    int g = group[order[i]];
    size_t end = i;
    double go = 0, ge = 0;
    while (end < order.size() && group[order[end]] == g) {
      int l = order[end++];
      if (!(prob[l] > 0) && counts[l] > 0)
        f.failures += "light " + std::to_string(l) + " has probability 0 but was picked; ";
      go += counts[l];
      ge += prob[l] * total;
    }
    if (ge < min_expected) {
      double lo = poisson_lower(ge, 1e-6), hi = poisson_upper(ge, 1e-6);
      if (go < lo || go > hi)
        f.failures += "group " + std::to_string(g) + ": " + std::to_string(go) +
                      " picks, expected " + std::to_string(ge) + " (bounds " + std::to_string(lo) +
                      ", " + std::to_string(hi) + "); ";
      i = end;
      continue;
    }
    f.group_chi2 += (go - ge) * (go - ge) / ge;
    ++f.group_dof;
    size_t first_bin = bo.size();
    double o = 0, e = 0;
    for (; i < end; ++i) {
      int l = order[i];
      o += counts[l];
      e += prob[l] * total;
      if (e >= min_expected) {
        bo.push_back(o);
        be.push_back(e);
        o = e = 0;
      }
    }
    if (e > 0 || o > 0) { // remainder joins the group's last bin (there is one: ge >= min)
      bo.back() += o;
      be.back() += e;
    }
    bins += int(bo.size() - first_bin);
  }
  for (size_t b = 0; b < bo.size(); ++b)
    f.chi2 += (bo[b] - be[b]) * (bo[b] - be[b]) / be[b];
  f.dof = std::max(1, bins - 1);
  f.quantile = chi2_quantile(f.dof, z);
  f.group_dof = std::max(1, f.group_dof - 1);
  f.group_quantile = chi2_quantile(f.group_dof, z);
  return f;
}

// Four spot lights with different positions, axes, cones and energies (bounding radius 0): a
// light tree of one node, one light per lane (the orientation ablation tests).
inline std::vector<Light> four_spot_lights() {
  return {make_spot_light(make_float3(1, 2, 0), make_float3(0, -1, 0), 0.8f, 0.9f,
                          make_float3(3, 3, 3)),
          make_spot_light(make_float3(-2, 1, 1), make_float3(0, 1, 0), 0.8f, 0.9f,
                          make_float3(1, 1, 1)),
          make_spot_light(make_float3(0, -1, 3), make_float3(1, 0, 0), 0.5f, 0.7f,
                          make_float3(2, 1, 1)),
          make_spot_light(make_float3(4, 3, -2), make_float3(-1, -1, 0) / std::sqrt(2.0f), 0.9f,
                          0.95f, make_float3(5, 4, 4))};
}

} // namespace canopy::test
