// The in-memory scene: everything the renderer needs, in world space, already validated.
// Produced by load_scene() (scene_loader.cpp) from the JSON format documented in
// docs/scene-format.md.
#pragma once

#include "light_tree/light_sampler_names.h" // kLightSamplerNames
#include "light_tree/split.h"               // cl/: LT_DEFAULT_SPLIT_THRESHOLD
#include "types.h"                          // cl/types.h: Light, Material (device layouts)

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace canopy {

// Numeric and resource limits of the scene format; docs/limits.md says why each exists.
// Every vertex and light, after transforms and light-set generation, lies in [-kMaxCoordinate,
// kMaxCoordinate]^3: then differences (< 2e18), squared distances (< 1.2e37) and cross products
// of edges stay finite in float, with 10 decades of headroom below FLT_MAX (3.4e38).
inline constexpr float kMaxCoordinate = 1e18f;
inline constexpr uint64_t kMaxSceneFileBytes = uint64_t(256) << 20; // 256 MiB
inline constexpr uint64_t kMaxObjFileBytes = uint64_t(2) << 30;     // 2 GiB
inline constexpr uint64_t kMaxMtlFileBytes = uint64_t(64) << 20;    // 64 MiB
inline constexpr uint64_t kMaxPlyFileBytes = uint64_t(2) << 30;     // 2 GiB, also decompressed
inline constexpr int kMaxPolygonVertices = 1024;                    // vertices of one OBJ face
inline constexpr int kMaxSpp = 1 << 24;
inline constexpr int kMaxFilmSide = 16384;
// tree-split's cap on the lights sampled per shading point: the split queue holds max_cut items per
// path of a wave, so a larger cap means smaller waves (docs/limits.md).
inline constexpr int kDefaultMaxCut = 64;
inline constexpr int kMaxMaxCut = 1 << 16;
inline constexpr int kMaxDepth = 1024; // path vertices after the camera hit
// Conductor eta and k (per channel) and plastic ior ranges of the scene format: they hold every
// measured metal and dielectric in the visible range with a wide margin, and keep the Fresnel
// arithmetic in float far from underflow (eta^2) and overflow (|eta + ik|^4).
inline constexpr float kMinConductorEta = 0.01f;
inline constexpr float kMaxConductorIndex = 1000.0f; // eta and k
inline constexpr float kMaxPlasticIor = 10.0f;
inline constexpr float kDefaultPlasticIor = 1.5f;
// A dielectric's index, inside over outside: below 1 is a bubble (air in water, say).
inline constexpr float kMinDielectricIor = 0.1f, kMaxDielectricIor = 10.0f;
// Coated materials (cl/bsdf/layered.h): the slab's thickness in mean free paths (beyond ~100 it
// is opaque), the walk's depth and samples per evaluation (each costs a walk per shading query).
inline constexpr float kMaxCoatThickness = 1e4f;
inline constexpr int kMaxCoatDepth = 1000, kMaxCoatSamples = 64;
// Largest medium coefficient (per scene unit): sigma * distance stays finite in float over any
// two points of the scene (2e18 * 1e20 < FLT_MAX), so transmittance underflows to 0, never NaN.
inline constexpr float kMaxMediumCoefficient = 1e20f;

// `s` made safe to echo inside a one-line message: control characters (including NUL and C1
// controls), invalid UTF-8 and the Unicode line/paragraph separators become \n, \t, \xHH or
// \uHHHH escapes, and a string longer than `max_chars` code points is cut with an ellipsis.
std::string printable(std::string_view s, size_t max_chars = 100);

// Thrown for any invalid input. what() is the complete one-line message, formatted as
// "<file>: <json path>: <problem>", e.g. "scene.json: lights[3].radius: must be > 0".
// The CLI prints it and exits with code 2. The message is passed through printable() (without a
// length limit), so whatever user text it quotes, it stays one line.
class SceneError : public std::runtime_error {
public:
  explicit SceneError(const std::string& message)
      : std::runtime_error(printable(message, std::string::npos)) {}
};

// A point or vector in double precision: scene coordinates before they are rebased to the scene
// origin and rounded to float (Scene::origin).
struct double3 {
  double x = 0, y = 0, z = 0;
};

struct Camera {
  float3 position{0, 0, 0};
  float3 look_at{0, 0, -1};
  float3 up{0, 1, 0};
  float fov_y_deg = 45.0f; // vertical field of view, degrees, in (0, 180)
};

struct FilmSettings {
  int width = 640;  // pixels, 1 .. kMaxFilmSide
  int height = 480; // pixels, 1 .. kMaxFilmSide
  // The scene's own output image (pbrt's Film "filename"), the default of `canopy render --out`;
  // empty: out/<scene>.exr.
  std::string output;
  // Every pixel is multiplied by this before it is written (pbrt's Film "scale" x iso / 100).
  float image_scale = 1.0f;
};

// The film at `scale` times its resolution (a preview, or the scaled films of docs/results.md):
// each side rounded, at least 1 pixel. The camera keeps its field of view.
inline void scale_film(FilmSettings& f, double scale) {
  f.width = std::max(1, int(std::lround(f.width * scale)));
  f.height = std::max(1, int(std::lround(f.height * scale)));
}

// Defaults show the renderer at its best: "auto", a pilot render that picks power, tree or brdf-mis
// (with splitting at the measured threshold) per scene (render/auto_sampler.h), within 10% of the
// best configuration on every shipped scene in docs/results.md ("The default estimator"), and
// paths of pbrt-v4's default depth.
struct IntegratorSettings {
  int spp = 16;      // samples per pixel, 1 .. kMaxSpp
  int max_depth = 5; // path vertices that sample lights (pbrt-v4's maxdepth): 1 = direct light
  std::string light_sampler = "auto";                 // "auto" or a name of kLightSamplerNames
  float split_threshold = LT_DEFAULT_SPLIT_THRESHOLD; // adaptive splitting threshold in [0, 1]
  int max_cut = kDefaultMaxCut; // tree-split: at most this many lights per shading point
  uint32_t seed = 1;
  // MIS (power heuristic) between light and BSDF sampling; false: light sampling alone counts
  // emission from non-delta bounces (the ablation of docs/results.md).
  bool mis = true;
  // brdf-mis / brdf-oriented (Liu et al. 2019; render/light_sampler_data.h BrdfSettings): the
  // cut's split threshold on S_C, N_max, lambda, and adaptive allocation (false: equal).
  float brdf_delta = 0.5f;
  int brdf_n_max = 50;
  float brdf_lambda = 10.0f;
  bool brdf_adaptive = true;
  // With a medium: "segment" (Conty Estevez & Kulla Eq. 7) or "midpoint" (the surface importance
  // at the segment's midpoint, an ablation) ranks light clusters for a ray segment.
  std::string volume_importance = "segment";
};
// Largest brdf_n_max: it bounds the BRDF-aware samples of one shading point (and the rounds of
// kernels per bounce, log2 of it).
inline constexpr int kMaxBrdfSamples = 1024;

// Whether a material reads a texture (cl/texture.h): its albedo, roughness or transmittance, or a
// mix's amount. The kernels then need the triangles' uv and HAS_TEXTURES.
inline bool material_textured(const Material& m) {
  return m.albedo_texture > 0 || m.alpha_texture > 0 || m.transmittance_texture > 0 ||
         m.mix_amount_texture > 0;
}

struct MaterialDesc {
  std::string name;
  Material gpu; // device record: type + albedo
};

// A diffuse (Lambertian) material with reflectance `albedo` per RGB channel.
inline MaterialDesc diffuse_material(std::string name, float3 albedo) {
  MaterialDesc d;
  d.name = std::move(name);
  d.gpu = Material{};
  d.gpu.albedo = make_float4(albedo.x, albedo.y, albedo.z, 0.0f);
  d.gpu.type = MATERIAL_DIFFUSE;
  return d;
}

// A conductor: GGX with alpha = roughness^2 (0: a perfect mirror) and the Fresnel reflectance of
// the complex index eta + i k per RGB channel (cl/types.h keeps eta in `specular`).
inline MaterialDesc conductor_material(std::string name, float roughness, float3 eta, float3 k) {
  MaterialDesc d;
  d.name = std::move(name);
  d.gpu = Material{};
  d.gpu.specular = make_float4(eta.x, eta.y, eta.z, 0.0f);
  d.gpu.k = make_float4(k.x, k.y, k.z, 0.0f);
  d.gpu.alpha = roughness * roughness;
  d.gpu.type = MATERIAL_CONDUCTOR;
  return d;
}

// pbrt-v3's plastic: albedo / pi plus specular * a GGX lobe (alpha = roughness^2) with the
// dielectric Fresnel reflectance of index `ior`.
inline MaterialDesc plastic_material(std::string name, float3 albedo, float3 specular,
                                     float roughness, float ior) {
  MaterialDesc d;
  d.name = std::move(name);
  d.gpu = Material{};
  d.gpu.albedo = make_float4(albedo.x, albedo.y, albedo.z, 0.0f);
  d.gpu.specular = make_float4(specular.x, specular.y, specular.z, 0.0f);
  d.gpu.alpha = roughness * roughness;
  d.gpu.ior = ior;
  d.gpu.type = MATERIAL_PLASTIC;
  return d;
}

// Glass of index `ior` (inside over outside; cl/bsdf/dielectric.h), smooth or rough (GGX alpha
// `alpha`, e.g. pbrt-v4's remapped roughness; 0: smooth), or a thin sheet of it (always smooth).
inline MaterialDesc dielectric_material(std::string name, float ior, bool thin,
                                        float alpha = 0.0f) {
  MaterialDesc d;
  d.name = std::move(name);
  d.gpu = Material{};
  d.gpu.ior = ior;
  d.gpu.alpha = thin ? 0.0f : alpha;
  d.gpu.type = thin ? MATERIAL_THIN_DIELECTRIC : MATERIAL_DIELECTRIC;
  return d;
}

// The slab between the coat and the base of a coated material (cl/bsdf/layered.h) and the limits
// of its random walk; the defaults are pbrt-v4's.
struct CoatLayer {
  float thickness = 0.01f;   // in mean free paths: the medium's extinction is 1 per unit
  float3 albedo = {0, 0, 0}; // the medium's scattering albedo rgb; 0: it only absorbs
  float g = 0.0f;            // its Henyey-Greenstein asymmetry, in (-1, 1)
  int max_depth = 10;        // bounces of a walk at most
  int n_samples = 1;         // walks per evaluation of f and of the pdf
};

inline void set_coat_layer(Material& m, const CoatLayer& layer) {
  m.medium = make_float4(layer.albedo.x, layer.albedo.y, layer.albedo.z, layer.g);
  m.thickness = layer.thickness;
  m.max_depth = layer.max_depth;
  m.n_samples = layer.n_samples;
}

// pbrt-v4's coateddiffuse: a dielectric coat of index `eta` and GGX alpha `alpha` (0: smooth; the
// caller remaps pbrt's roughness) over a Lambertian base of reflectance `reflectance`.
inline MaterialDesc coated_diffuse_material(std::string name, float3 reflectance, float alpha,
                                            float eta, const CoatLayer& layer = {}) {
  MaterialDesc d;
  d.name = std::move(name);
  d.gpu = Material{};
  d.gpu.albedo = make_float4(reflectance.x, reflectance.y, reflectance.z, 0.0f);
  d.gpu.alpha = alpha;
  d.gpu.ior = eta;
  d.gpu.type = MATERIAL_COATED_DIFFUSE;
  set_coat_layer(d.gpu, layer);
  return d;
}

// pbrt-v4's coatedconductor: a dielectric coat (index `eta`, GGX alpha `alpha`) over a conductor
// of complex index conductor_eta + i conductor_k (its index in vacuum, per RGB channel: the BSDF
// divides it by the coat's, as pbrt-v4's material does) and GGX alpha `conductor_alpha`.
inline MaterialDesc coated_conductor_material(std::string name, float alpha, float eta,
                                              float3 conductor_eta, float3 conductor_k,
                                              float conductor_alpha, const CoatLayer& layer = {}) {
  MaterialDesc d;
  d.name = std::move(name);
  d.gpu = Material{};
  d.gpu.alpha = alpha;
  d.gpu.ior = eta;
  d.gpu.specular = make_float4(conductor_eta.x, conductor_eta.y, conductor_eta.z, 0.0f);
  d.gpu.k = make_float4(conductor_k.x, conductor_k.y, conductor_k.z, 0.0f);
  d.gpu.base_alpha = conductor_alpha;
  d.gpu.type = MATERIAL_COATED_CONDUCTOR;
  set_coat_layer(d.gpu, layer);
  return d;
}

// pbrt-v4's diffusetransmission: reflectance / pi on the viewer's side of the surface and
// transmittance / pi on the other (each rgb in [0, 1]; cl/bsdf/diffuse_transmission.h).
inline MaterialDesc diffuse_transmission_material(std::string name, float3 reflectance,
                                                  float3 transmittance) {
  MaterialDesc d;
  d.name = std::move(name);
  d.gpu = Material{};
  d.gpu.albedo = make_float4(reflectance.x, reflectance.y, reflectance.z, 0.0f);
  d.gpu.specular = make_float4(transmittance.x, transmittance.y, transmittance.z, 0.0f);
  d.gpu.type = MATERIAL_DIFFUSE_TRANSMISSION;
  return d;
}
// pbrt-v4's mix: material `second` (an index into Scene::materials) with probability `amount` at
// each shading point, else `first` (cl/material_mix.h).
inline MaterialDesc mix_material(std::string name, int first, int second, float amount) {
  MaterialDesc d;
  d.name = std::move(name);
  d.gpu = Material{};
  d.gpu.type = MATERIAL_MIX;
  d.gpu.mix_material[0] = first;
  d.gpu.mix_material[1] = second;
  d.gpu.mix_amount = amount;
  return d;
}
// How many mixes deep material `index` of `materials` nests (0: not a mix). The loaders refuse a
// mix deeper than MATERIAL_MIX_MAX_DEPTH (the device resolves that many levels).
template <class Materials> int mix_depth(const Materials& materials, int index) {
  const Material& m = materials[size_t(index)].gpu;
  if (m.type != MATERIAL_MIX) return 0;
  return 1 +
         std::max(mix_depth(materials, m.mix_material[0]), mix_depth(materials, m.mix_material[1]));
}

// An environment light's radiance map (cl/lights/environment.h): the image file, read by the
// renderer (host/render/environment_map.h), and its projection (ENV_EQUIRECT, ENV_OCTAHEDRAL).
struct EnvironmentMap {
  std::filesystem::path file;
  int projection = 0;
  // Names it in messages: "<scene file>: <light's JSON path>" or "<file>:<line>: LightSource ...".
  std::string where;
};

// How an image's stored values become linear ones (pbrt-v4's "encoding" of image textures).
// Auto: integer formats (PNG, JPEG, TGA, ...) are sRGB-decoded, float formats (EXR, HDR) taken
// as they are.
enum class ImageEncoding { Auto, Linear, Srgb, Gamma };

// A node of a material's texture (cl/types.h Texture, cl/texture.h): an image (its file, read by
// the renderer, host/render/texture_data.h, and how its values are looked up), a constant, or
// pbrt-v4's checkerboard, mix or scale of the nodes before it. A texture is a tree of nodes in
// postfix order in Scene::textures, each node after its inputs' subtrees (`nodes` records in all,
// ending at the node). A material refers to its root by Material::albedo_texture, alpha_texture,
// transmittance_texture or mix_amount_texture (1 + the root's index in Scene::textures).
struct TextureDesc {
  int kind = TEXTURE_IMAGE;   // TEXTURE_*
  int nodes = 1;              // this node and its inputs' subtrees
  std::filesystem::path file; // an image
  std::string where; // names it in messages: "<scene file>: texture '<name>'" or "<file>:<line>"
  int channels = 3;  // 3: rgb (albedo); 1: the mean of the image's colour channels (roughness)
  ImageEncoding encoding = ImageEncoding::Auto;
  float gamma = 1.0f;       // ImageEncoding::Gamma: linear = stored^gamma
  float3 scale{1, 1, 1};    // image: multiplies the filtered value (a float texture uses x);
                            // constant: the value
  float4 uvmap{1, 1, 0, 0}; // image, checkerboard: (s, t) = (x u + z, y v + w)
  int wrap = TEXTURE_WRAP_REPEAT;
  int map = TEXTURE_MAP_VALUE; // TEXTURE_MAP_*: how a float texture's value becomes GGX alpha
};

// All geometry flattened into one world-space triangle soup. Emissive mesh triangles (OBJ/MTL Ke
// or an emission given in the scene) have a TRIANGLE light with LIGHT_FLAG_FROM_MESH and
// triangle_light[i] pointing at it. Analytic area lights (sphere, quad, triangle) are NOT in this
// soup: the accel builder adds their primitives from `lights`.
struct Scene {
  std::filesystem::path path; // the scene file, for messages
  // Every float coordinate below (camera, vertices, lights, medium bounds) is relative to this
  // point: world = coordinate + origin. load_scene sets it to the camera position and subtracts it
  // from each input coordinate in double before rounding to float, so a scene far from (0, 0, 0)
  // keeps its shape (docs/design.md, Robustness). Scenes built in code may leave it at 0.
  double3 origin;
  Camera camera;
  FilmSettings film;
  IntegratorSettings integrator;
  std::vector<MaterialDesc> materials; // at least one; index 0 is the default
  std::vector<float3> vertices;
  std::vector<uint32_t> indices;          // 3 per triangle
  std::vector<int32_t> triangle_material; // per triangle
  std::vector<int32_t> triangle_light;    // per triangle, -1 if not emissive
  // Shading normals (OBJ vn): the unit world-space normals at the three vertices of each smooth
  // triangle, in the triangle's vertex order; triangle_normals[t] is the index of triangle t's
  // first one, or -1 for a flat triangle. triangle_normals is empty while every triangle is flat.
  std::vector<float3> shading_normals;
  std::vector<int32_t> triangle_normals;
  // Texture coordinates: the uv at the three vertices of every triangle (in its vertex order),
  // once any mesh has them; empty while none has. A triangle given without uv has pbrt-v4's
  // default (0, 0), (1, 0), (1, 1).
  std::vector<float2> triangle_uvs;
  std::vector<TextureDesc> textures; // the materials' textures: trees of nodes (TextureDesc)
  std::vector<Light> lights;         // only lights that emit (zero-emission lights are skipped)
  // Lights at infinity (LIGHT_DISTANT, LIGHT_ENVIRONMENT; at most MAX_INFINITE_LIGHTS): apart from
  // `lights`, which the light samplers and the tree cover; every shading point samples each of
  // them. An environment light with a map has its index in environment_maps in Light::pad (-1:
  // constant); the renderer loads the map.
  std::vector<Light> infinite_lights;
  std::vector<EnvironmentMap> environment_maps;
  // A homogeneous participating medium (the scene's "medium"; cl/types.h Medium), if any.
  bool has_medium = false;
  Medium medium{};
  size_t skipped_lights = 0; // lights given with zero emission, not in `lights`
  // Input the loader read but could not map exactly (a pbrt-v4 construct Canopy lacks, an unknown
  // parameter), one line each, "<file>:<line>: ... ignored". The JSON loader never warns (it
  // refuses instead); the CLI prints these on stderr.
  std::vector<std::string> warnings;

  size_t triangle_count() const { return indices.size() / 3; }
};

struct SceneLoadOptions {
  bool strict = false; // every warning is a SceneError instead (canopy render --strict)
};

// Loads and validates a scene file: a file ending in .pbrt is read as a pbrt-v4 scene
// (pbrt_reader.h), anything else as JSON. Relative paths inside (OBJ files, pbrt Includes) are
// resolved against the including file's directory. Throws SceneError on any invalid input.
Scene load_scene(const std::filesystem::path& file, const SceneLoadOptions& options = {});

// Same, from a JSON string; `name` is used in messages and `base_dir` resolves relative paths.
Scene load_scene_from_string(const std::string& json_text, const std::string& name,
                             const std::filesystem::path& base_dir);

} // namespace canopy
