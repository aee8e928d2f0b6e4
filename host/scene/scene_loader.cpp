// load_scene / load_scene_from_string: the top level of the scene format (docs/scene-format.md).
#include "scene/loader_internal.h"
#include "scene/metal_presets.h"
#include "scene/pbrt_reader.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

namespace canopy {
namespace detail {

// ------------------------------------------------------------------------------------ Transform

Transform Transform::then(const Transform& outer) const {
  Transform r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[i][j] = outer.m[i][0] * m[0][j] + outer.m[i][1] * m[1][j] + outer.m[i][2] * m[2][j];
  r.t = outer.apply(t);
  return r;
}

double Transform::cofactors(double c[3][3]) const {
  const auto& a = m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      c[i][j] = a[i1][j1] * a[i2][j2] - a[i1][j2] * a[i2][j1];
    }
  return a[0][0] * c[0][0] + a[0][1] * c[0][1] + a[0][2] * c[0][2];
}

float3 Transform::apply_normal(float3 n) const {
  // Normals transform by M^-T; the cofactor matrix C = det(M) M^-T avoids the division, and the
  // sign of det keeps the direction (a mirror must not turn the normal inside out).
  double c[3][3];
  double det = cofactors(c);
  double s = det < 0.0 ? -1.0 : 1.0;
  double x = double(n.x), y = double(n.y), z = double(n.z);
  double r[3];
  for (int i = 0; i < 3; ++i)
    r[i] = s * (c[i][0] * x + c[i][1] * y + c[i][2] * z);
  double len = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
  if (!(len > 0.0) || !std::isfinite(len)) return make_float3(0, 0, 0);
  return make_float3(float(r[0] / len), float(r[1] / len), float(r[2] / len));
}

Transform Transform::translate(double3 d) {
  Transform r;
  r.t = d;
  return r;
}

Transform Transform::scale(double3 s) {
  Transform r;
  r.m[0][0] = s.x;
  r.m[1][1] = s.y;
  r.m[2][2] = s.z;
  return r;
}

Transform Transform::rotate(double3 a, double degrees) {
  // Rodrigues; entries below 1e-15 are zeroed so 90 degrees gives exact zeros where it should.
  double th = degrees * (3.14159265358979323846 / 180.0);
  double c = std::cos(th), s = std::sin(th), C = 1.0 - c;
  double x = a.x, y = a.y, z = a.z;
  Transform r;
  double m[3][3] = {{c + x * x * C, x * y * C - z * s, x * z * C + y * s},
                    {y * x * C + z * s, c + y * y * C, y * z * C - x * s},
                    {z * x * C - y * s, z * y * C + x * s, c + z * z * C}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double v = m[i][j];
      r.m[i][j] = std::fabs(v) < 1e-15 ? 0.0 : v;
    }
  return r;
}

// -------------------------------------------------------------------------------------- Builder

int Builder::material_ref(const JsonValue& v) const {
  std::string name = v.as_string();
  auto it = material_by_name.find(name);
  if (it == material_by_name.end()) v.fail(fmt::format("unknown material \"{}\"", printable(name)));
  return it->second;
}

int Builder::mtl_material(const std::string& mtl_file, const MaterialDesc& d) {
  // A scene material with the same name wins: it lets a scene recolour an OBJ.
  if (auto it = material_by_name.find(d.name); it != material_by_name.end()) return it->second;
  std::string key = mtl_file + "\n" + d.name;
  if (auto it = mtl_material_by_key.find(key); it != mtl_material_by_key.end()) return it->second;
  int idx = int(scene.materials.size());
  scene.materials.push_back(d);
  mtl_material_by_key.emplace(key, idx);
  return idx;
}

namespace {
// reserve() with geometric growth: many small meshes (instances) must not reallocate every time.
template <class T> void reserve_more(std::vector<T>& v, size_t extra) {
  size_t need = v.size() + extra;
  if (need > v.capacity()) v.reserve(std::max(need, 2 * v.capacity()));
}
} // namespace

size_t Builder::add_mesh(const Mesh& mesh, const Transform& xf) {
  Scene& s = scene;
  size_t first_tri = s.triangle_count();
  if (s.vertices.size() + mesh.vertices.size() > size_t(std::numeric_limits<uint32_t>::max()))
    throw SceneError(fmt::format("{}: shapes: too many vertices (more than 2^32)", file));
  uint32_t base = uint32_t(s.vertices.size());
  reserve_more(s.vertices, mesh.vertices.size());
  for (const float3& v : mesh.vertices)
    s.vertices.push_back(rebase(xf.apply(v), s.origin));
  bool flip = xf.flips();
  size_t nt = mesh.triangle_count();
  reserve_more(s.indices, 3 * nt);
  reserve_more(s.triangle_material, nt);
  reserve_more(s.triangle_light, nt);
  // Shading normals: world-space unit normals, transformed once per mesh normal.
  const bool smooth = !mesh.normal_indices.empty();
  std::vector<float3> world_normals;
  if (smooth) {
    world_normals.resize(mesh.normals.size());
    for (size_t i = 0; i < mesh.normals.size(); ++i)
      world_normals[i] = xf.apply_normal(mesh.normals[i]);
    if (s.triangle_normals.empty()) s.triangle_normals.assign(first_tri, -1);
    reserve_more(s.shading_normals, 3 * nt);
  }
  if (!s.triangle_normals.empty()) reserve_more(s.triangle_normals, nt);
  // Texture coordinates: the earlier triangles get the default once a mesh brings uv.
  const bool has_uv = !mesh.uv_indices.empty();
  const float2 default_uv[3] = {make_float2(0, 0), make_float2(1, 0), make_float2(1, 1)};
  if (has_uv && s.triangle_uvs.empty())
    for (size_t t = 0; t < first_tri; ++t)
      s.triangle_uvs.insert(s.triangle_uvs.end(), default_uv, default_uv + 3);
  if (!s.triangle_uvs.empty()) reserve_more(s.triangle_uvs, 3 * nt);
  for (size_t t = 0; t < nt; ++t) {
    uint32_t a = base + mesh.indices[3 * t], bb = base + mesh.indices[3 * t + 1],
             c = base + mesh.indices[3 * t + 2];
    if (flip) std::swap(bb, c);
    s.indices.insert(s.indices.end(), {a, bb, c});
    s.triangle_material.push_back(mesh.material[t]);
    if (smooth) {
      // A triangle without a normal at every vertex, or with a zero or non-finite one, is flat.
      float3 n[3];
      bool ok = true;
      for (int k = 0; k < 3; ++k) {
        int32_t ni = mesh.normal_indices[3 * t + size_t(k)];
        n[k] = ni < 0 ? make_float3(0, 0, 0) : world_normals[size_t(ni)];
        ok = ok && (n[k].x != 0.0f || n[k].y != 0.0f || n[k].z != 0.0f);
      }
      if (flip) std::swap(n[1], n[2]);
      int32_t first = -1;
      if (ok) {
        if (s.shading_normals.size() + 3 > size_t(std::numeric_limits<int32_t>::max()))
          throw SceneError(
              fmt::format("{}: shapes: too many shading normals (more than 2^31)", file));
        first = int32_t(s.shading_normals.size());
        s.shading_normals.insert(s.shading_normals.end(), {n[0], n[1], n[2]});
      }
      s.triangle_normals.push_back(first);
    } else if (!s.triangle_normals.empty()) {
      s.triangle_normals.push_back(-1);
    }
    if (has_uv || !s.triangle_uvs.empty()) {
      float2 uv[3] = {default_uv[0], default_uv[1], default_uv[2]};
      if (has_uv) {
        // A triangle lacking uv at a vertex takes the default at all three.
        bool ok = true;
        for (int k = 0; k < 3; ++k) {
          int32_t ui = mesh.uv_indices[3 * t + size_t(k)];
          ok = ok && ui >= 0;
          if (ok) uv[k] = mesh.uvs[size_t(ui)];
        }
        if (!ok) std::copy(default_uv, default_uv + 3, uv);
      }
      if (flip) std::swap(uv[1], uv[2]);
      s.triangle_uvs.insert(s.triangle_uvs.end(), uv, uv + 3);
    }
    int32_t light = -1;
    float3 em = mesh.emission[t];
    if (em.x > 0.0f || em.y > 0.0f || em.z > 0.0f) {
      Light l{};
      float3 v0 = s.vertices[a], v1 = s.vertices[bb], v2 = s.vertices[c];
      l.p = f4_from3(v0, 0.0f);
      l.e1 = f4_from3(v1 - v0, 0.0f);
      l.e2 = f4_from3(v2 - v0, 0.0f);
      l.emission = f4_from3(em, 0.0f);
      l.type = LIGHT_TRIANGLE;
      l.flags = LIGHT_FLAG_FROM_MESH | (mesh.two_sided_emission ? LIGHT_FLAG_TWO_SIDED : 0);
      l.prim = -1;
      // A zero-area triangle of an emissive mesh stays in the geometry but is no light.
      if (finish_area_light(l)) {
        light = int32_t(s.lights.size());
        s.lights.push_back(l);
      }
    }
    s.triangle_light.push_back(light);
  }
  return first_tri;
}

std::string vertices_problem(const Scene& s, size_t first_vertex) {
  for (size_t i = first_vertex; i < s.vertices.size(); ++i)
    if (auto e = check_coordinate(s.vertices[i], s.origin); !e.empty())
      return fmt::format("vertex {} after the transform: {}", i - first_vertex + 1, e);
  return {};
}

void check_vertices(const Scene& s, size_t first_vertex, const JsonValue& at,
                    std::string_view what) {
  if (auto e = vertices_problem(s, first_vertex); !e.empty()) at.fail(fmt::format("{}{}", what, e));
}

bool emits(const Light& l) {
  return l.emission.x > 0.0f || l.emission.y > 0.0f || l.emission.z > 0.0f;
}

void add_infinite_light(Scene& scene, const Light& l,
                        const std::function<void(const std::string&)>& fail) {
  // Lights at infinity are sampled at surfaces only (cl/integrator/light_pick.h): in a medium
  // their light along a ray segment would be missing, so such a scene is refused, not rendered
  // wrong.
  const char* what = l.type == LIGHT_DISTANT ? "distant" : "environment";
  if (scene.has_medium)
    fail(fmt::format("a {} light in a scene with a medium is not supported (medium points would "
                     "miss its light)",
                     what));
  if (scene.infinite_lights.size() >= MAX_INFINITE_LIGHTS)
    fail(fmt::format("more than {} distant and environment lights", MAX_INFINITE_LIGHTS));
  scene.infinite_lights.push_back(l);
}

// ------------------------------------------------------------------------------ top-level parts

namespace {

// The camera position becomes the scene origin: the camera sits exactly at (0, 0, 0), where float
// coordinates are finest.
void parse_camera(const JsonValue& v, Camera& cam, double3& origin) {
  auto o = v.as_object();
  o.allow({"position", "look_at", "up", "fov"});
  auto pos = o.req("position");
  double3 p = pos.as_dvec3();
  // The inputs stay within kMaxCoordinate too: world positions (origin + coordinate) then stay
  // within 2 kMaxCoordinate.
  if (auto e = check_coordinate(to_float3(p)); !e.empty()) pos.fail(e);
  auto look = o.req("look_at");
  double3 at = look.as_dvec3();
  if (auto e = check_coordinate(to_float3(at)); !e.empty()) look.fail(e);
  origin = p;
  cam.position = make_float3(0, 0, 0);
  cam.look_at = rebase(at, origin);
  float3 dir = cam.look_at;
  if (dir.x == 0.0f && dir.y == 0.0f && dir.z == 0.0f)
    look.fail("must differ from camera.position");
  if (!std::isfinite(dot(dir, dir))) look.fail("is too far from camera.position");
  if (auto up = o.get("up")) {
    cam.up = up->as_vec3_nonzero();
    float3 d = normalize(dir), u = normalize(cam.up);
    float3 c = cross(d, u);
    if (!(std::sqrt(dot(c, c)) > 1e-4f)) up->fail("must not be parallel to the view direction");
  } else {
    cam.up = make_float3(0, 1, 0);
    float3 d = normalize(dir);
    if (std::fabs(d.x) < 1e-4f && std::fabs(d.z) < 1e-4f)
      throw_error(v.file(), o.child_path("up"),
                  "the default [0, 1, 0] is parallel to the view direction; give camera.up");
  }
  if (auto f = o.get("fov")) cam.fov_y_deg = f->as_float_open(0.0f, 180.0f);
}

void parse_film(const JsonValue& v, FilmSettings& film) {
  auto o = v.as_object();
  o.allow({"width", "height"});
  if (auto w = o.get("width")) film.width = int(w->as_int(1, kMaxFilmSide));
  if (auto h = o.get("height")) film.height = int(h->as_int(1, kMaxFilmSide));
}

void parse_integrator(const JsonValue& v, IntegratorSettings& in) {
  auto o = v.as_object();
  o.allow({"spp", "max_depth", "light_sampler", "split_threshold", "max_cut", "seed", "mis",
           "brdf_delta", "brdf_n_max", "brdf_lambda", "brdf_adaptive", "volume_importance"});
  if (auto x = o.get("spp")) in.spp = int(x->as_int(1, kMaxSpp));
  if (auto x = o.get("max_depth")) in.max_depth = int(x->as_int(1, kMaxDepth));
  if (auto x = o.get("light_sampler")) in.light_sampler = x->as_enum(kLightSamplerChoices);
  if (auto x = o.get("split_threshold")) in.split_threshold = x->as_float_in(0.0f, 1.0f);
  if (auto x = o.get("max_cut")) in.max_cut = int(x->as_int(1, kMaxMaxCut));
  if (auto x = o.get("seed")) in.seed = uint32_t(x->as_int(0, 0xffffffffLL));
  if (auto x = o.get("mis")) in.mis = x->as_bool();
  if (auto x = o.get("brdf_delta")) in.brdf_delta = x->as_float_in(0.0f, 1e3f);
  if (auto x = o.get("brdf_n_max")) in.brdf_n_max = int(x->as_int(1, kMaxBrdfSamples));
  if (auto x = o.get("brdf_lambda")) in.brdf_lambda = x->as_float_in(1e-3f, 1e6f);
  if (auto x = o.get("brdf_adaptive")) in.brdf_adaptive = x->as_bool();
  if (auto x = o.get("volume_importance"))
    in.volume_importance = x->as_enum({"segment", "midpoint"});
}

// The top-level "medium" (docs/scene-format.md, Participating media): homogeneous, everywhere or
// inside a box.
Medium parse_medium(const JsonValue& v, double3 origin) {
  auto o = v.as_object();
  o.allow({"sigma_a", "sigma_s", "g", "bounds"});
  float3 sa = o.req("sigma_a").as_color_in(0.0f, kMaxMediumCoefficient);
  float3 ss = o.req("sigma_s").as_color_in(0.0f, kMaxMediumCoefficient);
  float g = 0.0f;
  if (auto x = o.get("g")) g = x->as_float_open(-1.0f, 1.0f);
  Medium m{};
  m.sigma_t = make_float4(sa.x + ss.x, sa.y + ss.y, sa.z + ss.z, g);
  m.sigma_s = make_float4(ss.x, ss.y, ss.z, 0.0f);
  if (auto b = o.get("bounds")) {
    auto bo = b->as_object();
    bo.allow({"min", "max"});
    auto lo = bo.req("min");
    auto hi = bo.req("max");
    float3 mn = rebase(lo.as_dvec3(), origin), mx = rebase(hi.as_dvec3(), origin);
    if (auto e = check_coordinate(mn, origin); !e.empty()) lo.fail(e);
    if (auto e = check_coordinate(mx, origin); !e.empty()) hi.fail(e);
    if (!(mn.x < mx.x && mn.y < mx.y && mn.z < mx.z))
      hi.fail("must exceed bounds.min in every coordinate");
    m.sigma_s.w = 1.0f;
    m.bmin = make_float4(mn.x, mn.y, mn.z, 0.0f);
    m.bmax = make_float4(mx.x, mx.y, mx.z, 0.0f);
  }
  return m;
}

// An image texture given for a material's "albedo" (channels 3) or "roughness" (channels 1):
// A 2D texture's "uv_scale" and "uv_offset" (pairs of numbers) into uvmap's (x, y) and (z, w).
void read_uv_mapping(const JsonObject& o, float4* uvmap) {
  auto pair = [](const JsonValue& a) {
    if (!a.is_array() || a.array_size() != 2) a.fail("must be an array of 2 numbers");
    return make_float2(a.at(0).as_float(), a.at(1).as_float());
  };
  if (auto sv = o.get("uv_scale")) {
    float2 k = pair(*sv);
    uvmap->x = k.x;
    uvmap->y = k.y;
  }
  if (auto ov = o.get("uv_offset")) {
    float2 d = pair(*ov);
    uvmap->z = d.x;
    uvmap->w = d.y;
  }
}

// {"texture": file, "scale", "wrap", "encoding", "uv_scale", "uv_offset"} (docs/scene-format.md,
// Textures).
TextureDesc parse_texture(const JsonValue& v, const Builder& b, int channels) {
  auto o = v.as_object();
  o.allow({"type", "texture", "scale", "wrap", "encoding", "uv_scale", "uv_offset"});
  TextureDesc t;
  auto fv = o.req("texture");
  std::string f = fv.as_string();
  if (f.empty()) fv.fail("must not be empty");
  std::filesystem::path p(f);
  if (p.is_relative()) p = b.base_dir / p;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(p, ec))
    fv.fail(fmt::format("{}: no such file", p.string()));
  t.file = p;
  t.where = fmt::format("{}: {}", b.file, v.path());
  t.channels = channels;
  if (auto sv = o.get("scale")) {
    if (channels == 1) {
      float k = sv->as_float_nonneg();
      t.scale = make_float3(k, k, k);
    } else {
      t.scale = sv->as_color();
    }
  }
  if (auto wv = o.get("wrap")) {
    std::string w = wv->as_enum({"repeat", "clamp", "black"});
    t.wrap = w == "repeat" ? TEXTURE_WRAP_REPEAT
                           : (w == "clamp" ? TEXTURE_WRAP_CLAMP : TEXTURE_WRAP_BLACK);
  }
  if (auto ev = o.get("encoding")) {
    if (ev->is_number()) {
      t.encoding = ImageEncoding::Gamma;
      t.gamma = ev->as_float_in(0.01f, 100.0f);
    } else {
      std::string e = ev->as_enum({"auto", "srgb", "linear"});
      t.encoding = e == "auto" ? ImageEncoding::Auto
                               : (e == "srgb" ? ImageEncoding::Srgb : ImageEncoding::Linear);
    }
  }
  read_uv_mapping(o, &t.uvmap);
  return t;
}

// The nodes of a texture input (docs/scene-format.md, Textures) appended to `out` in postfix order:
// a constant (a number for a float input, channels 1, else a colour), an image texture, or a
// checkerboard, mix or scale of inputs. Returns the evaluation stack it needs.
int parse_texture_nodes(const JsonValue& v, const Builder& b, int channels,
                        std::vector<TextureDesc>& out) {
  if (!v.is_object()) {
    TextureDesc c;
    c.kind = TEXTURE_CONSTANT;
    if (channels == 1) {
      float k = v.as_float_nonneg();
      c.scale = make_float3(k, k, k);
    } else {
      c.scale = v.as_color();
    }
    out.push_back(c);
    return 1;
  }
  auto o = v.as_object();
  std::string type = "image";
  if (auto t = o.get("type")) type = t->as_enum({"image", "checkerboard", "mix", "scale"});
  if (type == "image") {
    out.push_back(parse_texture(v, b, channels));
    return 1;
  }
  const size_t start = out.size();
  int stack = 0;
  auto input = [&](const JsonValue& x, int ch, int i) {
    stack = std::max(stack, i + parse_texture_nodes(x, b, ch, out));
  };
  TextureDesc root;
  if (type == "checkerboard") {
    o.allow({"type", "tex1", "tex2", "uv_scale", "uv_offset"});
    root.kind = TEXTURE_CHECKERBOARD;
    input(o.req("tex1"), channels, 0);
    input(o.req("tex2"), channels, 1);
    read_uv_mapping(o, &root.uvmap);
  } else if (type == "mix") {
    o.allow({"type", "tex1", "tex2", "amount"});
    root.kind = TEXTURE_MIX;
    input(o.req("tex1"), channels, 0);
    input(o.req("tex2"), channels, 1);
    if (auto a = o.get("amount")) {
      input(*a, 1, 2);
    } else {
      TextureDesc half;
      half.kind = TEXTURE_CONSTANT;
      half.scale = make_float3(0.5f, 0.5f, 0.5f);
      out.push_back(half);
      stack = std::max(stack, 3);
    }
  } else {
    o.allow({"type", "tex", "scale"});
    root.kind = TEXTURE_SCALE;
    input(o.req("tex"), channels, 0);
    input(o.req("scale"), 1, 1);
  }
  root.nodes = int(out.size() - start) + 1;
  out.push_back(root);
  if (stack > TEXTURE_STACK)
    v.fail(fmt::format("textures nested too deeply (this one needs {} values at once, at most {})",
                       stack, TEXTURE_STACK));
  return stack;
}

// A texture input of a material as Scene::textures nodes: 1 + its root's index, whose `map` is
// `map`.
int add_texture_input(const JsonValue& v, Builder& b, int channels, int map) {
  std::vector<TextureDesc> nodes;
  parse_texture_nodes(v, b, channels, nodes);
  nodes.back().map = map;
  int id = 0;
  for (TextureDesc& t : nodes)
    id = add_texture(b.scene, std::move(t));
  return id;
}

// A material's "albedo": a reflectance (rgb in [0, 1]) or a texture.
void parse_albedo(const JsonValue& v, Builder& b, MaterialDesc& d) {
  if (v.is_object()) {
    d.gpu.albedo = make_float4(0, 0, 0, 0);
    d.gpu.albedo_texture = add_texture_input(v, b, 3, TEXTURE_MAP_VALUE);
  } else {
    d.gpu.albedo = f4_from3(v.as_albedo(), 0.0f);
  }
}

// A material's "roughness": r in [0, 1] (GGX alpha = r^2) or a texture of r.
float parse_roughness(const JsonValue& v, Builder& b, MaterialDesc& d) {
  if (!v.is_object()) return v.as_float_in(0.0f, 1.0f);
  d.gpu.alpha_texture = add_texture_input(v, b, 1, TEXTURE_MAP_ALPHA_SQUARE);
  return 0.5f; // the material's constant, unused where the texture applies
}

// A conductor's complex index: "metal" (a preset name) or "eta" and "k"; without any of them, the
// preset `fallback` (nullptr: one is required).
void parse_conductor_index(const JsonObject& o, float3* eta, float3* k, const char* fallback) {
  auto metal = o.get("metal");
  auto e = o.get("eta");
  auto kv = o.get("k");
  if (metal) {
    // The message names eta if both eta and k are given.
    for (const auto& x : {e, kv})
      if (x) x->fail("not allowed together with \"metal\" (give a preset or eta and k)");
  }
  if (metal || (!e && !kv && fallback)) {
    const MetalPreset* p = metal ? find_metal_preset(metal->as_enum(metal_preset_names()))
                                 : find_metal_preset(fallback);
    *eta = make_float3(p->eta[0], p->eta[1], p->eta[2]);
    *k = make_float3(p->k[0], p->k[1], p->k[2]);
    return;
  }
  if (!e && !kv) o.fail("a conductor needs \"metal\" (a preset name) or \"eta\" and \"k\"");
  *eta = o.req("eta").as_color_in(kMinConductorEta, kMaxConductorIndex);
  *k = o.req("k").as_color_in(0.0f, kMaxConductorIndex);
}

// The slab and walk of a coated material (pbrt-v4's defaults where absent).
CoatLayer parse_coat_layer(const JsonObject& o) {
  CoatLayer l;
  if (auto x = o.get("thickness")) l.thickness = x->as_float_in(0.0f, kMaxCoatThickness);
  if (auto x = o.get("medium_albedo")) l.albedo = x->as_albedo();
  if (auto x = o.get("g")) l.g = x->as_float_in(-1.0f, 1.0f);
  if (auto x = o.get("max_depth")) l.max_depth = int(x->as_int(1, kMaxCoatDepth));
  if (auto x = o.get("samples")) l.n_samples = int(x->as_int(1, kMaxCoatSamples));
  return l;
}

// One entry of "materials" (docs/scene-format.md, Materials). Roughness r becomes GGX alpha = r^2.
// "albedo" and "roughness" may be image textures.
MaterialDesc parse_material(const JsonValue& v, Builder& b) {
  auto o = v.as_object();
  auto nv = o.req("name");
  std::string name = nv.as_string();
  if (name.empty()) nv.fail("must not be empty");
  std::string type = "diffuse"; // the default keeps scenes written before glossy materials valid
  if (auto t = o.get("type"))
    type = t->as_enum({"diffuse", "conductor", "plastic", "dielectric", "coated_diffuse",
                       "coated_conductor", "diffuse_transmission", "mix"});
  if (type == "diffuse") {
    o.allow({"name", "type", "albedo"});
    MaterialDesc d = diffuse_material(name, make_float3(0, 0, 0));
    parse_albedo(o.req("albedo"), b, d);
    return d;
  }
  if (type == "diffuse_transmission") {
    o.allow({"name", "type", "albedo", "transmittance"});
    MaterialDesc d = diffuse_transmission_material(name, make_float3(0.25f, 0.25f, 0.25f),
                                                   make_float3(0.25f, 0.25f, 0.25f));
    if (auto a = o.get("albedo")) parse_albedo(*a, b, d);
    if (auto t = o.get("transmittance")) {
      if (t->is_object())
        d.gpu.transmittance_texture = add_texture_input(*t, b, 3, TEXTURE_MAP_VALUE);
      else
        d.gpu.specular = f4_from3(t->as_albedo(), 0.0f);
    }
    float3 r = xyz_of(d.gpu.albedo), tr = xyz_of(d.gpu.specular);
    if (!d.gpu.albedo_texture && !d.gpu.transmittance_texture &&
        (r.x + tr.x > 1.0f || r.y + tr.y > 1.0f || r.z + tr.z > 1.0f))
      o.fail("albedo + transmittance must be at most 1 in every channel (energy conservation)");
    return d;
  }
  if (type == "mix") {
    o.allow({"name", "type", "materials", "amount"});
    if (name == "default") nv.fail("the default material cannot be a mix");
    auto mv = o.req("materials");
    if (!mv.is_array() || mv.array_size() != 2) mv.fail("must be an array of 2 material names");
    int parts[2] = {b.material_ref(mv.at(0)), b.material_ref(mv.at(1))};
    for (int i = 0; i < 2; ++i)
      if (mix_depth(b.scene.materials, parts[i]) >= MATERIAL_MIX_MAX_DEPTH)
        mv.at(size_t(i)).fail(
            fmt::format("mixes nested more than {} deep", MATERIAL_MIX_MAX_DEPTH));
    MaterialDesc d = mix_material(name, parts[0], parts[1], 0.5f);
    if (auto a = o.get("amount")) {
      if (a->is_object())
        d.gpu.mix_amount_texture = add_texture_input(*a, b, 1, TEXTURE_MAP_VALUE);
      else
        d.gpu.mix_amount = a->as_float_in(0.0f, 1.0f);
    }
    return d;
  }
  if (type == "conductor") {
    o.allow({"name", "type", "roughness", "metal", "eta", "k"});
    MaterialDesc d{};
    float r = parse_roughness(o.req("roughness"), b, d);
    const int alpha_texture = d.gpu.alpha_texture;
    float3 e, kk;
    parse_conductor_index(o, &e, &kk, nullptr);
    d = conductor_material(name, r, e, kk);
    d.gpu.alpha_texture = alpha_texture;
    return d;
  }
  if (type == "dielectric") {
    o.allow({"name", "type", "ior", "thin", "roughness"});
    float ior = kDefaultPlasticIor;
    if (auto i = o.get("ior")) ior = i->as_float_in(kMinDielectricIor, kMaxDielectricIor);
    bool thin = false;
    if (auto t = o.get("thin")) thin = t->as_bool();
    float r = 0.0f;
    if (auto rv = o.get("roughness")) {
      if (thin) rv->fail("a thin dielectric is smooth");
      r = rv->as_float_in(0.0f, 1.0f);
    }
    return dielectric_material(name, ior, thin, r * r);
  }
  if (type == "coated_diffuse" || type == "coated_conductor") {
    const bool diffuse = type == "coated_diffuse";
    if (diffuse)
      o.allow({"name", "type", "albedo", "roughness", "ior", "thickness", "medium_albedo", "g",
               "max_depth", "samples"});
    else
      o.allow({"name", "type", "roughness", "ior", "metal", "eta", "k", "conductor_roughness",
               "thickness", "medium_albedo", "g", "max_depth", "samples"});
    MaterialDesc t{}; // the textures
    float r = 0.0f;
    if (auto rv = o.get("roughness")) r = parse_roughness(*rv, b, t);
    float ior = kDefaultPlasticIor;
    if (auto i = o.get("ior")) ior = i->as_float_in(1.0f, kMaxPlasticIor);
    CoatLayer layer = parse_coat_layer(o);
    MaterialDesc d;
    if (diffuse) {
      t.gpu.albedo = make_float4(0.5f, 0.5f, 0.5f, 0.0f);
      if (auto a = o.get("albedo")) parse_albedo(*a, b, t);
      d = coated_diffuse_material(name, xyz_of(t.gpu.albedo), r * r, ior, layer);
      d.gpu.albedo_texture = t.gpu.albedo_texture;
    } else {
      float3 e, kk;
      parse_conductor_index(o, &e, &kk, "copper");
      float cr = 0.0f;
      if (auto c = o.get("conductor_roughness")) cr = c->as_float_in(0.0f, 1.0f);
      d = coated_conductor_material(name, r * r, ior, e, kk, cr * cr, layer);
    }
    d.gpu.alpha_texture = t.gpu.alpha_texture;
    return d;
  }
  // plastic
  o.allow({"name", "type", "albedo", "specular", "roughness", "ior"});
  MaterialDesc d{};
  parse_albedo(o.req("albedo"), b, d);
  float r = parse_roughness(o.req("roughness"), b, d);
  float3 spec = make_float3(1, 1, 1);
  if (auto sp = o.get("specular")) spec = sp->as_color();
  float ior = kDefaultPlasticIor;
  if (auto i = o.get("ior")) ior = i->as_float_in(1.0f, kMaxPlasticIor);
  MaterialDesc p = plastic_material(name, xyz_of(d.gpu.albedo), spec, r, ior);
  p.gpu.albedo_texture = d.gpu.albedo_texture;
  p.gpu.alpha_texture = d.gpu.alpha_texture;
  return p;
}

void parse_materials(const JsonValue& v, Builder& b) {
  Scene& s = b.scene;
  bool default_replaced = false;
  for (const JsonValue& mv : v.as_array()) {
    MaterialDesc d = parse_material(mv, b);
    const std::string& name = d.name;
    auto nv = mv.as_object().req("name");
    if (name == "default" && !default_replaced) {
      s.materials[0] = d; // replaces the built-in default
      default_replaced = true;
      continue;
    }
    if (b.material_by_name.count(name))
      nv.fail(fmt::format("duplicate material name \"{}\"", printable(name)));
    b.material_by_name[name] = int(s.materials.size());
    s.materials.push_back(d);
  }
}

void parse_shapes(const JsonValue& v, Builder& b) {
  for (const JsonValue& sv : v.as_array()) {
    ShapeDesc d = parse_shape(sv, b);
    if (!d.name.empty())
      for (const auto& r : b.shapes)
        if (r.name == d.name)
          sv.as_object().req("name").fail(
              fmt::format("duplicate shape name \"{}\"", printable(d.name)));
    size_t first_vertex = b.scene.vertices.size();
    size_t first = b.add_mesh(d.mesh, d.transform);
    check_vertices(b.scene, first_vertex, sv, "");
    b.shapes.push_back({d.name, first, b.scene.triangle_count()});
  }
}

} // namespace
} // namespace detail

