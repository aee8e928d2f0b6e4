// The Shape directive of a pbrt-v4 file, and the meshes it adds to the scene.
#include "scene/loop_subdivision.h"
#include "scene/pbrt/meshes.h"
#include "scene/pbrt/reader.h"
#include "scene/pbrt/transforms.h"
#include "scene/ply_mesh.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace canopy::pbrt {

namespace {

// Flattened instances copy triangles: a few directives could ask for 10^12 of them. The cap keeps
// memory to a few GiB and turns such a file into an error instead of an out-of-memory kill.
constexpr size_t kMaxTriangles = size_t(1) << 27;

} // namespace

void Reader::add_mesh(const Loc& loc, Mesh& m, const Transform& ctm) {
  if (m.triangle_count() > kMaxTriangles - std::min(kMaxTriangles, scene_.triangle_count()))
    fail(loc,
         fmt::format("more than {} triangles (after flattening object instances)", kMaxTriangles));
  Transform xf = world(ctm);
  float det = to_float(xf.det());
  if (!std::isfinite(det)) fail(loc, "the transform is too large (its determinant overflows)");
  if (det == 0.0f) fail(loc, "the transform is degenerate (zero determinant)");
  size_t first_vertex = scene_.vertices.size();
  b_.add_mesh(m, xf);
  if (auto e = vertices_problem(scene_, first_vertex); !e.empty()) fail(loc, e);
}

