// The pbrt-v4 scene reader's private interface (the public one is scene/pbrt_reader.h): the
// graphics state and the Reader that runs a file's directives and builds the canopy::Scene.
//
// pbrt-v4 scene files (https://pbrt.org/fileformat-v4; "the format page" below): tokenizer,
// attribute/transform state, Include/Import, object instances (flattened), the perspective camera,
// film/sampler/integrator settings, triangle/bilinear meshes, PLY meshes (plymesh, read by
// scene/ply_mesh.cpp) with their uv, spheres and disks, point/spot/diffuse area lights,
// diffuse/conductor/coateddiffuse materials, and image textures (imagemap, constant, scale) for
// their reflectance and roughness. Everything else is skipped with a one-line warning naming
// file:line (docs/scene-format.md, "pbrt-v4 scenes"; docs/pbrt-scenes.md, "Image textures"). The
// result is the same canopy::Scene the JSON loader builds: geometry goes through Builder::add_mesh
// (transformed in double, rebased to the camera position, rounded once) and lights through the
// helpers of scene/lights.cpp.
//
// The files of this folder, as pbrt-v4 splits its parser, scene entities and their creation:
//   lexer          tokens, the lexer, source locations and fail()
//   params         parameter lists and their typed getters (spectra as RGB)
//   blackbody      blackbody spectra as linear sRGB
//   transforms     transform arithmetic of the graphics state
//   directives     the reading loop and the directive dispatch: Include/Import, attributes,
//                  object instances, transforms, Film, Sampler, Integrator
//   camera         Camera and the camera frame fixed at WorldBegin
//   meshes         winding, orientation and sphere/disk tessellation of triangle meshes
//   shapes         Shape
//   light_sources  LightSource and AreaLightSource
//   textures       Texture and the texture-valued parameters of materials
//   materials      Material and MakeNamedMaterial
//   media          MakeNamedMedium, MediumInterface and the camera's medium
//   spectrum_file  spectra read from files of (wavelength, value) pairs
//   load           the public entry points (scene/pbrt_reader.h)
#pragma once

#include "scene/loader_internal.h"
#include "scene/pbrt/lexer.h"
#include "scene/pbrt/params.h"
#include "scene/scene.h"

#include <fmt/format.h>

#include <deque>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace canopy::pbrt {

// The scene loader's internals (loader_internal.h: Transform, Mesh, Builder, ...), which the
// reader builds the scene with, as the JSON loader does.
using namespace detail;

constexpr size_t kMaxWarnings = 100; // kept in Scene::warnings; the rest are counted

struct GState {
  Transform ctm; // pbrt's current transformation matrix: object space -> world
  int material = 0;
  bool reverse = false; // ReverseOrientation
  bool area = false;    // an AreaLightSource "diffuse" applies to the shapes
  float3 area_L{0, 0, 0};
  bool area_twosided = false;
  std::string medium_inside, medium_outside; // MediumInterface ("": vacuum)
};

// A MakeNamedMedium (media.cpp): homogeneous ones are rendered.
struct NamedMedium {
  bool homogeneous = false;
  Medium medium{};
  Loc loc;
};

struct ObjectPart {
  Mesh mesh;
  Transform xf; // the shape's CTM at its definition (object -> instance space)
};

// A named pbrt-v4 texture (the format page, "Textures") as far as Canopy can use it: a texture
// the device evaluates (Kind::Image: an image map with its scale folded in, or a checkerboard, mix
// or scale over images and constants), a constant, or a class Canopy cannot render (warned where
// it is defined; a material using it keeps the parameter's constant default).
struct NamedTexture {
  enum class Kind { Image, Constant, Unsupported };
  Kind kind = Kind::Unsupported;
  std::string name;
  TextureDesc desc;               // an image alone: all but channels and map (set by the use)
  std::vector<TextureDesc> tree;  // an operator: its nodes in postfix order (scene.h TextureDesc)
  int stack = 1;                  // the evaluation stack it needs (at most TEXTURE_STACK)
  float3 value{1.0f, 1.0f, 1.0f}; // Constant (a float texture: x = y = z)
};

class Reader {
public:
  Reader(Scene& s, const std::string& name, const std::filesystem::path& base,
         const SceneLoadOptions& o)
      : scene_(s), b_{s, name, base, {}, {}, {}}, opt_(o) {}

  void warn(const Loc& loc, const std::string& msg) {
    std::string line = fmt::format("{}:{}: {}", *loc.file, loc.line, msg);
    if (opt_.strict) throw SceneError(line + " (--strict: warnings are errors)");
    if (scene_.warnings.size() < kMaxWarnings)
      scene_.warnings.push_back(printable(line, 400));
    else
      ++dropped_warnings_;
  }

  void run_file(const std::filesystem::path& file, const std::string& display, const Loc* from);
  void run_text(const std::string& text, const std::string& display,
                const std::filesystem::path& dir);
  void finish();

private:
  void directive(const Token& d, Lexer& lx, const std::filesystem::path& dir);

