// Exact culling of one-sided planar emitters (cl/light_tree/layout.h, LT_PLANE_SLOPE): the
// importance of a leaf emitter or of a node lane is 0 wherever no emitter below it can send light
// to P (checked against the vertices in long double, the renderer's emission test being
// dot(n, P - x) > 0), and it is exactly 0 for points behind the plane by more than the bound's
// stated band (2^-12 of the distance plus the emitter's rounding margin; for nodes of coplanar
// emitters 2^-10 of the radius more), including points inside the bounding spheres.
#include "test_light_tree_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using namespace canopy;
using namespace canopy::test;

namespace {

using ld = long double;

// Largest dot(n, P - x) over the emitter's vertices (exact enough in long double): > 0 iff the
// one-sided emitter sends light to P (a linear function is largest at a vertex). A disk emits
// towards P iff dot(n, P - centre) > 0 (cl/lights/light_sample.h): its distance is that of the
// centre.
ld front_distance(const Light& l, float3 P) {
  const ld n[3] = {l.n.x, l.n.y, l.n.z};
  if (l.type == LIGHT_DISK) {
    ld s = n[0] * (ld(P.x) - l.p.x) + n[1] * (ld(P.y) - l.p.y) + n[2] * (ld(P.z) - l.p.z);
    return s / std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  }
  const ld p[3] = {l.p.x, l.p.y, l.p.z}, e1[3] = {l.e1.x, l.e1.y, l.e1.z},
           e2[3] = {l.e2.x, l.e2.y, l.e2.z}, q[3] = {P.x, P.y, P.z};
  ld best = -INFINITY;
  for (int v = 0; v < (l.type == LIGHT_QUAD ? 4 : 3); ++v) {
    ld s = 0;
    for (int k = 0; k < 3; ++k)
      s += n[k] * (q[k] - (p[k] + ((v & 1) ? e1[k] : 0) + ((v & 2) ? e2[k] : 0)));
    best = std::max(best, s);
  }
  ld nl = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  return best / nl;
}

// A grid of nx x nx one-sided quads in the plane through `origin` spanned by u, v (cells of size
// `cell`, quads of size 0.6 cell), all facing cross(u, v).
std::vector<Light> quad_grid(float3 origin, float3 u, float3 v, int nx, float cell) {
  std::vector<Light> lights;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < nx; ++j)
      lights.push_back(make_quad_light(origin + u * (cell * float(i)) + v * (cell * float(j)),
                                       u * (0.6f * cell), v * (0.6f * cell), make_float3(1, 1, 1)));
  return lights;
}

// The same grid of one-sided disks (radius 0.3 cell), facing cross(u, v); every fifth two-sided.
std::vector<Light> disk_grid(float3 origin, float3 u, float3 v, int nx, float cell) {
  std::vector<Light> lights;
  float3 n = cross(u, v);
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < nx; ++j)
      lights.push_back(make_disk_light(origin + u * (cell * float(i)) + v * (cell * float(j)), n,
                                       0.3f * cell, make_float3(1, 1, 1), (i + j) % 5 == 0));
  return lights;
}

struct Frame {
  float3 o, u, v, n;
};
Frame random_frame(LtRng& r, float offset) {
  Frame f;
  f.n = random_unit(r);
  f.u = lt_any_perpendicular(f.n);
  f.v = normalize(cross(f.n, f.u));
  f.u = normalize(cross(f.v, f.n)); // cross(u, v) = n
  f.o = random_unit(r) * offset;
  return f;
}

