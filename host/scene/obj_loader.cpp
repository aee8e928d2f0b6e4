// OBJ + MTL meshes via tinyobjloader. An MTL material becomes a diffuse or plastic material named
// after it (mtl_to_material: Kd, Ks, Ns, Ni, illum); MTL Ke > 0 makes the material's triangles
// emitters (radiance Ke); map_Kd makes an albedo texture, map_Pr a roughness texture of a plastic
// (mtl_texture). Vertex normals (vn) become shading normals, texture coordinates (vt) the mesh's
// uv.
#include "scene/loader_internal.h"

#include <fmt/format.h>
#include <tiny_obj_loader.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

namespace canopy::detail {

namespace {

// tinyobjloader reads a missing or unparsable number as 0 ("v 1" is the vertex (1, 0, 0), "v nan 0
// 0" the origin) and triangulates a polygon in time quadratic in its vertex count. The text is
// therefore checked first, line by line: every number of a v / vn / vt line must parse completely
// and be finite, a v line needs at least 3 numbers, vn 3 and vt 1, and a face has at most
// kMaxPolygonVertices vertices. A scan is simpler and cheaper than a second parser, and it knows
// the line number for the message.
void check_obj_text(const std::string& text, const std::string& prefix) {
  size_t line_no = 0;
  std::vector<std::string_view> tok;
  for (size_t pos = 0; pos < text.size();) {
    size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) eol = text.size();
    std::string_view line(text.data() + pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    if (auto h = line.find('#'); h != std::string_view::npos) line = line.substr(0, h);
    tok.clear();
    for (size_t i = 0; i < line.size();) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r'))
        ++i;
      size_t j = i;
      while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r')
        ++j;
      if (j > i) tok.push_back(line.substr(i, j - i));
      i = j;
    }
    if (tok.empty()) continue;
    auto fail = [&](const std::string& problem) {
      throw SceneError(fmt::format("{}line {}: {}", prefix, line_no, problem));
    };
    if (tok[0] == "f") {
      if (tok.size() - 1 > size_t(kMaxPolygonVertices))
        fail(fmt::format("a face with {} vertices (the limit is {}, docs/limits.md)",
                         tok.size() - 1, kMaxPolygonVertices));
      continue;
    }
    size_t need = tok[0] == "v" ? 3 : tok[0] == "vn" ? 3 : tok[0] == "vt" ? 1 : 0;
    if (need == 0) continue;
    if (tok.size() - 1 < need)
      fail(fmt::format("'{}' needs {} numbers, found {}", tok[0], need, tok.size() - 1));
    for (size_t k = 1; k < tok.size(); ++k) {
      std::string_view t = tok[k];
      if (t.size() > 1 && t[0] == '+' && t[1] != '-') t.remove_prefix(1); // from_chars: no '+'
      double d = 0.0;
      auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), d);
      if (ec != std::errc() || end != t.data() + t.size() || !std::isfinite(d) ||
          std::fabs(d) > double(std::numeric_limits<float>::max()))
        fail(fmt::format("'{}': '{}' is not a finite number", tok[0], printable(tok[k], 40)));
    }
  }
}

// Every existing material library named by an mtllib line must be a regular file under the size
// limit; tinyobjloader only warns about a missing one, and the scene format makes that an error.
void check_mtllibs(const std::string& text, const std::filesystem::path& dir,
                   const std::string& prefix) {
  for (size_t pos = 0; pos < text.size();) {
    size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) eol = text.size();
    std::string_view view(text.data() + pos, eol - pos);
    pos = eol + 1;
    if (view.find("mtllib") == std::string_view::npos) continue;
    std::string line(view);
    size_t i = line.find_first_not_of(" \t");
    if (i == std::string::npos || line.compare(i, 6, "mtllib") != 0) continue;
    if (i + 6 < line.size() && line[i + 6] != ' ' && line[i + 6] != '\t') continue;
    std::istringstream names(line.substr(i + 6));
    std::string n;
    bool any = false, found = false;
    std::string first;
    while (names >> n) {
      if (!any) first = n;
      any = true;
      std::error_code ec;
      if (std::filesystem::exists(dir / n, ec)) found = true;
    }
    if (any && !found)
      throw SceneError(fmt::format("{}cannot open material library '{}'", prefix,
                                   printable((dir / first).string(), 256)));
  }
}

