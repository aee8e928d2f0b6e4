#include "accel/bvh.h"

#include "geometry.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace canopy {

namespace {

Primitive make_triangle(float3 a, float3 b, float3 c, int material, int light) {
  Primitive p{};
  p.v0 = f4_from3(a, 0.0f);
  p.e1 = f4_from3(b - a, 0.0f);
  p.e2 = f4_from3(c - a, 0.0f);
  p.type = PRIM_TRIANGLE;
  p.material = material;
  p.light = light;
  p.normals = -1;
  return p;
}

void primitive_bounds(const Primitive& p, float3& lo, float3& hi) {
  float3 v0 = xyz_of(p.v0);
  if (p.type == PRIM_SPHERE) {
    float r = p.v0.w;
    lo = v0 - make_float3(r, r, r);
    hi = v0 + make_float3(r, r, r);
    return;
  }
  if (p.type == PRIM_DISK) {
    // A circle of radius r in the plane with unit normal n spans r sqrt(1 - n_i^2) along axis i;
    // padded (2^-20 of r and of |centre|) so rounding cannot put a hit point outside the box.
    float r = p.v0.w;
    float3 n = xyz_of(p.e1);
    float3 ext = make_float3(std::sqrt(std::max(0.0f, 1.0f - n.x * n.x)),
                             std::sqrt(std::max(0.0f, 1.0f - n.y * n.y)),
                             std::sqrt(std::max(0.0f, 1.0f - n.z * n.z))) *
                     (r * 1.000001f) +
                 fabs(v0) * 9.5367432e-07f;
    lo = v0 - ext;
    hi = v0 + ext;
    return;
  }
  float3 v1 = v0 + xyz_of(p.e1), v2 = v0 + xyz_of(p.e2);
  lo = fmin(v0, fmin(v1, v2));
  hi = fmax(v0, fmax(v1, v2));
}

// Temporary tree produced by Embree's callbacks (allocated in Embree's thread-local arenas).
struct BuildNode {
  bool leaf;
  int count;                   // leaf: primitive count; interior: child count
  RTCBounds bounds[BVH_WIDTH]; // interior: child bounds
  BuildNode* children[BVH_WIDTH];
  const unsigned* ids; // leaf: primitive ids
};

void* create_node(RTCThreadLocalAllocator alloc, unsigned int count, void*) {
  auto* n = static_cast<BuildNode*>(rtcThreadLocalAlloc(alloc, sizeof(BuildNode), 16));
  *n = BuildNode{};
  n->count = int(count);
  return n;
}

void set_children(void* node, void** children, unsigned int count, void*) {
  auto* n = static_cast<BuildNode*>(node);
  for (unsigned i = 0; i < BVH_WIDTH; ++i)
    n->children[i] = i < count ? static_cast<BuildNode*>(children[i]) : nullptr;
  n->count = int(count);
}

void set_bounds(void* node, const RTCBounds** bounds, unsigned int count, void*) {
  auto* n = static_cast<BuildNode*>(node);
  for (unsigned i = 0; i < count && i < BVH_WIDTH; ++i)
    n->bounds[i] = *bounds[i];
}

void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count,
                  void*) {
  auto* n = static_cast<BuildNode*>(rtcThreadLocalAlloc(alloc, sizeof(BuildNode), 16));
  auto* ids = static_cast<unsigned*>(rtcThreadLocalAlloc(alloc, sizeof(unsigned) * count, 16));
  for (size_t i = 0; i < count; ++i)
    ids[i] = prims[i].primID;
  *n = BuildNode{};
  n->leaf = true;
  n->count = int(count);
  n->ids = ids;
  return n;
}

RTCBounds empty_bounds() {
  float inf = std::numeric_limits<float>::infinity();
  return RTCBounds{inf, inf, inf, 0, -inf, -inf, -inf, 0};
}

void set_lane(BvhNode& n, int lane, const RTCBounds& b, int code) {
  const int g = lane / 4, k = lane % 4;
  float* f[6] = {&n.min_x[g].x, &n.min_y[g].x, &n.min_z[g].x,
                 &n.max_x[g].x, &n.max_y[g].x, &n.max_z[g].x};
  const float v[6] = {b.lower_x, b.lower_y, b.lower_z, b.upper_x, b.upper_y, b.upper_z};
  for (int c = 0; c < 6; ++c)
    f[c][k] = v[c];
  (&n.child[g].x)[k] = code;
}

