#include "scene/pbrt/meshes.h"

#include "scene/pbrt/transforms.h"

#include <algorithm>
#include <cmath>

namespace canopy::pbrt {

namespace {

// Tessellation of spheres and disks that are not analytic lights (Canopy has no analytic
// sphere/disk primitive apart from its lights): smooth shading normals hide the facets.
constexpr int kSphereRings = 24, kSphereSegments = 48, kDiskSegments = 64;

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

} // namespace

void reverse_winding(Mesh& m) {
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    std::swap(m.indices[3 * t + 1], m.indices[3 * t + 2]);
    if (!m.normal_indices.empty())
      std::swap(m.normal_indices[3 * t + 1], m.normal_indices[3 * t + 2]);
    if (!m.uv_indices.empty()) std::swap(m.uv_indices[3 * t + 1], m.uv_indices[3 * t + 2]);
  }
}

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

} // namespace canopy::pbrt