// tinyobjloader reads exactly three numbers after a texture map's -s, -o and -t, and two after
// -mm, taking the next words whatever they are: "map_Kd -s 2 2 wood.png" loses its file name to
// the third scale. The MTL format makes the second and third optional, so map_Kd and map_Pr lines
// get the missing ones (-s: 1, -o and -t: 0; -mm: gain 1) before tinyobjloader reads them. The
// file name (the rest of the line after the options, spaces included) is kept as it is.
std::string pad_map_options(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  auto is_number = [](std::string_view t) {
    if (t.size() > 1 && t[0] == '+') t.remove_prefix(1);
    double d = 0.0;
    auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), d);
    return !t.empty() && ec == std::errc() && end == t.data() + t.size();
  };
  for (size_t pos = 0; pos < text.size();) {
    size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) eol = text.size();
    std::string_view line(text.data() + pos, eol - pos);
    pos = eol + 1;
    const bool newline = eol < text.size();
    size_t i = line.find_first_not_of(" \t");
    if (i == std::string_view::npos ||
        (line.substr(i, 6) != "map_Kd" && line.substr(i, 6) != "map_Pr") ||
        (i + 6 < line.size() && line[i + 6] != ' ' && line[i + 6] != '\t')) {
      out.append(line);
      if (newline) out.push_back('\n');
      continue;
    }
    out.append(line.substr(0, i + 6));
    size_t k = i + 6;
    // The next word from k (k moves past it); empty at the end of the line.
    auto word = [&](size_t& at) {
      at = line.find_first_not_of(" \t\r", at);
      if (at == std::string_view::npos) at = line.size();
      size_t e = line.find_first_of(" \t\r", at);
      if (e == std::string_view::npos) e = line.size();
      std::string_view w = line.substr(at, e - at);
      at = e;
      return w;
    };
    while (true) {
      size_t start = k;
      std::string_view opt = word(k);
      if (opt.empty() || opt[0] != '-') { // the file name: the rest of the line as it is
        out.append(line.substr(start));
        break;
      }
      out.push_back(' ');
      out.append(opt);
      int want = (opt == "-s" || opt == "-o" || opt == "-t") ? 3 : opt == "-mm" ? 2 : -1;
      if (want < 0) { // an option of one word (-clamp on, -bm 1, ...), or an unknown one
        if (opt == "-blendu" || opt == "-blendv" || opt == "-clamp" || opt == "-boost" ||
            opt == "-bm" || opt == "-texres" || opt == "-imfchan" || opt == "-type" ||
            opt == "-colorspace") {
          out.push_back(' ');
          out.append(word(k));
        }
        continue;
      }
      int have = 0;
      for (; have < want; ++have) {
        size_t at = k;
        std::string_view v = word(at);
        if (!is_number(v)) break;
        k = at;
        out.push_back(' ');
        out.append(v);
      }
      for (; have < want; ++have)
        out.append(opt == "-s" || (opt == "-mm" && have == 1) ? " 1" : " 0");
    }
    if (newline) out.push_back('\n');
  }
  return out;
}

// Reads MTL files through read_input_file (regular files under the size limit only).
class CheckedMaterialReader : public tinyobj::MaterialReader {
public:
  CheckedMaterialReader(std::filesystem::path dir, std::string prefix)
      : dir_(std::move(dir)), prefix_(std::move(prefix)) {}
  bool operator()(const std::string& mat_id, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* mat_map, std::string* warn,
                  std::string* err) override {
    std::filesystem::path p = dir_ / mat_id;
    std::error_code ec;
    if (!std::filesystem::exists(p, ec)) {
      if (warn) *warn += "Material file [ " + mat_id + " ] not found\n";
      return false;
    }
    std::string text = read_input_file(p, kMaxMtlFileBytes,
                                       fmt::format("{}{}: ", prefix_, printable(mat_id, 256)));
    std::istringstream in(pad_map_options(text));
    tinyobj::LoadMtl(mat_map, materials, &in, warn, err);
    files.resize(materials->size(), p);
    names.resize(materials->size(), mat_id);
    return true;
  }
  // The MTL file of each material read so far (map_Kd names are relative to its directory),
  // and its name as the mtllib line gives it (for messages).
  std::vector<std::filesystem::path> files;
  std::vector<std::string> names;

private:
  std::filesystem::path dir_;
  std::string prefix_;
};

