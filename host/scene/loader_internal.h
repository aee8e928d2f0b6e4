// Internals of the scene loader shared by scene_loader.cpp, shapes.cpp, obj_loader.cpp and
// light_sets.cpp. Not part of the public interface (that is scene.h).
#pragma once

#include "scene/json_reader.h"
#include "scene/scene.h"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace canopy {

inline double3 operator+(double3 a, double3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline double3 operator-(double3 a, double3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline double3 operator*(double3 a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}

} // namespace canopy

namespace canopy::detail {

inline double3 dvec(float3 v) {
  return {double(v.x), double(v.y), double(v.z)};
}
// Rounded to float; beyond the float range +-inf (a plain conversion would be undefined), which
// the coordinate checks then refuse.
inline float to_float(double v) {
  if (std::fabs(v) > double(std::numeric_limits<float>::max()))
    return v > 0 ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
  return float(v);
}
inline float3 to_float3(double3 v) {
  return make_float3(to_float(v.x), to_float(v.y), to_float(v.z));
}
// A world position as the renderer stores it: relative to the scene origin, rounded once.
inline float3 rebase(double3 p, double3 origin) {
  return to_float3(p - origin);
}

// PCG32 (O'Neill): small, fast, and the same sequence on every platform and compiler (unlike the
// std:: distributions), so a seed means the same scene everywhere.
struct Pcg32 {
  uint64_t state = 0, inc = 1;
  Pcg32(uint64_t seed, uint64_t stream) {
    inc = (stream << 1u) | 1u;
    next();
    state += seed;
    next();
  }
  uint32_t next() {
    uint64_t old = state;
    state = old * 6364136223846793005ULL + inc;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
  }
  // Uniform in [0, 1): 24 random bits.
  float uniform() { return float(next() >> 8) * (1.0f / 16777216.0f); }
};

// Affine transform: world = M * local + t. `flips` when det(M) < 0 (winding is swapped so the
// geometric normal keeps its meaning). In double: t holds world positions (a shape's corner, a
// light-set site, a JSON translate) that are rounded to float only after the scene origin is
// subtracted (Builder::add_mesh).
struct Transform {
  double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  double3 t;

  double3 apply(double3 p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + t.x,
            m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + t.y,
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + t.z};
  }
  double3 apply(float3 p) const { return apply(dvec(p)); }
  double det() const {
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  }
  bool flips() const { return det() < 0.0; }
  // The cofactor matrix of m, C = det(m) m^-T, and det(m) from the first row of C (for normals
  // and for the inverse).
  double cofactors(double c[3][3]) const;
  // The transformed direction of a surface normal n: the inverse transpose of m applied to n,
  // up to a positive factor (the cofactor matrix, sign-corrected by det), unit length; (0,0,0)
  // if n is zero or not finite, or the result cannot be normalised. In double, so a tiny or huge
  // normal still normalises.
  float3 apply_normal(float3 n) const;
  // this ∘ other: first other, then this.
  Transform then(const Transform& outer) const;
  static Transform translate(double3 d);
  static Transform scale(double3 s);
  static Transform rotate(double3 unit_axis, double degrees);
};

// Adds an image texture to the scene: the value for Material::albedo_texture or alpha_texture
// (1 + its index in Scene::textures).
inline int add_texture(Scene& s, TextureDesc t) {
  s.textures.push_back(std::move(t));
  return int(s.textures.size());
}

// A triangle mesh in local space, before it is placed into the scene.
struct Mesh {
  std::vector<float3> vertices;
  std::vector<uint32_t> indices; // 3 per triangle
  std::vector<int32_t> material; // per triangle
  std::vector<float3> emission;  // per triangle radiance; (0,0,0) = not emissive
  bool two_sided_emission = false;
  // Vertex normals (OBJ vn, local space, as given: not normalised) and, for each triangle, the
  // indices of its three vertices' normals (-1: none). normal_indices is empty for a mesh without
  // normals, else 3 per triangle.
  std::vector<float3> normals;
  std::vector<int32_t> normal_indices;
  // Texture coordinates (OBJ vt, PLY u v, pbrt "uv") and, for each triangle, the indices of its
  // three vertices' uv (-1: none). uv_indices is empty for a mesh without uv, else 3 per triangle.
  std::vector<float2> uvs;
  std::vector<int32_t> uv_indices;

  size_t triangle_count() const { return indices.size() / 3; }
  void add_triangle(uint32_t a, uint32_t b, uint32_t c, int32_t mat, float3 em) {
    indices.insert(indices.end(), {a, b, c});
    material.push_back(mat);
    emission.push_back(em);
  }
};

// Mutable state while a scene is built.
struct Builder {
  Scene& scene;
  std::string file;                               // name used in messages
  std::filesystem::path base_dir;                 // resolves relative file names
  std::map<std::string, int> material_by_name;    // scene materials (from the JSON)
  std::map<std::string, int> mtl_material_by_key; // MTL materials: "<mtl file>\n<name>"
  struct ShapeRange {
    std::string name;
    size_t first_triangle = 0, end_triangle = 0;
  };
  std::vector<ShapeRange> shapes; // one per entry of "shapes", in order

  // Index of the material named by a JSON string value, or an error at that value.
  int material_ref(const JsonValue& v) const;
  // Index of the material `d` of an MTL file (added on first use), unless the scene defines one
  // with the name d.name.
  int mtl_material(const std::string& mtl_file, const MaterialDesc& d);
  // Appends a mesh to the triangle soup (transformed in double, then rebased to the scene origin
  // and rounded) and creates its mesh lights; its vertex normals become shading normals (a
  // triangle with a zero or non-finite normal stays flat). Returns the index of its first
  // triangle.
  size_t add_mesh(const Mesh& mesh, const Transform& xf);
};

// Shapes (shapes.cpp): parses one shape object ("obj", "quad", "box") into a local mesh plus its
// transform. Used for "shapes" entries and for instanced shapes of light sets.
struct ShapeDesc {
  Mesh mesh;
  Transform transform;
  std::string name;
};
ShapeDesc parse_shape(const JsonValue& v, Builder& b);
Transform parse_transform(const JsonValue& v);

// OBJ + MTL (obj_loader.cpp). `at` is the JSON value naming the file (for messages).
// material_override >= 0 replaces every MTL material.
Mesh load_obj(const std::filesystem::path& file, const JsonValue& at, Builder& b,
              int material_override);

// Input guards (input_guard.cpp).
// The whole content of a regular file of at most `max_bytes`; anything else (missing, a
// directory, FIFO, device, socket, too large) is a SceneError "<prefix>cannot open file (...)".
// `prefix` is the message start, e.g. "scene.json: " or "scene.json: shapes[0].file: a.obj: ".
std::string read_input_file(const std::filesystem::path& file, uint64_t max_bytes,
                            const std::string& prefix);
// Empty if every component of p (a float coordinate as the renderer stores it) is within
// kMaxCoordinate, else the problem (for a message), which quotes the world position p + origin.
std::string check_coordinate(float3 p, double3 origin = {});
// Same for the extent of a light (position, corners, or sphere bounds), "its position [...] is
// outside ...".
std::string check_light_extent(const Light& l, double3 origin);

// Empty if every vertex of s.vertices[first_vertex..] is within the coordinate range, else the
// problem with the first one outside, "vertex N after the transform: ..." (N counted from 1).
std::string vertices_problem(const Scene& s, size_t first_vertex);
// Fails at `at` if a vertex of s.vertices[first_vertex..] is outside the coordinate range;
// `what` starts the problem text (e.g. "instance 3: ").
void check_vertices(const Scene& s, size_t first_vertex, const JsonValue& at,
                    std::string_view what);
// True if the light has a non-zero emission.
bool emits(const Light& l);
// Adds a distant light (LIGHT_DISTANT) to scene.infinite_lights, or calls fail (which throws) with
// the reason it cannot be rendered: a medium in the scene, or more than MAX_INFINITE_LIGHTS.
void add_infinite_light(Scene& scene, const Light& l,
                        const std::function<void(const std::string&)>& fail);

// Lights (lights.cpp).
// An analytic light from a JSON object, its positions rebased to `origin` (the scene origin). As a
// template of a light set, position-like keys are offsets from the generated site (`origin` is not
// used) and may be omitted (quad/triangle are then centred on the site).
Light parse_light(const JsonValue& v, bool is_template, double3 origin);
// A JSON "environment" light (docs/scene-format.md): constant `radiance`, or a `map` file (resolved
// against the scene's directory, appended to scene.environment_maps: Light::pad) with `scale`,
// `projection`, and the frame given by `up` and `front`.
Light parse_environment_light(const JsonValue& v, Builder& b);
// The map frame of an environment light (cl/lights/environment.h): pole `up`, the image's centre
// towards `front` (made perpendicular to up); both non-zero, not parallel.
void set_environment_frame(Light& l, double3 up, double3 front);
// Fills n (unit normal, area in w) of a quad/triangle light; false if the area is zero.
bool finish_area_light(Light& l);
// Fills n (unit normal of `normal`, area in w) and the tangent frame e1, e2 of a disk light whose
// p holds centre and radius; false if the normal cannot be normalised or the area is not a
// positive finite float.
bool finish_disk_light(Light& l, float3 normal);
// A spot's cone fields (cl/types.h) from its half-angles in degrees (start <= cone).
void set_spot_cone(Light& l, double cone_deg, double start_deg);
// Light sets (light_sets.cpp): expands one entry of "light_sets".
void expand_light_set(const JsonValue& v, Builder& b);

} // namespace canopy::detail
