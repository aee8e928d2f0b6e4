// pbrt-v4 scene files (https://pbrt.org/fileformat-v4; "the format page" below): tokenizer,
// attribute/transform state, Include/Import, object instances (flattened), the perspective camera,
// film/sampler/integrator settings, triangle/bilinear meshes, PLY meshes (plymesh, read by
// ply_mesh.cpp) with their uv, spheres and disks, point/spot/diffuse area lights,
// diffuse/conductor/coateddiffuse materials, and image textures (imagemap, constant, scale) for
// their reflectance and roughness. Everything else is skipped with a one-line warning naming
// file:line (docs/scene-format.md, "pbrt-v4 scenes"; docs/pbrt-scenes.md, "Image textures"). The
// result is the same canopy::Scene the JSON loader builds: geometry goes through Builder::add_mesh
// (transformed in double, rebased to the camera position, rounded once) and lights through the
// helpers of lights.cpp.
#include "scene/pbrt_reader.h"

#include "scene/loader_internal.h"
#include "scene/metal_presets.h"
#include "scene/ply_mesh.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <vector>

namespace canopy {

// ------------------------------------------------------------------------------------ blackbody

namespace {

// CIE 1931 2-degree colour matching functions, the multi-lobe piecewise-Gaussian fit of C. Wyman,
// P.-P. Sloan and P. Shirley, "Simple Analytic Approximations to the CIE XYZ Color Matching
// Functions", JCGT 2(2), 2013, Eq. 2-4 (within a few percent of the tabulated functions, far
// below what three RGB channels keep of a spectrum).
double lobe(double l, double mu, double s1, double s2) {
  double t = (l - mu) / (l < mu ? s1 : s2);
  return std::exp(-0.5 * t * t);
}
double cie_x(double l) {
  return 1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) -
         0.065 * lobe(l, 501.1, 20.4, 26.2);
}
double cie_y(double l) {
  return 0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1);
}
double cie_z(double l) {
  return 1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8);
}

// Planck's law (pbrt-v4 Blackbody()), spectral radiance at wavelength `nm`.
double planck(double nm, double kelvin) {
  const double c = 299792458.0, h = 6.62606957e-34, kb = 1.3806488e-23;
  double l = nm * 1e-9;
  double e = std::expm1((h * c) / (l * kb * kelvin));
  if (!std::isfinite(e)) return 0.0;
  return (2.0 * h * c * c) / (std::pow(l, 5) * e);
}

} // namespace

float3 blackbody_rgb(double kelvin) {
  // pbrt-v4 BlackbodySpectrum: B(lambda, T) / B(lambda_max, T), Wien's displacement law giving
  // lambda_max; XYZ as pbrt's SpectrumToXYZ (1 nm steps over 360..830 nm, divided by the y-bar
  // integral), then XYZ -> linear sRGB (IEC 61966-2-1 matrix).
  if (!(kelvin > 0.0) || !std::isfinite(kelvin)) return make_float3(0, 0, 0);
  double peak = planck(2.8977721e-3 / kelvin * 1e9, kelvin);
  if (!(peak > 0.0) || !std::isfinite(peak)) return make_float3(0, 0, 0);
  double X = 0, Y = 0, Z = 0, yint = 0;
  for (int nm = 360; nm <= 830; ++nm) {
    double l = double(nm), b = planck(l, kelvin) / peak;
    X += cie_x(l) * b;
    Y += cie_y(l) * b;
    Z += cie_z(l) * b;
    yint += cie_y(l);
  }
  X /= yint;
  Y /= yint;
  Z /= yint;
  double r = 3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z;
  double g = -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z;
  double bl = 0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z;
  return make_float3(float(std::max(r, 0.0)), float(std::max(g, 0.0)), float(std::max(bl, 0.0)));
}

namespace {

using namespace detail;

constexpr int kMaxIncludeDepth = 64;
constexpr size_t kMaxWarnings = 100; // kept in Scene::warnings; the rest are counted
// Flattened instances copy triangles: a few directives could ask for 10^12 of them. The cap keeps
// memory to a few GiB and turns such a file into an error instead of an out-of-memory kill.
constexpr size_t kMaxTriangles = size_t(1) << 27;
// Tessellation of spheres and disks that are not analytic lights (Canopy has no analytic
// sphere/disk primitive apart from its lights): smooth shading normals hide the facets.
constexpr int kSphereRings = 24, kSphereSegments = 48, kDiskSegments = 64;

// --------------------------------------------------------------------------------- tokenizer

struct Loc {
  const std::string* file = nullptr;
  int line = 0;
};

[[noreturn]] void fail(const Loc& loc, std::string_view msg) {
  throw SceneError(fmt::format("{}:{}: {}", *loc.file, loc.line, msg));
}

enum class Tok { String, Number, LBracket, RBracket, Ident };

struct Token {
  Tok kind;
  std::string text; // string content, identifier, or the number as written
  double num = 0.0;
  Loc loc;
};

bool is_bool_ident(const Token& t) {
  return t.kind == Tok::Ident && (t.text == "true" || t.text == "false");
}

// The format page, "Basic structure": '#' starts a comment to the end of the line; strings are
// double-quoted on one line; numbers, brackets and bare identifiers (directives, true/false)
// are separated by white space. Tokens are made one at a time as the reader asks for them, so a
// mesh of N numbers costs N doubles, not N tokens.
class Lexer {
public:
  Lexer(const std::string& text, const std::string* file) : text_(text), file_(file) {}
  // The next token, or nullptr at the end of the text.
  const Token* peek() {
    if (!has_) has_ = lex(tok_);
    return has_ ? &tok_ : nullptr;
  }
  // Consumes and returns the next token; the caller has checked peek().
  Token next() {
    peek();
    has_ = false;
    return std::move(tok_);
  }
  // True at the end of the text or at the next directive (an identifier other than true/false).
  bool at_directive() {
    const Token* t = peek();
    return !t || (t->kind == Tok::Ident && !is_bool_ident(*t));
  }
  Loc here() const { return {file_, line_}; }

private:
  bool lex(Token& out);

  const std::string& text_;
  const std::string* file_;
  size_t i_ = 0;
  int line_ = 1;
  Token tok_{Tok::Ident, {}, 0.0, {}};
  bool has_ = false;
};

bool Lexer::lex(Token& out) {
  const std::string& text = text_;
  size_t& i = i_;
  const size_t n = text.size();
  auto delim = [](char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '[' || c == ']' || c == '"' ||
           c == '#';
  };
  while (i < n) {
    char c = text[i];
    const Loc loc{file_, line_};
    if (c == '\n') {
      ++line_;
      ++i;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
      ++i;
    } else if (c == '#') {
      while (i < n && text[i] != '\n')
        ++i;
    } else if (c == '[' || c == ']') {
      out = {c == '[' ? Tok::LBracket : Tok::RBracket, std::string(1, c), 0.0, loc};
      ++i;
      return true;
    } else if (c == '"') {
      out = {Tok::String, {}, 0.0, loc};
      ++i;
      bool closed = false;
      while (i < n) {
        char d = text[i++];
        if (d == '"') {
          closed = true;
          break;
        }
        if (d == '\n') break;
        if (d == '\\' && i < n && text[i] != '\n') {
          char e = text[i++];
          d = e == 'n' ? '\n' : e == 't' ? '\t' : e == 'r' ? '\r' : e == 'b' ? '\b' : e;
        }
        out.text.push_back(d);
      }
      if (!closed) fail(loc, "unterminated string");
      return true;
    } else if ((c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.') {
      size_t j = i;
      while (j < n && !delim(text[j]))
        ++j;
      out = {Tok::Number, text.substr(i, j - i), 0.0, loc};
      std::string_view sv(out.text);
      if (!sv.empty() && sv[0] == '+') sv.remove_prefix(1);
      double v = 0.0;
      auto r = std::from_chars(sv.data(), sv.data() + sv.size(), v);
      if (sv.empty() || r.ec != std::errc() || r.ptr != sv.data() + sv.size())
        fail(loc, fmt::format("bad number '{}'", printable(out.text)));
      if (!std::isfinite(v)) fail(loc, fmt::format("number '{}' is not finite", out.text));
      out.num = v;
      i = j;
      return true;
    } else if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_') {
      size_t j = i;
      while (j < n && (std::isalnum(static_cast<unsigned char>(text[j])) || text[j] == '_'))
        ++j;
      out = {Tok::Ident, text.substr(i, j - i), 0.0, loc};
      i = j;
      return true;
    } else {
      fail(loc, fmt::format("unexpected character '{}'", printable(text.substr(i, 1))));
    }
  }
  return false;
}

std::string describe(const Token& t) {
  switch (t.kind) {
  case Tok::String:
    return fmt::format("\"{}\"", printable(t.text, 40));
  case Tok::Number:
    return t.text;
  case Tok::LBracket:
    return "[";
  case Tok::RBracket:
    return "]";
  default:
    return printable(t.text, 40);
  }
}

// -------------------------------------------------------------------------------- parameters

// One "type name" value list of a directive (the format page, "Parameter lists").
struct Param {
  std::string type, name;
  Loc loc;
  std::vector<double> nums;
  std::vector<std::string> strs; // string, texture, bool and named-spectrum values
  bool used = false;
};

bool is_numeric_type(const std::string& t) {
  static const std::set<std::string> k = {"integer", "float",   "point2",  "vector2",
                                          "point3",  "vector3", "normal3", "normal",
                                          "point",   "vector",  "rgb",     "blackbody"};
  return k.count(t) > 0;
}

// Reads the parameter list up to the next directive; checks each value against its declared
// type.
std::vector<Param> parse_params(Lexer& lx) {
  std::vector<Param> ps;
  while (!lx.at_directive()) {
    const Token d = lx.next();
    if (d.kind != Tok::String)
      fail(d.loc, fmt::format("expected a parameter \"type name\", got {}", describe(d)));
    Param p;
    p.loc = d.loc;
    {
      size_t s0 = d.text.find_first_not_of(" \t");
      size_t s1 = s0 == std::string::npos ? s0 : d.text.find_first_of(" \t", s0);
      size_t s2 = s1 == std::string::npos ? s1 : d.text.find_first_not_of(" \t", s1);
      size_t s3 = s2 == std::string::npos ? s2 : d.text.find_first_of(" \t", s2);
      if (s2 == std::string::npos ||
          (s3 != std::string::npos && d.text.find_first_not_of(" \t", s3) != std::string::npos))
        fail(d.loc, fmt::format("expected a parameter \"type name\", got {}", describe(d)));
      p.type = d.text.substr(s0, s1 - s0);
      p.name = d.text.substr(s2, s3 == std::string::npos ? std::string::npos : s3 - s2);
    }
    static const std::set<std::string> types = {
        "integer", "float",  "point2", "vector2",   "point3",   "vector3", "normal3", "normal",
        "point",   "vector", "rgb",    "blackbody", "spectrum", "bool",    "string",  "texture"};
    if (!types.count(p.type))
      fail(d.loc, fmt::format("\"{} {}\": unknown parameter type '{}'", printable(p.type),
                              printable(p.name), printable(p.type)));
    for (const Param& q : ps)
      if (q.name == p.name)
        fail(d.loc, fmt::format("parameter '{}' given twice", printable(p.name)));
    const std::string pn = fmt::format("\"{} {}\"", p.type, printable(p.name));
    // The kind of the values (numbers or strings) is set by the type, and for "spectrum" by the
    // first value (wavelength-value pairs or a named spectrum).
    int numeric = is_numeric_type(p.type) ? 1 : p.type == "spectrum" ? -1 : 0;
    auto take = [&](const Token& v) {
      if (numeric < 0) numeric = v.kind == Tok::Number ? 1 : 0;
      if (numeric) {
        if (v.kind != Tok::Number)
          fail(v.loc, fmt::format("{}: expected a number, got {}", pn, describe(v)));
        if (p.type == "integer" && (v.num != std::floor(v.num) || std::fabs(v.num) > 2147483647.0))
          fail(v.loc, fmt::format("{}: '{}' is not an integer", pn, v.text));
        p.nums.push_back(v.num);
      } else if (p.type == "bool") {
        if (!(v.kind == Tok::String || is_bool_ident(v)) || (v.text != "true" && v.text != "false"))
          fail(v.loc, fmt::format("{}: expected true or false, got {}", pn, describe(v)));
        p.strs.push_back(v.text);
      } else {
        if (v.kind != Tok::String)
          fail(v.loc, fmt::format("{}: expected a quoted string, got {}", pn, describe(v)));
        p.strs.push_back(v.text);
      }
    };
    if (lx.at_directive())
      fail(d.loc, fmt::format("parameter '{}' has no value", printable(p.name)));
    if (lx.peek()->kind == Tok::LBracket) {
      lx.next();
      while (true) {
        if (lx.at_directive()) fail(d.loc, fmt::format("{}: '[' without ']'", pn));
        Token v = lx.next();
        if (v.kind == Tok::RBracket) break;
        if (v.kind == Tok::LBracket) fail(v.loc, "'[' inside a value list");
        take(v);
      }
    } else if (lx.peek()->kind == Tok::RBracket) {
      fail(lx.peek()->loc, "']' without '['");
    } else {
      take(lx.next());
    }
    size_t cnt = numeric ? p.nums.size() : p.strs.size();
    if (cnt == 0) fail(d.loc, fmt::format("{}: no values", pn));
    auto want = [&](bool ok, std::string_view what) {
      if (!ok) fail(d.loc, fmt::format("{}: wrong count of values ({}; {})", pn, cnt, what));
    };
    if (p.type == "rgb") want(cnt == 3, "want 3");
    if (p.type == "blackbody") want(cnt == 1, "want 1 temperature");
    if (p.type == "point2" || p.type == "vector2") want(cnt % 2 == 0, "want pairs");
    if (p.type == "point3" || p.type == "vector3" || p.type == "normal3" || p.type == "normal" ||
        p.type == "point" || p.type == "vector")
      want(cnt % 3 == 0, "want triples");
    if (p.type == "spectrum")
      want(numeric ? cnt % 2 == 0 : cnt == 1, numeric ? "want wavelength-value pairs" : "want 1");
    if (p.type == "bool") want(cnt == 1, "want 1");
    ps.push_back(std::move(p));
  }
  return ps;
}

class Reader;

// A directive's parameters with typed getters. A parameter read with the wrong type is an error;
// one never read is reported by finish() as an unknown parameter.
class Params {
public:
  Params(Reader& r, std::vector<Param> ps, std::string what)
      : r_(r), ps_(std::move(ps)), what_(std::move(what)) {}
  const std::string& what() const { return what_; }

