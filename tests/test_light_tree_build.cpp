// Light-tree construction: SAOH partition choice (paper Fig. 5), tree invariants, degenerate and
// pathological inputs.
#include "test_light_tree_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

using namespace canopy;
using namespace canopy::test;

namespace {

// Two slopes of a roof (ridge along y at x = 0): normals tilted to -x on the left, +x on the right,
// or all +z when `flat_normals` (same geometry, no orientation difference). Each slope is nx x ny
// cells of two triangles: 4 nx ny triangles in all.
std::vector<Light> roof(bool flat_normals, float length, int nx = 8, int ny = 16) {
  std::vector<Light> lights;
  for (int side = 0; side < 2; ++side) {
    float sx = side == 0 ? -1.0f : 1.0f;
    for (int i = 0; i < nx; ++i) {
      for (int j = 0; j < ny; ++j) {
        float x0 = sx * float(i) / nx, x1 = sx * float(i + 1) / nx;
        float y0 = length * float(j) / ny, y1 = length * float(j + 1) / ny;
        auto pt = [&](float x, float y) { return make_float3(x, y, 1.0f - std::fabs(x)); };
        float3 a = pt(x0, y0), b = pt(x1, y0), c = pt(x1, y1), d = pt(x0, y1);
        Light t1 = make_triangle_light(a, b, c, make_float3(1, 1, 1), false);
        Light t2 = make_triangle_light(a, c, d, make_float3(1, 1, 1), false);
        for (Light* t : {&t1, &t2}) {
          float3 n = normalize(make_float3(sx, 0, 1));
          if (flat_normals) n = make_float3(0, 0, 1);
          t->n = f4_from3(n, t->n.w);
          lights.push_back(*t);
        }
      }
    }
  }
  return lights;
}

// Which side(s) of the roof the emitters below a binary node come from (bit 0: left, 1: right).
int sides(const BinaryLightTree& bt, const std::vector<Light>& lights, int node) {
  const BinaryLightNode& n = bt.nodes[node];
  int s = 0;
  for (int i = n.first; i < n.first + n.count; ++i) {
    const Light& l = lights[bt.order[i]];
    float cx = l.p.x + (l.e1.x + l.e2.x) / 3.0f;
    s |= cx < 0 ? 1 : 2;
  }
  return s;
}

struct Walk {
  int node, lane;
};

// Checks every invariant of a built tree against its lights.
void check_tree(const std::vector<Light>& lights, const LightTree& t) {
  const int n = int(lights.size());
  ASSERT_EQ(t.num_lights, n);
  ASSERT_EQ(int(t.leaf_lights.size()), n);
  ASSERT_EQ(int(t.trails.size()), n);
  ASSERT_LE(t.levels, LT_MAX_NODE_LEVELS);
  ASSERT_EQ(t.nodes.size(), size_t(t.num_nodes()) * LT_NODE_F4 + size_t(n) * LT_EMITTER_F4);
  // every light exactly once in the leaves
  std::vector<int> seen(n, 0);
  for (int l : t.leaf_lights) {
    ASSERT_TRUE(l >= 0 && l < n);
    ++seen[l];
  }
  for (int i = 0; i < n; ++i)
    ASSERT_EQ(seen[i], 1) << "light " << i;

  // the tree stores the energies normalised by one power of two (normalize_emitter_energies)
  std::vector<EmitterBounds> eb = emitter_bounds(lights);
  ASSERT_EQ(normalize_emitter_energies(eb), t.energy_scale);
  auto lane = [&](int node, int k, int lane_idx) {
    return f4_get(t.nodes[size_t(node) * LT_NODE_F4 + k], lane_idx);
  };
  // lane energies = sum below; empty lanes are empty
  for (int node = 0; node < t.num_nodes(); ++node) {
    for (int k = 0; k < 4; ++k) {
      int c = i4_get(t.children[node], k);
      double e = lane(node, LT_ENERGY, k);
      if (c == LT_EMPTY) {
        EXPECT_EQ(e, 0.0);
        continue;
      }
      double sum = 0;
      if (c >= 0) {
        for (int j = 0; j < 4; ++j)
          sum += lane(c, LT_ENERGY, j);
      } else {
        for (int j = 0; j < lt_leaf_count(c); ++j)
          sum += eb[t.leaf_lights[lt_leaf_first(c) + j]].energy;
      }
      EXPECT_NEAR(e, sum, 1e-5 * sum + 1e-30) << "node " << node << " lane " << k;
    }
  }
  // every light: its trail leads to it, and every cluster on the way bounds it
  for (int l = 0; l < n; ++l) {
    uint32_t trail = t.trails[l];
    int code = 0;
    int depth = 0;
    const EmitterBounds& b = eb[l];
    while (code >= 0) {
      ASSERT_LT(depth++, LT_MAX_NODE_LEVELS);
      int k = int(trail & 3u);
      trail >>= 2;
      int c = i4_get(t.children[code], k);
      ASSERT_NE(c, LT_EMPTY);
      // sphere contains the light's box
      float3 centre = make_float3(lane(code, LT_CX, k), lane(code, LT_CY, k), lane(code, LT_CZ, k));
      double r = lane(code, LT_R, k);
      for (int corner = 0; corner < 8; ++corner) {
        float3 q = make_float3(corner & 1 ? b.bmax.x : b.bmin.x, corner & 2 ? b.bmax.y : b.bmin.y,
                               corner & 4 ? b.bmax.z : b.bmin.z);
        float3 d = q - centre;
        ASSERT_LE(std::sqrt(dot_d(d, d)),
                  r * (1 + 1e-6) +
                      1e-6 * (std::fabs(centre.x) + std::fabs(centre.y) + std::fabs(centre.z) + r))
            << "light " << l;
      }
      // cone covers the light's cone (axis decoded as the traversal decodes it)
      // a lane with a half-space bound (LT_PLANE_FLAG) has theta_o = LT_PLANE_SLOPE,
      // theta_e = pi/2 (its 16 bits hold the plane offset)
      const bool plane = lane(code, LT_COS_O, k) > 1.5f;
      double co = plane ? double(LT_PLANE_COS_O) : double(lane(code, LT_COS_O, k));
      if (co > -1.0) {
        float4 ax, ay, az;
        float4 bits = t.nodes[size_t(code) * LT_NODE_F4 + LT_AXIS];
        lt_oct_decode4(lt_lo16_4(bits), lt_hi16_4(bits), &ax, &ay, &az);
        float3 axis = make_float3(f4_get(ax, k), f4_get(ay, k), f4_get(az, k));
        double need = angle_d(axis, b.cone.axis) + b.cone.theta_o;
        ASSERT_LE(need, std::acos(std::clamp(co, -1.0, 1.0)) + 1e-5) << "light " << l;
      }
      double ce = plane ? 0.0
                        : f4_get(lt_lo16_4(t.nodes[size_t(code) * LT_NODE_F4 + LT_CE_CV2]), k) *
                              double(LT_U16_SCALE);
      ASSERT_LE(ce, std::cos(double(b.cone.theta_e)) + 1e-6);
      ASSERT_GE(lane(code, LT_ENERGY, k), b.energy * (1 - 1e-6));
      code = c;
    }
    int idx = int(trail & 3u);
    ASSERT_LT(idx, lt_leaf_count(code));
    ASSERT_EQ(t.leaf_lights[lt_leaf_first(code) + idx], l);
    // the emitter record bounds the light as conservatively as the nodes do
    LtTree view = t.view(lights.data());
    const float4* rec = lt_emitter_records(&view, lt_leaf_first(code) + idx);
    ASSERT_EQ(int(float_as_uint_(rec[1].w)), l);
    float4 sp = lt_sphere_of_box(b.bmin, b.bmax);
    ASSERT_EQ(rec[0].x, sp.x);
    ASSERT_EQ(rec[0].w, sp.w);
    ASSERT_EQ(rec[1].z, float(b.energy));
    float q = rec[1].y;
    double rco = q > 1.5f ? 1.0 : (q < -1.5f ? double(LT_PLANE_COS_O) : double(q));
    double rce = q > 1.5f ? double(q) - 2.0 : 0.0;
    if (q < -1.5f) {
      ASSERT_FALSE(std::isnan(b.plane_h)) << "light " << l; // one-sided planar only
    }
    ASSERT_LE(rce, std::cos(double(b.cone.theta_e)) + 1e-7) << "light " << l;
    if (rco > -1.0) {
      float4 ax, ay, az;
      lt_oct_decode4(lt_lo16_4(rec[1]), lt_hi16_4(rec[1]), &ax, &ay, &az);
      double err = angle_d(make_float3(ax.x, ay.x, az.x), b.cone.axis);
      if (q > 1.5f) {
        // theta_o = 0: the axis error widens theta_e
        ASSERT_EQ(b.cone.theta_o, 0.0f);
        ASSERT_LE(err + double(b.cone.theta_e), std::acos(std::clamp(rce, -1.0, 1.0)) + 1e-6);
      } else {
        ASSERT_LE(err + double(b.cone.theta_o), std::acos(std::clamp(rco, -1.0, 1.0)) + 1e-6)
            << "light " << l;
      }
    }
  }
}

} // namespace