// Every (node, lane) and every leaf emitter of the tree: the emitter range below it.
struct Lane {
  int code, lane;
  std::vector<int> lights;
};
void collect(const LightTree& t, int node, std::vector<Lane>& out) {
  for (int k = 0; k < 4; ++k) {
    int c = i4_get(t.children[size_t(node)], k);
    if (c == LT_EMPTY) continue;
    Lane ln{node, k, {}};
    if (c >= 0) {
      size_t before = out.size();
      collect(t, c, out);
      for (size_t i = before; i < out.size(); ++i)
        if (out[i].code < 0)
          ln.lights.insert(ln.lights.end(), out[i].lights.begin(), out[i].lights.end());
    } else {
      for (int j = 0; j < lt_leaf_count(c); ++j) {
        int l = t.leaf_lights[size_t(lt_leaf_first(c) + j)];
        out.push_back(Lane{c, j, {l}});
        ln.lights.push_back(l);
      }
    }
    out.push_back(ln);
  }
}

// Checks conservativeness at P (N = 0: no receiver term, only the emitters' bounds act): a lane
// with importance 0 (split importances: no fallback) has no emitter below that sends light to P.
// Returns how many lanes were 0.
int check_conservative(const LightTree& t, const std::vector<Light>& lights,
                       const std::vector<Lane>& lanes, float3 P) {
  LtTree view = t.view(lights.data());
  const float3 N = make_float3(0, 0, 0);
  int zeros = 0;
  for (const Lane& ln : lanes) {
    float imp = f4_get(lt_code_importance(&view, ln.code, P, N), ln.lane);
    EXPECT_TRUE(imp >= 0.0f && std::isfinite(imp));
    if (imp > 0.0f) continue;
    ++zeros;
    for (int l : ln.lights) {
      const Light& x = lights[size_t(l)];
      const bool one_sided =
          (x.type == LIGHT_QUAD || x.type == LIGHT_TRIANGLE || x.type == LIGHT_DISK) &&
          !(x.flags & LIGHT_FLAG_TWO_SIDED);
      // points and two-sided quads reach every P (N = 0)
      EXPECT_TRUE(one_sided && front_distance(x, P) <= 0.0L)
          << "culled a light that reaches P: light " << l << " code " << ln.code << " lane "
          << ln.lane;
    }
  }
  return zeros;
}

// P at signed distance t from the plane (o, n) above a point of the grid's footprint (or beyond
// it), t spanning 1e-7 .. 1 of the grid's size on both sides.
float3 point_near_plane(LtRng& r, const Frame& f, float size, float t_sign) {
  float a = (1.6f * lt_rng_next(&r) - 0.3f) * size, b = (1.6f * lt_rng_next(&r) - 0.3f) * size;
  float t = t_sign * size * std::pow(10.0f, -7.0f * lt_rng_next(&r));
  return f.o + f.u * a + f.v * b + f.n * t;
}

} // namespace

TEST(LightTreeCull, LanesAreZeroOnlyWhereNoEmitterReachesP) {
  // Coplanar grids (node lanes get half-space bounds) in random orientations and offsets, random
  // one-sided triangles (leaf records only), and a mixed set with point lights and two-sided
  // quads (no bound may apply to their lanes). 400 points per set near the planes, both sides.
  // Sets 6 and 7: coplanar grids of one- and two-sided disks.
  LtRng r = lt_rng_make(7, 1);
  int zeros = 0, points = 0;
  for (int set = 0; set < 8; ++set) {
    Frame f = random_frame(r, set < 3 || set == 6 ? 2.0f : 300.0f);
    std::vector<Light> lights =
        set < 6 ? quad_grid(f.o, f.u, f.v, 12, 0.1f) : disk_grid(f.o, f.u, f.v, 12, 0.1f);
    if (set % 3 == 1) {
      for (Light& l : random_triangle_lights(200, 11 + set, 1.2f)) {
        l.p = f4_from3(xyz_of(l.p) + f.o, l.p.w);
        lights.push_back(l);
      }
    } else if (set % 3 == 2 && set < 6) {
      for (int i = 0; i < 30; ++i) {
        lights.push_back(make_point_light(f.o + random_unit(r), make_float3(1, 1, 1)));
        lights.push_back(make_quad_light(f.o + random_unit(r), f.u * 0.05f, f.v * 0.05f,
                                         make_float3(1, 1, 1), true));
      }
    }
    LightTree t = build_light_tree(lights);
    std::vector<Lane> lanes;
    collect(t, 0, lanes);
    for (int i = 0; i < 400; ++i) {
      float3 P = point_near_plane(r, f, 1.2f, i % 2 ? 1.0f : -1.0f);
      zeros += check_conservative(t, lights, lanes, P);
      ++points;
    }
  }
  EXPECT_GT(zeros, points); // the bound does cull (on average more than one lane per point)
}