  Param* find(std::string_view name) {
    for (Param& p : ps_)
      if (p.name == name) {
        p.used = true;
        return &p;
      }
    return nullptr;
  }
  [[noreturn]] void wrong_type(const Param& p, std::string_view want) const {
    fail(p.loc, fmt::format("{}: \"{} {}\": wrong parameter type (want {})", what_, p.type,
                            printable(p.name), want));
  }
  // The parameter `name` if given, checked to hold one value of one of `types`; else nullptr.
  Param* one(std::string_view name, std::initializer_list<std::string_view> types) {
    Param* p = find(name);
    if (!p) return nullptr;
    bool ok = false;
    for (auto t : types)
      ok = ok || p->type == t;
    if (!ok) wrong_type(*p, *types.begin());
    size_t cnt = p->nums.empty() ? p->strs.size() : p->nums.size();
    if (cnt != 1)
      fail(p->loc, fmt::format("{}: \"{} {}\": wrong count of values ({}; want 1)", what_, p->type,
                               printable(p->name), cnt));
    return p;
  }
  double get_float(std::string_view name, double def);
  bool get_bool(std::string_view name, bool def) {
    Param* p = one(name, {"bool"});
    return p ? p->strs[0] == "true" : def;
  }
  std::optional<std::string> get_string(std::string_view name) {
    Param* p = one(name, {"string"});
    if (!p) return std::nullopt;
    return p->strs[0];
  }
  // The numbers of `name`, checked to be of one of `types`; nullptr if absent.
  const std::vector<double>* get_nums(std::string_view name,
                                      std::initializer_list<std::string_view> types) {
    Param* p = find(name);
    if (!p) return nullptr;
    bool ok = false;
    for (auto t : types)
      ok = ok || p->type == t;
    if (!ok) wrong_type(*p, *types.begin());
    return &p->nums;
  }
  std::optional<double3> get_point(std::string_view name) {
    const auto* v = get_nums(name, {"point3", "point"});
    if (!v) return std::nullopt;
    if (v->size() != 3)
      fail(find(name)->loc,
           fmt::format("{}: \"{}\": wrong count of values ({}; want 3)", what_, name, v->size()));
    return double3{(*v)[0], (*v)[1], (*v)[2]};
  }
  // Illuminant: the spectrum of a light, normalised as pbrt-v4 does; Reflectance: any other value
  // (reflectances, conductor indices), used as it is.
  enum class Use { Reflectance, Illuminant };
  // A spectrum-valued parameter as RGB (the format page, "Spectra"); nullopt if absent or not
  // read (a texture or a named spectrum: warned, the caller's default applies). A named spectrum
  // the caller handles itself (metal-*) is returned in `named`.
  std::optional<float3> spectrum(std::string_view name, Use use, std::string* named = nullptr);
  // Unknown parameters: one warning each.
  void finish();
  // Marks every parameter read (a directive skipped as a whole warns once, not per parameter).
  void mark_all_used() {
    for (Param& p : ps_)
      p.used = true;
  }

private:
  Reader& r_;
  std::vector<Param> ps_;
  std::string what_;
};

// ------------------------------------------------------------------------------------- reader

struct GState {
  Transform ctm; // pbrt's current transformation matrix: object space -> world
  int material = 0;
  bool reverse = false; // ReverseOrientation
  bool area = false;    // an AreaLightSource "diffuse" applies to the shapes
  float3 area_L{0, 0, 0};
  bool area_twosided = false;
};

struct ObjectPart {
  Mesh mesh;
  Transform xf; // the shape's CTM at its definition (object -> instance space)
};

// A named pbrt-v4 texture (the format page, "Textures") as far as Canopy can use it: an image map
// (with its scale folded in), a constant, or a class Canopy cannot render (warned where it is
// defined; a material using it keeps the parameter's constant default).
struct NamedTexture {
  enum class Kind { Image, Constant, Unsupported };
  Kind kind = Kind::Unsupported;
  std::string name;
  TextureDesc desc;               // Image: all but channels and map, which depend on the use
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

std::optional<float3> Params::spectrum(std::string_view name, Use use, std::string* named) {
  Param* p = find(name);
  if (!p) return std::nullopt;
  const std::string pn = fmt::format("{}: \"{} {}\"", what_, p->type, printable(p->name));
  if (p->type == "rgb") {
    float3 c = to_float3({p->nums[0], p->nums[1], p->nums[2]});
    if (!(c.x >= 0.0f && c.y >= 0.0f && c.z >= 0.0f))
      fail(p->loc, fmt::format("{}: must be >= 0", pn));
    if (!std::isfinite(c.x + c.y + c.z)) fail(p->loc, fmt::format("{}: is too large", pn));
    return c;
  }
  if (p->type == "blackbody") {
    double t = p->nums[0];
    if (!(t > 0.0)) fail(p->loc, fmt::format("{}: the temperature must be > 0", pn));
    float3 c = blackbody_rgb(t);
    if (use == Use::Illuminant) {
      // pbrt-v4 divides every light's scale by SpectrumToPhotometric(spectrum) ("scale so that
      // radiance is equivalent to 1 nit", lights.cpp): a blackbody emitter has luminance 1. An
      // "rgb" emitter is divided by its illuminant's (the colour space's white) luminance only,
      // so its RGB passes through unchanged.
      float y = 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
      c = y > 0.0f ? c * (1.0f / y) : make_float3(0, 0, 0);
    }
    return c;
  }
  if (p->type == "spectrum") {
    if (named && !p->strs.empty()) {
      *named = p->strs[0];
      return std::nullopt;
    }
    r_.warn(p->loc,
            fmt::format("{}: spectra are not read in this slice (white used), ignored", pn));
    return make_float3(1, 1, 1);
  }
  if (p->type == "texture") {
    r_.warn(p->loc, fmt::format("{}: Canopy reads no texture here (the constant default used), "
                                "ignored",
                                pn));
    return std::nullopt;
  }
  wrong_type(*p, "rgb, blackbody or spectrum");
}

double Params::get_float(std::string_view name, double def) {
  Param* p = find(name);
  if (p && p->type == "texture") {
    r_.warn(p->loc, fmt::format("{}: \"texture {}\": Canopy reads no texture here (the "
                                "constant default used), ignored",
                                what_, printable(p->name)));
    return def;
  }
  p = one(name, {"float"});
  return p ? p->nums[0] : def;
}

void Params::finish() {
  for (const Param& p : ps_)
    if (!p.used)
      r_.warn(p.loc, fmt::format("{}: unknown parameter \"{} {}\" ignored", what_, p.type,
                                 printable(p.name)));
}

// ----------------------------------------------------------------------------- transforms

Transform inverse(const Transform& x, bool& ok) {
  double c[3][3];
  double det = x.cofactors(c); // m^-1 = C^T / det
  Transform r;
  ok = det != 0.0 && std::isfinite(det);
  if (!ok) return r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[i][j] = c[j][i] / det;
  double3 t = x.t;
  r.t = {-(r.m[0][0] * t.x + r.m[0][1] * t.y + r.m[0][2] * t.z),
         -(r.m[1][0] * t.x + r.m[1][1] * t.y + r.m[1][2] * t.z),
         -(r.m[2][0] * t.x + r.m[2][1] * t.y + r.m[2][2] * t.z)};
  return r;
}

double3 linear(const Transform& x, double3 v) {
  return {x.m[0][0] * v.x + x.m[0][1] * v.y + x.m[0][2] * v.z,
          x.m[1][0] * v.x + x.m[1][1] * v.y + x.m[1][2] * v.z,
          x.m[2][0] * v.x + x.m[2][1] * v.y + x.m[2][2] * v.z};
}
double dot3(double3 a, double3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
double3 cross3(double3 a, double3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double len3(double3 a) {
  return std::sqrt(dot3(a, a));
}

// The uniform scale of x if its linear part is a similarity (rotation, reflection and uniform
// scale), else 0: spheres and disks stay round only under those.
double similarity_scale(const Transform& x) {
  double3 c[3] = {linear(x, {1, 0, 0}), linear(x, {0, 1, 0}), linear(x, {0, 0, 1})};
  double s2 = dot3(c[0], c[0]);
  if (!(s2 > 0.0) || !std::isfinite(s2)) return 0.0;
  for (int i = 0; i < 3; ++i) {
    if (std::fabs(dot3(c[i], c[i]) / s2 - 1.0) > 1e-6) return 0.0;
    if (std::fabs(dot3(c[i], c[(i + 1) % 3])) / s2 > 1e-6) return 0.0;
  }
  return std::sqrt(s2);
}

// pbrt's 4x4 matrices are written column by column (the format page, "Transformations": the
// translation is elements 12..14); the last row must be 0 0 0 1 for an affine transform.
Transform from_pbrt_matrix(const Loc& loc, const std::vector<double>& v) {
  Transform x;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j)
      x.m[i][j] = v[size_t(4 * j + i)];
  }
  x.t = {v[12], v[13], v[14]};
  if (v[3] != 0.0 || v[7] != 0.0 || v[11] != 0.0 || v[15] != 1.0)
    fail(loc, "projective matrices are not supported (the last row must be 0 0 0 1)");
  return x;
}

// ------------------------------------------------------------------------------------ shapes

void reverse_winding(Mesh& m) {
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    std::swap(m.indices[3 * t + 1], m.indices[3 * t + 2]);
    if (!m.normal_indices.empty())
      std::swap(m.normal_indices[3 * t + 1], m.normal_indices[3 * t + 2]);
    if (!m.uv_indices.empty()) std::swap(m.uv_indices[3 * t + 1], m.uv_indices[3 * t + 2]);
  }
}

// pbrt-v4 Triangle/BilinearPatch: with vertex normals the geometric normal is turned towards the
// shading normal (FaceForward), whatever the winding or ReverseOrientation. Canopy's emission and
// geometric normal follow the winding, so the winding is turned instead (the vertex normals'
// sum standing in for the interpolated one).
void face_forward_to_normals(Mesh& m) {
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    const float3 a = m.vertices[m.indices[3 * t]], b = m.vertices[m.indices[3 * t + 1]],
                 c = m.vertices[m.indices[3 * t + 2]];
    double3 ng = cross3(dvec(b - a), dvec(c - a));
    double3 ns{};
    for (int k = 0; k < 3; ++k)
      ns = ns + dvec(m.normals[size_t(m.normal_indices[3 * t + size_t(k)])]);
    if (dot3(ng, ns) < 0.0) {
      std::swap(m.indices[3 * t + 1], m.indices[3 * t + 2]);
      std::swap(m.normal_indices[3 * t + 1], m.normal_indices[3 * t + 2]);
      if (!m.uv_indices.empty()) std::swap(m.uv_indices[3 * t + 1], m.uv_indices[3 * t + 2]);
    }
  }
}