// An istream over a string without copying it (an OBJ may be up to kMaxObjFileBytes).
class StringViewBuf : public std::streambuf {
public:
  explicit StringViewBuf(const std::string& s) {
    char* p = const_cast<char*>(s.data()); // read-only use: the get area is never written
    setg(p, p, p + s.size());
  }
};

bool finite_nonneg3(const tinyobj::real_t* c) {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(c[i]) || c[i] < 0) return false;
  return true;
}

// GGX roughness for a Phong exponent Ns: Walter et al. 2007 ("Microfacet Models for Refraction
// through Rough Surfaces", eq. 33) match a Blinn-Phong exponent n to Beckmann's
// alpha = sqrt(2 / (n + 2)); GGX takes the same alpha (their section 5.2 compares the two at
// equal alpha), and roughness = sqrt(alpha) since alpha = roughness^2. Ns = 0 gives roughness 1.
float roughness_from_ns(double ns) {
  double alpha = std::sqrt(2.0 / (ns + 2.0));
  return float(std::sqrt(alpha));
}

// The scene material of an MTL material (docs/scene-format.md, "MTL materials"): illum 0 or 1, or
// Ks = 0, is diffuse Kd; illum >= 2 with Ks > 0 is plastic with albedo Kd, specular Ks, the
// roughness of Ns and ior Ni (Ni <= 1, MTL's default and tinyobjloader's value for a missing Ni,
// means unset: 1.5). `fail` reports a problem with the material.
template <class Fail> MaterialDesc mtl_to_material(const tinyobj::material_t& mt, Fail fail) {
  const std::string mname = printable(mt.name);
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(mt.diffuse[c]) || mt.diffuse[c] < 0 || mt.diffuse[c] > 1)
      fail(fmt::format("material '{}': Kd must be in [0, 1]", mname));
  if (!finite_nonneg3(mt.specular)) fail(fmt::format("material '{}': Ks must be >= 0", mname));
  float3 kd = make_float3(mt.diffuse[0], mt.diffuse[1], mt.diffuse[2]);
  float3 ks = make_float3(mt.specular[0], mt.specular[1], mt.specular[2]);
  bool glossy = mt.illum >= 2 && (ks.x > 0.0f || ks.y > 0.0f || ks.z > 0.0f);
  if (!glossy) return diffuse_material(mt.name, kd);
  if (!std::isfinite(mt.shininess) || mt.shininess < 0)
    fail(fmt::format("material '{}': Ns must be >= 0", mname));
  if (!std::isfinite(mt.ior) || mt.ior > kMaxPlasticIor)
    fail(fmt::format("material '{}': Ni must be <= {}", mname, kMaxPlasticIor));
  float ior = mt.ior > 1.0f ? float(mt.ior) : kDefaultPlasticIor;
  return plastic_material(mt.name, kd, ks, roughness_from_ns(double(mt.shininess)), ior);
}

// The texture of an MTL material's map `key` (map_Kd, map_Pr; file name `texname`, options `o`),
// relative to the directory of its MTL file `mtl`. The options tinyobjloader parses that Canopy can
// express: -s (scale of u, v), -o (offset of u, v), i.e. (s, t) = (s_u u + o_u, s_v v + o_v),
// -clamp on (TEXTURE_WRAP_CLAMP), and the "-colorspace sRGB|linear" extension; the others (-bm,
// -mm, -t, -texres, -imfchan, -blendu/v, -boost) are ignored. `where` starts the texture's messages
// (the JSON value naming the OBJ, the OBJ and the MTL name), `fail` reports a problem with the
// material.
template <class Fail>
TextureDesc mtl_texture(const tinyobj::material_t& mt, const char* key, const std::string& texname,
                        const tinyobj::texture_option_t& o, const std::filesystem::path& mtl,
                        const std::string& where, Fail fail) {
  const std::string what = fmt::format("material '{}': {}", printable(mt.name), key);
  std::filesystem::path file(texname);
  if (file.is_relative()) file = mtl.parent_path() / file;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    fail(fmt::format("{} '{}': no such file", what, printable(file.string(), 1024)));
  TextureDesc t;
  t.file = file;
  t.where = where + what;
  t.uvmap = make_float4(o.scale[0], o.scale[1], o.origin_offset[0], o.origin_offset[1]);
  if (!std::isfinite(t.uvmap.x + t.uvmap.y + t.uvmap.z + t.uvmap.w))
    fail(what + ": -s and -o must be finite");
  t.wrap = o.clamp ? TEXTURE_WRAP_CLAMP : TEXTURE_WRAP_REPEAT;
  if (o.colorspace == "sRGB")
    t.encoding = ImageEncoding::Srgb;
  else if (o.colorspace == "linear")
    t.encoding = ImageEncoding::Linear;
  return t;
}

} // namespace

