// Analytic lights: point, spot, sphere, quad, triangle, disk (docs/scene-format.md, "lights").
#include "scene/loader_internal.h"

#include "shading.h"

#include <fmt/format.h>

#include <cmath>

namespace canopy::detail {

bool finish_area_light(Light& l) {
  float3 c = cross(xyz_of(l.e1), xyz_of(l.e2));
  float len = length(c);
  if (!(len > 0.0f) || !std::isfinite(len)) return false;
  float3 n = c * (1.0f / len);
  if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z)) return false;
  float area = l.type == LIGHT_QUAD ? len : 0.5f * len;
  if (!(area > 0.0f)) return false;
  l.n = f4_from3(n, area);
  return true;
}

bool finish_disk_light(Light& l, float3 normal) {
  // The unit normal in double (a normal given with large components keeps its direction), then
  // an orthonormal tangent frame around it (cl/shading.h onb_from).
  double nx = normal.x, ny = normal.y, nz = normal.z;
  double nl = std::sqrt(nx * nx + ny * ny + nz * nz);
  if (!(nl > 0.0) || !std::isfinite(nl)) return false;
  float3 n = make_float3(float(nx / nl), float(ny / nl), float(nz / nl));
  float3 t1, t2;
  onb_from(n, &t1, &t2);
  double r = l.p.w;
  float area = float(3.14159265358979323846 * r * r);
  if (!(area > 0.0f) || !std::isfinite(area)) return false;
  l.n = f4_from3(n, area);
  l.e1 = f4_from3(t1, 0.0f);
  l.e2 = f4_from3(t2, 0.0f);
  return true;
}

void set_spot_cone(Light& l, double cone_deg, double start_deg) {
  const double d2r = 3.14159265358979323846 / 180.0;
  auto one_minus_cos = [&](double deg) {
    double h = std::sin(0.5 * deg * d2r);
    return 2.0 * h * h; // 1 - cos without cancellation
  };
  // cos of the edge rounded down: the light tree's cone bound never excludes a lit direction
  double ce = std::cos(cone_deg * d2r);
  float ce_f = float(ce);
  if (double(ce_f) > ce) ce_f = std::nextafter(ce_f, -2.0f);
  l.e1.w = ce_f;
  l.e2 = make_float4(float(one_minus_cos(cone_deg)), float(one_minus_cos(start_deg)), 0.0f,
                     float(std::cos(start_deg * d2r)));
}

namespace {

// A position: as a template an offset from the site (`def` if omitted), else a world position
// rebased to `origin` in double before it is rounded.
float3 position(const JsonObject& o, std::string_view key, bool is_template, float3 def,
                double3 origin) {
  if (is_template) {
    auto v = o.get(key);
    return v ? v->as_vec3() : def;
  }
  return rebase(o.req(key).as_dvec3(), origin);
}

} // namespace

