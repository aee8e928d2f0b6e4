// Loop subdivision surfaces, tessellated as pbrt-v4 does for its Shape "loopsubdiv"
// (src/pbrt/util/loopsubdiv.cpp; Pharr, Jakob and Humphreys, Physically Based Rendering, 3rd ed.,
// section 3.8): `levels` rounds of Loop's rules, then every vertex moved to its position on the
// limit surface, with the limit surface's normal. Not part of the public interface (scene.h).
#pragma once

#include "scene/scene.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace canopy::detail {

// The most triangles a subdivision may produce: the pbrt reader's cap on a scene's triangles
// (kMaxTriangles in pbrt_reader.cpp), so a "levels" of 20 is an error instead of an
// out-of-memory kill.
constexpr size_t kMaxSubdividedTriangles = size_t(1) << 27;

struct SubdividedMesh {
  std::vector<float3> positions; // on the limit surface
  // Per vertex: the limit surface's unit normal, on the side the triangles' winding gives
  // ((p1 - p0) x (p2 - p0)); zero where the surface has no tangent plane (a degenerate ring).
  // pbrt-v4's normals are the opposite ones, and pbrt turns a triangle's geometric normal to its
  // shading normal, so a pbrt loopsubdiv surface faces against its winding: what one-sided
  // emission and a dielectric's inside see (the killeroo is wound outward, so in pbrt it faces in).
  std::vector<float3> normals;
  std::vector<uint32_t> indices; // 3 per triangle, wound as the input
};

// Loop subdivision (Loop 1987) with Warren's weights as pbrt-v4 uses them: an interior even
// vertex of valence n keeps 1 - n beta of itself and beta = 3/(8n) (3/16 for n = 3) of each
// neighbour; an odd (edge) vertex is 3/8, 3/8, 1/8, 1/8 of the edge's ends and opposite corners.
// Boundary edges are cubic B-spline curves: even 1/8, 3/4, 1/8 along the boundary, odd 1/2, 1/2.
// The limit positions and normals are exact where pbrt-v4's are approximations (see
// loop_subdivision.cpp): a vertex's limit point and normal do not depend on `levels`.
//
// The input is a consistently wound manifold triangle mesh, with or without boundary. Output
// vertex i < P.size() is the limit of input vertex i when every input vertex is used (vertices no
// triangle uses are dropped); each level appends the vertices it adds on the edges, so the first
// vertices of a subdivision by k levels are those of k - 1 levels, at the same limit points. The
// result has 4^levels times the input's triangles; levels = 0 gives the input triangles with their
// vertices on the limit surface.
//
// Throws a one-line SceneError (without file or line: the caller adds them) for: levels < 0, a
// result of more than kMaxSubdividedTriangles triangles, no triangles, an index count that is not
// a multiple of 3, an index >= P.size(), a triangle that repeats a vertex, a non-finite position,
// or a surface that is not a consistently wound manifold (mesh_topology.h).
SubdividedMesh loop_subdivide(const std::vector<float3>& P, const std::vector<uint32_t>& indices,
                              int levels);

} // namespace canopy::detail
