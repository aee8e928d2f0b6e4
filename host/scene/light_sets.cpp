// Procedural light sets: grid, random_box, spiral, mesh_surface. Each generates `count` sites;
// every site gets a copy of the `light` template (its position-like keys are offsets from the
// site) and, optionally, a copy of an `instance` shape translated to the site.
#include "scene/loader_internal.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace canopy::detail {

namespace {

constexpr int64_t kMaxLights = 50'000'000;

struct Variation {
  bool active = false;
  float scale_lo = 1.0f, scale_hi = 1.0f;
  float color = 0.0f;
};

Variation parse_variation(const JsonValue& v) {
  auto o = v.as_object();
  o.allow({"scale", "color"});
  Variation var;
  var.active = true;
  if (auto s = o.get("scale")) {
    if (!s->is_array() || s->array_size() != 2) s->fail("must be an array [min, max]");
    var.scale_lo = s->at(0).as_float_positive();
    var.scale_hi = s->at(1).as_float_positive();
    if (!(var.scale_hi >= var.scale_lo)) s->at(1).fail("must be >= scale[0]");
  }
  if (auto c = o.get("color")) {
    var.color = c->as_float();
    if (!(var.color >= 0.0f && var.color < 1.0f)) c->fail("must be in [0, 1)");
  }
  return var;
}

// Moves a template light to a site (a world position), rebased to the scene origin in double.
inline Light place(const Light& t, double3 site, double3 origin) {
  Light l = t;
  double3 p = site - origin;
  l.p.x = to_float(double(t.p.x) + p.x);
  l.p.y = to_float(double(t.p.y) + p.y);
  l.p.z = to_float(double(t.p.z) + p.z);
  return l;
}

} // namespace

