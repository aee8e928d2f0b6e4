// Light tree (Conty Estevez & Kulla 2018, §4): emitter bounds, binned SAOH build of a binary tree
// (parallel, TBB), collapse into the 4-wide struct-of-arrays tree that the host sampler and the
// kernels traverse with the functions of cl/light_tree/ (traverse.h, pmf.h).
//
// Device layout (upload each vector as one buffer, as is; see the top of cl/light_tree/layout.h):
//   nodes        float4 x LT_NODE_F4 (8) per 4-wide node: per-lane sphere centre x/y/z, radius,
//                octahedral cone axis, cos(theta_o), energy, cos(theta_e) | energy CV^2 (16 bits
//                each; lanes of one-sided planar emitters flag a half-space bound in cos(theta_o)
//                and keep its offset in the cos(theta_e) bits); then LT_EMITTER_F4 (2) float4 per
//                emitter in leaf order (emitter records: sphere; axis, cone or plane offset,
//                energy, light index)
//   children     int4 per node: child node index, LT_EMPTY, or a leaf code (lt_leaf_code)
//   leaf_lights  int per emitter, light indices in leaf order (leaves are contiguous ranges)
//   trails       uint per light index: bit-trail, 2 bits per level from the root, then 2 bits for
//                the index inside the leaf
//   root_sphere, root_info: two float4 kernel arguments (LtTree fields; root_info.z locates the
//                emitter records)
// The traversal reads only nodes and children (and the Light record of the light it returns).
#pragma once

#include "light_tree/cone.h"     // cl/: LtCone
#include "light_tree/layout.h"   // cl/: LtTree, layout constants
#include "lights/light_bounds.h" // cl/: lt_light_bounds, lt_sphere_of_box

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace canopy {

// Bounds of one emitter (paper Table 1 and §5.1): box, cone, energy (luminance of the maximum
// radiant intensity). Computed with lt_light_bounds(), the energy in double (emission below
// float's normal range, e.g. 1e-40, or near its maximum times an area keeps its value); the
// emitter records of the leaves are built from them.
struct EmitterBounds {
  float3 bmin, bmax;
  LtCone cone; // axis, theta_o, theta_e
  double energy;
  float cos_o, cos_e; // the cone as lt_light_bounds gives it (cosines, exact)
  // One-sided planar emitters (quad, triangle; not two-sided, with a normal): the largest
  // dot(n, c - x) over its vertices x (n = cone.axis, c = the centre of lt_sphere_of_box(bmin,
  // bmax)) plus a margin for the float rounding of its sample and hit points, so every point
  // the renderer can sample on it lies on the front side of the plane through c - plane_h n
  // (negative when c is behind that plane, e.g. the box centre of a tilted triangle). NaN for
  // every other emitter (no half-space bound).
  double plane_h = NAN;
};
EmitterBounds emitter_bounds(const Light& light);
std::vector<EmitterBounds> emitter_bounds(const std::vector<Light>& lights); // parallel
// Scales every energy by one power of two so the largest is in [1, 2) (a common scale leaves every
// pmf unchanged) and raises a positive energy that would fall below float's normal range to
// FLT_MIN, so the float energies of the tree are never denormal, 0 or Inf for an emitter that
// emits (emission anywhere in 1e-40 .. 1e37, whatever global scale the emission was given).
// Returns the scale (1 if no energy is positive).
double normalize_emitter_energies(std::vector<EmitterBounds>& emitters);

struct LightTreeBuildOptions {
  int bins = 16;             // SAOH bins per axis (2..64)
  int leaf_size = 4;         // clusters of at most this many emitters always become leaves (1..4);
                             // clusters of up to 4 also become leaves when no split beats the leaf
                             // cost E_c
  int parallel_grain = 4096; // subtrees smaller than this are built serially
};

// ---------------------------------------------------------------- binary tree (build result)
struct BinaryLightNode {
  float3 bmin, bmax;         // union of the emitter boxes
  LtCone cone;               // union of the emitter cones (Alg. 1)
  double energy;             // sum of emitter energies
  double energy2;            // sum of squared emitter energies
  int count;                 // emitters below
  int first;                 // first emitter in BinaryLightTree::order (the subtree's range)
  int left = -1, right = -1; // children, -1 for a leaf
  bool is_leaf() const { return left < 0; }
  float cv2() const; // n * sum(E^2) / sum(E)^2 - 1, the squared coefficient of variation
};
struct BinaryLightTree {
  std::vector<BinaryLightNode> nodes; // nodes[0] is the root
  std::vector<int> order;             // emitter indices in leaf order
  int depth = 0;                      // deepest leaf (root = 0)
};
// Top-down binned SAOH (Eq. 2 with K_r, leaf cost E_c, all three axes). Falls back to a median
// split by index when all centroids coincide, and to a median split on the widest centroid axis
// where a deep SAOH split would exceed the bit-trail budget (leaves at binary depth <= 30).
BinaryLightTree build_binary_light_tree(const std::vector<EmitterBounds>& emitters,
                                        const LightTreeBuildOptions& opt = {});
// The SAOH cost of splitting a cluster into (left, right) by Eq. 2 without K_r, exposed for tests.
double saoh_cost(const BinaryLightNode& parent, const BinaryLightNode& left,
                 const BinaryLightNode& right);

// ---------------------------------------------------------------- 4-wide tree
struct LightTree {
  std::vector<float4> nodes;
  std::vector<int4> children;
  std::vector<int> leaf_lights;
  std::vector<uint32_t> trails;
  float4 root_sphere{0, 0, 0, 0};
  float4 root_info{0, 0, 0, 0}; // energy CV^2, total energy, emitter base, importance terms
  int num_lights = 0;
  int levels = 0;            // 4-wide node levels (root level = 1)
  double energy_scale = 1.0; // the tree's energies are the emitters' times this (a power of two)

  int num_nodes() const { return static_cast<int>(children.size()); }
  double total_energy() const { return root_info.y; }
  // Bytes of the device buffers above (excluding the scene's Light buffer).
  size_t device_bytes() const;
  // With `false`, cluster importance keeps energy and distance only (LT_TERMS_DISTANCE: the
  // orientation ablation of the paper's Fig. 15-16); the default is the full Eq. 3.
  void set_orientation_term(bool on) { root_info.w = on ? LT_TERMS_FULL : LT_TERMS_DISTANCE; }
  // A traversal view over these buffers and the scene's lights (which must outlive it).
  LtTree view(const Light* lights) const;
};

LightTree collapse_light_tree(const BinaryLightTree& bt,
                              const std::vector<EmitterBounds>& emitters);
// emitter_bounds + build_binary_light_tree + collapse_light_tree. An empty light list gives an
// empty tree (num_nodes() == 0).
LightTree build_light_tree(const std::vector<Light>& lights, const LightTreeBuildOptions& opt = {});

} // namespace canopy
