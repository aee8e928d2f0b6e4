// Shapes of the scene format: "obj" (OBJ + MTL file), "quad", "box", each with an optional
// transform, material and emission.
#include "scene/loader_internal.h"

#include <fmt/format.h>

#include <cmath>

namespace canopy::detail {

Transform parse_transform(const JsonValue& v) {
  auto o = v.as_object();
  o.allow({"translate", "scale", "rotate"});
  Transform xf;
  if (auto s = o.get("scale")) {
    float3 sc;
    if (s->is_number()) {
      float f = s->as_float();
      sc = make_float3(f, f, f);
    } else {
      sc = s->as_vec3();
    }
    if (sc.x == 0.0f || sc.y == 0.0f || sc.z == 0.0f) s->fail("must be non-zero");
    xf = xf.then(Transform::scale(sc));
  }
  if (auto r = o.get("rotate")) {
    auto ro = r->as_object();
    ro.allow({"axis", "degrees"});
    float3 axis = ro.req("axis").as_vec3_nonzero();
    float deg = ro.req("degrees").as_float();
    xf = xf.then(Transform::rotate(normalize(axis), deg));
  }
  if (auto t = o.get("translate")) xf = xf.then(Transform::translate(t->as_vec3()));
  if (!std::isfinite(xf.det())) v.fail("is too large (its determinant overflows; docs/limits.md)");
  if (xf.det() == 0.0f) v.fail("is degenerate (zero determinant)");
  return xf;
}

namespace {

// Appends a parallelogram (two triangles) with normal along cross(e1, e2).
void add_quad(Mesh& m, float3 c, float3 e1, float3 e2, int mat, float3 em) {
  uint32_t base = uint32_t(m.vertices.size());
  m.vertices.insert(m.vertices.end(), {c, c + e1, c + e1 + e2, c + e2});
  m.add_triangle(base, base + 1, base + 2, mat, em);
  m.add_triangle(base, base + 2, base + 3, mat, em);
}

} // namespace

ShapeDesc parse_shape(const JsonValue& v, Builder& b) {
  auto o = v.as_object();
  std::string type = o.req("type").as_enum({"obj", "quad", "box"});
  ShapeDesc d;
  if (auto n = o.get("name")) {
    d.name = n->as_string();
    if (d.name.empty()) n->fail("must not be empty");
  }
  int mat = -1;
  if (auto mv = o.get("material")) mat = b.material_ref(*mv);
  float3 em = make_float3(0, 0, 0);
  if (auto e = o.get("emission")) em = e->as_emission();
  d.mesh.two_sided_emission = o.get_bool("two_sided", false);
  if (auto t = o.get("transform")) d.transform = parse_transform(*t);

  if (type == "obj") {
    o.allow({"type", "name", "material", "emission", "two_sided", "transform", "file"});
    auto fv = o.req("file");
    std::string f = fv.as_string();
    if (f.empty()) fv.fail("must not be empty");
    std::filesystem::path p(f);
    if (p.is_relative()) p = b.base_dir / p;
    d.mesh = load_obj(p, fv, b, mat);
    d.mesh.two_sided_emission = o.get_bool("two_sided", false);
    // "emission" in the scene overrides the MTL Ke of every triangle.
    if (o.has("emission"))
      for (float3& e : d.mesh.emission)
        e = em;
  } else if (type == "quad") {
    o.allow({"type", "name", "material", "emission", "two_sided", "transform", "corner", "edge1",
             "edge2"});
    float3 c = o.req("corner").as_vec3();
    float3 e1 = o.req("edge1").as_vec3();
    float3 e2 = o.req("edge2").as_vec3();
    float3 n = cross(e1, e2);
    float a = length(n);
    if (!(a > 0.0f)) o.fail("area must be > 0 (edge1 and edge2 are parallel or zero)");
    if (!std::isfinite(a)) o.fail("area is too large");
    add_quad(d.mesh, c, e1, e2, mat < 0 ? 0 : mat, em);
  } else { // box
    o.allow({"type", "name", "material", "emission", "two_sided", "transform", "min", "max",
             "rotate_y"});
    float3 lo = o.req("min").as_vec3();
    auto maxv = o.req("max");
    float3 hi = maxv.as_vec3();
    if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z)) maxv.fail("must be > min in every component");
    float3 ctr = (lo + hi) * 0.5f;
    float3 ext = hi - lo;
    int m = mat < 0 ? 0 : mat;
    // Six faces, each oriented so cross(e1, e2) points out of the box.
    float3 X = make_float3(ext.x, 0, 0), Y = make_float3(0, ext.y, 0), Z = make_float3(0, 0, ext.z);
    add_quad(d.mesh, lo, Z, Y, m, em);     // -x
    add_quad(d.mesh, lo + X, Y, Z, m, em); // +x
    add_quad(d.mesh, lo, X, Z, m, em);     // -y
    add_quad(d.mesh, lo + Y, Z, X, m, em); // +y
    add_quad(d.mesh, lo, Y, X, m, em);     // -z
    add_quad(d.mesh, lo + Z, X, Y, m, em); // +z
    if (auto r = o.get("rotate_y")) {
      float deg = r->as_float();
      // Rotation about the vertical axis through the box centre, before the transform.
      Transform rot = Transform::translate(-ctr)
                          .then(Transform::rotate(make_float3(0, 1, 0), deg))
                          .then(Transform::translate(ctr));
      for (float3& p : d.mesh.vertices)
        p = rot.apply(p);
    }
  }
  return d;
}

} // namespace canopy::detail