BvhNode empty_node() {
  BvhNode n{};
  for (int lane = 0; lane < BVH_WIDTH; ++lane)
    set_lane(n, lane, empty_bounds(), BVH_EMPTY);
  return n;
}

struct Flattener {
  const std::vector<Primitive>& prims;
  Bvh& out;

  RTCBounds bounds_of(const unsigned* ids, int count) const {
    RTCBounds b = empty_bounds();
    for (int i = 0; i < count; ++i) {
      float3 lo, hi;
      primitive_bounds(prims[ids[i]], lo, hi);
      b.lower_x = std::min(b.lower_x, lo.x), b.lower_y = std::min(b.lower_y, lo.y);
      b.lower_z = std::min(b.lower_z, lo.z), b.upper_x = std::max(b.upper_x, hi.x);
      b.upper_y = std::max(b.upper_y, hi.y), b.upper_z = std::max(b.upper_z, hi.z);
    }
    return b;
  }

  LeafBlock block(const unsigned* ids, int count) const {
    LeafBlock b{};
    b.prim = make_int4(-1, -1, -1, -1);
    float* f[9] = {&b.v0_x.x, &b.v0_y.x, &b.v0_z.x, &b.e1_x.x, &b.e1_y.x,
                   &b.e1_z.x, &b.e2_x.x, &b.e2_y.x, &b.e2_z.x};
    for (int lane = 0; lane < count; ++lane) {
      const Primitive& p = prims[ids[lane]];
      (&b.prim.x)[lane] = p.type == PRIM_TRIANGLE ? int(ids[lane]) : -2 - int(ids[lane]);
      if (p.type != PRIM_TRIANGLE) continue;
      const float v[9] = {p.v0.x, p.v0.y, p.v0.z, p.e1.x, p.e1.y, p.e1.z, p.e2.x, p.e2.y, p.e2.z};
      for (int k = 0; k < 9; ++k)
        f[k][lane] = v[k];
    }
    return b;
  }

  // A leaf's code; leaves over BVH_MAX_LEAF primitives (Embree makes them only at its depth limit)
  // become a small subtree of nodes.
  int leaf(const unsigned* ids, int count, int depth) {
    if (count <= BVH_MAX_LEAF) {
      int first = int(out.leaf_blocks.size());
      for (int i = 0; i < count; i += 4)
        out.leaf_blocks.push_back(block(ids + i, std::min(4, count - i)));
      return bvh_leaf_code(first, int(out.leaf_blocks.size()) - first);
    }
    int at = int(out.nodes.size());
    out.nodes.push_back(empty_node());
    out.depth = std::max(out.depth, depth + 1);
    int per = (count + BVH_WIDTH - 1) / BVH_WIDTH;
    for (int lane = 0, start = 0; lane < BVH_WIDTH && start < count; ++lane, start += per) {
      int c = std::min(per, count - start);
      int code = leaf(ids + start, c, depth + 1);
      set_lane(out.nodes[size_t(at)], lane, bounds_of(ids + start, c), code);
    }
    return at;
  }

  // The code of `src` (a node index or a leaf code); `depth` is its node level.
  int node(const BuildNode* src, int depth) {
    if (src->leaf) return leaf(src->ids, src->count, depth);
    int at = int(out.nodes.size());
    out.nodes.push_back(empty_node());
    out.depth = std::max(out.depth, depth + 1);
    for (int lane = 0; lane < src->count; ++lane) {
      int code = node(src->children[lane], depth + 1);
      set_lane(out.nodes[size_t(at)], lane, src->bounds[lane], code);
    }
    return at;
  }
};

} // namespace