Mesh load_obj(const std::filesystem::path& file, const JsonValue& at, Builder& b,
              int material_override) {
  std::string name = printable(at.as_string(), 256);
  std::error_code ec;
  if (!std::filesystem::exists(file, ec))
    at.fail(fmt::format("cannot open OBJ file '{}'", printable(file.string(), 1024)));
  const std::string prefix = fmt::format("{}: {}: {}: ", at.file(), at.path(), name);
  const std::string text = read_input_file(file, kMaxObjFileBytes, prefix);
  std::filesystem::path dir = file.parent_path();
  if (dir.empty()) dir = std::filesystem::path(".");
  check_mtllibs(text, dir, prefix);
  check_obj_text(text, prefix);

  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  StringViewBuf buf(text);
  std::istream in(&buf);
  CheckedMaterialReader mtl_reader(dir, prefix);
  bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, &mtl_reader,
                             /*triangulate=*/true);
  auto first_line = [](std::string_view s) { return s.substr(0, s.find('\n')); };
  if (!ok || !err.empty()) at.fail(fmt::format("{}: {}", name, first_line(err)));
  if (auto p = warn.find("material ["); p != std::string::npos)
    at.fail(fmt::format("{}: {}", name, first_line(std::string_view(warn).substr(p))));

  Mesh m;
  size_t nv = attrib.vertices.size() / 3;
  m.vertices.resize(nv);
  for (size_t i = 0; i < nv; ++i) {
    float x = attrib.vertices[3 * i], y = attrib.vertices[3 * i + 1],
          z = attrib.vertices[3 * i + 2];
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
      at.fail(fmt::format("{}: vertex {} is not finite", name, i + 1));
    m.vertices[i] = make_float3(x, y, z);
  }

  // Vertex normals as given (add_mesh normalises them after the transform; a zero or non-finite
  // one makes its triangles flat). check_obj_text has already refused non-finite numbers.
  size_t nn = attrib.normals.size() / 3;
  m.normals.resize(nn);
  for (size_t i = 0; i < nn; ++i)
    m.normals[i] =
        make_float3(attrib.normals[3 * i], attrib.normals[3 * i + 1], attrib.normals[3 * i + 2]);

  // Texture coordinates as given (check_obj_text has refused non-finite numbers).
  size_t nt = attrib.texcoords.size() / 2;
  m.uvs.resize(nt);
  for (size_t i = 0; i < nt; ++i)
    m.uvs[i] = make_float2(attrib.texcoords[2 * i], attrib.texcoords[2 * i + 1]);

  // Materials of the MTL, resolved once.
  std::vector<int> mat_index(materials.size(), 0);
  std::vector<float3> mat_emission(materials.size(), make_float3(0, 0, 0));
  auto mtl_fail = [&](const std::string& problem) {
    at.fail(fmt::format("{}: {}", name, problem));
  };
  for (size_t i = 0; i < materials.size(); ++i) {
    const auto& mt = materials[i];
    MaterialDesc d = mtl_to_material(mt, mtl_fail);
    if (!finite_nonneg3(mt.emission))
      mtl_fail(fmt::format("material '{}': Ke must be >= 0", printable(mt.name)));
    mat_emission[i] = make_float3(mt.emission[0], mt.emission[1], mt.emission[2]);
    // Textures only for a material this OBJ adds (not one the scene replaces or one already
    // added), so nothing unused is read at render time. map_Kd: as in pbrt's and Cycles'
    // importers, the map replaces Kd (Kd only matters where the map is absent). map_Pr (the PBR
    // extension's roughness, which tinyobjloader reads): for a plastic, the roughness map
    // replacing the one of Ns, Canopy's roughness (alpha = r^2: TEXTURE_MAP_ALPHA_SQUARE); a
    // diffuse material has no roughness, so it ignores map_Pr.
    const bool plastic = d.gpu.type == MATERIAL_PLASTIC;
    if (material_override < 0 &&
        (!mt.diffuse_texname.empty() || (plastic && !mt.roughness_texname.empty())) &&
        !b.material_by_name.count(d.name) && !b.mtl_material_by_key.count(name + "\n" + d.name)) {
      const bool known = i < mtl_reader.files.size();
      const std::string mtl_name = printable(known ? mtl_reader.names[i] : std::string("?"), 256);
      const std::filesystem::path mtl = known ? mtl_reader.files[i] : dir / "?";
      const std::string where =
          fmt::format("{}: {}: {}: {}: ", at.file(), at.path(), name, mtl_name);
      auto fail = [&](const std::string& problem) { mtl_fail(mtl_name + ": " + problem); };
      if (!mt.diffuse_texname.empty())
        d.gpu.albedo_texture =
            add_texture(b.scene, mtl_texture(mt, "map_Kd", mt.diffuse_texname, mt.diffuse_texopt,
                                             mtl, where, fail));
      if (plastic && !mt.roughness_texname.empty()) {
        TextureDesc t =
            mtl_texture(mt, "map_Pr", mt.roughness_texname, mt.roughness_texopt, mtl, where, fail);
        t.channels = 1;
        t.map = TEXTURE_MAP_ALPHA_SQUARE;
        d.gpu.alpha_texture = add_texture(b.scene, std::move(t));
      }
    }
    mat_index[i] = material_override < 0 ? b.mtl_material(name, d) : material_override;
  }

  bool any_normals = false, any_uv = false;
  for (const auto& sh : shapes) {
    const auto& mesh = sh.mesh;
    size_t nf = mesh.num_face_vertices.size();
    for (size_t f = 0; f < nf; ++f) {
      if (mesh.num_face_vertices[f] != 3)
        at.fail(fmt::format("{}: face {} of '{}' is not a triangle after triangulation", name,
                            f + 1, printable(sh.name)));
      uint32_t idx[3];
      int32_t nidx[3], tidx[3];
      bool has_normals = true, has_uv = true;
      for (int k = 0; k < 3; ++k) {
        int vi = mesh.indices[3 * f + k].vertex_index;
        if (vi < 0 || size_t(vi) >= nv)
          at.fail(fmt::format("{}: face {} of '{}' has a vertex index out of range", name, f + 1,
                              printable(sh.name)));
        idx[k] = uint32_t(vi);
        int ni = mesh.indices[3 * f + k].normal_index; // -1: the face gives no normal
        if (ni >= 0 && size_t(ni) >= nn)
          at.fail(fmt::format("{}: face {} of '{}' has a normal index out of range", name, f + 1,
                              printable(sh.name)));
        nidx[k] = ni;
        has_normals = has_normals && ni >= 0;
        int ti = mesh.indices[3 * f + k].texcoord_index; // -1: the face gives no uv
        if (ti >= 0 && size_t(ti) >= nt)
          at.fail(fmt::format("{}: face {} of '{}' has a texture coordinate index out of range",
                              name, f + 1, printable(sh.name)));
        tidx[k] = ti;
        has_uv = has_uv && ti >= 0;
      }
      // normal_indices starts at the first triangle with normals (earlier ones: -1).
      if (has_normals && !any_normals) m.normal_indices.assign(3 * m.triangle_count(), -1);
      any_normals = any_normals || has_normals;
      if (any_normals)
        for (int k = 0; k < 3; ++k)
          m.normal_indices.push_back(has_normals ? nidx[k] : -1);
      // uv_indices likewise; a face without vt at every vertex has none (add_mesh's default).
      if (has_uv && !any_uv) m.uv_indices.assign(3 * m.triangle_count(), -1);
      any_uv = any_uv || has_uv;
      if (any_uv)
        for (int k = 0; k < 3; ++k)
          m.uv_indices.push_back(has_uv ? tidx[k] : -1);
      int mid = f < mesh.material_ids.size() ? mesh.material_ids[f] : -1;
      int mat = material_override >= 0 ? material_override : 0;
      float3 em = make_float3(0, 0, 0);
      if (mid >= 0 && size_t(mid) < materials.size()) {
        mat = mat_index[size_t(mid)];
        em = mat_emission[size_t(mid)];
      }
      m.add_triangle(idx[0], idx[1], idx[2], mat, em);
    }
  }
  if (m.triangle_count() == 0) at.fail(fmt::format("{}: contains no faces", name));
  return m;
}

} // namespace canopy::detail
