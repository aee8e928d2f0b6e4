// Geometry acceleration: the primitives of a scene (its triangles plus the shapes of analytic area
// lights), a BVH_WIDTH-wide (8) BVH over them built by Embree's rtcBuildBVH (SAH) and flattened for
// the intersect kernels, and an Embree RTCScene used as the reference intersector in
// tests/benchmarks.
#pragma once

#include "scene/scene.h"
#include "types.h"

#include <embree3/rtcore.h>

#include <vector>

namespace canopy {

struct Bvh {
  std::vector<BvhNode> nodes;         // nodes[0] is the root
  std::vector<LeafBlock> leaf_blocks; // the leaves' primitives, in leaf order (cl/types.h)
  int depth = 0;                      // node levels on the longest path (<= BVH_MAX_DEPTH)
};

struct SceneGeometry {
  std::vector<Primitive> prims;
  // Shading normals of the smooth triangles (Scene::shading_normals as float4, w = 0): a
  // triangle's Primitive::normals indexes its first of three (cl/geometry.h
  // primitive_shading_normal). Empty when every triangle is flat.
  std::vector<float4> shading_normals;
  // With a textured material: three uv per scene triangle (Scene::triangle_uvs, or the default
  // (0, 0), (1, 0), (1, 1) when no mesh has uv); empty otherwise (cl/texture.h).
  std::vector<float2> texcoords;
  Bvh bvh;
  float3 bounds_min{0, 0, 0}, bounds_max{0, 0, 0};
};

// Primitives for every scene triangle and every sphere/quad/triangle light (a quad is two
// triangles). Sets Light::prim of each light that has a shape (mesh-light triangles point at their
// own triangle). Analytic light shapes use an extra black material appended to the list.
// Primitive::normals of a scene triangle is Scene::triangle_normals[t] (an index into
// Scene::shading_normals), -1 for flat triangles and light shapes.
std::vector<Primitive> build_primitives(Scene& scene, std::vector<Material>& materials);

// BVH_WIDTH-wide SAH BVH over `prims`, via rtcBuildBVH; depth limited (BVH_MAX_DEPTH) so the
// kernels' fixed traversal stack never overflows.
Bvh build_bvh(const std::vector<Primitive>& prims);

SceneGeometry build_scene_geometry(Scene& scene, std::vector<Material>& materials);

// Embree's own BVH over the triangle primitives: the reference for the intersect kernels.
class EmbreeReference {
public:
  explicit EmbreeReference(const std::vector<Primitive>& triangles);
  ~EmbreeReference();
  EmbreeReference(const EmbreeReference&) = delete;
  EmbreeReference& operator=(const EmbreeReference&) = delete;

  // Closest hit: returns the primitive index or -1, and its t.
  int intersect(float3 o, float3 d, float tmin, float tmax, float* t) const;
  bool occluded(float3 o, float3 d, float tmin, float tmax) const;
  RTCScene scene() const { return scene_; }

private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
};

} // namespace canopy
