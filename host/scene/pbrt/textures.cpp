// The textures of a pbrt-v4 file: the Texture directive and the texture-valued parameters of
// materials.
#include "scene/pbrt/reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <sstream>
#include <system_error>

namespace canopy::pbrt {

namespace {

using K = NamedTexture::Kind;

// The nodes of `t` as an input whose values are floats (is_float: an image is read as one channel,
// the mean of its colours) or rgb: its tree, its image or its constant.
std::vector<TextureDesc> texture_nodes(const NamedTexture& t, bool is_float) {
  if (!t.tree.empty()) return t.tree;
  TextureDesc d;
  if (t.kind == K::Constant) {
    d.kind = TEXTURE_CONSTANT;
    d.scale = t.value;
    return {d};
  }
  d = t.desc;
  d.kind = TEXTURE_IMAGE;
  d.nodes = 1;
  d.channels = is_float ? 1 : 3;
  d.map = TEXTURE_MAP_VALUE;
  return {d};
}

// The operator `kind` (TEXTURE_CHECKERBOARD, _MIX, _SCALE) over `inputs` (each a texture and
// whether it is a float input), as a tree in postfix order.
NamedTexture compose(int kind, const std::vector<std::pair<const NamedTexture*, bool>>& inputs,
                     float4 uvmap = make_float4(1, 1, 0, 0)) {
  NamedTexture t;
  t.kind = K::Image;
  t.stack = 0;
  for (size_t i = 0; i < inputs.size(); ++i) {
    std::vector<TextureDesc> n = texture_nodes(*inputs[i].first, inputs[i].second);
    t.tree.insert(t.tree.end(), n.begin(), n.end());
    t.stack = std::max(t.stack, int(i) + inputs[i].first->stack);
  }
  TextureDesc root;
  root.kind = kind;
  root.uvmap = uvmap;
  root.nodes = int(t.tree.size()) + 1;
  t.tree.push_back(root);
  return t;
}

} // namespace

// The format page, "Textures": `Texture "name" "float"|"spectrum" "class" params`. Canopy renders
// "imagemap" (pbrt-v4 FloatImageTexture / SpectrumImageTexture), "constant", and pbrt-v4's
// "checkerboard" (2D, uv mapping), "mix" and "scale" over those (cl/texture.h evaluates them as
// a tree; constants are folded, and a scale of an image by a constant goes into the image's
// scale, as pbrt-v4's FloatScaledTexture::Create does). Other classes warn here; a material using
// one keeps the parameter's constant default.
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
  } else if (cls == "scale" || cls == "mix" || cls == "checkerboard") {
    t = operator_texture(loc, p, name, cls, is_float);
  } else {
    static const std::set<std::string> known = {"bilerp", "directionmix", "dots",  "fbm",
                                                "marble", "ptex",         "windy", "wrinkled"};
    warn(loc, fmt::format("{}: {} texture class \"{}\" is not supported (a material using it "
                          "keeps its constant default), ignored",
                          p.what(), known.count(cls) ? "the" : "unknown", printable(cls)));
    p.mark_all_used();
  }
  if (t.stack > TEXTURE_STACK)
    fail(loc, fmt::format("{}: textures nested too deeply (the texture needs {} values at once, "
                          "Canopy evaluates at most {})",
                          p.what(), t.stack, TEXTURE_STACK));
  p.finish();
  t.name = name;
  named[name] = std::move(t);
}

float4 Reader::uv_mapping(const Loc& loc, Params& p) {
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
  return make_float4(float(uvm[0]), float(uvm[1]), float(uvm[2]), float(uvm[3]));
}

NamedTexture Reader::texture_input(Params& p, std::string_view name, bool is_float, float3 def) {
  NamedTexture c;
  c.kind = K::Constant;
  c.value = def;
  return texture_param(p, name, is_float).value_or(c);
}

