// Participating media of a pbrt-v4 file: MakeNamedMedium, MediumInterface, the camera's medium and
// the "interface" material, mapped to Canopy's one homogeneous medium (cl/types.h Medium: all
// space, or an axis-aligned box) with objects that exclude it (Material::excludes_medium).
//
// pbrt-v4 gives each shape an inside and an outside medium and the camera the outside medium
// current at its Camera directive; a ray takes the medium of the side it leaves a surface on.
// Canopy renders the configurations of pbrt-v4's scenes exactly where they are one medium M and
// vacuum:
// - the camera in M: M fills all space (a shape whose outside is M bounds something else);
// - the camera in vacuum, M entered through surfaces: M fills the bounding box of the scene's
//   geometry (pbrt's walls of a box of fog; an approximation elsewhere: warned);
// - a shape with vacuum inside and M outside (glass in fog): its material excludes the medium, so
//   a path refracted into it travels without M until it leaves.
// A second medium, other medium types and emission are warned about and not rendered; as pbrt-v4,
// an integrator other than volpath, simplevolpath, bdpt or mlt renders no medium.
#include "scene/pbrt/reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cfloat>

namespace canopy::pbrt {

void Reader::make_named_medium(const Token& d, Params& p, const std::string& name) {
  auto t = p.get_string("type");
  if (!t) fail(d.loc, fmt::format("{}: needs a \"string type\" parameter", p.what()));
  if (media_.count(name))
    fail(d.loc, fmt::format("MakeNamedMedium: \"{}\" is defined twice", printable(name)));
  NamedMedium m;
  m.loc = d.loc;
  if (*t != "homogeneous") {
    warn(d.loc, fmt::format("{}: medium type \"{}\" is not rendered (Canopy's media are "
                            "homogeneous): vacuum used",
                            p.what(), printable(*t)));
    p.mark_all_used();
    media_[name] = m;
    return;
  }
  m.homogeneous = true;
  if (Param* q = p.find("preset"))
    warn(q->loc, fmt::format("{}: \"preset\" (measured media) is not read: sigma_a and sigma_s "
                             "used",
                             p.what()));
  // pbrt-v4 HomogeneousMedium::Create: sigma_a and sigma_s default to 1, times "scale".
  float3 sa = p.spectrum("sigma_a", Params::Use::Reflectance).value_or(make_float3(1, 1, 1));
  float3 ss = p.spectrum("sigma_s", Params::Use::Reflectance).value_or(make_float3(1, 1, 1));
  double scale = p.get_float("scale", 1.0), g = p.get_float("g", 0.0);
  if (!(scale >= 0.0)) fail(d.loc, fmt::format("{}: \"float scale\": must be >= 0", p.what()));
  if (!(g > -1.0 && g < 1.0))
    fail(d.loc, fmt::format("{}: \"float g\": must be in (-1, 1)", p.what()));
  sa = sa * float(scale);
  ss = ss * float(scale);
  if (!(max3(sa + ss) <= kMaxMediumCoefficient))
    fail(d.loc, fmt::format("{}: sigma_a + sigma_s (times scale) must be <= {}", p.what(),
                            kMaxMediumCoefficient));
  if (auto le = p.spectrum("Le", Params::Use::Illuminant); le && max3(*le) > 0.0f)
    warn(p.find("Le")->loc,
         fmt::format("{}: \"Le\": Canopy's media do not emit, ignored", p.what()));
  p.get_float("Lescale", 1.0);
  m.medium.sigma_t = make_float4(sa.x + ss.x, sa.y + ss.y, sa.z + ss.z, float(g));
  m.medium.sigma_s = make_float4(ss.x, ss.y, ss.z, 0.0f);
  p.finish();
  media_[name] = m;
}

void Reader::medium_interface(const Token& d, const std::vector<std::string>& names) {
  for (const std::string& n : names)
    if (!n.empty() && !media_.count(n))
      fail(d.loc, fmt::format("MediumInterface: unknown medium \"{}\"", printable(n)));
  gs_.medium_inside = names[0];
  gs_.medium_outside = names.size() > 1 ? names[1] : names[0];
}

// The material a shape is added with: a copy that excludes the medium for a shape with vacuum
// inside and a medium outside.
int Reader::shape_material(const Loc& loc) {
  if (!gs_.medium_inside.empty() || gs_.medium_outside.empty()) {
    if (!gs_.medium_inside.empty() && !gs_.medium_outside.empty() &&
        gs_.medium_inside != gs_.medium_outside)
      warn(loc, fmt::format("a shape between two media (\"{}\" inside, \"{}\" outside): Canopy "
                            "renders one medium, the boundary ignored",
                            printable(gs_.medium_inside), printable(gs_.medium_outside)));
    return gs_.material;
  }
  media_used_.insert(gs_.medium_outside);
  auto [it, fresh] = excluding_materials_.try_emplace(gs_.material, 0);
  if (fresh) {
    MaterialDesc md = scene_.materials[size_t(gs_.material)];
    md.name += " (excludes the medium)";
    md.gpu.excludes_medium = 1;
    scene_.materials.push_back(md);
    it->second = int(scene_.materials.size()) - 1;
  }
  return it->second;
}

void Reader::finish_media() {
  for (const std::string& n : {gs_.medium_inside, gs_.medium_outside})
    if (!n.empty()) media_used_.insert(n); // (the state at the end stands for shapes' insides)
  if (!camera_medium_.empty()) media_used_.insert(camera_medium_);
  std::vector<std::string> used;
  for (const std::string& n : media_used_)
    if (media_.at(n).homogeneous) used.push_back(n);
  if (used.empty()) return;
  // The camera's medium first, else the first by name.
  std::string m = std::count(used.begin(), used.end(), camera_medium_) ? camera_medium_ : used[0];
  const NamedMedium& nm = media_.at(m);
  for (const std::string& n : used)
    if (n != m)
      warn(media_.at(n).loc, fmt::format("MakeNamedMedium \"{}\": Canopy renders one medium "
                                         "(\"{}\"): vacuum used",
                                         printable(n), printable(m)));
  if (!(max3(xyz_of(nm.medium.sigma_t)) > 0.0f)) return; // vacuum
  // pbrt-v4's "path" integrator (and the others but these) ignores media (cpu/render.cpp).
  if (integrator_ != "volpath" && integrator_ != "simplevolpath" && integrator_ != "bdpt" &&
      integrator_ != "mlt") {
    warn(nm.loc, fmt::format("MakeNamedMedium \"{}\": Integrator \"{}\" renders no media, as "
                             "in pbrt-v4: ignored",
                             printable(m), printable(integrator_)));
    return;
  }
  if (!scene_.infinite_lights.empty())
    fail(nm.loc, "a distant or environment light in a scene with a medium is not supported "
                 "(medium points would miss its light)");
  scene_.medium = nm.medium;
  scene_.has_medium = true;
  if (m == camera_medium_) return; // everywhere
  // Entered through surfaces: the box of the scene's geometry.
  float3 lo = make_float3(FLT_MAX, FLT_MAX, FLT_MAX), hi = lo * -1.0f;
  for (const float3& v : scene_.vertices) {
    lo = make_float3(std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z));
    hi = make_float3(std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z));
  }
  if (!(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z)) {
    warn(nm.loc, fmt::format("MakeNamedMedium \"{}\": the camera is outside it and the scene's "
                             "geometry bounds no volume: not rendered",
                             printable(m)));
    scene_.has_medium = false;
    return;
  }
  warn(nm.loc, fmt::format("MakeNamedMedium \"{}\": the camera is outside it; Canopy fills the "
                           "bounding box of the scene's geometry with it",
                           printable(m)));
  scene_.medium.sigma_s.w = 1.0f;
  scene_.medium.bmin = f4_from3(lo, 0.0f);
  scene_.medium.bmax = f4_from3(hi, 0.0f);
}

} // namespace canopy::pbrt
