// The materials of a pbrt-v4 file: Material and MakeNamedMaterial.
#include "scene/metal_presets.h"
#include "scene/pbrt/reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace canopy::pbrt {

// A dielectric's "eta": a float, or one of pbrt-v4's named glass spectra as its index at 550 nm
// (pbrt-v4 spectrum.cpp's tables; Canopy renders in RGB, so without dispersion: warned).
// Default 1.5, as pbrt-v4's.
float Reader::dielectric_eta(Params& p) {
  Param* q = p.find("eta");
  if (!q) return 1.5f;
  if (q->type == "float") {
    double eta = p.get_float("eta", 1.5);
    if (!(eta >= kMinDielectricIor && eta <= kMaxDielectricIor))
      fail(q->loc, fmt::format("{}: \"float eta\": must be in [{}, {}]", p.what(),
                               kMinDielectricIor, kMaxDielectricIor));
    return float(eta);
  }
  static const std::map<std::string, float> glass = {
      {"glass-BK7", 1.51854f},   {"glass-BAF10", 1.67305f}, {"glass-FK51A", 1.48780f},
      {"glass-LASF9", 1.85581f}, {"glass-F5", 1.67709f},    {"glass-F10", 1.73357f},
      {"glass-F11", 1.79112f}};
  std::string named;
  if (q->type == "spectrum" && !q->strs.empty()) {
    named = q->strs[0];
    auto it = glass.find(named);
    if (it != glass.end()) {
      warn(q->loc, fmt::format("{}: \"spectrum eta\" \"{}\": its index at 550 nm, {}, used "
                               "(no dispersion)",
                               p.what(), named, it->second));
      return it->second;
    }
  }
  warn(q->loc, fmt::format("{}: \"{} eta\"{}: not a float or a named glass, 1.5 used", p.what(),
                           q->type, named.empty() ? "" : " \"" + printable(named) + "\""));
  return 1.5f;
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
  // `prefix`: "" or pbrt-v4's "interface." / "conductor." of coatedconductor; a texture is read
  // only where `textured` (the material's one alpha texture), else warned about.
  auto roughness = [&](const std::string& prefix = "", bool textured = true) -> float {
    // pbrt-v4: uroughness and vroughness, each defaulting to roughness (itself 0).
    struct Rough {
      double value = 0.0;
      const NamedTexture* image = nullptr; // in float_textures_ (stable)
      const Param* param = nullptr;
    };
    auto get = [&](const std::string& k) -> std::optional<Rough> {
      const std::string key = prefix + k;
      Param* q = p.find(key);
      if (!q) return std::nullopt;
      if (q->type != "texture") return Rough{p.get_float(key, 0.0), nullptr, q};
      std::optional<NamedTexture> t = texture_param(p, key, true);
      if (t->kind == K::Image && !textured) {
        warn(q->loc, fmt::format("{}: \"texture {}\": an image only for the coat's roughness, "
                                 "0 used",
                                 p.what(), key));
        return Rough{0.0, nullptr, q};
      }
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
  // A conductor's index eta + i k (pbrt-v4 ConductorMaterial; `prefix` "conductor." for
  // coatedconductor): its "reflectance" if given, else its eta and k (named metal spectra map to
  // Canopy's presets), copper by default.
  auto conductor_index = [&](const std::string& prefix, float3& eta, float3& k) {
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
      // measured presets (metal_presets.cpp); another name is a spectrum file; copper is pbrt's
      // default conductor.
      auto named_value = [&](const std::string& spec, const std::string& key,
                             bool is_eta) -> float3 {
        static const std::map<std::string, std::string> m = {
            {"Au", "gold"}, {"Ag", "silver"}, {"Cu", "copper"}, {"Al", "aluminium"}};
        std::string pre = "metal-", suf = is_eta ? "-eta" : "-k";
        const MetalPreset* pr = nullptr;
        if (spec.size() > pre.size() + suf.size() && spec.rfind(pre, 0) == 0 &&
            spec.compare(spec.size() - suf.size(), suf.size(), suf) == 0) {
          auto it = m.find(spec.substr(pre.size(), spec.size() - pre.size() - suf.size()));
          if (it != m.end()) pr = find_metal_preset(it->second);
        }
        if (!pr) {
          const Loc& at = p.find(key)->loc;
          if (auto v = spectrum_file(at, p.what(), spec)) return *v;
          warn(at, fmt::format("{}: spectrum \"{}\" is no Canopy preset (gold, silver, copper, "
                               "aluminium) and no file: copper used, the spectrum ignored",
                               p.what(), printable(spec)));
          pr = find_metal_preset("copper");
        }
        const float* c = is_eta ? pr->eta : pr->k;
        return make_float3(c[0], c[1], c[2]);
      };
      const MetalPreset* cu = find_metal_preset("copper");
      eta = make_float3(cu->eta[0], cu->eta[1], cu->eta[2]);
      k = make_float3(cu->k[0], cu->k[1], cu->k[2]);
      std::string named;
      if (auto e = p.spectrum(prefix + "eta", Params::Use::Reflectance, &named))
        eta = *e;
      else if (!named.empty())
        eta = named_value(named, prefix + "eta", true);
      named.clear();
      if (auto e = p.spectrum(prefix + "k", Params::Use::Reflectance, &named))
        k = *e;
      else if (!named.empty())
        k = named_value(named, prefix + "k", false);
      auto in = [](float3 c, float lo, float hi) {
        return c.x >= lo && c.y >= lo && c.z >= lo && c.x <= hi && c.y <= hi && c.z <= hi;
      };
      if (!in(eta, kMinConductorEta, kMaxConductorIndex))
        fail(loc, fmt::format("{}: eta must be in [{}, {}]", p.what(), kMinConductorEta,
                              kMaxConductorIndex));
      if (!in(k, 0.0f, kMaxConductorIndex))
        fail(loc, fmt::format("{}: k must be in [0, {}]", p.what(), kMaxConductorIndex));
    }
  };
  MaterialDesc md;
  if (type == "diffuse") {
    md = diffuse_material(mname, albedo("reflectance"));
  } else if (type == "conductor") {
    float r = roughness();
    float3 eta, k;
    conductor_index("", eta, k);
    md = conductor_material(mname, r, eta, k);
  } else if (type == "coateddiffuse" || type == "coatedconductor") {
    // pbrt-v4's layered materials: a dielectric coat over a Lambertian or conductor base, with a
    // random walk between them (cl/bsdf/layered.h), with pbrt-v4's parameters and defaults.
    const bool conductor = type == "coatedconductor";
    // (the reflectance first: its texture is registered before the roughness's, as for diffuse)
    const float3 kd = conductor ? make_float3(0, 0, 0) : albedo("reflectance");
    float r = roughness(conductor ? "interface." : "");
    double eta = kDefaultPlasticIor;
    const std::string eta_key = conductor ? "interface.eta" : "eta";
    if (Param* q = p.find(eta_key)) {
      if (q->type == "float") {
        eta = p.get_float(eta_key, kDefaultPlasticIor);
        if (!(eta >= 1.0 && eta <= kMaxPlasticIor))
          fail(q->loc, fmt::format("{}: \"float {}\": must be in [1, {}]", p.what(), eta_key,
                                   kMaxPlasticIor));
      } else {
        warn(q->loc, fmt::format("{}: a spectral \"{}\" ({} used) ignored", p.what(), eta_key,
                                 kDefaultPlasticIor));
      }
    }
    CoatLayer layer;
    double thickness = p.get_float("thickness", 0.01), g = p.get_float("g", 0.0);
    if (!(thickness >= 0.0 && thickness <= 1e4))
      fail(loc, fmt::format("{}: \"float thickness\": must be in [0, 10000]", p.what()));
    if (!(g >= -1.0 && g <= 1.0))
      fail(loc, fmt::format("{}: \"float g\": must be in [-1, 1]", p.what()));
    layer.thickness = float(thickness);
    layer.g = float(g);
    if (p.find("albedo"))
      layer.albedo =
          clamp01(p.spectrum("albedo", Params::Use::Reflectance).value_or(make_float3(0, 0, 0)));
    int depth = 10, samples = 1;
    if (Param* q = p.one("maxdepth", {"integer"})) {
      if (!(q->nums[0] >= 1 && q->nums[0] <= 1000))
        fail(q->loc, fmt::format("{}: \"integer maxdepth\": must be in [1, 1000]", p.what()));
      depth = int(q->nums[0]);
    }
    if (Param* q = p.one("nsamples", {"integer"})) {
      if (!(q->nums[0] >= 1 && q->nums[0] <= 64))
        fail(q->loc, fmt::format("{}: \"integer nsamples\": must be in [1, 64]", p.what()));
      samples = int(q->nums[0]);
    }
    layer.max_depth = depth;
    layer.n_samples = samples;
    if (conductor) {
      float rc = roughness("conductor.", false);
      float3 ceta, ck;
      conductor_index("conductor.", ceta, ck);
      md = coated_conductor_material(mname, r * r, float(eta), ceta, ck, rc * rc, layer);
    } else {
      md = coated_diffuse_material(mname, kd, r * r, float(eta), layer);
    }
  } else if (type == "dielectric" || type == "thindielectric") {
    const bool thin = type == "thindielectric";
    float ior = dielectric_eta(p);
    // pbrt-v4's thin dielectric is smooth; the dielectric may be rough (GGX).
    float r = thin ? 0.0f : roughness();
    md = dielectric_material(mname, ior, thin, r * r);
  } else if (type == "diffusetransmission") {
    // pbrt-v4's DiffuseTransmissionMaterial: R / pi on wo's side, T / pi on the other, with
    // R = clamp(scale reflectance) and T = clamp(scale transmittance), both 0.25 by default.
    double scale = p.get_float("scale", 1.0);
    if (!(scale >= 0.0) || !std::isfinite(float(scale)))
      fail(p.find("scale")->loc,
           fmt::format("{}: \"float scale\": must be >= 0 and a finite float", p.what()));
    const float k = float(scale);
    int transmittance_texture = 0;
    auto value = [&](const char* key, int* tex) {
      const float3 def = make_float3(0.25f, 0.25f, 0.25f);
      if (Param* q = p.find(key); q && q->type == "texture") {
        std::optional<NamedTexture> t = texture_param(p, key, false);
        if (t->kind == K::Image)
          *tex = texture_index(scaled_texture(q->loc, *t, k, false), 3, TEXTURE_MAP_VALUE);
        return clamp01((t->kind == K::Constant ? t->value : def) * k);
      }
      return clamp01(p.spectrum(key, Params::Use::Reflectance).value_or(def) * k);
    };
    float3 r = value("reflectance", &albedo_texture);
    float3 t = value("transmittance", &transmittance_texture);
    md = diffuse_transmission_material(mname, r, t);
    md.gpu.transmittance_texture = transmittance_texture;
  } else if (type == "mix") {
    // pbrt-v4's MixMaterial: two named materials, the second chosen with probability `amount`
    // (cl/material_mix.h).
    Param* q = p.find("materials");
    if (!q || q->type != "string" || q->strs.size() != 2)
      fail(q ? q->loc : loc,
           fmt::format("{}: needs \"string materials\" with two material names", p.what()));
    int parts[2];
    for (int i = 0; i < 2; ++i) {
      auto it = named_materials_.find(q->strs[size_t(i)]);
      if (it == named_materials_.end())
        fail(q->loc, fmt::format("{}: \"string materials\": no material named \"{}\"", p.what(),
                                 printable(q->strs[size_t(i)])));
      if (interface_materials_.count(it->second))
        fail(q->loc, fmt::format("{}: \"string materials\": \"{}\" is an interface, which a "
                                 "mix cannot hold",
                                 p.what(), printable(q->strs[size_t(i)])));
      parts[i] = it->second;
    }
    if (mix_depth(scene_.materials, parts[0]) >= MATERIAL_MIX_MAX_DEPTH ||
        mix_depth(scene_.materials, parts[1]) >= MATERIAL_MIX_MAX_DEPTH)
      fail(loc,
           fmt::format("{}: mixes nested more than {} deep", p.what(), MATERIAL_MIX_MAX_DEPTH));
    float amount = 0.5f;
    int amount_texture = 0;
    if (Param* a = p.find("amount"); a && a->type == "texture") {
      std::optional<NamedTexture> t = texture_param(p, "amount", true);
      if (t->kind == K::Image)
        amount_texture = texture_index(*t, 1, TEXTURE_MAP_VALUE);
      else if (t->kind == K::Constant)
        amount = t->value.x;
    } else if (a) {
      amount = to_float(p.get_float("amount", 0.5));
    }
    md = mix_material(mname, parts[0], parts[1], amount);
    md.gpu.mix_amount_texture = amount_texture;
    p.find("type");
    p.finish();
    scene_.materials.push_back(md);
    return int(scene_.materials.size()) - 1;
  } else if (type == "interface") {
    // pbrt-v4's interface bounds a medium and is otherwise invisible: its shapes are not added
    // (media.cpp renders the medium's extent).
    md = diffuse_material(mname, make_float3(0, 0, 0));
    interface_materials_.insert(int(scene_.materials.size()));
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

} // namespace canopy::pbrt
