// Half-edge connectivity of a triangle mesh (mesh_topology.h): twins by a search in each vertex's
// outgoing half-edges sorted by destination, then each vertex's fan walked about it.
#include "scene/mesh_topology.h"

#include "scene/scene.h"

#include <fmt/format.h>

#include <algorithm>

namespace canopy::detail {

namespace {

// Each vertex's outgoing half-edges, sorted by their destination vertex, in compressed rows:
// half_edges[start[v] .. start[v + 1]).
struct OutgoingHalfEdges {
  std::vector<uint32_t> start, half_edges;
};

OutgoingHalfEdges outgoing_half_edges(const std::vector<uint32_t>& indices, uint32_t vertex_count) {
  OutgoingHalfEdges out;
  out.start.assign(size_t(vertex_count) + 1, 0);
  for (uint32_t v : indices)
    ++out.start[v + 1];
  for (uint32_t v = 0; v < vertex_count; ++v)
    out.start[v + 1] += out.start[v];
  out.half_edges.resize(indices.size());
  std::vector<uint32_t> fill(out.start.begin(), out.start.end() - 1);
  for (uint32_t h = 0; h < indices.size(); ++h)
    out.half_edges[fill[indices[h]]++] = h;
  auto dest = [&](uint32_t h) { return indices[next_half_edge(h)]; };
  for (uint32_t v = 0; v < vertex_count; ++v)
    std::sort(out.half_edges.begin() + out.start[v], out.half_edges.begin() + out.start[v + 1],
              [&](uint32_t a, uint32_t b) { return dest(a) < dest(b); });
  return out;
}

// The half-edges from `from` to `to`: a range of out.half_edges.
std::pair<const uint32_t*, const uint32_t*> half_edges_between(const OutgoingHalfEdges& out,
                                                               const std::vector<uint32_t>& idx,
                                                               uint32_t from, uint32_t to) {
  const uint32_t* first = out.half_edges.data() + out.start[from];
  const uint32_t* last = out.half_edges.data() + out.start[from + 1];
  auto dest_less = [&](uint32_t h, uint32_t v) { return idx[next_half_edge(h)] < v; };
  auto less_dest = [&](uint32_t v, uint32_t h) { return v < idx[next_half_edge(h)]; };
  return {std::lower_bound(first, last, to, dest_less),
          std::upper_bound(first, last, to, less_dest)};
}

// Per vertex a, its outgoing half-edges come in runs of equal destination b: a run of two is two
// triangles running the same way from a to b; the half-edges from b to a are found by a binary
// search in b's.
std::vector<uint32_t> find_twins(const std::vector<uint32_t>& idx, const OutgoingHalfEdges& out) {
  std::vector<uint32_t> twin(idx.size(), kNoHalfEdge);
  const uint32_t vertex_count = uint32_t(out.start.size() - 1);
  for (uint32_t a = 0; a < vertex_count; ++a)
    for (uint32_t i = out.start[a], run; i < out.start[a + 1]; i += run) {
      uint32_t b = idx[next_half_edge(out.half_edges[i])];
      run = 1;
      while (i + run < out.start[a + 1] && idx[next_half_edge(out.half_edges[i + run])] == b)
        ++run;
      auto opposite = half_edges_between(out, idx, b, a);
      size_t n_opposite = size_t(opposite.second - opposite.first);
      if (run + n_opposite > 2)
        throw SceneError(fmt::format("the edge between vertices {} and {} is shared by {} "
                                     "triangles (the surface must be a manifold)",
                                     std::min(a, b), std::max(a, b), run + n_opposite));
      if (run == 2)
        throw SceneError(fmt::format("the two triangles on the edge between vertices {} and {} "
                                     "are wound in opposite directions (inconsistent orientation)",
                                     std::min(a, b), std::max(a, b)));
      if (n_opposite == 1) twin[out.half_edges[i]] = *opposite.first;
    }
  return twin;
}

// Appends vertex v's ring to topo.ring and sets topo.boundary[v]. Walking about v: from the
// outgoing half-edge h, the next triangle counter-clockwise is across the edge of prev(h), so
// twin(prev(h)) is the next outgoing half-edge; clockwise, next(twin(h)).
void append_ring(const std::vector<uint32_t>& idx, const OutgoingHalfEdges& out, uint32_t v,
                 MeshTopology& topo) {
  size_t triangles = out.start[v + 1] - out.start[v];
  if (triangles == 0) return;
  uint32_t first = out.half_edges[out.start[v]];
  // To the clockwise end of the fan, if it has one (at most `triangles` steps: the steps permute
  // v's outgoing half-edges).
  for (size_t i = 0; i < triangles && topo.twin[first] != kNoHalfEdge; ++i) {
    uint32_t h = next_half_edge(topo.twin[first]);
    if (h == out.half_edges[out.start[v]]) break;
    first = h;
  }
  size_t visited = 0;
  uint32_t h = first;
  do {
    topo.ring.push_back(idx[next_half_edge(h)]);
    ++visited;
    uint32_t p = prev_half_edge(h);
    if (topo.twin[p] == kNoHalfEdge) {
      topo.ring.push_back(idx[p]);
      topo.boundary[v] = 1;
      break;
    }
    h = topo.twin[p];
  } while (h != first && visited <= triangles);
  if (visited != triangles)
    throw SceneError(fmt::format("the triangles at vertex {} do not form a single fan "
                                 "(the surface must be a manifold)",
                                 v));
}

} // namespace

MeshTopology build_mesh_topology(const std::vector<uint32_t>& indices, uint32_t vertex_count) {
  OutgoingHalfEdges out = outgoing_half_edges(indices, vertex_count);
  MeshTopology topo;
  topo.twin = find_twins(indices, out);

  topo.edge.assign(indices.size(), 0);
  for (uint32_t h = 0; h < indices.size(); ++h) {
    uint32_t t = topo.twin[h];
    if (t != kNoHalfEdge && t < h) continue; // numbered with its twin
    topo.edge[h] = topo.edge_count;
    if (t != kNoHalfEdge) topo.edge[t] = topo.edge_count;
    ++topo.edge_count;
  }

  topo.boundary.assign(vertex_count, 0);
  topo.ring_start.assign(size_t(vertex_count) + 1, 0);
  topo.ring.reserve(indices.size() + vertex_count);
  for (uint32_t v = 0; v < vertex_count; ++v) {
    append_ring(indices, out, v, topo);
    topo.ring_start[v + 1] = uint32_t(topo.ring.size());
  }
  return topo;
}

} // namespace canopy::detail