// The format page, "Shapes".
// `dir` resolves relative PLY file names (the directory of the file being read).
void Reader::shape(const Token& d, Params& p, const std::string& type,
                   const std::filesystem::path& dir) {
  const Loc& loc = d.loc;
  if (interface_materials_.count(gs_.material)) { // invisible: it only bounds a medium
    if (gs_.area) warn(loc, "an area light on a shape of material \"interface\" ignored");
    p.mark_all_used();
    return;
  }
  const int mat = shape_material(loc);
  Mesh m;
  bool analytic_light_done = false;
  // pbrt-v4 does not support area lights on instanced shapes either.
  if (gs_.area && object_)
    warn(loc, "an area light on a shape inside ObjectBegin (not supported with instancing) "
              "ignored");
  const bool area = gs_.area && !object_;
  auto emission = [&] { return area ? gs_.area_L : make_float3(0, 0, 0); };
  auto points = [&](const char* name, size_t min_count) -> std::vector<float3> {
    const auto* v = p.get_nums(name, {"point3", "point"});
    if (!v) fail(loc, fmt::format("{}: needs \"point3 {}\"", p.what(), name));
    if (v->size() < 3 * min_count)
      fail(p.find(name)->loc, fmt::format("{}: \"point3 {}\": wrong count of values ({}; want at "
                                          "least {})",
                                          p.what(), name, v->size(), 3 * min_count));
    std::vector<float3> out;
    for (size_t i = 0; i < v->size(); i += 3) {
      float3 q = to_float3({(*v)[i], (*v)[i + 1], (*v)[i + 2]});
      if (!std::isfinite(q.x + q.y + q.z))
        fail(p.find(name)->loc,
             fmt::format("{}: \"point3 {}\": a value is too large", p.what(), name));
      out.push_back(q);
    }
    return out;
  };
  auto indices = [&](size_t per, size_t nverts) -> std::vector<uint32_t> {
    const auto* v = p.get_nums("indices", {"integer"});
    std::vector<uint32_t> out;
    if (!v) {
      if (nverts != per)
        fail(loc, fmt::format("{}: needs \"integer indices\" (it has {} vertices, not {})",
                              p.what(), nverts, per));
      for (size_t i = 0; i < per; ++i)
        out.push_back(uint32_t(i));
      return out;
    }
    const Loc& il = p.find("indices")->loc;
    if (v->empty() || v->size() % per != 0)
      fail(il, fmt::format("{}: \"integer indices\": wrong count of values ({}; want a multiple "
                           "of {})",
                           p.what(), v->size(), per));
    for (double x : *v) {
      if (!(x >= 0 && x < double(nverts)))
        fail(il, fmt::format("{}: \"integer indices\": {} is out of range [0, {})", p.what(), x,
                             nverts));
      out.push_back(uint32_t(x));
    }
    return out;
  };
  auto normals = [&](size_t nverts) {
    const auto* v = p.get_nums("N", {"normal", "normal3"});
    if (!v) return;
    if (v->size() != 3 * nverts)
      fail(p.find("N")->loc, fmt::format("{}: \"normal N\": wrong count of values ({}; want {}, "
                                         "one per vertex)",
                                         p.what(), v->size(), 3 * nverts));
    for (size_t i = 0; i < v->size(); i += 3)
      m.normals.push_back(to_float3({(*v)[i], (*v)[i + 1], (*v)[i + 2]}));
  };
  // Texture coordinates, one pair per vertex ("float uv" is pbrt-v3's spelling).
  auto uvs = [&](size_t nverts) {
    const auto* v = p.get_nums("uv", {"point2", "float"});
    if (!v) return;
    const Param& q = *p.find("uv");
    if (v->size() != 2 * nverts)
      fail(q.loc, fmt::format("{}: \"{} uv\": wrong count of values ({}; want {}, one pair per "
                              "vertex)",
                              p.what(), q.type, v->size(), 2 * nverts));
    for (size_t i = 0; i < v->size(); i += 2) {
      float2 uv = make_float2(to_float((*v)[i]), to_float((*v)[i + 1]));
      if (!std::isfinite(uv.x + uv.y))
        fail(q.loc, fmt::format("{}: \"{} uv\": a value is too large", p.what(), q.type));
      m.uvs.push_back(uv);
    }
  };

  if (type == "trianglemesh" || type == "bilinearmesh") {
    const bool tri = type == "trianglemesh";
    m.vertices = points("P", tri ? 3 : 4);
    std::vector<uint32_t> idx = indices(tri ? 3 : 4, m.vertices.size());
    normals(m.vertices.size());
    uvs(m.vertices.size());
    add_polygons(m, idx, !tri, mat, emission(), gs_.reverse);
  } else if (type == "plymesh") {
    // pbrt-v4 makes bilinear patches of a PLY file's quads; triangles are the same surface for
    // planar quads.
    const std::optional<std::string> f = p.get_string("filename");
    if (!f) fail(loc, fmt::format("{}: needs \"string filename\"", p.what()));
    std::filesystem::path file(*f);
    if (file.is_relative()) file = dir / file; // as Include
    PlyMesh ply = load_ply_mesh(file, fmt::format("{}:{}: {} \"{}\": ", *loc.file, loc.line,
                                                  p.what(), file.lexically_normal().string()));
    if (ply.skipped_faces > 0)
      warn(loc, fmt::format("{}: {} faces of fewer than 3 vertices ignored", p.what(),
                            ply.skipped_faces));
    if (ply.indices.empty())
      warn(loc,
           fmt::format("{}: no faces of 3 or more vertices, nothing added, ignored", p.what()));
    m.vertices = std::move(ply.positions);
    m.normals = std::move(ply.normals);
    m.uvs = std::move(ply.uv);
    add_polygons(m, ply.indices, false, mat, emission(), gs_.reverse);
    // Only used to tessellate for displacement, which is ignored below.
    if (Param* q = p.one("edgelength", {"float"}))
      warn(q->loc, fmt::format("{}: \"float edgelength\" ignored", p.what()));
  } else if (type == "sphere" || type == "disk") {
    const bool sph = type == "sphere";
    double radius = p.get_float("radius", 1.0);
    if (!(radius > 0.0) || !std::isfinite(float(radius)))
      fail(loc, fmt::format("{}: \"float radius\": must be > 0", p.what()));
    double height = 0.0;
    if (sph) {
      double zmin = p.get_float("zmin", -radius), zmax = p.get_float("zmax", radius);
      double phimax = p.get_float("phimax", 360.0);
      if (zmin > -radius || zmax < radius || phimax < 360.0)
        warn(loc, fmt::format("{}: zmin/zmax/phimax (a partial sphere) ignored, full sphere "
                              "used",
                              p.what()));
    } else {
      height = p.get_float("height", 0.0);
      if (p.get_float("innerradius", 0.0) != 0.0)
        warn(p.find("innerradius")->loc,
             fmt::format("{}: \"float innerradius\" (an annulus) ignored, full disk used",
                         p.what()));
      if (p.get_float("phimax", 360.0) < 360.0)
        warn(
            p.find("phimax")->loc,
            fmt::format("{}: \"float phimax\" (a partial disk) ignored, full disk used", p.what()));
    }
    Transform xf = world(gs_.ctm);
    double s = similarity_scale(xf);
    if (area && s > 0.0) {
      // Canopy has analytic sphere and disk lights: the emitter is exact and sampled by solid
      // angle (sphere) or area (disk) instead of as a mesh of triangle lights.
      Light l{};
      l.prim = -1;
      l.emission = f4_from3(gs_.area_L, 0.0f);
      double3 c = xf.apply(double3{0, 0, height});
      float r = to_float(radius * s);
      if (!std::isfinite(r) || !(r > 0.0f))
        fail(loc, "the radius after the transform is out of range");
      l.p = f4_from3(rebase(c, scene_.origin), r);
      if (sph) {
        l.type = LIGHT_SPHERE;
        if (gs_.reverse)
          warn(loc, "ReverseOrientation on a sphere light (Canopy's emits outward) ignored");
        if (gs_.area_twosided)
          warn(loc, "\"bool twosided\" of a sphere light (Canopy's emits outward) ignored");
      } else {
        l.type = LIGHT_DISK;
        l.flags = gs_.area_twosided ? LIGHT_FLAG_TWO_SIDED : 0;
        float3 n = xf.apply_normal(make_float3(0, 0, 1));
        if (gs_.reverse) n = n * -1.0f;
        if (!finish_disk_light(l, n)) fail(loc, "disk light: area pi r^2 is out of range");
      }
      if (auto e = check_light_extent(l, scene_.origin); !e.empty()) fail(loc, e);
      if (emits(l))
        scene_.lights.push_back(l);
      else
        ++scene_.skipped_lights;
      analytic_light_done = true;
    } else {
      m = sph ? sphere_mesh(float(radius)) : disk_mesh(float(radius), float(height));
      float3 em = emission();
      for (size_t t = 0; t < m.triangle_count(); ++t) {
        m.material[t] = mat;
        m.emission[t] = em;
      }
      if (gs_.reverse) reverse_winding(m); // spheres keep their outward shading normals
    }
  } else if (type == "loopsubdiv") {
    // Tessellated here, as pbrt-v4 does at load time (scene/loop_subdivision.h).
    std::vector<float3> P = points("P", 3);
    std::vector<uint32_t> idx = indices(3, P.size());
    int levels = 3; // pbrt-v4's default
    if (Param* q = p.one("levels", {"integer"})) {
      if (!(q->nums[0] >= 0 && q->nums[0] <= 16))
        fail(q->loc, fmt::format("{}: \"integer levels\": must be in [0, 16]", p.what()));
      levels = int(q->nums[0]);
    }
    detail::SubdividedMesh sd;
    try {
      sd = detail::loop_subdivide(P, idx, levels);
    } catch (const SceneError& e) {
      fail(loc, fmt::format("{}: {}", p.what(), e.what()));
    }
    // pbrt-v4's limit normals point against the winding, and its triangles face their shading
    // normals: the surface faces against its winding (add_polygons turns the winding to them).
    m.vertices = std::move(sd.positions);
    for (const float3& n : sd.normals)
      m.normals.push_back(n * -1.0f);
    add_polygons(m, sd.indices, false, mat, emission(), gs_.reverse);
  } else {
    warn(loc, fmt::format("Shape \"{}\" is not read in this slice, ignored", printable(type)));
    return;
  }
  for (const char* skip : {"alpha", "emissionfilename", "displacement"})
    if (Param* q = p.find(skip))
      warn(q->loc, fmt::format("{}: \"{} {}\" ignored", p.what(), q->type, skip));
  p.finish();
  if (analytic_light_done) return;
  m.two_sided_emission = area && gs_.area_twosided;
  if (object_) {
    object_->push_back({std::move(m), gs_.ctm});
    return;
  }
  add_mesh(loc, m, gs_.ctm);
}

} // namespace canopy::pbrt
