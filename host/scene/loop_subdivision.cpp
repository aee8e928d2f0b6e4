// Loop subdivision (loop_subdivision.h): the rules of pbrt-v4's LoopSubdivide
// (src/pbrt/util/loopsubdiv.cpp), on a half-edge topology (mesh_topology.h) rebuilt per level,
// in double precision.
#include "scene/loop_subdivision.h"

#include "scene/loader_internal.h"
#include "scene/mesh_topology.h"

#include <fmt/format.h>

#include <cmath>

namespace canopy::detail {

namespace {

constexpr double kPi = 3.14159265358979323846;

double dot(double3 a, double3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
double3 cross(double3 a, double3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// The weight of each neighbour of an interior even vertex of valence n: Warren's simplification
// of Loop's weight, as pbrt-v4 uses it (PBR 3rd ed., section 3.8): 3/16 for n = 3, else 3/(8n).
double warren_beta(size_t n) {
  return n == 3 ? 3.0 / 16.0 : 3.0 / (8.0 * double(n));
}

// The weight of each neighbour in an interior vertex's limit position: the left eigenvector of
// eigenvalue 1 of the subdivision matrix on the vertex and its ring, (1 - n gamma, gamma, ...):
// l S = l holds in a neighbour's entry when gamma (3/8 + 1/8 + 1/8) + (1 - n gamma) beta =
// gamma, i.e. gamma = 1 / (n + 3 / (8 beta)) (PBR 3rd ed., section 3.8).
double limit_gamma(size_t n) {
  return 1.0 / (double(n) + 3.0 / (8.0 * warren_beta(n)));
}

// One round of Loop's rules: vertex v keeps index v (even), the vertex on edge e is
// vertex_count + e (odd), and triangle t becomes triangles 4t .. 4t + 3, wound as t.
void subdivide_once(std::vector<double3>& p, std::vector<uint32_t>& idx) {
  const uint32_t vertex_count = uint32_t(p.size());
  MeshTopology topo = build_mesh_topology(idx, vertex_count);
  if (size_t(vertex_count) + topo.edge_count > UINT32_MAX)
    throw SceneError("the subdivided mesh has too many vertices");

  std::vector<double3> q(size_t(vertex_count) + topo.edge_count);
  for (uint32_t v = 0; v < vertex_count; ++v) {
    size_t n = topo.valence(v);
    const uint32_t* r = topo.ring_of(v);
    if (n == 0) {
      q[v] = p[v]; // unused: dropped at the end
    } else if (topo.boundary[v]) {
      q[v] = p[v] * 0.75 + (p[r[0]] + p[r[n - 1]]) * 0.125;
    } else {
      double3 sum;
      for (size_t j = 0; j < n; ++j)
        sum = sum + p[r[j]];
      q[v] = p[v] * (1.0 - double(n) * warren_beta(n)) + sum * warren_beta(n);
    }
  }
  for (uint32_t h = 0; h < idx.size(); ++h) {
    uint32_t t = topo.twin[h];
    if (t != kNoHalfEdge && t < h) continue; // done from its twin
    double3 a = p[idx[h]], b = p[idx[next_half_edge(h)]];
    double3& odd = q[vertex_count + topo.edge[h]];
    if (t == kNoHalfEdge) {
      odd = (a + b) * 0.5;
    } else {
      double3 c = p[idx[prev_half_edge(h)]], d = p[idx[prev_half_edge(t)]];
      odd = (a + b) * 0.375 + (c + d) * 0.125;
    }
  }

  std::vector<uint32_t> children;
  children.reserve(4 * idx.size());
  for (uint32_t h = 0; h < idx.size(); h += 3) {
    uint32_t v0 = idx[h], v1 = idx[h + 1], v2 = idx[h + 2];
    // e0 on v0 v1, e1 on v1 v2, e2 on v2 v0: the boundary of t reads v0 e0 v1 e1 v2 e2.
    uint32_t e0 = vertex_count + topo.edge[h], e1 = vertex_count + topo.edge[h + 1],
             e2 = vertex_count + topo.edge[h + 2];
    for (uint32_t c : {v0, e0, e2, e0, v1, e1, e2, e1, v2, e0, e1, e2})
      children.push_back(c);
  }
  p = std::move(q);
  idx = std::move(children);
}

// The limit surface's normal at a vertex, cross(S, T) of two tangents from its control points.
// Interior (Loop 1987; PBR 3rd ed., section 3.8): S = sum_j cos(2 pi j/n) r_j and
// T = sum_j sin(2 pi j/n) r_j. Boundary (Hoppe et al. 1994, "Piecewise smooth surface
// reconstruction", as pbrt-v4 uses them): S between the two boundary neighbours, T across the
// boundary into the surface by a mask per number of neighbours. These are left eigenvectors of
// the subdivision matrix for its subdominant eigenvalues, so a vertex's normal is the same at
// every level; not so for a boundary vertex of 5 or more neighbours, where Hoppe's mask assumes
// his modified edge rule, which pbrt's Loop rules do not use: there the normal is an estimate.
// pbrt-v4 applies these masks to the limit positions instead (an approximation that changes with
// the level); its interior ring runs clockwise and its boundary S the other way, so its
// cross(S, T) points against the winding (and pbrt turns the geometric normal to agree with it).
double3 limit_normal(const std::vector<double3>& p, uint32_t v, const MeshTopology& topo) {
  size_t n = topo.valence(v);
  const uint32_t* r = topo.ring_of(v);
  double3 s, t;
  if (!topo.boundary[v]) {
    for (size_t j = 0; j < n; ++j) {
      double angle = 2.0 * kPi * double(j) / double(n);
      s = s + p[r[j]] * std::cos(angle);
      t = t + p[r[j]] * std::sin(angle);
    }
  } else {
    s = p[r[0]] - p[r[n - 1]];
    if (n == 2) {
      t = p[r[0]] + p[r[1]] - p[v] * 2.0;
    } else if (n == 3) {
      t = p[r[1]] - p[v];
    } else if (n == 4) { // regular
      t = (p[r[1]] + p[r[2]]) * 2.0 - p[r[0]] - p[r[3]] - p[v] * 2.0;
    } else {
      double theta = kPi / double(n - 1);
      t = (p[r[0]] + p[r[n - 1]]) * -std::sin(theta);
      for (size_t k = 1; k + 1 < n; ++k)
        t = t + p[r[k]] * ((2.0 - 2.0 * std::cos(theta)) * std::sin(double(k) * theta));
    }
  }
  double3 normal = cross(s, t);
  double length = std::sqrt(dot(normal, normal));
  if (!(length > 0.0) || !std::isfinite(length)) return {};
  return normal * (1.0 / length);
}

// Interior: the left eigenvector of eigenvalue 1 (limit_gamma). Boundary: the cubic B-spline's
// limit (1/6, 2/3, 1/6) of the vertex and its boundary neighbours, the left eigenvector of the
// boundary rules. pbrt-v4 uses (1/5, 3/5, 1/5), which is not: a boundary vertex's point would
// then move with the level (a corner of a flat square by (e1 + e2)/40, for unit steps e1, e2
// along its sides, from level 0 to 1).
double3 limit_position(const std::vector<double3>& p, uint32_t v, const MeshTopology& topo) {
  size_t n = topo.valence(v);
  const uint32_t* r = topo.ring_of(v);
  if (topo.boundary[v]) return p[v] * (2.0 / 3.0) + (p[r[0]] + p[r[n - 1]]) * (1.0 / 6.0);
  double3 sum;
  for (size_t j = 0; j < n; ++j)
    sum = sum + p[r[j]];
  return p[v] * (1.0 - double(n) * limit_gamma(n)) + sum * limit_gamma(n);
}

void check_input(const std::vector<float3>& P, const std::vector<uint32_t>& indices, int levels) {
  if (levels < 0) throw SceneError(fmt::format("levels {} is negative", levels));
  if (indices.empty()) throw SceneError("no triangles");
  if (indices.size() % 3 != 0)
    throw SceneError(fmt::format("{} indices is not a multiple of 3", indices.size()));
  size_t triangles = indices.size() / 3;
  for (int level = 0; level < levels && triangles <= kMaxSubdividedTriangles; ++level)
    triangles *= 4;
  if (triangles > kMaxSubdividedTriangles)
    throw SceneError(fmt::format("{} levels of subdivision of {} triangles give more than {} "
                                 "triangles",
                                 levels, indices.size() / 3, kMaxSubdividedTriangles));
  if (P.size() > UINT32_MAX) throw SceneError("more than 2^32 - 1 vertices");
  for (size_t i = 0; i < indices.size(); ++i) {
    if (indices[i] >= P.size())
      throw SceneError(fmt::format("index {} is out of range ({} vertices)", indices[i], P.size()));
    float3 p = P[indices[i]];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw SceneError(fmt::format("vertex {} is not finite", indices[i]));
  }
  for (size_t i = 0; i < indices.size(); i += 3)
    if (indices[i] == indices[i + 1] || indices[i + 1] == indices[i + 2] ||
        indices[i + 2] == indices[i])
      throw SceneError(fmt::format("triangle {} ({} {} {}) repeats a vertex", i / 3, indices[i],
                                   indices[i + 1], indices[i + 2]));
}

} // namespace

SubdividedMesh loop_subdivide(const std::vector<float3>& P, const std::vector<uint32_t>& indices,
                              int levels) {
  check_input(P, indices, levels);
  std::vector<double3> p(P.size());
  for (size_t i = 0; i < P.size(); ++i)
    p[i] = dvec(P[i]);
  std::vector<uint32_t> idx = indices;
  for (int level = 0; level < levels; ++level)
    subdivide_once(p, idx);

  // Limits and normals from the last level's control points; unused input vertices dropped.
  MeshTopology topo = build_mesh_topology(idx, uint32_t(p.size()));
  SubdividedMesh out;
  std::vector<uint32_t> renumber(p.size(), UINT32_MAX);
  for (uint32_t v = 0; v < p.size(); ++v) {
    if (topo.valence(v) == 0) continue;
    renumber[v] = uint32_t(out.positions.size());
    out.positions.push_back(to_float3(limit_position(p, v, topo)));
    out.normals.push_back(to_float3(limit_normal(p, v, topo)));
  }
  out.indices.reserve(idx.size());
  for (uint32_t v : idx)
    out.indices.push_back(renumber[v]);
  return out;
}

} // namespace canopy::detail
