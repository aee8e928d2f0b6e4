// pbrt-v4 reader: the parameter lists of directives (the format page, "Parameter lists"), read
// and checked against their declared types, and the typed getters the directives use.
#pragma once

#include "scene/pbrt/lexer.h"
#include "scene/scene.h"

#include <fmt/format.h>

#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace canopy::pbrt {

// One "type name" value list of a directive (the format page, "Parameter lists").
struct Param {
  std::string type, name;
  Loc loc;
  std::vector<double> nums;
  std::vector<std::string> strs; // string, texture, bool and named-spectrum values
  bool used = false;
};

// Reads the parameter list up to the next directive; checks each value against its declared
// type.
std::vector<Param> parse_params(Lexer& lx);

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

} // namespace canopy::pbrt
