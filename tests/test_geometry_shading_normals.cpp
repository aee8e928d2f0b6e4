// Shading normals from OBJ vn (tests/data/smooth.obj): the loader keeps a unit world-space normal
// for each vertex of a smooth triangle (through the shape's transform, mirrors included), the
// geometry links each primitive to its three, and primitive_shading_normal (cl/geometry.h)
// interpolates them: the vertex normal at each vertex, the normalised mean at the centre, always
// on the geometric normal's side; flat triangles, spheres and cancelling normals give Ng.
#include "accel/bvh.h"
#include "geometry.h"
#include "test_scene_util.h"

#include <cmath>
#include <functional>
#include <map>
#include <vector>

using namespace canopy;
using namespace canopy::test;

namespace {

// smooth.obj's normals as written (local space, not unit) and, per triangle after tinyobjloader's
// triangulation, the normal of each of its (local) vertices; an empty map: a flat triangle.
const float3 kFileNormals[] = {{0, 1, 0}, {1, 1, 0}, {0, 2, 1}, {0, 0, 0}, {0, -1, 0}};
const std::vector<std::map<uint32_t, int>> kTriangleNormals = {
    {{0, 0}, {1, 1}, {2, 2}},         // f 1//1 2//2 3//3
    {},                               // a zero normal: flat
    {},                               // no normals: flat
    {{0, 4}, {1, 4}, {2, 4}},         // normals against the winding
    {{0, 0}, {1, 1}, {3, 2}, {2, 0}}, // the quad's two triangles (either diagonal)
    {{0, 0}, {1, 1}, {3, 2}, {2, 0}},
};

float3 unit(float3 a) {
  double x = a.x, y = a.y, z = a.z, l = std::sqrt(x * x + y * y + z * z);
  return make_float3(float(x / l), float(y / l), float(z / l));
}

float3 on_side(float3 n, float3 ng) {
  return dot(n, ng) < 0.0f ? n * -1.0f : n;
}

void expect_near3(float3 a, float3 b, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, 2e-6f) << what;
  EXPECT_NEAR(a.y, b.y, 2e-6f) << what;
  EXPECT_NEAR(a.z, b.z, 2e-6f) << what;
}

struct Built {
  Scene scene;
  std::vector<Material> materials;
  SceneGeometry geometry;
};

Built build(const std::string& shapes, const std::string& lights = "[]") {
  Built b;
  b.scene = load_str(scene_with(R"("shapes": [)" + shapes + "]", lights));
  for (const MaterialDesc& m : b.scene.materials)
    b.materials.push_back(m.gpu);
  b.geometry = build_scene_geometry(b.scene, b.materials);
  return b;
}

// Checks every triangle of smooth.obj, whose first vertex is scene vertex `base` and first
// triangle scene triangle `first`; `to_world` maps a file normal to the expected world direction.
void check_smooth_obj(const Built& b, uint32_t base, size_t first,
                      const std::function<float3(float3)>& to_world) {
  const Scene& s = b.scene;
  ASSERT_EQ(s.triangle_normals.size(), s.triangle_count());
  ASSERT_EQ(b.geometry.shading_normals.size(), s.shading_normals.size());
  for (size_t i = 0; i < s.shading_normals.size(); ++i) {
    EXPECT_NEAR(length(s.shading_normals[i]), 1.0f, 1e-6f);
    EXPECT_EQ(b.geometry.shading_normals[i].x, s.shading_normals[i].x);
    EXPECT_EQ(b.geometry.shading_normals[i].w, 0.0f);
  }
  for (size_t j = 0; j < kTriangleNormals.size(); ++j) {
    size_t t = first + j;
    const Primitive& p = b.geometry.prims[t];
    EXPECT_EQ(p.normals, s.triangle_normals[t]);
    const float3 v0 = xyz_of(p.v0);
    const float3 ng = primitive_normal(&p, v0);
    const auto& vn = kTriangleNormals[j];
    std::string what = "triangle " + std::to_string(j);
    if (vn.empty()) {
      EXPECT_EQ(p.normals, -1) << what;
      float3 n = primitive_shading_normal(&p, b.geometry.shading_normals.data(), 0.2f, 0.3f, ng);
      EXPECT_EQ(n.x, ng.x);
      EXPECT_EQ(n.y, ng.y);
      EXPECT_EQ(n.z, ng.z);
      continue;
    }
    ASSERT_GE(p.normals, 0) << what;
    // The expected unit normal at each primitive vertex k (v0, v0 + e1, v0 + e2), found through
    // the scene's index list, which a mirroring transform reorders.
    float3 want[3];
    for (int k = 0; k < 3; ++k) {
      uint32_t local = s.indices[3 * t + size_t(k)] - base;
      ASSERT_TRUE(vn.count(local)) << what;
      want[k] = unit(to_world(kFileNormals[vn.at(local)]));
    }
    // Stored as given (no flip): a transform that turned normals inside out would show here.
    for (int k = 0; k < 3; ++k)
      expect_near3(s.shading_normals[size_t(p.normals + k)], want[k],
                   what + " stored normal " + std::to_string(k));
    const float uv[3][2] = {{0, 0}, {1, 0}, {0, 1}};
    for (int k = 0; k < 3; ++k)
      expect_near3(
          primitive_shading_normal(&p, b.geometry.shading_normals.data(), uv[k][0], uv[k][1], ng),
          on_side(want[k], ng), what + " vertex " + std::to_string(k));
    float3 centre = unit(want[0] + want[1] + want[2]);
    expect_near3(primitive_shading_normal(&p, b.geometry.shading_normals.data(), 1.0f / 3.0f,
                                          1.0f / 3.0f, ng),
                 on_side(centre, ng), what + " centre");
  }
}

} // namespace

