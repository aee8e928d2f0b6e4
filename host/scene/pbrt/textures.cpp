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

} // namespace canopy::pbrt