// The triangles of a polygon mesh whose vertices (and vertex normals and uv, if any, one per
// vertex) are in m: `idx` holds 3 indices a triangle, or with `bilinear` 4 a pbrt-v4
// BilinearPatch (p00 p10 p01 p11, whose normal cross(p10 - p00, p01 - p00) the triangles
// (p00 p10 p11) and (p00 p11 p01) keep). A bilinear patch without "uv" has pbrt-v4's default, its
// own parameterisation: (0, 0), (1, 0), (0, 1), (1, 1) at p00, p10, p01, p11 (a triangle's
// default, (0, 0), (1, 0), (1, 1), is Builder::add_mesh's). Then pbrt-v4's orientation: towards
// the vertex normals, else the winding (reversed by ReverseOrientation).
void add_polygons(Mesh& m, const std::vector<uint32_t>& idx, bool bilinear, int32_t material,
                  float3 emission, bool reverse) {
  const bool patch_uv = bilinear && m.uvs.empty();
  if (patch_uv)
    m.uvs = {make_float2(0, 0), make_float2(1, 0), make_float2(0, 1), make_float2(1, 1)};
  auto add = [&](uint32_t x, uint32_t y, uint32_t z, std::initializer_list<int32_t> corner_uv) {
    m.add_triangle(x, y, z, material, emission);
    if (!m.normals.empty())
      m.normal_indices.insert(m.normal_indices.end(), {int32_t(x), int32_t(y), int32_t(z)});
    if (patch_uv)
      m.uv_indices.insert(m.uv_indices.end(), corner_uv);
    else if (!m.uvs.empty())
      m.uv_indices.insert(m.uv_indices.end(), {int32_t(x), int32_t(y), int32_t(z)});
  };
  if (!bilinear) {
    for (size_t t = 0; t + 2 < idx.size(); t += 3)
      add(idx[t], idx[t + 1], idx[t + 2], {});
  } else {
    for (size_t t = 0; t + 3 < idx.size(); t += 4) {
      add(idx[t], idx[t + 1], idx[t + 3], {0, 1, 3});
      add(idx[t], idx[t + 3], idx[t + 2], {0, 3, 2});
    }
  }
  if (!m.normals.empty())
    face_forward_to_normals(m);
  else if (reverse)
    reverse_winding(m);
}

// pbrt-v4's Sphere, tessellated, with its uv (in object space): u = phi / (2 pi), phi = atan2(y, x)
// in [0, 2 pi), and v = (theta - thetaZMin) / (thetaZMax - thetaZMin), which for the full sphere
// is 1 - theta / pi, theta = acos(z / r). The seam (u = 1 against u = 0) and the poles (one vertex,
// a u per triangle: the middle of its segment) have uv of their own, apart from the vertices.
Mesh sphere_mesh(float radius) {
  Mesh m;
  const int nr = kSphereRings, ns = kSphereSegments;
  const double pi = 3.14159265358979323846;
  // Poles plus (nr - 1) rings; normals are the unit positions.
  m.vertices.push_back(make_float3(0, 0, radius));
  m.normals.push_back(make_float3(0, 0, 1));
  for (int i = 1; i < nr; ++i) {
    double th = pi * i / nr;
    for (int j = 0; j < ns; ++j) {
      double ph = 2.0 * pi * j / ns;
      float3 n = make_float3(float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)),
                             float(std::cos(th)));
      m.vertices.push_back(n * radius);
      m.normals.push_back(n);
    }
  }
  m.vertices.push_back(make_float3(0, 0, -radius));
  m.normals.push_back(make_float3(0, 0, -1));
  const uint32_t south = uint32_t(m.vertices.size() - 1);
  auto ring = [&](int i, int j) { return uint32_t(1 + (i - 1) * ns + ((j % ns) + ns) % ns); };
  // uv: the rings' grid (ns + 1 columns: column ns is the seam at u = 1), then the poles' ns each.
  for (int i = 1; i < nr; ++i)
    for (int j = 0; j <= ns; ++j)
      m.uvs.push_back(make_float2(float(double(j) / ns), float(1.0 - double(i) / nr)));
  const int32_t north_uv = int32_t(m.uvs.size()), south_uv = north_uv + ns;
  for (float v : {1.0f, 0.0f})
    for (int j = 0; j < ns; ++j)
      m.uvs.push_back(make_float2(float((j + 0.5) / ns), v));
  auto grid = [&](int i, int j) { return int32_t((i - 1) * (ns + 1) + j); };
  auto tri = [&](uint32_t a, uint32_t b, uint32_t c, int32_t ua, int32_t ub, int32_t uc) {
    m.add_triangle(a, b, c, 0, make_float3(0, 0, 0));
    m.normal_indices.insert(m.normal_indices.end(), {int32_t(a), int32_t(b), int32_t(c)});
    m.uv_indices.insert(m.uv_indices.end(), {ua, ub, uc});
  };
  // Counter-clockwise seen from outside: the winding normal points out, as pbrt's sphere normal.
  for (int j = 0; j < ns; ++j)
    tri(0, ring(1, j), ring(1, j + 1), north_uv + j, grid(1, j), grid(1, j + 1));
  for (int i = 1; i < nr - 1; ++i)
    for (int j = 0; j < ns; ++j) {
      tri(ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), grid(i, j), grid(i + 1, j),
          grid(i + 1, j + 1));
      tri(ring(i, j), ring(i + 1, j + 1), ring(i, j + 1), grid(i, j), grid(i + 1, j + 1),
          grid(i, j + 1));
    }
  for (int j = 0; j < ns; ++j)
    tri(ring(nr - 1, j), south, ring(nr - 1, j + 1), grid(nr - 1, j), south_uv + j,
        grid(nr - 1, j + 1));
  return m;
}

// pbrt's disk: radius r at z = height, normal +z (pbrt-v4 Disk), with its uv: u = phi / (2 pi),
// v = (radius - r) / (radius - innerradius) (innerradius 0 here: 1 at the centre, 0 on the rim).
// The seam and the centre have uv of their own, as the sphere's.
Mesh disk_mesh(float radius, float height) {
  Mesh m;
  const int ns = kDiskSegments;
  const double pi = 3.14159265358979323846;
  m.vertices.push_back(make_float3(0, 0, height));
  for (int j = 0; j < ns; ++j) {
    double ph = 2.0 * pi * j / ns;
    m.vertices.push_back(
        make_float3(float(radius * std::cos(ph)), float(radius * std::sin(ph)), height));
  }
  for (int j = 0; j <= ns; ++j) // the rim, column ns the seam at u = 1
    m.uvs.push_back(make_float2(float(double(j) / ns), 0.0f));
  for (int j = 0; j < ns; ++j) // the centre, per triangle
    m.uvs.push_back(make_float2(float((j + 0.5) / ns), 1.0f));
  for (int j = 0; j < ns; ++j) {
    m.add_triangle(0, uint32_t(1 + j), uint32_t(1 + (j + 1) % ns), 0, make_float3(0, 0, 0));
    m.uv_indices.insert(m.uv_indices.end(), {ns + 1 + j, j, j + 1});
  }
  return m;
}