std::vector<Primitive> build_primitives(Scene& scene, std::vector<Material>& materials) {
  std::vector<Primitive> prims;
  prims.reserve(scene.triangle_count() + scene.lights.size());
  for (size_t t = 0; t < scene.triangle_count(); ++t) {
    const float3 a = scene.vertices[scene.indices[3 * t]];
    const float3 b = scene.vertices[scene.indices[3 * t + 1]];
    const float3 c = scene.vertices[scene.indices[3 * t + 2]];
    int light = scene.triangle_light.empty() ? -1 : scene.triangle_light[t];
    prims.push_back(make_triangle(a, b, c, scene.triangle_material[t], light));
    if (!scene.triangle_normals.empty()) prims.back().normals = scene.triangle_normals[t];
    if (light >= 0) scene.lights[light].prim = int(t);
  }
  // Light shapes are black: they emit, they do not reflect.
  int black = int(materials.size());
  Material m{};
  m.albedo = make_float4(0, 0, 0, 0);
  m.type = MATERIAL_DIFFUSE;
  materials.push_back(m);
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    Light& l = scene.lights[i];
    if (l.flags & LIGHT_FLAG_FROM_MESH) continue;
    float3 p = xyz_of(l.p), e1 = xyz_of(l.e1), e2 = xyz_of(l.e2);
    if (l.type == LIGHT_SPHERE) {
      Primitive s{};
      s.v0 = l.p;
      s.type = PRIM_SPHERE;
      s.material = black;
      s.light = int(i);
      s.normals = -1;
      l.prim = int(prims.size());
      prims.push_back(s);
    } else if (l.type == LIGHT_DISK) {
      Primitive dk{};
      dk.v0 = l.p;
      dk.e1 = f4_from3(xyz_of(l.n), 0.0f);
      dk.type = PRIM_DISK;
      dk.material = black;
      dk.light = int(i);
      l.prim = int(prims.size());
      prims.push_back(dk);
    } else if (l.type == LIGHT_QUAD) {
      l.prim = int(prims.size());
      prims.push_back(make_triangle(p, p + e1, p + e1 + e2, black, int(i)));
      prims.push_back(make_triangle(p, p + e1 + e2, p + e2, black, int(i)));
    } else if (l.type == LIGHT_TRIANGLE) {
      l.prim = int(prims.size());
      prims.push_back(make_triangle(p, p + e1, p + e2, black, int(i)));
    } else {
      l.prim = -1;
    }
  }
  return prims;
}

Bvh build_bvh(const std::vector<Primitive>& prims) {
  Bvh out;
  if (prims.empty()) { // an empty scene: a root whose lanes are all empty
    out.nodes.push_back(empty_node());
    out.depth = 1;
    return out;
  }
  RTCDevice device = rtcNewDevice(nullptr);
  if (!device) throw std::runtime_error("rtcNewDevice failed");
  std::vector<RTCBuildPrimitive> bp(prims.size());
  RTCBounds root = empty_bounds();
  for (size_t i = 0; i < prims.size(); ++i) {
    float3 lo, hi;
    primitive_bounds(prims[i], lo, hi);
    bp[i] = RTCBuildPrimitive{lo.x, lo.y, lo.z, 0, hi.x, hi.y, hi.z, unsigned(i)};
    root.lower_x = std::min(root.lower_x, lo.x);
    root.lower_y = std::min(root.lower_y, lo.y);
    root.lower_z = std::min(root.lower_z, lo.z);
    root.upper_x = std::max(root.upper_x, hi.x);
    root.upper_y = std::max(root.upper_y, hi.y);
    root.upper_z = std::max(root.upper_z, hi.z);
  }
  RTCBVH bvh = rtcNewBVH(device);
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.byteSize = sizeof(args);
  args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;
  args.maxBranchingFactor = BVH_WIDTH;
  args.maxDepth = BVH_MAX_DEPTH - 4; // headroom for splitting oversized leaves
  // Leaves are tested four primitives at a time (LeafBlock): SAH counts their cost in blocks of
  // 4, and leaves of up to 8 fill blocks with 3.0 triangles on average (1.26 with leaves of 1-4
  // costed per primitive): 11 MB of blocks for 200k triangles instead of 25 MB.
  args.sahBlockSize = 4;
  args.minLeafSize = 1;
  args.maxLeafSize = 8;
  args.traversalCost = 1.0f;
  args.intersectionCost = 1.0f;
  args.bvh = bvh;
  args.primitives = bp.data();
  args.primitiveCount = bp.size();
  args.primitiveArrayCapacity = bp.size();
  args.createNode = create_node;
  args.setNodeChildren = set_children;
  args.setNodeBounds = set_bounds;
  args.createLeaf = create_leaf;
  args.splitPrimitive = nullptr;
  auto* root_node = static_cast<BuildNode*>(rtcBuildBVH(&args));
  if (!root_node) {
    rtcReleaseBVH(bvh);
    rtcReleaseDevice(device);
    throw std::runtime_error("rtcBuildBVH failed");
  }
  out.nodes.reserve(prims.size() / 2 + 1);
  out.leaf_blocks.reserve(prims.size() / 2 + 1);
  Flattener f{prims, out};
  if (root_node->leaf) { // the root is always a node: wrap a lone leaf
    out.nodes.push_back(empty_node());
    int code = f.leaf(root_node->ids, root_node->count, 1);
    set_lane(out.nodes[0], 0, root, code);
    out.depth = std::max(out.depth, 1);
  } else {
    f.node(root_node, 0);
  }
  rtcReleaseBVH(bvh);
  rtcReleaseDevice(device);
  if (out.depth > BVH_MAX_DEPTH)
    throw std::runtime_error(fmt::format("BVH depth {} exceeds {}", out.depth, BVH_MAX_DEPTH));
  return out;
}

