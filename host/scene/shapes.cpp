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
    xf = xf.then(Transform::scale(dvec(sc)));
  }
  if (auto r = o.get("rotate")) {
    auto ro = r->as_object();
    ro.allow({"axis", "degrees"});
    double3 axis = dvec(ro.req("axis").as_vec3_nonzero());
    // Normalised in double: any non-zero float axis has a finite, non-zero length there.
    double len = std::sqrt(axis.x * axis.x + axis.y * axis.y + axis.z * axis.z);
    xf = xf.then(Transform::rotate(axis * (1.0 / len), double(ro.req("degrees").as_float())));
  }
  // The translation stays in double: it is where a shape far from the origin gets its position.
  if (auto t = o.get("translate")) xf = xf.then(Transform::translate(t->as_dvec3()));
  // The matrix is in double, but the limits are those of float arithmetic on its entries.
  float det = to_float(xf.det());
  if (!std::isfinite(det)) v.fail("is too large (its determinant overflows; docs/limits.md)");
  if (det == 0.0f) v.fail("is degenerate (zero determinant)");
  return xf;
}

namespace {

// Appends a parallelogram (two triangles) with normal along cross(e1, e2), and uv (0, 0) at c,
// (1, 0) at c + e1, (0, 1) at c + e2.
void add_quad(Mesh& m, float3 c, float3 e1, float3 e2, int mat, float3 em) {
  uint32_t base = uint32_t(m.vertices.size());
  m.vertices.insert(m.vertices.end(), {c, c + e1, c + e1 + e2, c + e2});
  m.uvs.insert(m.uvs.end(),
               {make_float2(0, 0), make_float2(1, 0), make_float2(1, 1), make_float2(0, 1)});
  m.add_triangle(base, base + 1, base + 2, mat, em);
  m.add_triangle(base, base + 2, base + 3, mat, em);
  for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u})
    m.uv_indices.push_back(int32_t(base + i));
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
    // The corner goes into the (double) transform, the mesh holds the edges only: a quad far
    // from the origin keeps its shape (Scene::origin).
    double3 c = o.req("corner").as_dvec3();
    float3 e1 = o.req("edge1").as_vec3();
    float3 e2 = o.req("edge2").as_vec3();
    float3 n = cross(e1, e2);
    float a = length(n);
    if (!(a > 0.0f)) o.fail("area must be > 0 (edge1 and edge2 are parallel or zero)");
    if (!std::isfinite(a)) o.fail("area is too large");
    add_quad(d.mesh, make_float3(0, 0, 0), e1, e2, mat < 0 ? 0 : mat, em);
    d.transform = Transform::translate(c).then(d.transform);
  } else { // box
    o.allow({"type", "name", "material", "emission", "two_sided", "transform", "min", "max",
             "rotate_y"});
    double3 lo = o.req("min").as_dvec3();
    auto maxv = o.req("max");
    double3 hi = maxv.as_dvec3();
    if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z)) maxv.fail("must be > min in every component");
    // The mesh is the box from its min corner, which goes into the (double) transform: a box far
    // from the origin keeps its shape. Vertex 1 is the min corner itself, so a box beyond the
    // coordinate range is reported there even if its extent overflows float.
    float3 ext = to_float3(hi - lo);
    int m = mat < 0 ? 0 : mat;
    // Six faces, each oriented so cross(e1, e2) points out of the box.
    const float3 o0 = make_float3(0, 0, 0);
    float3 X = make_float3(ext.x, 0, 0), Y = make_float3(0, ext.y, 0), Z = make_float3(0, 0, ext.z);
    add_quad(d.mesh, o0, Z, Y, m, em); // -x
    add_quad(d.mesh, X, Y, Z, m, em);  // +x
    add_quad(d.mesh, o0, X, Z, m, em); // -y
    add_quad(d.mesh, Y, Z, X, m, em);  // +y
    add_quad(d.mesh, o0, Y, X, m, em); // -z
    add_quad(d.mesh, Z, X, Y, m, em);  // +z
    Transform place = Transform::translate(lo);
    if (auto r = o.get("rotate_y")) {
      // Rotation about the vertical axis through the box centre, before the transform.
      double3 h = dvec(ext) * 0.5;
      place = Transform::translate(h * -1.0)
                  .then(Transform::rotate(double3{0, 1, 0}, double(r->as_float())))
                  .then(Transform::translate(h))
                  .then(place);
    }
    d.transform = place.then(d.transform);
  }
  return d;
}

} // namespace canopy::detail