// ---------------------------------------------------------------------------- the reader proper

void Reader::run_file(const std::filesystem::path& file, const std::string& display,
                      const Loc* from) {
  std::error_code ec;
  std::string canon = std::filesystem::weakly_canonical(file, ec).string();
  if (ec) canon = file.lexically_normal().string();
  for (size_t k = 0; k < include_stack_.size(); ++k)
    if (include_stack_[k].first == canon) {
      std::string chain;
      for (size_t m = k; m < include_stack_.size(); ++m)
        chain += include_stack_[m].second + " -> ";
      fail(*from, fmt::format("Include cycle: {}{}", chain, display));
    }
  if (include_stack_.size() >= size_t(kMaxIncludeDepth))
    fail(*from, fmt::format("Includes nested deeper than {}", kMaxIncludeDepth));
  std::string prefix =
      from ? fmt::format("{}:{}: Include \"{}\": ", *from->file, from->line, display)
           : display + ": ";
  std::string text = read_input_file(file, kMaxSceneFileBytes, prefix);
  include_stack_.push_back({canon, display});
  run_text(text, display, file.parent_path());
  include_stack_.pop_back();
}

void Reader::run_text(const std::string& text, const std::string& display,
                      const std::filesystem::path& dir) {
  names_.push_back(display);
  Lexer lx(text, &names_.back());
  while (lx.peek()) {
    const Token d = lx.next();
    if (d.kind != Tok::Ident || is_bool_ident(d))
      fail(d.loc, fmt::format("expected a directive, got {}", describe(d)));
    last_loc_ = d.loc;
    directive(d, lx, dir);
  }
}

std::vector<double> Reader::numbers(const Token& d, Lexer& lx, size_t want, bool brackets_ok) {
  std::vector<double> v;
  const bool br = brackets_ok && lx.peek() && lx.peek()->kind == Tok::LBracket;
  if (br) lx.next();
  while (v.size() <= want) { // one more than wanted is enough to report the count
    if (br && lx.peek() && lx.peek()->kind == Tok::RBracket) {
      lx.next();
      break;
    }
    if (lx.at_directive()) {
      if (br) fail(d.loc, fmt::format("{}: '[' without ']'", d.text));
      break;
    }
    Token t = lx.next();
    if (t.kind != Tok::Number)
      fail(t.loc, fmt::format("{}: expected a number, got {}", d.text, describe(t)));
    v.push_back(t.num);
  }
  if (v.size() != want)
    fail(d.loc, fmt::format("{}: wrong count of values ({}{}; want {} numbers)", d.text,
                            v.size() > want ? "more than " : "", std::min(v.size(), want), want));
  if (!lx.at_directive())
    fail(lx.peek()->loc, fmt::format("{}: unexpected {}", d.text, describe(*lx.peek())));
  return v;
}

std::string Reader::one_string(const Token& d, Lexer& lx) {
  const Token* t = lx.peek();
  if (!t || t->kind != Tok::String)
    fail(t && !lx.at_directive() ? t->loc : d.loc,
         fmt::format("{}: expected a quoted name{}", d.text,
                     t && !lx.at_directive() ? ", got " + describe(*t) : ""));
  return lx.next().text;
}

void Reader::directive(const Token& d, Lexer& lx, const std::filesystem::path& dir) {
  const std::string& k = d.text;
  auto no_args = [&] {
    if (!lx.at_directive())
      fail(lx.peek()->loc, fmt::format("{}: unexpected {}", k, describe(*lx.peek())));
  };
  auto skip = [&] { // the arguments of a directive that is not read
    while (!lx.at_directive())
      lx.next();
  };
  auto need_world = [&](bool inside) {
    if (world_block_ != inside)
      fail(d.loc, fmt::format("{} is not allowed {} WorldBegin", k, inside ? "before" : "after"));
  };
  auto post = [&](const Transform& x) { gs_.ctm = x.then(gs_.ctm); }; // CTM = CTM * x

  // ---- structure (the format page, "Scene-wide rendering options" / "Attributes")
  if (k == "Include" || k == "Import") {
    // Import may only add named things in pbrt-v4 (it exists so files can be parsed in
    // parallel); read sequentially, it is the same as Include.
    std::string f = one_string(d, lx);
    no_args();
    std::filesystem::path p(f);
    if (p.is_relative()) p = dir / p;
    run_file(p, p.lexically_normal().string(), &d.loc);
  } else if (k == "AttributeBegin" || k == "TransformBegin") {
    // TransformBegin/End: deprecated in pbrt-v4 but accepted there; they save the CTM only.
    no_args();
    stack_.push_back({gs_, d.loc, k});
  } else if (k == "AttributeEnd" || k == "TransformEnd") {
    no_args();
    const char* open = k == "AttributeEnd" ? "AttributeBegin" : "TransformBegin";
    if (stack_.empty() || stack_.back().kind != open)
      fail(d.loc, stack_.empty() ? fmt::format("{} without {}", k, open)
                                 : fmt::format("{} closes the {} of line {}", k, stack_.back().kind,
                                               stack_.back().loc.line));
    if (k == "AttributeEnd")
      gs_ = stack_.back().gs;
    else
      gs_.ctm = stack_.back().gs.ctm;
    stack_.pop_back();
  } else if (k == "WorldBegin") {
    no_args();
    need_world(false);
    finish_camera(d.loc);
    world_block_ = true;
    gs_.ctm = Transform{};
    coord_systems_["world"] = Transform{};
  } else if (k == "ReverseOrientation") {
    no_args();
    gs_.reverse = !gs_.reverse;
  } else if (k == "Option") {
    warn(d.loc, "Option: rendering options are not read, ignored");
    skip();
  } else if (k == "ObjectBegin") {
    // Object instances are flattened: each ObjectInstance copies the object's triangles with the
    // instance transform into the one triangle soup (Canopy's BVH has no instance level). Memory
    // grows with instances x triangles, capped by kMaxTriangles.
    need_world(true);
    std::string name = one_string(d, lx);
    no_args();
    if (object_) fail(d.loc, "ObjectBegin inside another ObjectBegin");
    if (objects_.count(name))
      fail(d.loc, fmt::format("object \"{}\" is defined twice", printable(name)));
    stack_.push_back({gs_, d.loc, "ObjectBegin"}); // pbrt-v4: ObjectBegin implies AttributeBegin
    object_ = &objects_[name];
  } else if (k == "ObjectEnd") {
    no_args();
    if (!object_ || stack_.empty() || stack_.back().kind != "ObjectBegin")
      fail(d.loc, stack_.empty() || !object_
                      ? std::string("ObjectEnd without ObjectBegin")
                      : fmt::format("ObjectEnd closes the {} of line {}", stack_.back().kind,
                                    stack_.back().loc.line));
    gs_ = stack_.back().gs;
    stack_.pop_back();
    object_ = nullptr;
  } else if (k == "ObjectInstance") {
    need_world(true);
    std::string name = one_string(d, lx);
    no_args();
    if (object_) fail(d.loc, "ObjectInstance inside ObjectBegin");
    auto it = objects_.find(name);
    if (it == objects_.end()) fail(d.loc, fmt::format("unknown object \"{}\"", printable(name)));
    for (ObjectPart& part : it->second)
      add_mesh(d.loc, part.mesh, part.xf.then(gs_.ctm));
  }
  // ---- transforms (the format page, "Transformations"); pbrt post-multiplies the CTM
  else if (k == "Identity") {
    no_args();
    gs_.ctm = Transform{};
  } else if (k == "Translate") {
    auto v = numbers(d, lx, 3, false);
    post(Transform::translate({v[0], v[1], v[2]}));
  } else if (k == "Scale") {
    auto v = numbers(d, lx, 3, false);
    post(Transform::scale({v[0], v[1], v[2]}));
  } else if (k == "Rotate") {
    auto v = numbers(d, lx, 4, false);
    double3 ax{v[1], v[2], v[3]};
    double l = len3(ax);
    if (!(l > 0.0) || !std::isfinite(l)) fail(d.loc, "Rotate: the axis must be non-zero");
    post(Transform::rotate(ax * (1.0 / l), v[0]));
  } else if (k == "LookAt") {
    auto v = numbers(d, lx, 9, false);
    double3 eye{v[0], v[1], v[2]}, at{v[3], v[4], v[5]}, up{v[6], v[7], v[8]};
    double3 dirv = at - eye;
    double dl = len3(dirv), ul = len3(up);
    if (!(dl > 0.0) || !std::isfinite(dl)) fail(d.loc, "LookAt: eye and target coincide");
    if (!(ul > 0.0) || !std::isfinite(ul)) fail(d.loc, "LookAt: the up vector is zero");
    dirv = dirv * (1.0 / dl);
    // pbrt-v4 LookAt: right = normalize(cross(normalize(up), dir)), newUp = cross(dir, right);
    // worldFromCamera has columns right, newUp, dir and the eye; the CTM gets its inverse.
    double3 right = cross3(up * (1.0 / ul), dirv);
    double rl = len3(right);
    if (!(rl > 1e-9)) fail(d.loc, "LookAt: the up vector is parallel to the view direction");
    right = right * (1.0 / rl);
    double3 nup = cross3(dirv, right);
    Transform cam_from_world; // the transpose of the rotation, then minus the rotated eye
    double3 rows[3] = {right, nup, dirv};
    for (int i = 0; i < 3; ++i) {
      cam_from_world.m[i][0] = rows[i].x;
      cam_from_world.m[i][1] = rows[i].y;
      cam_from_world.m[i][2] = rows[i].z;
    }
    cam_from_world.t = {-dot3(right, eye), -dot3(nup, eye), -dot3(dirv, eye)};
    post(cam_from_world);
  } else if (k == "Transform" || k == "ConcatTransform") {
    Transform x = from_pbrt_matrix(d.loc, numbers(d, lx, 16, true));
    if (k == "Transform")
      gs_.ctm = x;
    else
      post(x);
  } else if (k == "CoordinateSystem") {
    std::string name = one_string(d, lx);
    no_args();
    coord_systems_[name] = gs_.ctm;
  } else if (k == "CoordSysTransform") {
    std::string name = one_string(d, lx);
    no_args();
    auto it = coord_systems_.find(name);
    if (it == coord_systems_.end())
      warn(d.loc, fmt::format("CoordSysTransform: unknown coordinate system \"{}\" ignored",
                              printable(name)));
    else
      gs_.ctm = it->second;
  }
  // ---- everything with a type name and a parameter list
  else {
    static const std::set<std::string> typed = {
        "Camera",          "Film",        "Sampler",
        "Integrator",      "PixelFilter", "Accelerator",
        "ColorSpace",      "Shape",       "LightSource",
        "AreaLightSource", "Material",    "MakeNamedMaterial",
        "NamedMaterial",   "Texture",     "MakeNamedMedium",
        "MediumInterface", "Attribute",   "ActiveTransform",
        "TransformTimes"};
    if (!typed.count(k)) {
      warn(d.loc, fmt::format("unknown directive '{}' ignored", printable(k)));
      skip();
      return;
    }
    if (k == "Texture") {
      need_world(true);
      std::string name = one_string(d, lx);
      std::string type = one_string(d, lx);
      std::string cls = one_string(d, lx);
      Params p(*this, parse_params(lx), fmt::format("Texture \"{}\"", printable(name, 40)));
      texture(d, p, name, type, cls, dir);
      return;
    }
    if (k == "MakeNamedMedium" || k == "MediumInterface" || k == "Attribute" ||
        k == "ActiveTransform" || k == "TransformTimes" || k == "PixelFilter" ||
        k == "Accelerator" || k == "ColorSpace") {
      warn(d.loc, fmt::format("{} is not read in this slice, ignored", k));
      skip();
      return;
    }
    std::string type = one_string(d, lx);
    if (k == "NamedMaterial") {
      no_args();
      auto it = named_materials_.find(type);
      if (it == named_materials_.end())
        fail(d.loc, fmt::format("NamedMaterial: unknown material \"{}\"", printable(type)));
      gs_.material = it->second;
      return;
    }
    Params p(*this, parse_params(lx), fmt::format("{} \"{}\"", k, printable(type, 40)));
    if (k == "Camera") {
      need_world(false);
      camera(d, p, type);
    } else if (k == "Film") {
      need_world(false);
      if (type != "rgb")
        warn(d.loc, fmt::format("Film \"{}\": read as \"rgb\" (its other outputs ignored)",
                                printable(type)));
      auto res = [&](const char* name, int& out) {
        if (Param* q = p.one(name, {"integer"})) {
          double v = q->nums[0];
          if (!(v >= 1 && v <= kMaxFilmSide))
            fail(q->loc, fmt::format("{}: \"integer {}\": must be in [1, {}]", p.what(), name,
                                     kMaxFilmSide));
          out = int(v);
        }
      };
      res("xresolution", scene_.film.width);
      res("yresolution", scene_.film.height);
      // pbrt-v4 (FilmBaseParameters) writes `filename` as given, relative to the working
      // directory; here it is the default of --out. Canopy writes EXR and PNG: another extension
      // is replaced by .exr, with a warning.
      if (auto f = p.get_string("filename")) {
        std::filesystem::path out(*f);
        std::string ext = out.extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(),
                       [](unsigned char c) { return char(std::tolower(c)); });
        if (f->empty() || out.filename().empty())
          fail(p.find("filename")->loc, fmt::format("{}: \"string filename\": empty", p.what()));
        if (ext != ".exr" && ext != ".png") {
          warn(p.find("filename")->loc,
               fmt::format("{}: \"string filename\" \"{}\": Canopy writes EXR and PNG, written "
                           "as .exr",
                           p.what(), printable(*f)));
          out.replace_extension(".exr");
        }
        scene_.film.output = out.string();
      }
      // The image scale: pbrt-v4's RGBFilm multiplies by its sensor's imaging ratio, ISO / 100
      // for the default sensor (and the shutter time, 1 by default); pbrt-v3's "scale" multiplies
      // too. Both are read, as one factor.
      double scale = p.get_float("scale", 1.0) * p.get_float("iso", 100.0) / 100.0;
      if (!(scale > 0.0 && scale <= 1e30))
        fail(d.loc, fmt::format("{}: the image scale (scale x iso / 100 = {}) must be in "
                                "(0, 1e30]",
                                p.what(), scale));
      scene_.film.image_scale = float(scale);
      p.finish();
    } else if (k == "Sampler") {
      need_world(false);
      count_param(p, "pixelsamples", kMaxSpp, &scene_.integrator.spp);
      p.finish();
    } else if (k == "Integrator") {
      need_world(false);
      // "path" and "volpath" are what Canopy renders (paths with light sampling and MIS, pbrt's
      // maxdepth); any other integrator is replaced by it.
      if (type != "path" && type != "volpath")
        warn(d.loc, fmt::format("Integrator \"{}\": rendered with Canopy's path tracer, the "
                                "integrator ignored",
                                printable(type)));
      count_param(p, "maxdepth", kMaxDepth, &scene_.integrator.max_depth);
      p.finish();
    } else if (k == "Shape") {
      need_world(true);
      shape(d, p, type, dir);
    } else if (k == "LightSource") {
      need_world(true);
      light_source(d, p, type, dir);
    } else if (k == "AreaLightSource") {
      need_world(true);
      area_light(d, p, type);
    } else if (k == "Material") {
      need_world(true);
      gs_.material = material(d.loc, p, type, "");
    } else { // MakeNamedMaterial "name" "string type" "..." params
      need_world(true);
      auto t = p.get_string("type");
      if (!t) fail(d.loc, "MakeNamedMaterial: needs a \"string type\" parameter");
      if (named_materials_.count(type))
        fail(d.loc, fmt::format("MakeNamedMaterial: \"{}\" is defined twice", printable(type)));
      named_materials_[type] = material(d.loc, p, *t, type);
    }
  }
}