TEST(LightTreeCull, OneSidedEmitterIsZeroBehindItsPlaneAndPositiveInFront) {
  // One quad or triangle (a leaf of one emitter; the root lane bounds it too), random orientation,
  // size and offset. P behind the plane by more than 2^-12 |P - c| + plane_h: the emitter record
  // and the root lane give exactly 0; P strictly in front (exact test): both > 0.
  // Iterations from 4000 on use a one-sided disk of radius `size`.
  LtRng r = lt_rng_make(8, 2);
  for (int i = 0; i < 6000; ++i) {
    Frame f = random_frame(r, std::pow(10.0f, 3.0f * lt_rng_next(&r) - 1.0f));
    float size = std::pow(10.0f, 4.0f * lt_rng_next(&r) - 3.0f);
    Light l =
        i >= 4000 ? make_disk_light(f.o, f.n, size, make_float3(1, 1, 1))
        : i % 2   ? make_quad_light(f.o, f.u * size, f.v * (0.7f * size), make_float3(1, 1, 1))
                : make_triangle_light(f.o, f.o + f.u * size, f.o + (f.u * 0.3f + f.v * 0.8f) * size,
                                      make_float3(1, 1, 1));
    std::vector<Light> lights = {l};
    LightTree t = build_light_tree(lights);
    LtTree view = t.view(lights.data());
    EmitterBounds b = emitter_bounds(l);
    ASSERT_FALSE(std::isnan(b.plane_h));
    float4 sp = lt_sphere_of_box(b.bmin, b.bmax);
    int leaf = i4_get(t.children[0], 0);
    ASSERT_TRUE(lt_is_leaf(leaf));
    for (int j = 0; j < 8; ++j) {
      float3 P = point_near_plane(r, f, 2.0f * size, j % 2 ? 1.0f : -1.0f);
      ld front = front_distance(l, P);
      float3 d = P - xyz_of(sp);
      // the record's band: the slope, the octahedral axis' error (< 2^-14 rad: 16 bits per
      // coordinate) and the float evaluation of the test (2^-20) times the distance, plane_h's
      // margin over the exact plane (2^-20 (|p| + |e1| + |e2|), 1-norm) and its storage in q (2^-20
      // r); the root lane's adds the axis tilt over the emitter
      // (<= 2 * 2^-12 r) and the 16-bit offset (2^-14 r)
      const ld dist = std::sqrt(ld(dot_d(d, d))), r_e = sp.w;
      // (a disk: |centre| + 2r per axis in place of |p| + |e1| + |e2|)
      const ld norm1 = l.type == LIGHT_DISK
                           ? std::fabs(l.p.x) + std::fabs(l.p.y) + std::fabs(l.p.z) + 6.0L * l.p.w
                           : std::fabs(l.p.x) + std::fabs(l.p.y) + std::fabs(l.p.z) +
                                 std::fabs(l.e1.x) + std::fabs(l.e1.y) + std::fabs(l.e1.z) +
                                 std::fabs(l.e2.x) + std::fabs(l.e2.y) + std::fabs(l.e2.z);
      const ld band = std::ldexp(dist, -12) + std::ldexp(dist, -14) + std::ldexp(dist, -20) +
                      std::ldexp(norm1, -20) + std::ldexp(r_e, -20);
      const ld root_band = band + std::ldexp(r_e, -11) + std::ldexp(r_e, -14);
      // N = 0; N = the light's normal (P's hemisphere holds the light only where P is behind it)
      for (float3 N : {make_float3(0, 0, 0), f.n}) {
        float leaf_imp = lt_code_importance(&view, leaf, P, N).x;
        float root_imp = lt_code_importance(&view, 0, P, N).x;
        if (front > 0 && N.x == 0 && N.y == 0 && N.z == 0) {
          EXPECT_GT(leaf_imp, 0.0f) << "in front by " << double(front);
          EXPECT_GT(root_imp, 0.0f) << "in front by " << double(front);
        }
        if (front < -band) {
          EXPECT_EQ(leaf_imp, 0.0f) << "behind by " << double(-front) << ", band " << double(band);
        }
        if (front < -root_band) {
          EXPECT_EQ(root_imp, 0.0f)
              << "behind by " << double(-front) << ", band " << double(root_band);
        }
      }
    }
  }
}

