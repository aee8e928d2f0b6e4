// Half-edge topology (host/scene/mesh_topology.cpp) of a fan of six triangles around vertex 0 in
// the plane z = 0, wound counter-clockwise seen from +z: twins, edge ids and ordered one-rings,
// worked out by hand from the picture. Its errors are in test_scene_loop_subdivision_errors.cpp.
#include "scene/mesh_topology.h"

#include <gtest/gtest.h>

#include <vector>

using namespace canopy::detail;

namespace {

// Vertex 0 at the centre, vertex k = 1..6 at angle 60 (k - 1) degrees; triangle k - 1 is
// (0, k, k + 1), with 7 read as 1.
std::vector<uint32_t> hexagon_fan() {
  std::vector<uint32_t> idx;
  for (uint32_t k = 1; k <= 6; ++k)
    idx.insert(idx.end(), {0, k, k % 6 + 1});
  return idx;
}

std::vector<uint32_t> ring(const MeshTopology& t, uint32_t v) {
  return {t.ring_of(v), t.ring_of(v) + t.valence(v)};
}

} // namespace

// 6 spokes and 6 rim edges; each spoke is shared (half-edge 3t runs 0 -> k, and triangle k - 2's
// half-edge 3(k - 2) + 2 runs k -> 0), each rim edge (half-edge 3t + 1) is on the boundary.
TEST(MeshTopology, FanTwinsAndEdges) {
  MeshTopology t = build_mesh_topology(hexagon_fan(), 7);
  EXPECT_EQ(t.edge_count, 12u);
  for (uint32_t tri = 0; tri < 6; ++tri) {
    uint32_t spoke = 3 * tri, rim = 3 * tri + 1, back = 3 * ((tri + 5) % 6) + 2;
    EXPECT_EQ(t.twin[spoke], back);
    EXPECT_EQ(t.twin[back], spoke);
    EXPECT_EQ(t.edge[spoke], t.edge[back]);
    EXPECT_EQ(t.twin[rim], kNoHalfEdge);
  }
  std::vector<int> uses(t.edge_count, 0);
  for (uint32_t e : t.edge)
    ++uses[e];
  for (int n : uses)
    EXPECT_TRUE(n == 1 || n == 2);
}

// Vertex 0 is interior, its ring 1..6 counter-clockwise (from any start). Vertex 1 at (1, 0) sees
// vertex 2 at 120 degrees, vertex 0 at 180 and vertex 6 at 240, and lies on the boundary: its ring
// runs counter-clockwise from the boundary neighbour at the clockwise end, 2, 0, 6.
TEST(MeshTopology, FanRingsAreCounterClockwise) {
  MeshTopology t = build_mesh_topology(hexagon_fan(), 7);
  EXPECT_FALSE(t.boundary[0]);
  std::vector<uint32_t> r = ring(t, 0);
  ASSERT_EQ(r.size(), 6u);
  for (size_t j = 0; j < 6; ++j)
    EXPECT_EQ(r[(j + 1) % 6], r[j] % 6 + 1);
  for (uint32_t k = 1; k <= 6; ++k) {
    EXPECT_TRUE(t.boundary[k]);
    EXPECT_EQ(ring(t, k), (std::vector<uint32_t>{k % 6 + 1, 0, (k + 4) % 6 + 1})) << k;
  }
}

// A vertex no triangle uses has an empty ring.
TEST(MeshTopology, UnusedVertexHasNoRing) {
  MeshTopology t = build_mesh_topology(hexagon_fan(), 8);
  EXPECT_EQ(t.valence(7), 0u);
  EXPECT_FALSE(t.boundary[7]);
}
