// Half-edge connectivity of a triangle mesh, as Loop subdivision (loop_subdivision.cpp) needs it:
// the twin of every half-edge, one id per undirected edge, and each vertex's one-ring in order.
// Not part of the public interface (that is scene.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace canopy::detail {

// Half-edge h = 3 t + k of triangle t runs from its corner k to its corner (k + 1) % 3.
constexpr uint32_t kNoHalfEdge = UINT32_MAX;
inline uint32_t next_half_edge(uint32_t h) {
  return h - h % 3 + (h % 3 + 1) % 3;
}
inline uint32_t prev_half_edge(uint32_t h) {
  return h - h % 3 + (h % 3 + 2) % 3;
}

struct MeshTopology {
  // Per half-edge: the half-edge of the neighbouring triangle that runs the other way along the
  // same edge, or kNoHalfEdge on a boundary edge.
  std::vector<uint32_t> twin;
  // Per half-edge: its undirected edge, 0 .. edge_count - 1 (a half-edge and its twin share one).
  std::vector<uint32_t> edge;
  uint32_t edge_count = 0;
  // Vertex v's neighbours ring[ring_start[v] .. ring_start[v + 1]), counter-clockwise about the
  // winding normal (p1 - p0) x (p2 - p0). An interior vertex of n triangles has n neighbours; a
  // boundary vertex of n triangles has n + 1, from the boundary neighbour at the clockwise end
  // to the one at the counter-clockwise end. A vertex no triangle uses has none.
  std::vector<uint32_t> ring_start, ring;
  std::vector<uint8_t> boundary; // per vertex: 1 on the boundary

  size_t valence(uint32_t v) const { return ring_start[v + 1] - ring_start[v]; }
  const uint32_t* ring_of(uint32_t v) const { return ring.data() + ring_start[v]; }
};

// The topology of the triangles `indices` (3 per triangle, each < vertex_count, the three of a
// triangle distinct: the caller checks). The surface must be a consistently wound manifold with
// or without boundary; otherwise a one-line SceneError naming the vertices: an edge of more than
// two triangles, two triangles that run the same way along their shared edge, a vertex whose
// triangles form more than one fan. O(n log n) in the number of triangles.
MeshTopology build_mesh_topology(const std::vector<uint32_t>& indices, uint32_t vertex_count);

} // namespace canopy::detail