SceneGeometry build_scene_geometry(Scene& scene, std::vector<Material>& materials) {
  SceneGeometry g;
  g.prims = build_primitives(scene, materials);
  g.shading_normals.reserve(scene.shading_normals.size());
  for (const float3& n : scene.shading_normals)
    g.shading_normals.push_back(f4_from3(n, 0.0f));
  const bool textured = std::any_of(materials.begin(), materials.end(),
                                    [](const Material& m) { return material_textured(m); });
  if (textured && !scene.triangle_uvs.empty()) {
    g.texcoords = scene.triangle_uvs;
  } else if (textured) {
    g.texcoords.reserve(3 * scene.triangle_count());
    for (size_t t = 0; t < scene.triangle_count(); ++t)
      g.texcoords.insert(g.texcoords.end(),
                         {make_float2(0, 0), make_float2(1, 0), make_float2(1, 1)});
  }
  g.bvh = build_bvh(g.prims);
  float3 lo = make_float3(0, 0, 0), hi = lo;
  bool any = false;
  auto grow = [&](float3 a, float3 b) {
    lo = any ? fmin(lo, a) : a;
    hi = any ? fmax(hi, b) : b;
    any = true;
  };
  for (const Primitive& p : g.prims) {
    float3 a, b;
    primitive_bounds(p, a, b);
    grow(a, b);
  }
  for (const Light& l : scene.lights)
    grow(xyz_of(l.p), xyz_of(l.p));
  grow(scene.camera.position, scene.camera.position);
  g.bounds_min = lo;
  g.bounds_max = hi;
  return g;
}

EmbreeReference::EmbreeReference(const std::vector<Primitive>& triangles) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw std::runtime_error("rtcNewDevice failed");
  scene_ = rtcNewScene(device_);
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * triangles.size()));
  auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles.size()));
  for (size_t i = 0; i < triangles.size(); ++i) {
    const Primitive& p = triangles[i];
    if (p.type != PRIM_TRIANGLE) throw std::invalid_argument("EmbreeReference: triangles only");
    float3 a = xyz_of(p.v0), b = a + xyz_of(p.e1), c = a + xyz_of(p.e2);
    float* dst = v + 9 * i;
    dst[0] = a.x, dst[1] = a.y, dst[2] = a.z;
    dst[3] = b.x, dst[4] = b.y, dst[5] = b.z;
    dst[6] = c.x, dst[7] = c.y, dst[8] = c.z;
    idx[3 * i] = unsigned(3 * i);
    idx[3 * i + 1] = unsigned(3 * i + 1);
    idx[3 * i + 2] = unsigned(3 * i + 2);
  }
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene_, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene_);
  if (RTCError e = rtcGetDeviceError(device_); e != RTC_ERROR_NONE)
    throw std::runtime_error(fmt::format("Embree error {} building the reference scene", int(e)));
}

EmbreeReference::~EmbreeReference() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

int EmbreeReference::intersect(float3 o, float3 d, float tmin, float tmax, float* t) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh{};
  rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
  rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
  rh.ray.tnear = tmin;
  rh.ray.tfar = tmax;
  rh.ray.mask = ~0u;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return -1;
  *t = rh.ray.tfar;
  return int(rh.hit.primID);
}

bool EmbreeReference::occluded(float3 o, float3 d, float tmin, float tmax) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r{};
  r.org_x = o.x, r.org_y = o.y, r.org_z = o.z;
  r.dir_x = d.x, r.dir_y = d.y, r.dir_z = d.z;
  r.tnear = tmin;
  r.tfar = tmax;
  r.mask = ~0u;
  rtcOccluded1(scene_, &ctx, &r);
  return r.tfar < 0.0f; // Embree sets tfar = -inf on a hit
}

} // namespace canopy
