// Loop subdivision (host/scene/loop_subdivision.cpp) against closed forms derived here by hand:
// the limit positions and normals of the vertices of a tetrahedron, a cube, a flat grid and an
// icosahedron, which do not depend on the number of levels; the triangle count and the Euler
// characteristic. The errors are in test_scene_loop_subdivision_errors.cpp.
#include "scene/loop_subdivision.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>
#include <vector>

using canopy::detail::loop_subdivide;
using canopy::detail::SubdividedMesh;

namespace {

struct D3 {
  double x, y, z;
};
D3 d3(float3 v) {
  return {v.x, v.y, v.z};
}
D3 operator+(D3 a, D3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
D3 operator-(D3 a, D3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
D3 operator*(D3 a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
double dot(D3 a, D3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
D3 cross(D3 a, D3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double length(D3 a) {
  return std::sqrt(dot(a, a));
}
D3 unit(D3 a) {
  return a * (1.0 / length(a));
}

void expect_near(D3 got, D3 want, double tol, const char* what) {
  EXPECT_NEAR(got.x, want.x, tol) << what;
  EXPECT_NEAR(got.y, want.y, tol) << what;
  EXPECT_NEAR(got.z, want.z, tol) << what;
}

struct Input {
  std::vector<float3> P;
  std::vector<uint32_t> indices;
};

// Winds every triangle of a convex solid around the origin so that (p1 - p0) x (p2 - p0) points
// away from the origin: the test data's orientation, independent of the code under test.
void wind_outward(Input& m) {
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    D3 a = d3(m.P[m.indices[t]]), b = d3(m.P[m.indices[t + 1]]), c = d3(m.P[m.indices[t + 2]]);
    if (dot(cross(b - a, c - a), a) < 0) std::swap(m.indices[t + 1], m.indices[t + 2]);
  }
}

// Regular tetrahedron centred at the origin.
Input tetrahedron() {
  Input m{{make_float3(1, 1, 1), make_float3(1, -1, -1), make_float3(-1, 1, -1),
           make_float3(-1, -1, 1)},
          {1, 2, 3, 0, 2, 3, 0, 1, 3, 0, 1, 2}};
  wind_outward(m);
  return m;
}

// The cube [-1, 1]^3, vertex i = (x > 0) + 2 (y > 0) + 4 (z > 0). Each face is split along the
// diagonal through vertex 7 = (1, 1, 1) or, on the faces of vertex 0 = (-1, -1, -1), the one that
// avoids vertex 0: vertices 7, 1, 2, 4 then have valence 6 and vertices 0, 3, 5, 6 valence 3, and
// the triangulation keeps the cube's 3-fold symmetry about the diagonal from 0 to 7.
Input cube() {
  Input m;
  for (int i = 0; i < 8; ++i)
    m.P.push_back(make_float3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  // Per face: the diagonal, then the other two corners.
  const int faces[6][4] = {{2, 4, 0, 6}, {7, 1, 3, 5}, {1, 4, 0, 5},
                           {7, 2, 3, 6}, {1, 2, 0, 3}, {7, 4, 5, 6}};
  for (const auto& f : faces)
    for (int other : {f[2], f[3]})
      for (int v : {f[0], f[1], other})
        m.indices.push_back(uint32_t(v));
  wind_outward(m);
  return m;
}

// Regular icosahedron of circumradius 1: the cyclic permutations of (0, +-1, +-phi), scaled; its
// triangles are the triples of vertices at mutual distance 2 before scaling.
Input icosahedron() {
  const double phi = (1 + std::sqrt(5.0)) / 2, s = 1 / std::sqrt(1 + phi * phi);
  std::vector<D3> v;
  for (double a : {-1.0, 1.0})
    for (double b : {-phi, phi})
      for (D3 p : {D3{0, a, b}, D3{a, b, 0}, D3{b, 0, a}})
        v.push_back(p);
  Input m;
  for (D3 p : v)
    m.P.push_back(make_float3(float(p.x * s), float(p.y * s), float(p.z * s)));
  auto adjacent = [&](size_t i, size_t j) { return std::fabs(length(v[i] - v[j]) - 2) < 1e-9; };
  for (uint32_t i = 0; i < 12; ++i)
    for (uint32_t j = i + 1; j < 12; ++j)
      for (uint32_t k = j + 1; k < 12; ++k)
        if (adjacent(i, j) && adjacent(j, k) && adjacent(i, k))
          m.indices.insert(m.indices.end(), {i, j, k});
  wind_outward(m);
  return m;
}

// The square [0, 4]^2 in z = 0 as a 4 x 4 grid of unit squares, vertex (i, j) = 5 j + i, each
// square split along its diagonal from (i, j) to (i + 1, j + 1), wound counter-clockwise seen from
// +z (or clockwise if `flip`).
Input grid(bool flip = false) {
  Input m;
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 4; ++i)
      m.P.push_back(make_float3(float(i), float(j), 0));
  for (uint32_t j = 0; j < 4; ++j)
    for (uint32_t i = 0; i < 4; ++i) {
      uint32_t a = 5 * j + i, b = a + 1, c = a + 6, d = a + 5;
      if (flip)
        m.indices.insert(m.indices.end(), {a, c, b, a, d, c});
      else
        m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
    }
  return m;
}

// Undirected edges, and those used by one triangle only (the boundary).
std::set<std::pair<uint32_t, uint32_t>> edges(const std::vector<uint32_t>& idx, bool boundary) {
  std::multiset<std::pair<uint32_t, uint32_t>> all;
  for (size_t t = 0; t < idx.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = idx[t + k], b = idx[t + (k + 1) % 3];
      all.insert({std::min(a, b), std::max(a, b)});
    }
  std::set<std::pair<uint32_t, uint32_t>> out;
  for (const auto& e : all)
    if (!boundary || all.count(e) == 1) out.insert(e);
  return out;
}

// The limit position of an interior vertex of valence n, from its 1-ring: (1 - n g) v + g sum,
// g = 1 / (n + 3 / (8 beta)), beta = 3/16 for n = 3 and 3/(8n) otherwise (Warren's weights, as
// pbrt-v4 uses them). Written here from the formula, on the input mesh.
D3 interior_limit(const Input& m, uint32_t v) {
  std::set<uint32_t> ring;
  for (const auto& e : edges(m.indices, false)) {
    if (e.first == v) ring.insert(e.second);
    if (e.second == v) ring.insert(e.first);
  }
  double n = double(ring.size()), beta = ring.size() == 3 ? 3.0 / 16 : 3.0 / (8 * n);
  double g = 1 / (n + 3 / (8 * beta));
  D3 sum{0, 0, 0};
  for (uint32_t r : ring)
    sum = sum + d3(m.P[r]);
  return d3(m.P[v]) * (1 - n * g) + sum * g;
}

} // namespace

// Every closed mesh: 4^levels times the triangles, V - E + F = 2 (a sphere's Euler
// characteristic, which subdivision preserves), every index in range.
TEST(LoopSubdivision, TriangleCountAndEulerCharacteristic) {
  for (const Input& m : {tetrahedron(), cube(), icosahedron()})
    for (int levels = 0; levels <= 3; ++levels) {
      SubdividedMesh s = loop_subdivide(m.P, m.indices, levels);
      size_t f = s.indices.size() / 3;
      EXPECT_EQ(f, (m.indices.size() / 3) << (2 * levels));
      EXPECT_EQ(s.normals.size(), s.positions.size());
      for (uint32_t i : s.indices)
        ASSERT_LT(i, s.positions.size());
      long euler = long(s.positions.size()) - long(edges(s.indices, false).size()) + long(f);
      EXPECT_EQ(euler, 2) << "levels " << levels;
      EXPECT_TRUE(edges(s.indices, true).empty());
    }
}

// Tetrahedron with centroid 0: every vertex v has valence 3, so beta = 3/16 and
// gamma = 1 / (3 + 3 / (8 * 3/16)) = 1/5, and its three neighbours sum to -v: the limit is
// (1 - 3/5) v + (1/5)(-v) = v/5. One level later the same point: v moves to
// (1 - 9/16) v + (3/16)(-v) = v/4, its new neighbours are the edge points
// 3/8 (v + w) + 1/8 (-v - w) = (v + w)/4 for its three old neighbours w, summing to v/2, and
// (2/5)(v/4) + (1/5)(v/2) = v/5. The normal is along v, outward, by the 3-fold symmetry about v.
TEST(LoopSubdivision, TetrahedronCornersGoToAFifthOfTheWay) {
  Input m = tetrahedron();
  for (int levels = 0; levels <= 2; ++levels) {
    SubdividedMesh s = loop_subdivide(m.P, m.indices, levels);
    for (uint32_t v = 0; v < 4; ++v) {
      expect_near(d3(s.positions[v]), d3(m.P[v]) * 0.2, 1e-6, "limit position");
      expect_near(d3(s.normals[v]), unit(d3(m.P[v])), 1e-6, "limit normal");
    }
  }
}

// Cube (see cube()): the three edge neighbours of a corner v are v with one coordinate negated,
// summing to v; the three diagonal neighbours have two negated, summing to -v. Valence 3
// (gamma = 1/5): (2/5) v + (1/5) v = 3v/5. Valence 6 (beta = 1/16, gamma = 1/12): the ring sums
// to 0, so v/2. Both also from the formula written out in interior_limit(), and at levels 1 and 2
// the same points (the limit of a vertex does not depend on the level). By the 3-fold symmetry
// about the diagonal from vertex 0 to vertex 7, their normals are -+(1, 1, 1)/sqrt(3); every
// vertex's normal is the same at each level (the tangent masks are eigenvectors of the
// subdivision matrix) and points out of the cube.
TEST(LoopSubdivision, CubeVerticesGoToTheirLimitByValence) {
  Input m = cube();
  const int valence[8] = {3, 6, 6, 3, 6, 3, 3, 6};
  SubdividedMesh level0 = loop_subdivide(m.P, m.indices, 0);
  for (int levels = 0; levels <= 2; ++levels) {
    SubdividedMesh s = loop_subdivide(m.P, m.indices, levels);
    for (uint32_t v = 0; v < 8; ++v) {
      D3 p = d3(m.P[v]);
      D3 want = p * (valence[v] == 6 ? 0.5 : 0.6);
      expect_near(interior_limit(m, v), want, 1e-12, "formula on the input ring");
      expect_near(d3(s.positions[v]), want, 1e-6, "limit position");
      expect_near(d3(s.normals[v]), d3(level0.normals[v]), 1e-6, "normal at each level");
      EXPECT_GT(dot(d3(s.normals[v]), p), 0.0) << "vertex " << v;
    }
    expect_near(d3(s.normals[0]), unit(D3{-1, -1, -1}), 1e-6, "normal at vertex 0");
    expect_near(d3(s.normals[7]), unit(D3{1, 1, 1}), 1e-6, "normal at vertex 7");
  }
}

// The grid (see grid()) is flat: every mask is an affine combination, so z stays 0 and the
// normals are +z (-z with the winding reversed). Its original vertices' limits: interior, valence
// 6 with the ring summing to 6v, (1 - 6/12) v + (1/12) 6v = v; on a side, the cubic B-spline
// limit (1/6, 2/3, 1/6) of two neighbours at v -+ the unit step, v again; a corner c with
// neighbours c + e1 and c + e2 along its sides, c + (e1 + e2)/6. One level later the corner is at
// (3/4) c + (1/8)(2c + e1 + e2) = c + (e1 + e2)/8 with neighbours c + e1/2 and c + e2/2 on its
// sides, and (2/3)(c + (e1 + e2)/8) + (1/6)(2c + (e1 + e2)/2) = c + (e1 + e2)/6 again. The boundary
// curve is the cubic B-spline of the boundary polygon: where four consecutive control points lie on
// a side, between the original vertices 1 and 3 along it, it lies on that side.
TEST(LoopSubdivision, FlatGridStaysFlatAndKeepsItsStraightSides) {
  for (bool flip : {false, true})
    for (int levels = 0; levels <= 3; ++levels) {
      Input m = grid(flip);
      SubdividedMesh s = loop_subdivide(m.P, m.indices, levels);
      for (size_t v = 0; v < s.positions.size(); ++v) {
        EXPECT_EQ(s.positions[v].z, 0.0f);
        expect_near(d3(s.normals[v]), {0, 0, flip ? -1.0 : 1.0}, 1e-6, "normal");
      }
      for (int j = 0; j <= 4; ++j)
        for (int i = 0; i <= 4; ++i) {
          D3 want{double(i), double(j), 0};
          if ((i == 0 || i == 4) && (j == 0 || j == 4))
            want = want + D3{i == 0 ? 1.0 : -1.0, j == 0 ? 1.0 : -1.0, 0} * (1.0 / 6);
          expect_near(d3(s.positions[5 * j + i]), want, 1e-6, "original vertex");
        }
      for (const auto& e : edges(s.indices, true))
        for (uint32_t v : {e.first, e.second}) {
          float3 p = s.positions[v];
          if (p.x >= 1 - 1e-4 && p.x <= 3 + 1e-4) {
            EXPECT_TRUE(p.y == 0 || p.y == 4) << p.y;
          }
          if (p.y >= 1 - 1e-4 && p.y <= 3 + 1e-4) {
            EXPECT_TRUE(p.x == 0 || p.x == 4) << p.x;
          }
        }
    }
}

// Icosahedron of circumradius 1: every vertex v has valence 5 (beta = 3/40, gamma = 1/10) and
// five neighbours at cos(angle) = 1/sqrt(5) from it, whose sum is sqrt(5) v (the parts across v
// cancel by the 5-fold symmetry): the limit is (1/2 + sqrt(5)/10) v = rho v, with the normal
// along v. The vertices added on the edges at level 1 lie on the edges' 2-fold symmetry axes: so
// do their limits and normals, the same at every level. The limit surface is close to, not
// exactly, the sphere of radius rho: at level 3 every vertex lies within 5 % of rho and its normal
// within 5 degrees of the radial direction (loose bounds), and within 1 degree of the mean normal
// of the triangles around it (the fine mesh follows the tangent plane).
TEST(LoopSubdivision, IcosahedronConvergesToARoundSurface) {
  Input m = icosahedron();
  ASSERT_EQ(m.indices.size(), 60u);
  const double rho = (5 + std::sqrt(5.0)) / 10;
  SubdividedMesh level1 = loop_subdivide(m.P, m.indices, 1);
  ASSERT_EQ(level1.positions.size(), 42u);
  for (int levels = 0; levels <= 3; ++levels) {
    SubdividedMesh s = loop_subdivide(m.P, m.indices, levels);
    for (uint32_t v = 0; v < 12; ++v) {
      expect_near(d3(s.positions[v]), d3(m.P[v]) * rho, 1e-6, "limit position");
      expect_near(d3(s.normals[v]), unit(d3(m.P[v])), 1e-6, "limit normal");
    }
    for (uint32_t v = 12; levels >= 1 && v < 42; ++v) {
      expect_near(d3(s.normals[v]), unit(d3(s.positions[v])), 1e-6, "on a 2-fold axis");
      expect_near(d3(s.positions[v]), d3(level1.positions[v]), 1e-6, "the same at each level");
    }
    if (levels < 3) continue;
    std::vector<D3> facets(s.positions.size(), D3{0, 0, 0});
    for (size_t t = 0; t < s.indices.size(); t += 3) {
      D3 a = d3(s.positions[s.indices[t]]), b = d3(s.positions[s.indices[t + 1]]);
      D3 n = unit(cross(b - a, d3(s.positions[s.indices[t + 2]]) - a));
      for (int k = 0; k < 3; ++k)
        facets[s.indices[t + k]] = facets[s.indices[t + k]] + n;
    }
    const double degree = 3.14159265358979 / 180;
    for (size_t v = 0; v < s.positions.size(); ++v) {
      D3 p = d3(s.positions[v]), n = d3(s.normals[v]);
      EXPECT_NEAR(length(p), rho, 0.05 * rho);
      EXPECT_GT(dot(unit(p), n), std::cos(5 * degree));
      EXPECT_GT(dot(unit(facets[v]), n), std::cos(1 * degree));
    }
  }
}

// The tetrahedron without the triangle opposite vertex 0: vertex 0 keeps its closed ring, so its
// limit is v0/5 as in TetrahedronCornersGoToAFifthOfTheWay (its ring at level 1 is made by the
// same interior rules). Vertices 1, 2, 3 are on the boundary, the cubic B-spline curve of the
// triangle they span: their limits are (2/3) v + (1/6)(the other two) = (2/3) v + (1/6)(-v0 - v),
// every boundary vertex lies in their plane (the boundary rules use only boundary vertices), and
// with 3 neighbours each, their normals are the same at every level and point out of the solid.
TEST(LoopSubdivision, OpenTetrahedronFollowsTheBoundaryRules) {
  Input m = tetrahedron();
  for (size_t t = 0; t < m.indices.size(); t += 3)
    if (m.indices[t] != 0 && m.indices[t + 1] != 0 && m.indices[t + 2] != 0) {
      m.indices.erase(m.indices.begin() + long(t), m.indices.begin() + long(t) + 3);
      break;
    }
  ASSERT_EQ(m.indices.size(), 9u);
  const D3 v0 = d3(m.P[0]);
  SubdividedMesh level0 = loop_subdivide(m.P, m.indices, 0);
  for (int levels = 0; levels <= 3; ++levels) {
    SubdividedMesh s = loop_subdivide(m.P, m.indices, levels);
    expect_near(d3(s.positions[0]), v0 * 0.2, 1e-6, "apex");
    expect_near(d3(s.normals[0]), unit(v0), 1e-6, "apex normal");
    for (uint32_t v = 1; v < 4; ++v) {
      D3 p = d3(m.P[v]);
      expect_near(d3(s.positions[v]), p * 0.5 - v0 * (1.0 / 6), 1e-6, "boundary limit");
      expect_near(d3(s.normals[v]), d3(level0.normals[v]), 1e-6, "normal at each level");
      EXPECT_GT(dot(d3(s.normals[v]), d3(s.positions[v])), 0.0);
    }
    // The plane of vertices 1, 2, 3 is dot(x, v0) = -|v0|^2 / 3 (they sum to -v0).
    for (const auto& e : edges(s.indices, true))
      for (uint32_t v : {e.first, e.second})
        EXPECT_NEAR(dot(d3(s.positions[v]), v0), -dot(v0, v0) / 3, 1e-5);
  }
}

// Vertices no triangle uses are dropped and the others renumbered in order.
TEST(LoopSubdivision, UnusedVerticesAreDropped) {
  Input m = tetrahedron();
  Input padded;
  padded.P = {make_float3(9, 9, 9)};
  padded.P.insert(padded.P.end(), m.P.begin(), m.P.end());
  padded.P.push_back(make_float3(-9, 9, 9));
  for (uint32_t i : m.indices)
    padded.indices.push_back(i + 1);
  SubdividedMesh s = loop_subdivide(padded.P, padded.indices, 0);
  ASSERT_EQ(s.positions.size(), 4u);
  EXPECT_EQ(s.indices, m.indices);
  for (uint32_t v = 0; v < 4; ++v)
    expect_near(d3(s.positions[v]), d3(m.P[v]) * 0.2, 1e-6, "limit position");
}