// The format page, "Cameras": the CTM at the Camera directive is camera-from-world, and the
// "camera" coordinate system is its inverse.
void Reader::camera(const Token& d, Params& p, const std::string& type) {
  if (type != "perspective")
    warn(d.loc, fmt::format("Camera \"{}\": read as \"perspective\" (its projection ignored)",
                            printable(type)));
  camera_set_ = true;
  camera_loc_ = d.loc;
  camera_from_world_ = gs_.ctm;
  bool ok = false;
  Transform wfc = inverse(gs_.ctm, ok);
  if (!ok) fail(d.loc, "Camera: the camera transform is singular");
  coord_systems_["camera"] = wfc;
  if (Param* q = p.one("fov", {"float"})) {
    if (!(q->nums[0] > 0.0 && q->nums[0] < 180.0))
      fail(q->loc, fmt::format("{}: \"float fov\": must be in (0, 180)", p.what()));
    fov_ = q->nums[0];
  }
  for (const char* lens : {"lensradius", "focaldistance"})
    if (p.find(lens))
      warn(p.find(lens)->loc,
           fmt::format("{}: \"{}\": Canopy's camera is a pinhole (no thin lens), ignored", p.what(),
                       lens));
  p.finish();
}

void Reader::finish_camera(const Loc& loc) {
  bool ok = false;
  Transform wfc = inverse(camera_from_world_, ok); // identity without a Camera: pbrt's default
  if (!ok) fail(camera_set_ ? camera_loc_ : loc, "Camera: the camera transform is singular");
  double3 pos = wfc.t;
  double3 fwd = linear(wfc, {0, 0, 1}), up = linear(wfc, {0, 1, 0}), right = linear(wfc, {1, 0, 0});
  if (!(len3(fwd) > 0.0 && len3(up) > 0.0 && len3(right) > 0.0) ||
      !std::isfinite(len3(fwd) + len3(up) + len3(right) + dot3(pos, pos)))
    fail(camera_set_ ? camera_loc_ : loc, "Camera: the camera transform is out of range");
  // Handedness (the format page, "Cameras", and pbrt-v4's PerspectiveCamera): in camera space
  // pbrt looks down +z with +y up, and raster x grows with camera +x. That frame is left-handed:
  // +x = cross(+y, +z). Canopy's camera (host/render/camera.cpp) puts raster x along
  // cross(forward, up), a right-handed frame. So when worldFromCamera keeps orientation
  // (det > 0: a plain LookAt, where camera +x = world cross(up, dir)) pbrt's image is the mirror
  // of what Canopy would show from the same eye, and Canopy must render the mirrored world:
  // every shape and light is reflected through the plane that holds the eye, the view direction
  // and the up vector (world_fix_), which swaps the two sides of the image and nothing else.
  // When worldFromCamera flips orientation (the common "Scale -1 1 1" before LookAt), the frames
  // already agree and the world is kept as written.
  double det = wfc.det();
  if (det > 0.0) {
    double rl = len3(right);
    double3 n = right * (1.0 / rl);
    Transform r; // p - 2 ((p - pos) . n) n
    double nn[3] = {n.x, n.y, n.z};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        r.m[i][j] = (i == j ? 1.0 : 0.0) - 2.0 * nn[i] * nn[j];
    r.t = n * (2.0 * dot3(pos, n));
    world_fix_ = r;
  }
  // A camera transform with scale or shear changes pbrt's rays; Canopy's camera is a pinhole
  // with an orthonormal frame: only the eye and the view and up directions are kept.
  double3 cols[3] = {right, up, fwd};
  bool ortho = true;
  for (int i = 0; i < 3; ++i) {
    ortho = ortho && std::fabs(len3(cols[i]) - 1.0) < 1e-6;
    ortho = ortho && std::fabs(dot3(cols[i], cols[(i + 1) % 3])) < 1e-6;
  }
  if (!ortho)
    warn(camera_set_ ? camera_loc_ : loc,
         "Camera: the camera transform scales or shears (only the eye, view and up directions "
         "are kept), the rest ignored");
  if (auto e = check_coordinate(to_float3(pos)); !e.empty())
    fail(camera_set_ ? camera_loc_ : loc, "Camera: the eye " + e);
  scene_.origin = pos;
  Camera& c = scene_.camera;
  c.position = make_float3(0, 0, 0);
  double fl = len3(fwd), ul = len3(up);
  c.look_at = to_float3(fwd * (1.0 / fl));
  c.up = to_float3(up * (1.0 / ul));
  // pbrt's fov spans the shorter image axis (PerspectiveCamera: the screen window is
  // [-1, 1] on the shorter axis); Canopy's fov_y_deg spans the vertical one. On a tall film the
  // horizontal half-width is tan(fov/2), so the vertical one is tan(fov/2) * height / width.
  const double d2r = 3.14159265358979323846 / 180.0;
  double fy = fov_;
  if (scene_.film.height > scene_.film.width)
    fy = 2.0 *
         std::atan(std::tan(0.5 * fov_ * d2r) * double(scene_.film.height) /
                   double(scene_.film.width)) /
         d2r;
  c.fov_y_deg = float(fy);
  if (!(c.fov_y_deg > 0.0f && c.fov_y_deg < 180.0f))
    fail(camera_set_ ? camera_loc_ : loc, "Camera: the vertical field of view is out of range");
}