namespace {

Scene load_from_string(const std::string& json_text, const std::string& name,
                       const std::filesystem::path& base_dir) {
  using namespace detail;
  Document doc;
  parse_json(json_text, name, doc);
  Scene scene;
  scene.path = name;
  scene.materials.push_back(diffuse_material("default", make_float3(0.8f, 0.8f, 0.8f)));

  Builder b{scene, name, base_dir, {}, {}, {}};
  b.material_by_name["default"] = 0;

  JsonValue root(doc, doc.root, name);
  auto o = root.as_object();
  o.allow(
      {"camera", "film", "integrator", "materials", "shapes", "lights", "light_sets", "medium"});
  // First: the camera sets the origin that every later coordinate is rebased to.
  parse_camera(o.req("camera"), scene.camera, scene.origin);
  if (auto x = o.get("film")) parse_film(*x, scene.film);
  if (auto x = o.get("integrator")) parse_integrator(*x, scene.integrator);
  if (auto x = o.get("medium")) {
    scene.medium = parse_medium(*x, scene.origin);
    // A medium with sigma_t = 0 is vacuum: no medium code at all.
    scene.has_medium = max3(xyz_of(scene.medium.sigma_t)) > 0.0f;
  }
  if (auto x = o.get("materials")) parse_materials(*x, b);
  if (auto x = o.get("shapes")) parse_shapes(*x, b);
  if (auto x = o.get("lights")) {
    size_t n = x->array_size();
    scene.lights.reserve(scene.lights.size() + n);
    for (size_t i = 0; i < n; ++i) {
      JsonValue lv = x->at(i);
      const bool env =
          lv.as_object().has("type") && lv.as_object().req("type").as_string() == "environment";
      Light l = env ? parse_environment_light(lv, b) : parse_light(lv, false, scene.origin);
      if (auto e = check_light_extent(l, scene.origin); !e.empty()) lv.fail(e);
      // A light switched off (zero emission) is skipped: it neither emits nor occludes.
      if (!emits(l))
        ++scene.skipped_lights;
      else if (l.type == LIGHT_DISTANT || l.type == LIGHT_ENVIRONMENT)
        add_infinite_light(scene, l, [&](const std::string& e) { lv.fail(e); });
      else
        scene.lights.push_back(l);
    }
  }
  if (auto x = o.get("light_sets")) {
    for (const JsonValue& sv : x->as_array())
      expand_light_set(sv, b);
  }
  // A scene without emitters is valid: it renders black (the CLI warns).
  return scene;
}

} // namespace

Scene load_scene_from_string(const std::string& json_text, const std::string& name,
                             const std::filesystem::path& base_dir) {
  try {
    return load_from_string(json_text, name, base_dir);
  } catch (const std::bad_alloc&) {
    throw SceneError(fmt::format("{}: out of memory while building the scene", name));
  } catch (const std::length_error&) {
    throw SceneError(fmt::format("{}: out of memory while building the scene", name));
  }
}

Scene load_scene(const std::filesystem::path& file, const SceneLoadOptions& options) {
  if (file.extension() == ".pbrt") return load_pbrt_scene(file, options);
  std::string name = printable(file.string(), 1024);
  std::string text = detail::read_input_file(file, kMaxSceneFileBytes, name + ": ");
  Scene s = load_scene_from_string(text, name, file.parent_path());
  s.path = file;
  return s;
}

} // namespace canopy