  // Directive parts.
  std::vector<double> numbers(const Token& d, Lexer& lx, size_t want, bool brackets_ok);
  std::string one_string(const Token& d, Lexer& lx);
  void camera(const Token& d, Params& p, const std::string& type);
  void finish_camera(const Loc& loc);
  // An "integer" parameter in [1, hi] into *out, if given.
  void count_param(Params& p, const char* name, int hi, int* out);
  void shape(const Token& d, Params& p, const std::string& type, const std::filesystem::path& dir);
  void light_source(const Token& d, Params& p, const std::string& type,
                    const std::filesystem::path& base_dir);
  void infinite_light(const Token& d, Params& p, const std::filesystem::path& dir);
  void area_light(const Token& d, Params& p, const std::string& type);
  int material(const Loc& loc, Params& p, const std::string& type, const std::string& name);
  float dielectric_eta(Params& p);
  // A spectrum file named by a "spectrum" parameter, as RGB; nullopt if no such file exists.
  std::optional<float3> spectrum_file(const Loc& loc, const std::string& what,
                                      const std::string& name);
  void make_named_medium(const Token& d, Params& p, const std::string& name);
  void medium_interface(const Token& d, const std::vector<std::string>& names);
  int shape_material(const Loc& loc);
  void finish_media();
  void texture(const Token& d, Params& p, const std::string& name, const std::string& type,
               const std::string& cls, const std::filesystem::path& dir);
  NamedTexture image_texture(const Loc& loc, Params& p, const std::string& name,
                             const std::filesystem::path& dir);
  // The texture a "texture"-typed parameter names (an error if there is no texture of that type
  // by that name, as pbrt-v4), or a constant one for a value given in place: "float" (is_float),
  // else a spectrum (rgb, blackbody or spectrum); nullopt if `name` is not given.
  std::optional<NamedTexture> texture_param(Params& p, std::string_view name, bool is_float);
  // The value for Material::albedo_texture / alpha_texture of an image texture used with
  // `channels` and `map` (one Scene::textures entry per named texture and use).
  int texture_index(const NamedTexture& t, int channels, int map);
  // A texture input of an operator texture or a material: the texture a parameter names or its
  // constant value (`def` where absent).
  NamedTexture texture_input(Params& p, std::string_view name, bool is_float, float3 def);
  // A 2D texture's uv mapping (uscale, vscale, udelta, vdelta); other mappings are warned about.
  float4 uv_mapping(const Loc& loc, Params& p);
  // pbrt-v4's checkerboard, mix and scale textures (textures.cpp).
  NamedTexture operator_texture(const Loc& loc, Params& p, const std::string& name,
                                const std::string& cls, bool is_float);
  // `t` times the constant `k` (a material's "scale"): the same texture where k is 1.
  NamedTexture scaled_texture(const Loc& loc, const NamedTexture& t, float k, bool is_float);
  void add_mesh(const Loc& loc, Mesh& m, const Transform& ctm);
  Transform world(const Transform& ctm) const { return ctm.then(world_fix_); }

  Scene& scene_;
  Builder b_;
  SceneLoadOptions opt_;
  std::deque<std::string> names_;                                  // file names the tokens point at
  std::vector<std::pair<std::string, std::string>> include_stack_; // canonical, display
  GState gs_;
  struct Pushed {
    GState gs;
    Loc loc;
    std::string kind; // "AttributeBegin", "ObjectBegin", "TransformBegin"
  };
  std::vector<Pushed> stack_;
  std::map<std::string, Transform> coord_systems_;
  std::map<std::string, int> named_materials_;
  std::set<int> interface_materials_; // pbrt-v4's "interface": its shapes are not added
  std::map<std::string, NamedMedium> media_;
  std::set<std::string> media_used_;
  std::map<int, int> excluding_materials_; // material -> its copy that excludes the medium
  std::string camera_medium_;              // the outside medium at the Camera directive
  std::string integrator_ = "volpath";     // pbrt-v4's default
  std::filesystem::path dir_;              // the directory of the file being read
  // Named textures: global (not scoped by attributes), one namespace per type (pbrt-v4
  // BasicSceneBuilder::Texture).
  std::map<std::string, NamedTexture> float_textures_, spectrum_textures_;
  std::map<std::string, int> texture_indices_; // "<f|s><channels><map>\n<name>" -> texture_index
  std::map<std::string, std::vector<ObjectPart>> objects_;
  std::vector<ObjectPart>* object_ = nullptr; // inside ObjectBegin
  bool world_block_ = false;
  bool camera_set_ = false;
  Loc camera_loc_;
  Transform camera_from_world_;
  double fov_ = 90.0; // pbrt's default
  Transform world_fix_;
  size_t dropped_warnings_ = 0;
  Loc last_loc_; // the last directive read, for problems found at the end

  friend class Params;

public:
  size_t dropped_warnings() const { return dropped_warnings_; }
};

} // namespace canopy::pbrt