NamedTexture Reader::operator_texture(const Loc& loc, Params& p, const std::string& name,
                                      const std::string& cls, bool is_float) {
  const float3 zero = make_float3(0, 0, 0), one = make_float3(1, 1, 1);
  NamedTexture t;
  if (cls == "scale") {
    // pbrt-v4 FloatScaledTexture / SpectrumScaledTexture: tex * scale, both textures (default 1).
    NamedTexture a = texture_input(p, "tex", is_float, one),
                 b = texture_input(p, "scale", true, one);
    if (a.kind == K::Unsupported || b.kind == K::Unsupported) return t; // warned where defined
    // An image (or any texture) times a constant: the constant folds into it (an image's scale).
    auto fold = [&](const NamedTexture& x, float k) {
      NamedTexture r = scaled_texture(loc, x, k, is_float);
      if (r.kind == K::Image && r.tree.empty())
        r.desc.where = fmt::format("{}:{}: texture \"{}\"", *loc.file, loc.line, printable(name));
      return r;
    };
    if (b.kind == K::Constant) return fold(a, b.value.x);
    if (a.kind == K::Constant && is_float) return fold(b, a.value.x); // float: both are scalars
    return compose(TEXTURE_SCALE, {{&a, is_float}, {&b, true}});
  }
  if (cls == "mix") {
    // pbrt-v4 FloatMixTexture / SpectrumMixTexture: (1 - amount) tex1 + amount tex2.
    NamedTexture a = texture_input(p, "tex1", is_float, zero),
                 b = texture_input(p, "tex2", is_float, one),
                 m = texture_input(p, "amount", true, make_float3(0.5f, 0.5f, 0.5f));
    if (a.kind == K::Unsupported || b.kind == K::Unsupported || m.kind == K::Unsupported) return t;
    if (a.kind == K::Constant && b.kind == K::Constant && m.kind == K::Constant) {
      t.kind = K::Constant;
      t.value = a.value * (1.0f - m.value.x) + b.value * m.value.x;
      return t;
    }
    return compose(TEXTURE_MIX, {{&a, is_float}, {&b, is_float}, {&m, true}});
  }
  // checkerboard: pbrt-v4 FloatCheckerboardTexture / SpectrumCheckerboardTexture, tex1 (default 1)
  // where floor(s) + floor(t) is even, tex2 (default 0) where it is odd.
  int dim = 2;
  if (Param* q = p.one("dimension", {"integer"})) {
    if (q->nums[0] != 2 && q->nums[0] != 3)
      fail(q->loc, fmt::format("{}: \"integer dimension\" {}: a checkerboard has 2 or 3 "
                               "dimensions",
                               p.what(), q->nums[0]));
    dim = int(q->nums[0]);
  }
  if (dim == 3) {
    warn(p.find("dimension")->loc,
         fmt::format("{}: a 3D checkerboard is not supported (a material using it keeps its "
                     "constant default), ignored",
                     p.what()));
    p.mark_all_used();
    return t;
  }
  NamedTexture a = texture_input(p, "tex1", is_float, one),
               b = texture_input(p, "tex2", is_float, zero);
  if (a.kind == K::Unsupported || b.kind == K::Unsupported) return t;
  return compose(TEXTURE_CHECKERBOARD, {{&a, is_float}, {&b, is_float}}, uv_mapping(loc, p));
}

NamedTexture Reader::scaled_texture(const Loc& loc, const NamedTexture& t, float k, bool is_float) {
  if (k == 1.0f || t.kind == K::Unsupported) return t;
  NamedTexture out = t;
  out.name = fmt::format("{}\n*{}", t.name, k); // its own Scene::textures entry
  if (t.kind == K::Constant) {
    out.value = t.value * k;
  } else if (t.tree.empty()) { // an image: into its scale
    out.desc.scale = t.desc.scale * k;
    out.desc.where = fmt::format("{}:{}: texture \"{}\"", *loc.file, loc.line, printable(t.name));
  } else {
    NamedTexture c;
    c.kind = K::Constant;
    c.value = make_float3(k, k, k);
    out = compose(TEXTURE_SCALE, {{&t, is_float}, {&c, true}});
    out.name = fmt::format("{}\n*{}", t.name, k);
  }
  return out;
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
  td.uvmap = uv_mapping(loc, p);
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
  int id = 0;
  if (!t.tree.empty()) {
    for (size_t i = 0; i < t.tree.size(); ++i) {
      TextureDesc td = t.tree[i];
      if (i + 1 == t.tree.size()) td.map = map;
      id = add_texture(scene_, std::move(td));
    }
  } else {
    TextureDesc td = t.desc;
    td.channels = channels;
    td.map = map;
    id = add_texture(scene_, std::move(td));
  }
  texture_indices_.emplace(key, id);
  return id;
}

} // namespace canopy::pbrt