TEST(LightTreeCull, PointsBehindACeilingOfLightsGetAnEmptyCut) {
  // The default scene's geometry: a 16 x 16 grid of down-facing quads just below a ceiling, in a
  // random orientation. Every point behind the grid's plane by more than 2^-10 of the grid's
  // radius plus 2^-11 of its distance (the node bound's band, see LT_PLANE_SLOPE) gets importance
  // 0 in every root lane, inside the bounding spheres too: an empty cut, pmf 0 for every light,
  // however the sampler splits. In front, the cut is not empty.
  LtRng r = lt_rng_make(9, 3);
  for (int set = 0; set < 4; ++set) {
    Frame f = random_frame(r, set < 2 ? 1.0f : 100.0f);
    std::vector<Light> lights = quad_grid(f.o, f.u, f.v, 16, 1.0f / 16.0f);
    LightTree t = build_light_tree(lights);
    LtTree view = t.view(lights.data());
    // The paper's threshold, which splits the root for these points (a cut that does not split
    // is one stochastic pick, whose E/d^2 fallback gives a light that contributes 0).
    LightSamplerOptions split_opt;
    split_opt.split_threshold = 0.85f;
    auto sampler = make_light_sampler("tree-split", lights, split_opt);
    float3 c = xyz_of(t.root_sphere);
    ld R = t.root_sphere.w;
    double scale = std::fabs(f.o.x) + std::fabs(f.o.y) + std::fabs(f.o.z) + 3.0;
    for (int i = 0; i < 300; ++i) {
      float3 P = point_near_plane(r, f, 1.0f, i % 2 ? 1.0f : -1.0f);
      float3 d = P - c;
      ld band = std::ldexp(R, -10) + std::ldexp(std::sqrt(ld(dot_d(d, d))) + R, -11) +
                std::ldexp(ld(scale), -18);
      ld front = -INFINITY;
      for (const Light& l : lights)
        front = std::max(front, front_distance(l, P));
      float4 imp = lt_code_importance(&view, 0, P, make_float3(0, 0, 0));
      // behind: N = the lights' normal (a ceiling above them); in front: facing them (a floor)
      const float3 N = i % 2 ? f.n * -1.0f : f.n;
      std::vector<LightPick> cut;
      Rng rng = make_rng(5, uint32_t(i));
      sampler->sample(P, N, rng, cut);
      if (front < -band) {
        EXPECT_EQ(lt_sum4(imp), 0.0f) << "behind by " << double(-front);
        EXPECT_TRUE(cut.empty()) << "behind by " << double(-front);
        for (int l = 0; l < int(lights.size()); l += 37)
          EXPECT_EQ(sampler->pmf(P, N, l), 0.0f);
      }
      if (front > 0) {
        EXPECT_GT(lt_sum4(imp), 0.0f);
      }
      if (front > 1e-3L) {
        EXPECT_FALSE(cut.empty());
      }
    }
  }
}
