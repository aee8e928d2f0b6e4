// The lights of a pbrt-v4 file: LightSource (point, spot, distant, infinite) and the
// AreaLightSource that the following shapes emit with.
#include "scene/pbrt/reader.h"
#include "scene/pbrt/transforms.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <system_error>

namespace canopy::pbrt {

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
    scene_.environment_maps.push_back(
        {file, ENV_OCTAHEDRAL, fmt::format("{}:{}: {}", *d.loc.file, d.loc.line, p.what())});
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

} // namespace canopy::pbrt