void expand_light_set(const JsonValue& v, Builder& b) {
  auto o = v.as_object();
  std::string type = o.req("type").as_enum({"grid", "random_box", "spiral", "mesh_surface"});
  Light tmpl = parse_light(o.req("light"), /*is_template=*/true, double3{});
  uint32_t seed = 1;
  if (auto s = o.get("seed")) seed = uint32_t(s->as_int(0, 0xffffffffLL));
  Variation var;
  if (auto vv = o.get("variation")) var = parse_variation(*vv);
  std::optional<ShapeDesc> inst;
  if (auto iv = o.get("instance")) inst = parse_shape(*iv, b);

  // A count of 0 is accepted (a set switched off); nx and ny, when given, are >= 1.
  auto count_of = [&](const char* key) { return o.req(key).as_int(0, kMaxLights); };

  // World positions in double, rebased when the lights and instances are placed.
  std::vector<double3> sites;
  std::vector<float3> normals; // mesh_surface only
  const double3 scene_origin = b.scene.origin;
  Pcg32 rng(seed, 0x5eed);

  if (type == "grid") {
    o.allow({"type", "light", "instance", "seed", "variation", "count", "nx", "ny", "origin",
             "edge1", "edge2"});
    double3 origin = o.req("origin").as_dvec3();
    double3 e1 = o.req("edge1").as_dvec3();
    double3 e2 = o.req("edge2").as_dvec3();
    int64_t nx, ny, count;
    if (o.has("nx") || o.has("ny")) {
      if (o.has("count")) o.req("count").fail("give either count or nx and ny, not both");
      nx = o.req("nx").as_int(1, kMaxLights);
      ny = o.req("ny").as_int(1, kMaxLights);
      count = nx * ny;
      if (count > kMaxLights) o.req("ny").fail(fmt::format("nx * ny must be <= {}", kMaxLights));
    } else {
      count = count_of("count");
      nx = std::max<int64_t>(1, int64_t(std::ceil(std::sqrt(double(count)))));
      ny = (count + nx - 1) / nx;
    }
    sites.reserve(size_t(count));
    for (int64_t j = 0; j < ny && int64_t(sites.size()) < count; ++j) {
      float fy = (float(j) + 0.5f) / float(ny);
      for (int64_t i = 0; i < nx && int64_t(sites.size()) < count; ++i) {
        float fx = (float(i) + 0.5f) / float(nx);
        sites.push_back(origin + e1 * double(fx) + e2 * double(fy));
      }
    }
  } else if (type == "random_box") {
    o.allow({"type", "light", "instance", "seed", "variation", "count", "min", "max"});
    double3 lo = o.req("min").as_dvec3();
    auto maxv = o.req("max");
    double3 hi = maxv.as_dvec3();
    if (!(hi.x >= lo.x && hi.y >= lo.y && hi.z >= lo.z))
      maxv.fail("must be >= min in every component");
    int64_t count = count_of("count");
    double3 ext = hi - lo;
    sites.resize(size_t(count));
    for (auto& s : sites) {
      double ux = rng.uniform(), uy = rng.uniform(), uz = rng.uniform();
      // Rounding could land exactly on hi only, never outside [lo, hi].
      s = {std::clamp(lo.x + ext.x * ux, lo.x, hi.x), std::clamp(lo.y + ext.y * uy, lo.y, hi.y),
           std::clamp(lo.z + ext.z * uz, lo.z, hi.z)};
    }
  } else if (type == "spiral") {
    o.allow({"type", "light", "instance", "seed", "variation", "count", "center", "radius",
             "inner_radius", "turns", "height"});
    double3 c = o.req("center").as_dvec3();
    float r1 = o.req("radius").as_float_positive();
    float r0 = 0.0f;
    if (auto iv = o.get("inner_radius")) {
      r0 = iv->as_float_nonneg();
      if (!(r0 < r1)) iv->fail("must be < radius");
    }
    float turns = o.req("turns").as_float_positive();
    float height = o.get_float("height", 0.0f);
    int64_t count = count_of("count");
    sites.resize(size_t(count));
    // Archimedean spiral r(φ) = r0 + (r1 - r0) φ / (2π turns) in the xz plane around `center`,
    // sites at (approximately) equal arc length: r² grows linearly with the site index.
    const double two_pi = 6.283185307179586;
    for (int64_t i = 0; i < count; ++i) {
      double t = count == 1 ? 0.0 : double(i) / double(count - 1);
      double r = std::sqrt(double(r0) * r0 + (double(r1) * r1 - double(r0) * r0) * t);
      double f = (r - r0) / (double(r1) - r0); // 0..1 along the spiral
      double phi = two_pi * double(turns) * f;
      sites[size_t(i)] = {c.x + r * std::cos(phi), c.y + double(height) * f,
                          c.z + r * std::sin(phi)};
    }
  } else { // mesh_surface
    o.allow({"type", "light", "instance", "seed", "variation", "count", "shape", "offset",
             "align_to_normal"});
    auto sv = o.req("shape");
    const Builder::ShapeRange* range = nullptr;
    if (sv.is_string()) {
      std::string name = sv.as_string();
      for (const auto& r : b.shapes)
        if (r.name == name) range = &r;
      if (!range)
        sv.fail(fmt::format("no shape named \"{}\" (shapes are matched by name)", printable(name)));
    } else {
      if (b.shapes.empty()) sv.fail("there are no shapes to refer to");
      int64_t k = sv.as_int(0, int64_t(b.shapes.size()) - 1);
      range = &b.shapes[size_t(k)];
    }
    float offset = o.get_float("offset", 0.0f);
    bool align = o.get_bool("align_to_normal", false);
    if (align && tmpl.type != LIGHT_SPOT && tmpl.type != LIGHT_DISK)
      o.req("align_to_normal").fail("applies to spot and disk lights only");
    int64_t count = count_of("count");
    const Scene& s = b.scene;
    size_t t0 = range->first_triangle, t1 = range->end_triangle;
    std::vector<double> cdf(t1 - t0);
    double total = 0.0;
    for (size_t t = t0; t < t1; ++t) {
      float3 a = s.vertices[s.indices[3 * t]], bb = s.vertices[s.indices[3 * t + 1]],
             c = s.vertices[s.indices[3 * t + 2]];
      double area = 0.5 * double(length(cross(bb - a, c - a)));
      if (!std::isfinite(area)) area = 0.0;
      total += area;
      cdf[t - t0] = total;
    }
    if (!(total > 0.0)) sv.fail("the shape has no surface area");
    sites.resize(size_t(count));
    normals.resize(size_t(count));
    for (int64_t i = 0; i < count; ++i) {
      double u = double(rng.uniform()) * total;
      size_t k = size_t(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin());
      if (k >= cdf.size()) k = cdf.size() - 1;
      // Skip zero-area triangles that upper_bound cannot land on anyway.
      size_t t = t0 + k;
      float3 a = s.vertices[s.indices[3 * t]], bb = s.vertices[s.indices[3 * t + 1]],
             c = s.vertices[s.indices[3 * t + 2]];
      float su = std::sqrt(rng.uniform()), w = rng.uniform();
      float b0 = 1.0f - su, b1 = su * (1.0f - w), b2 = su * w;
      float3 n = normalize(cross(bb - a, c - a));
      // The vertices are rebased already: back to world, like the other sites.
      sites[size_t(i)] = dvec(a * b0 + bb * b1 + c * b2 + n * offset) + scene_origin;
      normals[size_t(i)] = n;
    }
    if (!align) normals.clear();
  }

  size_t n = sites.size();
  if (int64_t(b.scene.lights.size()) + int64_t(n) > kMaxLights)
    v.fail(fmt::format("too many lights: the scene would have more than {}", kMaxLights));

  std::vector<Light>& lights = b.scene.lights;
  lights.reserve(lights.size() + n);
  Pcg32 vrng(seed, 0xc010);
  for (size_t i = 0; i < n; ++i) {
    Light l = place(tmpl, sites[i], scene_origin);
    if (!normals.empty() && l.type == LIGHT_DISK) {
      // the disk faces along the surface normal
      if (!finish_disk_light(l, normals[i]))
        v.fail(fmt::format("light {} (of {}): the surface normal is degenerate", i + 1, n));
    } else if (!normals.empty()) {
      l.e1.x = normals[i].x;
      l.e1.y = normals[i].y;
      l.e1.z = normals[i].z;
    }
    if (var.active) {
      float s = var.scale_lo + (var.scale_hi - var.scale_lo) * vrng.uniform();
      float cr = 1.0f - var.color * vrng.uniform();
      float cg = 1.0f - var.color * vrng.uniform();
      float cb = 1.0f - var.color * vrng.uniform();
      l.emission.x *= s * cr;
      l.emission.y *= s * cg;
      l.emission.z *= s * cb;
    }
    // A site far outside float range would make positions infinite; positions beyond
    // kMaxCoordinate would overflow the renderer's squared distances and bounds.
    if (!std::isfinite(l.emission.x) || !std::isfinite(l.emission.y) ||
        !std::isfinite(l.emission.z))
      v.fail(fmt::format("light {} (of {}) has a non-finite emission", i + 1, n));
    if (auto e = check_light_extent(l, scene_origin); !e.empty())
      v.fail(fmt::format("light {} (of {}): {}", i + 1, n, e));
    if (emits(l))
      lights.push_back(l);
    else
      ++b.scene.skipped_lights;
  }
  if (inst) {
    for (size_t i = 0; i < n; ++i) {
      size_t first_vertex = b.scene.vertices.size();
      b.add_mesh(inst->mesh, inst->transform.then(Transform::translate(sites[i])));
      check_vertices(b.scene, first_vertex, v, fmt::format("instance {} (of {}): ", i + 1, n));
    }
  }
}

} // namespace canopy::detail
