// OBJ + MTL meshes via tinyobjloader. MTL Kd becomes a diffuse material named after the MTL
// material; MTL Ke > 0 makes the material's triangles emitters (radiance Ke).
#include "scene/loader_internal.h"

#include <fmt/format.h>
#include <tiny_obj_loader.h>

#include <cmath>
#include <fstream>
#include <sstream>

namespace canopy::detail {

namespace {

// tinyobjloader only warns about a missing material library; the scene format makes it an error,
// so the mtllib lines are checked first.
void check_mtllibs(const std::filesystem::path& obj, const std::string& obj_name,
                   const JsonValue& at) {
  std::ifstream in(obj);
  std::string line;
  while (std::getline(in, line)) {
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
      if (std::filesystem::is_regular_file(obj.parent_path() / n, ec)) found = true;
    }
    if (any && !found)
      at.fail(fmt::format("{}: cannot open material library '{}'", obj_name,
                          (obj.parent_path() / first).string()));
  }
}

bool finite_nonneg3(const tinyobj::real_t* c) {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(c[i]) || c[i] < 0) return false;
  return true;
}

} // namespace

Mesh load_obj(const std::filesystem::path& file, const JsonValue& at, Builder& b,
              int material_override) {
  std::string name = at.as_string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    at.fail(fmt::format("cannot open OBJ file '{}'", file.string()));
  {
    std::ifstream probe(file);
    if (!probe) at.fail(fmt::format("cannot open OBJ file '{}'", file.string()));
  }
  check_mtllibs(file, name, at);

  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  std::filesystem::path dir = file.parent_path();
  if (dir.empty()) dir = std::filesystem::path(".");
  const std::string mtl_dir = dir.string();
  bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, file.string().c_str(),
                             mtl_dir.c_str(), /*triangulate=*/true);
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

  // Materials of the MTL, resolved once.
  std::vector<int> mat_index(materials.size(), 0);
  std::vector<float3> mat_emission(materials.size(), make_float3(0, 0, 0));
  for (size_t i = 0; i < materials.size(); ++i) {
    const auto& mt = materials[i];
    for (int c = 0; c < 3; ++c)
      if (!std::isfinite(mt.diffuse[c]) || mt.diffuse[c] < 0 || mt.diffuse[c] > 1)
        at.fail(fmt::format("{}: material '{}': Kd must be in [0, 1]", name, mt.name));
    if (!finite_nonneg3(mt.emission))
      at.fail(fmt::format("{}: material '{}': Ke must be >= 0", name, mt.name));
    mat_emission[i] = make_float3(mt.emission[0], mt.emission[1], mt.emission[2]);
    if (material_override < 0)
      mat_index[i] =
          b.mtl_material(name, mt.name, make_float3(mt.diffuse[0], mt.diffuse[1], mt.diffuse[2]));
    else
      mat_index[i] = material_override;
  }

  for (const auto& sh : shapes) {
    const auto& mesh = sh.mesh;
    size_t nf = mesh.num_face_vertices.size();
    for (size_t f = 0; f < nf; ++f) {
      if (mesh.num_face_vertices[f] != 3)
        at.fail(fmt::format("{}: face {} of '{}' is not a triangle after triangulation", name,
                            f + 1, sh.name));
      uint32_t idx[3];
      for (int k = 0; k < 3; ++k) {
        int vi = mesh.indices[3 * f + k].vertex_index;
        if (vi < 0 || size_t(vi) >= nv)
          at.fail(fmt::format("{}: face {} of '{}' has a vertex index out of range", name, f + 1,
                              sh.name));
        idx[k] = uint32_t(vi);
      }
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