void Reader::finish() {
  const Loc end = last_loc_.file ? last_loc_ : Loc{&names_.front(), 1};
  if (!world_block_) finish_camera(end); // a file without WorldBegin: camera and options only
  if (!stack_.empty())
    warn(stack_.back().loc,
         fmt::format("{} without its end at the end of the file, ignored", stack_.back().kind));
  if (dropped_warnings_ > 0)
    scene_.warnings.push_back(fmt::format("{}: {} more warnings", b_.file, dropped_warnings_));
}

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
    add_polygons(m, idx, !tri, gs_.material, emission(), gs_.reverse);
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
    add_polygons(m, ply.indices, false, gs_.material, emission(), gs_.reverse);
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
        m.material[t] = gs_.material;
        m.emission[t] = em;
      }
      if (gs_.reverse) reverse_winding(m); // spheres keep their outward shading normals
    }
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

// The format page, "Lights".
void Reader::light_source(const Token& d, Params& p, const std::string& type,
                          const std::filesystem::path& base_dir) {
  if (type == "infinite" && !object_) {
    infinite_light(d, p, base_dir);
    return;
  }
  if (type != "point" && type != "spot" && type != "distant" && type != "infinite") {
    warn(d.loc,
         fmt::format("LightSource \"{}\" is not read in this slice, ignored", printable(type)));
    return;
  }
  if (object_) {
    warn(d.loc, "LightSource inside ObjectBegin (not instanced) ignored");
    p.mark_all_used();
    return;
  }
  if (Param* q = p.find("power")) {
    warn(q->loc, fmt::format("{}: \"power\" given: Canopy does not rescale lights to a power; "
                             "the light is skipped, ignored",
                             p.what()));
    p.finish();
    return;
  }
  const bool distant = type == "distant";
  float3 I =
      p.spectrum(distant ? "L" : "I", Params::Use::Illuminant).value_or(make_float3(1, 1, 1));
  double scale = p.get_float("scale", 1.0);
  if (!(scale >= 0.0)) fail(d.loc, fmt::format("{}: \"float scale\": must be >= 0", p.what()));
  // pbrt-v4 DistantLight: "illuminance" E_v > 0 multiplies the 1-nit normalised L (lights.cpp).
  if (distant) {
    double ev = p.get_float("illuminance", -1.0);
    if (ev > 0.0) scale *= ev;
  }
  float3 em = to_float3(dvec(I) * scale);
  if (!std::isfinite(em.x + em.y + em.z))
    fail(d.loc, fmt::format("{}: I * scale is too large", p.what()));
  Transform xf = world(gs_.ctm);
  double3 from = p.get_point("from").value_or(double3{0, 0, 0});
  Light l{};
  l.prim = -1;
  l.emission = f4_from3(em, 0.0f);
  l.p = f4_from3(rebase(xf.apply(from), scene_.origin), 0.0f);
  if (type == "point") {
    l.type = LIGHT_POINT;
  } else {
    // The unit world direction from "from" to "to" (default (0 0 1)): a spot's axis; a distant
    // light's travel (pbrt-v4 DistantLight), whose e1 points back, towards the light.
    double3 to = p.get_point("to").value_or(double3{0, 0, 1});
    double3 dir = linear(xf, to - from);
    double dl = len3(dir);
    if (!(dl > 0.0) || !std::isfinite(dl))
      fail(d.loc, fmt::format("{}: \"from\" and \"to\" must differ", p.what()));
    l.e1 = f4_from3(to_float3(dir * ((distant ? -1.0 : 1.0) / dl)), 0.0f);
  }
  if (distant) {
    l.type = LIGHT_DISTANT;
    l.p = make_float4(0, 0, 0, 0);
  } else if (type == "spot") {
    l.type = LIGHT_SPOT;
    // pbrt-v4 SpotLight: full intensity inside coneangle - conedelta, a smoothstep in cos theta
    // out to coneangle; Canopy's spot (cl/lights/light_sample.h spot_falloff) is the same
    // smoothstep between its falloff start and its cone edge.
    double cone = p.get_float("coneangle", 30.0), delta = p.get_float("conedelta", 5.0);
    if (!(cone > 0.0 && cone <= 180.0))
      fail(d.loc, fmt::format("{}: \"float coneangle\": must be in (0, 180]", p.what()));
    if (!(delta >= 0.0))
      fail(d.loc, fmt::format("{}: \"float conedelta\": must be >= 0", p.what()));
    set_spot_cone(l, cone, std::clamp(cone - delta, 0.0, cone));
  }
  p.finish();
  if (auto e = check_light_extent(l, scene_.origin); !e.empty()) fail(d.loc, e);
  if (!emits(l))
    ++scene_.skipped_lights;
  else if (distant)
    add_infinite_light(scene_, l, [&](const std::string& e) { fail(d.loc, e); });
  else
    scene_.lights.push_back(l);
}

void Reader::count_param(Params& p, const char* name, int hi, int* out) {
  if (Param* q = p.one(name, {"integer"})) {
    if (!(q->nums[0] >= 1 && q->nums[0] <= hi))
      fail(q->loc, fmt::format("{}: \"integer {}\": must be in [1, {}]", p.what(), name, hi));
    *out = int(q->nums[0]);
  }
}

// pbrt-v4 "infinite": a constant L, or an equal-area octahedral image ("filename") in light space:
// the map frame is the current transform's x, y, z (orthonormalised in that order, so a mirror
// keeps its handedness).
void Reader::infinite_light(const Token& d, Params& p, const std::filesystem::path& dir) {
  Light l{};
  l.type = LIGHT_ENVIRONMENT;
  l.prim = -1;
  l.pad = -1;
  double scale = p.get_float("scale", 1.0);
  if (!(scale >= 0.0)) fail(d.loc, fmt::format("{}: \"float scale\": must be >= 0", p.what()));
  for (const char* skip : {"illuminance", "portal"})
    if (Param* q = p.find(skip))
      warn(q->loc, fmt::format("{}: \"{} {}\" ignored", p.what(), q->type, skip));
  Transform xf = world(gs_.ctm);
  double3 ex = linear(xf, {1, 0, 0}), ey = linear(xf, {0, 1, 0}), ez = linear(xf, {0, 0, 1});
  auto dot3 = [](double3 a, double3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; };
  auto unit = [&](double3 a) {
    double n = len3(a);
    if (!(n > 0.0) || !std::isfinite(n))
      fail(d.loc, fmt::format("{}: the transform is singular", p.what()));
    return double3{a.x / n, a.y / n, a.z / n};
  };
  double3 n = unit(ez);
  double3 e1 = unit(ex - n * dot3(ex, n));
  double3 e2 = unit(ey - n * dot3(ey, n) - e1 * dot3(ey, e1));
  l.n = f4_from3(to_float3(n), 0.0f);
  l.e1 = f4_from3(to_float3(e1), 0.0f);
  l.e2 = f4_from3(to_float3(e2), 0.0f);
  if (auto f = p.get_string("filename")) {
    if (p.find("L")) fail(d.loc, fmt::format("{}: both \"L\" and \"filename\" given", p.what()));
    std::filesystem::path file(*f);
    if (file.is_relative()) file = dir / file;
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
      fail(d.loc, fmt::format("{}: \"filename\" {}: no such file", p.what(), file.string()));
    l.pad = int(scene_.environment_maps.size());
    scene_.environment_maps.push_back({file, ENV_OCTAHEDRAL});
    l.emission = f4_from3(to_float3(double3{scale, scale, scale}), 0.0f);
  } else {
    float3 L = p.spectrum("L", Params::Use::Illuminant).value_or(make_float3(1, 1, 1));
    l.emission = f4_from3(to_float3(dvec(L) * scale), 0.0f);
  }
  if (!std::isfinite(l.emission.x + l.emission.y + l.emission.z))
    fail(d.loc, fmt::format("{}: L * scale is too large", p.what()));
  p.finish();
  if (!emits(l))
    ++scene_.skipped_lights;
  else
    add_infinite_light(scene_, l, [&](const std::string& e) { fail(d.loc, e); });
}

void Reader::area_light(const Token& d, Params& p, const std::string& type) {
  if (type != "diffuse") {
    warn(d.loc,
         fmt::format("AreaLightSource \"{}\" is not read in this slice, ignored", printable(type)));
    return;
  }
  float3 L = p.spectrum("L", Params::Use::Illuminant).value_or(make_float3(1, 1, 1));
  double scale = p.get_float("scale", 1.0);
  if (!(scale >= 0.0)) fail(d.loc, fmt::format("{}: \"float scale\": must be >= 0", p.what()));
  bool two = p.get_bool("twosided", false);
  if (Param* q = p.find("power"))
    warn(q->loc, fmt::format("{}: \"power\" (Canopy does not rescale lights to a power) ignored",
                             p.what()));
  p.finish();
  float3 em = to_float3(dvec(L) * scale);
  if (!std::isfinite(em.x + em.y + em.z))
    fail(d.loc, fmt::format("{}: L * scale is too large", p.what()));
  if (object_) {
    // pbrt-v4 does the same: "Area lights not supported with object instancing".
    warn(d.loc, "AreaLightSource inside ObjectBegin (not supported with instancing) ignored");
    return;
  }
  gs_.area = true;
  gs_.area_L = em;
  gs_.area_twosided = two;
}