Light parse_light(const JsonValue& v, bool is_template, double3 origin) {
  auto o = v.as_object();
  std::string type = o.req("type").as_enum(
      {"point", "spot", "sphere", "quad", "triangle", "disk", "distant", "environment"});
  if (type == "environment")
    o.req("type").fail("an environment light cannot be a light set template");
  Light l{};
  l.prim = -1;
  const float3 zero = make_float3(0, 0, 0);
  if (type == "point") {
    o.allow({"type", "position", "intensity"});
    l.type = LIGHT_POINT;
    l.p = f4_from3(position(o, "position", is_template, zero, origin), 0.0f);
    l.emission = f4_from3(o.req("intensity").as_emission(), 0.0f);
  } else if (type == "spot") {
    o.allow({"type", "position", "direction", "intensity", "cone_angle", "falloff_start"});
    l.type = LIGHT_SPOT;
    l.p = f4_from3(position(o, "position", is_template, zero, origin), 0.0f);
    float3 dir = normalize(o.req("direction").as_vec3_nonzero());
    if (!std::isfinite(dir.x) || !std::isfinite(dir.y) || !std::isfinite(dir.z))
      o.req("direction").fail("cannot be normalised");
    l.e1 = f4_from3(dir, 0.0f);
    float cone = o.req("cone_angle").as_float();
    if (!(cone > 0.0f && cone <= 180.0f)) o.req("cone_angle").fail("must be in (0, 180]");
    float start = 0.8f * cone;
    if (auto fs = o.get("falloff_start")) {
      start = fs->as_float();
      // falloff_start == cone_angle: a hard edge (step falloff)
      if (!(start >= 0.0f && start <= cone)) fs->fail("must be in [0, cone_angle]");
    }
    set_spot_cone(l, double(cone), double(start));
    l.emission = f4_from3(o.req("intensity").as_emission(), 0.0f);
  } else if (type == "distant") {
    // Parallel light travelling along `direction` (as pbrt-v4's from -> to), with `irradiance` on
    // a surface facing it. It has no position: as a light set template it would mean nothing.
    if (is_template) o.req("type").fail("a distant light cannot be a light set template");
    o.allow({"type", "direction", "irradiance"});
    l.type = LIGHT_DISTANT;
    float3 dir = normalize(o.req("direction").as_vec3_nonzero());
    if (!std::isfinite(dir.x) || !std::isfinite(dir.y) || !std::isfinite(dir.z))
      o.req("direction").fail("cannot be normalised");
    l.e1 = f4_from3(dir * -1.0f, 0.0f);
    l.emission = f4_from3(o.req("irradiance").as_emission(), 0.0f);
  } else if (type == "sphere") {
    o.allow({"type", "center", "radius", "radiance"});
    l.type = LIGHT_SPHERE;
    float3 c = position(o, "center", is_template, zero, origin);
    float r = o.req("radius").as_float_positive();
    l.p = f4_from3(c, r);
    l.emission = f4_from3(o.req("radiance").as_emission(), 0.0f);
  } else if (type == "quad") {
    o.allow({"type", "corner", "edge1", "edge2", "radiance", "two_sided"});
    l.type = LIGHT_QUAD;
    float3 e1 = o.req("edge1").as_vec3();
    float3 e2 = o.req("edge2").as_vec3();
    // As a template, the quad is centred on the generated site unless a corner offset is given.
    float3 corner = position(o, "corner", is_template, (e1 + e2) * -0.5f, origin);
    l.p = f4_from3(corner, 0.0f);
    l.e1 = f4_from3(e1, 0.0f);
    l.e2 = f4_from3(e2, 0.0f);
    l.flags = o.get_bool("two_sided", false) ? LIGHT_FLAG_TWO_SIDED : 0;
    l.emission = f4_from3(o.req("radiance").as_emission(), 0.0f);
    if (!finish_area_light(l)) o.fail("area must be > 0 (edge1 and edge2 are parallel or zero)");
  } else if (type == "disk") {
    o.allow({"type", "center", "normal", "radius", "radiance", "two_sided"});
    l.type = LIGHT_DISK;
    // As a template, the disk is centred on the generated site unless a centre offset is given.
    float3 c = position(o, "center", is_template, zero, origin);
    float3 normal = o.req("normal").as_vec3_nonzero();
    float r = o.req("radius").as_float_positive();
    l.p = f4_from3(c, r);
    l.flags = o.get_bool("two_sided", false) ? LIGHT_FLAG_TWO_SIDED : 0;
    l.emission = f4_from3(o.req("radiance").as_emission(), 0.0f);
    if (!finish_disk_light(l, normal))
      o.req("radius").fail("area pi r^2 must be a positive finite float");
  } else { // triangle
    o.allow({"type", "v0", "v1", "v2", "radiance", "two_sided"});
    l.type = LIGHT_TRIANGLE;
    // The edges in double: each rounded once, whatever the vertices' distance from the origin.
    double3 v0 = o.req("v0").as_dvec3(), v1 = o.req("v1").as_dvec3(), v2 = o.req("v2").as_dvec3();
    l.p = f4_from3(rebase(v0, is_template ? double3{} : origin), 0.0f);
    l.e1 = f4_from3(to_float3(v1 - v0), 0.0f);
    l.e2 = f4_from3(to_float3(v2 - v0), 0.0f);
    l.flags = o.get_bool("two_sided", false) ? LIGHT_FLAG_TWO_SIDED : 0;
    l.emission = f4_from3(o.req("radiance").as_emission(), 0.0f);
    if (!finish_area_light(l)) o.fail("area must be > 0 (the vertices are collinear)");
  }
  return l;
}