class LightTreeBuildRoof : public ::testing::TestWithParam<std::tuple<int, int>> {};

TEST_P(LightTreeBuildRoof, SaohPrefersOrientationSplittingPartition) {
  // The roof is longer along y (2.2) than across (2): by area alone (and K_r) the best cut is
  // across y, mixing both slopes; the orientation measure makes SAOH cut along the ridge instead
  // (Fig. 5). 512 triangles go through the binned SAOH; 32 and 64 are small enough to be packed
  // into full leaves, which must still split by orientation.
  const auto [nx, ny] = GetParam();
  std::vector<Light> lights = roof(false, 2.2f, nx, ny);
  ASSERT_EQ(int(lights.size()), 4 * nx * ny);
  BinaryLightTree bt = build_binary_light_tree(emitter_bounds(lights));
  const BinaryLightNode& root = bt.nodes[0];
  ASSERT_FALSE(root.is_leaf());
  EXPECT_EQ(sides(bt, lights, root.left) | sides(bt, lights, root.right), 3);
  EXPECT_NE(sides(bt, lights, root.left), 3) << "left child mixes both slopes";
  EXPECT_NE(sides(bt, lights, root.right), 3) << "right child mixes both slopes";
  EXPECT_NEAR(bt.nodes[root.left].cone.theta_o, 0.0, 1e-4);
  EXPECT_NEAR(bt.nodes[root.right].cone.theta_o, 0.0, 1e-4);
  // every leaf but one is full (the packing keeps 4 emitters per leaf)
  int partial = 0;
  for (const BinaryLightNode& x : bt.nodes)
    if (x.is_leaf() && x.count < LT_MAX_LEAF) ++partial;
  EXPECT_LE(partial, 1);

  // Control: identical geometry with identical normals: now the area term decides and cuts y.
  std::vector<Light> flat = roof(true, 2.2f, nx, ny);
  BinaryLightTree bf = build_binary_light_tree(emitter_bounds(flat));
  EXPECT_EQ(sides(bf, flat, bf.nodes[0].left), 3);
  EXPECT_EQ(sides(bf, flat, bf.nodes[0].right), 3);
  // And the SAOH cost agrees: ridge cut cheaper than the y cut with orientation.
  EXPECT_LT(saoh_cost(root, bt.nodes[root.left], bt.nodes[root.right]),
            saoh_cost(bf.nodes[0], bf.nodes[bf.nodes[0].left], bf.nodes[bf.nodes[0].right]) * 4.0);
}