// The format page, "Textures": `Texture "name" "float"|"spectrum" "class" params`. Canopy renders
// "imagemap" (pbrt-v4 FloatImageTexture / SpectrumImageTexture), "constant", and "scale" when it
// multiplies one of those by a constant (folded into the image's scale, as pbrt-v4's
// FloatScaledTexture::Create does). Other classes warn here; a material using one keeps the
// parameter's constant default.
void Reader::texture(const Token& d, Params& p, const std::string& name, const std::string& type,
                     const std::string& cls, const std::filesystem::path& dir) {
  const Loc& loc = d.loc;
  if (type != "float" && type != "spectrum")
    fail(loc, fmt::format("{}: texture type \"{}\" unknown (want \"float\" or \"spectrum\")",
                          p.what(), printable(type)));
  const bool is_float = type == "float";
  auto& named = is_float ? float_textures_ : spectrum_textures_;
  // pbrt-v4 refuses a second definition of a name (of the same type) too.
  if (named.count(name))
    fail(loc, fmt::format("{}: the {} texture \"{}\" is defined twice", p.what(), type,
                          printable(name)));
  NamedTexture t;
  if (cls == "imagemap") {
    t = image_texture(loc, p, name, dir);
  } else if (cls == "constant") {
    t.kind = NamedTexture::Kind::Constant;
    if (is_float) {
      float v = to_float(p.get_float("value", 1.0));
      t.value = make_float3(v, v, v);
    } else {
      t.value = p.spectrum("value", Params::Use::Reflectance).value_or(make_float3(1, 1, 1));
    }
  } else if (cls == "scale") {
    // pbrt-v4 FloatScaledTexture / SpectrumScaledTexture: tex * scale, both textures (default 1).
    std::optional<NamedTexture> tex = texture_param(p, "tex", is_float),
                                sc = texture_param(p, "scale", true);
    NamedTexture one;
    one.kind = NamedTexture::Kind::Constant;
    NamedTexture a = tex.value_or(one), b = sc.value_or(one);
    using K = NamedTexture::Kind;
    if (a.kind == K::Constant && b.kind == K::Image && is_float) std::swap(a, b);
    if (a.kind == K::Unsupported || b.kind == K::Unsupported) {
      t.kind = K::Unsupported; // warned where it was defined
    } else if (b.kind == K::Image) {
      warn(loc, fmt::format("{}: \"scale\" of {}: Canopy multiplies an image only by a constant "
                            "(the material's constant default used), ignored",
                            p.what(), a.kind == K::Image ? "two images" : "an image scale"));
      t.kind = K::Unsupported;
    } else if (a.kind == K::Image) {
      t = a;
      t.desc.scale = t.desc.scale * b.value.x;
      t.desc.where = fmt::format("{}:{}: texture \"{}\"", *loc.file, loc.line, name);
    } else {
      t.kind = K::Constant;
      t.value = a.value * b.value.x;
    }
  } else {
    static const std::set<std::string> known = {"bilerp", "checkerboard", "directionmix", "dots",
                                                "fbm",    "marble",       "mix",          "ptex",
                                                "windy",  "wrinkled"};
    warn(loc, fmt::format("{}: {} texture class \"{}\" is not supported (a material using it "
                          "keeps its constant default), ignored",
                          p.what(), known.count(cls) ? "the" : "unknown", printable(cls)));
    p.mark_all_used();
  }
  p.finish();
  t.name = name;
  named[name] = std::move(t);
}

NamedTexture Reader::image_texture(const Loc& loc, Params& p, const std::string& name,
                                   const std::filesystem::path& dir) {
  NamedTexture t;
  t.kind = NamedTexture::Kind::Image;
  TextureDesc& td = t.desc;
  td.where = fmt::format("{}:{}: texture \"{}\"", *loc.file, loc.line, printable(name));
  const std::optional<std::string> f = p.get_string("filename");
  if (!f) fail(loc, fmt::format("{}: needs \"string filename\"", p.what()));
  std::filesystem::path file(*f);
  if (file.is_relative()) file = dir / file; // as Include
  std::error_code ec;
  if (f->empty() || !std::filesystem::is_regular_file(file, ec))
    fail(p.find("filename")->loc, fmt::format("{}: \"string filename\" {}: no such file", p.what(),
                                              printable(file.string(), 1024)));
  td.file = file;
  if (auto w = p.get_string("wrap")) {
    if (*w == "repeat")
      td.wrap = TEXTURE_WRAP_REPEAT;
    else if (*w == "clamp")
      td.wrap = TEXTURE_WRAP_CLAMP;
    else if (*w == "black")
      td.wrap = TEXTURE_WRAP_BLACK;
    else
      fail(p.find("wrap")->loc,
           fmt::format("{}: \"string wrap\" \"{}\": unknown wrap mode (want \"repeat\", \"clamp\" "
                       "or \"black\")",
                       p.what(), printable(*w)));
  }
  // pbrt-v4 reads a PNG with the given encoding (default sRGB); other 8-bit images are sRGB and
  // float images linear whatever it says (Image::Read): ImageEncoding::Auto, so the parameter
  // counts for a PNG only, here too.
  if (auto e = p.get_string("encoding")) {
    const Loc& el = p.find("encoding")->loc;
    ImageEncoding enc = ImageEncoding::Auto;
    float gamma = 1.0f;
    if (*e == "sRGB") {
      enc = ImageEncoding::Srgb;
    } else if (*e == "linear") {
      enc = ImageEncoding::Linear;
    } else {
      std::istringstream in(*e);
      std::string word, extra;
      double g = 0.0;
      if (!(in >> word >> g) || word != "gamma" || (in >> extra) || !(g > 0.0) ||
          !std::isfinite(float(g)))
        fail(el, fmt::format("{}: \"string encoding\" \"{}\": unknown encoding (want \"sRGB\", "
                             "\"linear\" or \"gamma <value>\" with a value > 0)",
                             p.what(), printable(*e)));
      enc = ImageEncoding::Gamma;
      gamma = float(g);
    }
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".png") {
      td.encoding = enc;
      td.gamma = gamma;
    }
  }
  double scale = p.get_float("scale", 1.0);
  if (!(scale >= 0.0) || !std::isfinite(float(scale)))
    fail(p.find("scale")->loc,
         fmt::format("{}: \"float scale\": must be >= 0 and a finite float", p.what()));
  td.scale = make_float3(float(scale), float(scale), float(scale));
  if (p.get_bool("invert", false))
    warn(p.find("invert")->loc,
         fmt::format("{}: \"bool invert\" true (1 - value) is not supported, ignored", p.what()));
  // pbrt-v4's filters: point, bilinear (its default), trilinear, EWA; maxanisotropy only matters
  // to EWA, so with bilinear filtering it changes nothing in pbrt either.
  std::string filter = p.get_string("filter").value_or("bilinear");
  double aniso = p.get_float("maxanisotropy", 8.0);
  if (filter != "bilinear")
    warn(p.find("filter")->loc,
         fmt::format("{}: \"string filter\" \"{}\"{}: Canopy filters bilinearly, ignored", p.what(),
                     printable(filter),
                     p.find("maxanisotropy") ? fmt::format(" (maxanisotropy {})", aniso) : ""));
  std::string mapping = p.get_string("mapping").value_or("uv");
  if (mapping != "uv") {
    warn(p.find("mapping")->loc,
         fmt::format("{}: \"string mapping\" \"{}\": only \"uv\" mapping is supported (uv used), "
                     "ignored",
                     p.what(), printable(mapping)));
    for (const char* planar : {"v1", "v2"}) // the planar mapping's vectors
      p.find(planar);
  }
  double uvm[4] = {p.get_float("uscale", 1.0), p.get_float("vscale", 1.0),
                   p.get_float("udelta", 0.0), p.get_float("vdelta", 0.0)};
  for (double x : uvm)
    if (!std::isfinite(float(x)))
      fail(loc, fmt::format("{}: uscale, vscale, udelta, vdelta: a value is too large", p.what()));
  td.uvmap = make_float4(float(uvm[0]), float(uvm[1]), float(uvm[2]), float(uvm[3]));
  return t;
}

std::optional<NamedTexture> Reader::texture_param(Params& p, std::string_view name, bool is_float) {
  Param* q = p.find(name);
  if (!q) return std::nullopt;
  if (q->type == "texture") {
    if (q->strs.size() != 1)
      fail(q->loc, fmt::format("{}: \"texture {}\": wrong count of values ({}; want 1)", p.what(),
                               printable(q->name), q->strs.size()));
    const auto& named = is_float ? float_textures_ : spectrum_textures_;
    auto it = named.find(q->strs[0]);
    if (it == named.end()) {
      const auto& other = is_float ? spectrum_textures_ : float_textures_;
      fail(q->loc,
           fmt::format("{}: \"texture {}\": no {} texture named \"{}\"{}", p.what(),
                       printable(q->name), is_float ? "float" : "spectrum", printable(q->strs[0]),
                       other.count(q->strs[0])
                           ? fmt::format(" (\"{}\" is a {} texture)", printable(q->strs[0]),
                                         is_float ? "spectrum" : "float")
                           : ""));
    }
    return it->second;
  }
  NamedTexture t;
  t.kind = NamedTexture::Kind::Constant;
  if (is_float) {
    float v = to_float(p.get_float(name, 1.0));
    t.value = make_float3(v, v, v);
  } else {
    t.value = p.spectrum(name, Params::Use::Reflectance).value_or(make_float3(1, 1, 1));
  }
  return t;
}

int Reader::texture_index(const NamedTexture& t, int channels, int map) {
  std::string key = fmt::format("{}{}{}\n{}", channels == 1 ? 'f' : 's', channels, map, t.name);
  if (auto it = texture_indices_.find(key); it != texture_indices_.end()) return it->second;
  TextureDesc td = t.desc;
  td.channels = channels;
  td.map = map;
  int id = add_texture(scene_, std::move(td));
  texture_indices_.emplace(key, id);
  return id;
}