void set_environment_frame(Light& l, double3 up, double3 front) {
  double ul = std::sqrt(up.x * up.x + up.y * up.y + up.z * up.z);
  double3 n{up.x / ul, up.y / ul, up.z / ul};
  // The image's centre (u = 0.5: phi = pi, towards -e1) looks along `front` made perpendicular to
  // the pole; e2 = n x e1 completes the frame.
  double fn = front.x * n.x + front.y * n.y + front.z * n.z;
  double3 f{front.x - fn * n.x, front.y - fn * n.y, front.z - fn * n.z};
  double fl = std::sqrt(f.x * f.x + f.y * f.y + f.z * f.z);
  double3 e1{-f.x / fl, -f.y / fl, -f.z / fl};
  double3 e2{n.y * e1.z - n.z * e1.y, n.z * e1.x - n.x * e1.z, n.x * e1.y - n.y * e1.x};
  l.e1 = make_float4(float(e1.x), float(e1.y), float(e1.z), 0.0f);
  l.e2 = make_float4(float(e2.x), float(e2.y), float(e2.z), 0.0f);
  l.n = make_float4(float(n.x), float(n.y), float(n.z), 0.0f);
}

Light parse_environment_light(const JsonValue& v, Builder& b) {
  auto o = v.as_object();
  Light l{};
  l.type = LIGHT_ENVIRONMENT;
  l.prim = -1;
  l.pad = -1;
  set_environment_frame(l, {0, 1, 0}, {0, 0, -1});
  if (!o.has("map")) {
    o.allow({"type", "radiance"});
    l.emission = f4_from3(o.req("radiance").as_emission(), 0.0f);
    return l;
  }
  o.allow({"type", "map", "scale", "projection", "up", "front"});
  auto mv = o.req("map");
  std::string f = mv.as_string();
  if (f.empty()) mv.fail("must not be empty");
  std::filesystem::path p(f);
  if (p.is_relative()) p = b.base_dir / p;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(p, ec))
    mv.fail(fmt::format("{}: no such file", p.string()));
  EnvironmentMap map;
  map.file = p;
  map.projection = ENV_EQUIRECT;
  map.where = fmt::format("{}: {}", b.file, v.path());
  if (auto pv = o.get("projection"))
    map.projection =
        pv->as_enum({"equirect", "octahedral"}) == "equirect" ? ENV_EQUIRECT : ENV_OCTAHEDRAL;
  l.emission = make_float4(1, 1, 1, 0);
  if (auto sv = o.get("scale")) l.emission = f4_from3(sv->as_emission(), 0.0f);
  float3 up = make_float3(0, 1, 0), front = make_float3(0, 0, -1);
  if (auto uv = o.get("up")) up = uv->as_vec3_nonzero();
  if (auto fv = o.get("front")) front = fv->as_vec3_nonzero();
  // front must not be along up (it fixes the azimuth)
  float3 un = normalize(up);
  float3 fp = front - un * dot(front, un);
  if (!(length(fp) > 1e-6f * length(front))) o.req("front").fail("must not be parallel to up");
  set_environment_frame(l, {up.x, up.y, up.z}, {front.x, front.y, front.z});
  l.pad = int(b.scene.environment_maps.size());
  b.scene.environment_maps.push_back(map);
  return l;
}

} // namespace canopy::detail
