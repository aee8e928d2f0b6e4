#include "scene/pbrt/params.h"

#include "scene/pbrt/reader.h"
#include "scene/pbrt_reader.h"

#include <fmt/format.h>

#include <cmath>
#include <set>

namespace canopy::pbrt {

using namespace detail;

namespace {

bool is_numeric_type(const std::string& t) {
  static const std::set<std::string> k = {"integer", "float",   "point2",  "vector2",
                                          "point3",  "vector3", "normal3", "normal",
                                          "point",   "vector",  "rgb",     "blackbody"};
  return k.count(t) > 0;
}

} // namespace

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

} // namespace canopy::pbrt