// The format page, "Materials". Returns the index of the new scene material.
int Reader::material(const Loc& loc, Params& p, const std::string& type, const std::string& name) {
  // pbrt-v4 TrowbridgeReitzDistribution::RoughnessToAlpha is alpha = sqrt(roughness), applied
  // when remaproughness is true (the default); Canopy's roughness r means alpha = r^2
  // (scene.h conductor_material). So Canopy's r is roughness^(1/4) when remapped and
  // sqrt(roughness) otherwise. Alpha above 1 is beyond Canopy's range and is clamped.
  // A roughness image texture sets *alpha_texture instead (map TEXTURE_MAP_ALPHA_SQRT, or
  // TEXTURE_MAP_VALUE without remapping); the returned constant is then unused.
  using K = NamedTexture::Kind;
  int albedo_texture = 0, alpha_texture = 0;
  auto roughness = [&]() -> float {
    // pbrt-v4: uroughness and vroughness, each defaulting to roughness (itself 0).
    struct Rough {
      double value = 0.0;
      const NamedTexture* image = nullptr; // in float_textures_ (stable)
      const Param* param = nullptr;
    };
    auto get = [&](const char* key) -> std::optional<Rough> {
      Param* q = p.find(key);
      if (!q) return std::nullopt;
      if (q->type != "texture") return Rough{p.get_float(key, 0.0), nullptr, q};
      std::optional<NamedTexture> t = texture_param(p, key, true);
      if (t->kind == K::Image) return Rough{0.0, &float_textures_.at(q->strs[0]), q};
      return Rough{t->kind == K::Constant ? double(t->value.x) : 0.0, nullptr, q};
    };
    Rough r = get("roughness").value_or(Rough{});
    Rough u = get("uroughness").value_or(r), v = get("vroughness").value_or(r);
    bool remap = p.get_bool("remaproughness", true);
    if (u.image || v.image) {
      const Rough& used = u.image ? u : v;
      if (u.image != v.image || u.value != v.value)
        warn(used.param->loc,
             fmt::format("{}: uroughness and vroughness differ: Canopy's GGX is isotropic, the "
                         "texture \"{}\" used, anisotropy ignored",
                         p.what(), printable(used.image->name)));
      alpha_texture =
          texture_index(*used.image, 1, remap ? TEXTURE_MAP_ALPHA_SQRT : TEXTURE_MAP_VALUE);
      return 0.0f;
    }
    if (u.value != v.value)
      warn(u.param ? u.param->loc : v.param->loc,
           fmt::format("{}: uroughness {} != vroughness {}: Canopy's GGX is isotropic, their mean "
                       "used, anisotropy ignored",
                       p.what(), u.value, v.value));
    double rr = 0.5 * (u.value + v.value);
    if (!(rr >= 0.0)) fail(loc, fmt::format("{}: roughness must be >= 0", p.what()));
    double alpha = remap ? std::sqrt(rr) : rr;
    if (alpha > 1.0) {
      warn(loc,
           fmt::format("{}: GGX alpha {} > 1 clamped to 1, the excess ignored", p.what(), alpha));
      alpha = 1.0;
    }
    return float(std::sqrt(alpha));
  };
  auto clamp01 = [](float3 c) {
    // pbrt-v4 clamps reflectances to [0, 1] (DiffuseMaterial, CoatedDiffuseMaterial).
    return make_float3(std::min(c.x, 1.0f), std::min(c.y, 1.0f), std::min(c.z, 1.0f));
  };
  auto albedo = [&](const char* key) {
    const float3 def = make_float3(0.5f, 0.5f, 0.5f);
    if (Param* q = p.find(key); q && q->type == "texture") {
      std::optional<NamedTexture> t = texture_param(p, key, false);
      if (t->kind == K::Image)
        albedo_texture = texture_index(spectrum_textures_.at(q->strs[0]), 3, TEXTURE_MAP_VALUE);
      return t->kind == K::Constant ? clamp01(t->value) : def;
    }
    return clamp01(p.spectrum(key, Params::Use::Reflectance).value_or(def));
  };
  std::string mname = name.empty() ? fmt::format("pbrt:{}:{}", *loc.file, loc.line) : name;
  for (const char* skip : {"displacement", "normalmap"})
    if (Param* q = p.find(skip))
      warn(q->loc, fmt::format("{}: \"{} {}\" ignored", p.what(), q->type, skip));
  MaterialDesc md;
  if (type == "diffuse") {
    md = diffuse_material(mname, albedo("reflectance"));
  } else if (type == "conductor") {
    float r = roughness();
    float3 eta, k;
    // A textured "reflectance": only a constant texture is read (an image warns, and the
    // default conductor, eta and k, is used).
    std::optional<float3> refl;
    if (Param* q = p.find("reflectance"); q && q->type == "texture") {
      std::optional<NamedTexture> t = texture_param(p, "reflectance", false);
      if (t->kind == K::Constant)
        refl = clamp01(t->value);
      else if (t->kind == K::Image)
        warn(q->loc, fmt::format("{}: \"texture reflectance\" \"{}\": Canopy's conductor takes no "
                                 "reflectance image (eta and k used), ignored",
                                 p.what(), printable(q->strs[0])));
    } else if (q) {
      refl = albedo("reflectance");
    }
    if (refl) {
      // pbrt-v4 ConductorMaterial with "reflectance": eta = 1, k = 2 sqrt(r) / sqrt(1 - r),
      // the index whose normal-incidence Fresnel reflectance is r.
      float3 c = *refl;
      auto kk = [](float x) {
        x = std::clamp(x, 0.0f, 0.9999f);
        return 2.0f * std::sqrt(x) / std::sqrt(1.0f - x);
      };
      eta = make_float3(1, 1, 1);
      k = make_float3(kk(c.x), kk(c.y), kk(c.z));
    } else {
      // Named spectra "metal-<X>-eta"/"metal-<X>-k" (pbrt-v4 spectrum.cpp) map to Canopy's
      // measured presets (metal_presets.cpp); copper is pbrt's default conductor.
      auto preset_of = [&](const std::string& spec, const char* which) -> const MetalPreset* {
        static const std::map<std::string, std::string> m = {
            {"Au", "gold"}, {"Ag", "silver"}, {"Cu", "copper"}, {"Al", "aluminium"}};
        std::string pre = "metal-", suf = std::string("-") + which;
        if (spec.size() > pre.size() + suf.size() && spec.rfind(pre, 0) == 0 &&
            spec.compare(spec.size() - suf.size(), suf.size(), suf) == 0) {
          auto it = m.find(spec.substr(pre.size(), spec.size() - pre.size() - suf.size()));
          if (it != m.end()) return find_metal_preset(it->second);
        }
        warn(p.find(which)->loc,
             fmt::format("{}: spectrum \"{}\" has no Canopy preset (gold, silver, copper, "
                         "aluminium): copper used, the spectrum ignored",
                         p.what(), printable(spec)));
        return find_metal_preset("copper");
      };
      const MetalPreset* cu = find_metal_preset("copper");
      eta = make_float3(cu->eta[0], cu->eta[1], cu->eta[2]);
      k = make_float3(cu->k[0], cu->k[1], cu->k[2]);
      std::string named;
      if (auto e = p.spectrum("eta", Params::Use::Reflectance, &named)) {
        eta = *e;
      } else if (!named.empty()) {
        const MetalPreset* pr = preset_of(named, "eta");
        eta = make_float3(pr->eta[0], pr->eta[1], pr->eta[2]);
      }
      named.clear();
      if (auto e = p.spectrum("k", Params::Use::Reflectance, &named)) {
        k = *e;
      } else if (!named.empty()) {
        const MetalPreset* pr = preset_of(named, "k");
        k = make_float3(pr->k[0], pr->k[1], pr->k[2]);
      }
      auto in = [](float3 c, float lo, float hi) {
        return c.x >= lo && c.y >= lo && c.z >= lo && c.x <= hi && c.y <= hi && c.z <= hi;
      };
      if (!in(eta, kMinConductorEta, kMaxConductorIndex))
        fail(loc, fmt::format("{}: eta must be in [{}, {}]", p.what(), kMinConductorEta,
                              kMaxConductorIndex));
      if (!in(k, 0.0f, kMaxConductorIndex))
        fail(loc, fmt::format("{}: k must be in [0, {}]", p.what(), kMaxConductorIndex));
    }
    md = conductor_material(mname, r, eta, k);
  } else if (type == "coateddiffuse") {
    // pbrt-v4 CoatedDiffuse is a dielectric coat (index eta) over a Lambertian base, with light
    // bouncing between the two simulated stochastically. Canopy's plastic is the same pair of
    // lobes added without that coupling: the specular GGX lobe with the coat's Fresnel
    // reflectance and roughness matches; the diffuse part is lighter and less saturated than
    // pbrt's (which loses energy to the coat's internal reflection and tints it by repeated
    // bounces). The coat medium (albedo, thickness, g) is not modelled.
    float3 kd = albedo("reflectance");
    float r = roughness();
    double eta = kDefaultPlasticIor;
    if (Param* q = p.find("eta")) {
      if (q->type == "float") {
        eta = p.get_float("eta", kDefaultPlasticIor);
        if (!(eta >= 1.0 && eta <= kMaxPlasticIor))
          fail(q->loc,
               fmt::format("{}: \"float eta\": must be in [1, {}]", p.what(), kMaxPlasticIor));
      } else {
        warn(q->loc,
             fmt::format("{}: a spectral \"eta\" ({} used) ignored", p.what(), kDefaultPlasticIor));
      }
    }
    if (Param* q = p.find("albedo"))
      warn(q->loc, fmt::format("{}: \"albedo\" of the coat medium ignored", p.what()));
    for (const char* skip : {"thickness", "g", "maxdepth", "nsamples"})
      if (Param* q = p.find(skip))
        warn(q->loc, fmt::format("{}: \"{}\" (the coat's random walk) ignored", p.what(), skip));
    md = plastic_material(mname, kd, make_float3(1, 1, 1), r, float(eta));
  } else {
    warn(loc, fmt::format("Material \"{}\" is not read in this slice (diffuse 0.5 used), ignored",
                          printable(type)));
    scene_.materials.push_back(diffuse_material(mname, make_float3(0.5f, 0.5f, 0.5f)));
    return int(scene_.materials.size()) - 1;
  }
  p.find("type"); // MakeNamedMaterial's type is read by the caller
  p.finish();
  md.gpu.albedo_texture = albedo_texture;
  md.gpu.alpha_texture = alpha_texture;
  scene_.materials.push_back(md);
  return int(scene_.materials.size()) - 1;
}

Scene load(const std::string& text, const std::string& name, const std::filesystem::path& dir,
           const std::filesystem::path* file, const SceneLoadOptions& options) {
  Scene scene;
  scene.path = name;
  // pbrt-v4's defaults: a 1280 x 720 film and a diffuse material of reflectance 0.5.
  scene.film.width = 1280;
  scene.film.height = 720;
  scene.materials.push_back(diffuse_material("default", make_float3(0.5f, 0.5f, 0.5f)));
  Reader r(scene, name, dir, options);
  if (file)
    r.run_file(*file, name, nullptr);
  else
    r.run_text(text, name, dir);
  r.finish();
  return scene;
}

Scene guarded(const std::string& name, const std::function<Scene()>& f) {
  try {
    return f();
  } catch (const std::bad_alloc&) {
    throw SceneError(fmt::format("{}: out of memory while building the scene", name));
  } catch (const std::length_error&) {
    throw SceneError(fmt::format("{}: out of memory while building the scene", name));
  }
}

} // namespace

Scene load_pbrt_scene(const std::filesystem::path& file, const SceneLoadOptions& options) {
  std::string name = printable(file.string(), 1024);
  Scene s = guarded(name, [&] { return load({}, name, file.parent_path(), &file, options); });
  s.path = file;
  return s;
}

Scene load_pbrt_scene_from_string(const std::string& text, const std::string& name,
                                  const std::filesystem::path& base_dir,
                                  const SceneLoadOptions& options) {
  return guarded(name, [&] { return load(text, name, base_dir, nullptr, options); });
}

} // namespace canopy