INSTANTIATE_TEST_SUITE_P(Triangles, LightTreeBuildRoof,
                         ::testing::Values(std::make_tuple(8, 16), // 512
                                           std::make_tuple(2, 8),  // 64
                                           std::make_tuple(2, 4)), // 32
                         [](const ::testing::TestParamInfo<std::tuple<int, int>>& p) {
                           return std::to_string(4 * std::get<0>(p.param) * std::get<1>(p.param));
                         });

TEST(LightTreeBuild, InvariantsMixedLights) {
  std::vector<Light> lights = mixed_lights(20000, 3, 10.0f);
  LightTree t = build_light_tree(lights);
  check_tree(lights, t);
  EXPECT_LE(double(t.device_bytes()) / lights.size(), 64.0);
}

TEST(LightTreeBuild, InvariantsCityAndTriangles) {
  for (auto lights : {city_lights(30000, 5), random_triangle_lights(30000, 5)}) {
    LightTree t = build_light_tree(lights);
    check_tree(lights, t);
    EXPECT_LE(double(t.device_bytes()) / lights.size(), 64.0);
    // a 4-wide tree over 30000 lights in leaves of <= 4 needs >= 7 levels; SAOH keeps it shallow
    EXPECT_LE(t.levels, 12);
  }
}

TEST(LightTreeBuild, InvariantsWithOptions) {
  std::vector<Light> lights = mixed_lights(3000, 8, 5.0f);
  for (int leaf : {1, 2, 4}) {
    for (int bins : {2, 8, 32}) {
      LightTreeBuildOptions opt;
      opt.leaf_size = leaf;
      opt.bins = bins;
      opt.parallel_grain = 256;
      LightTree t = build_light_tree(lights, opt);
      check_tree(lights, t);
    }
  }
}