TEST(ObjShadingNormals, InterpolatedAtVerticesAndCentre) {
  Built b = build(R"({"type": "obj", "file": "smooth.obj"})");
  ASSERT_EQ(b.scene.triangle_count(), kTriangleNormals.size());
  EXPECT_EQ(b.scene.shading_normals.size(), 3u * 4u); // four smooth triangles
  check_smooth_obj(b, 0, 0, [](float3 n) { return n; });
  // Normals against the winding come out on the geometric normal's side (+y).
  const Primitive& p = b.geometry.prims[3];
  float3 n = primitive_shading_normal(&p, b.geometry.shading_normals.data(), 0.25f, 0.25f,
                                      make_float3(0, 1, 0));
  EXPECT_FLOAT_EQ(n.y, 1.0f);
}

TEST(ObjShadingNormals, ThroughAMirroringTransform) {
  // scale [2, 1, -0.5] (a mirror: the winding is swapped) then 90 degrees about y:
  // world = R S v + t, so a normal goes to R S^-1 n; R(x, y, z) = (z, y, -x).
  Built b = build(R"({"type": "box", "min": [5, 5, 5], "max": [6, 6, 6]},
      {"type": "obj", "file": "smooth.obj", "transform": {"scale": [2, 1, -0.5],
       "rotate": {"axis": [0, 1, 0], "degrees": 90}, "translate": [1, 2, 3]}})");
  ASSERT_EQ(b.scene.triangle_count(), 12u + kTriangleNormals.size());
  for (size_t t = 0; t < 12; ++t) // the box before the OBJ is flat
    EXPECT_EQ(b.scene.triangle_normals[t], -1);
  check_smooth_obj(b, 24, 12, [](float3 n) { // the box: 6 quads of 4 vertices
    float3 m = make_float3(n.x / 2.0f, n.y, n.z / -0.5f);
    return make_float3(m.z, m.y, -m.x);
  });
}

TEST(ObjShadingNormals, FlatScenesAndLightShapes) {
  // Without vn anywhere nothing is stored; light shapes are flat.
  Built flat = build(R"({"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]})",
                     R"([{"type": "sphere", "center": [0, 3, 0], "radius": 0.5, "radiance": 1},
                         {"type": "quad", "corner": [0, 4, 0], "edge1": [1, 0, 0],
                          "edge2": [0, 0, 1], "radiance": 1}])");
  EXPECT_TRUE(flat.scene.triangle_normals.empty());
  EXPECT_TRUE(flat.scene.shading_normals.empty());
  EXPECT_TRUE(flat.geometry.shading_normals.empty());
  ASSERT_EQ(flat.geometry.prims.size(), 12u + 1u + 2u);
  for (const Primitive& p : flat.geometry.prims)
    EXPECT_EQ(p.normals, -1);
  // A smooth OBJ followed by a flat shape: the later triangles are marked flat too.
  Built mixed = build(R"({"type": "obj", "file": "smooth.obj"},
                         {"type": "quad", "corner": [0, 0, 0], "edge1": [1, 0, 0],
                          "edge2": [0, 0, 1]})",
                      R"([{"type": "sphere", "center": [0, 3, 0], "radius": 0.5, "radiance": 1}])");
  ASSERT_EQ(mixed.scene.triangle_normals.size(), kTriangleNormals.size() + 2);
  EXPECT_EQ(mixed.scene.triangle_normals[kTriangleNormals.size()], -1);
  EXPECT_EQ(mixed.scene.triangle_normals[kTriangleNormals.size() + 1], -1);
  EXPECT_EQ(mixed.geometry.prims.back().type, PRIM_SPHERE);
  EXPECT_EQ(mixed.geometry.prims.back().normals, -1);
}

TEST(ObjShadingNormals, CancellingNormalsAndSpheresGiveNg) {
  std::vector<float4> normals = {make_float4(0, 1, 0, 0), make_float4(0, -1, 0, 0),
                                 make_float4(1, 0, 0, 0)};
  Primitive p{};
  p.type = PRIM_TRIANGLE;
  p.e1 = make_float4(1, 0, 0, 0);
  p.e2 = make_float4(0, 0, -1, 0);
  p.normals = 0;
  const float3 ng = make_float3(0, 1, 0);
  // Halfway between +y and -y the interpolant is zero: no direction, so Ng.
  float3 n = primitive_shading_normal(&p, normals.data(), 0.5f, 0.0f, ng);
  EXPECT_EQ(n.x, 0.0f);
  EXPECT_EQ(n.y, 1.0f);
  EXPECT_EQ(n.z, 0.0f);
  // Elsewhere on the same edge the interpolant points along +y or -y; both come out as +y.
  EXPECT_FLOAT_EQ(primitive_shading_normal(&p, normals.data(), 0.25f, 0.0f, ng).y, 1.0f);
  EXPECT_FLOAT_EQ(primitive_shading_normal(&p, normals.data(), 0.75f, 0.0f, ng).y, 1.0f);
  // On the edge v0-v2 the normal turns from +y to +x: at v = 1/2 it is (1, 1, 0)/sqrt(2).
  float3 h = primitive_shading_normal(&p, normals.data(), 0.0f, 0.5f, ng);
  EXPECT_FLOAT_EQ(h.x, std::sqrt(0.5f));
  EXPECT_FLOAT_EQ(h.y, std::sqrt(0.5f));
  Primitive sphere{};
  sphere.type = PRIM_SPHERE;
  sphere.normals = 0; // ignored for a sphere
  float3 s = primitive_shading_normal(&sphere, normals.data(), 0.0f, 0.0f, ng);
  EXPECT_EQ(s.y, 1.0f);
}