TEST(LightTreeBuild, MillionCoincidentLights) {
  // All centroids coincide: no SAOH split exists; the build splits by index, stays balanced.
  const int n = 1000000;
  std::vector<Light> lights(n, make_point_light(make_float3(1, 2, 3), make_float3(1, 1, 1)));
  LightTree t = build_light_tree(lights);
  ASSERT_EQ(t.num_lights, n);
  EXPECT_LE(t.levels, 10); // ceil(log4(n / 4)) = 9, plus the root
  std::vector<char> seen(n, 0);
  for (int l : t.leaf_lights)
    seen[l]++;
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), n);
  EXPECT_LE(double(t.device_bytes()) / n, 64.0);
}

TEST(LightTreeBuild, DegenerateInputs) {
  EXPECT_EQ(build_light_tree({}).num_nodes(), 0);
  for (int n : {1, 2, 3, 4, 5, 17}) {
    std::vector<Light> l = random_point_lights(n, 1);
    LightTree t = build_light_tree(l);
    check_tree(l, t);
  }
  // collinear, coplanar, zero-energy, non-finite emission, zero-area triangles
  std::vector<Light> l;
  for (int i = 0; i < 1000; ++i)
    l.push_back(make_point_light(make_float3(float(i), 0, 0), make_float3(1, 1, 1)));
  for (int i = 0; i < 1000; ++i)
    l.push_back(
        make_point_light(make_float3(float(i % 30), float(i / 30), 5), make_float3(0, 0, 0)));
  Light bad = make_point_light(make_float3(1, 1, 1), make_float3(NAN, 1, 1));
  l.push_back(bad);
  l.push_back(make_triangle_light(make_float3(0, 0, 0), make_float3(1, 0, 0), make_float3(2, 0, 0),
                                  make_float3(1, 1, 1)));
  LightTree t = build_light_tree(l);
  check_tree(l, t);
  // all zero energy
  std::vector<Light> z = random_point_lights(500, 2);
  for (Light& x : z)
    x.emission = make_float4(0, 0, 0, 0);
  check_tree(z, build_light_tree(z));
}

TEST(LightTreeBuild, DeepChainStaysWithinBitTrailBudget) {
  // Points at x = i^4 (spacing grows without bound): SAOH peels off the far points one by one;
  // the depth guard must switch to median splits so every trail fits in 32 bits.
  std::vector<Light> l;
  for (int i = 0; i < 50000; ++i) {
    double x = std::pow(double(i), 4.0);
    l.push_back(make_point_light(make_float3(float(x), 0, 0), make_float3(1, 1, 1)));
  }
  LightTree t = build_light_tree(l);
  check_tree(l, t);
}
