// PLY triangle meshes (ASCII, binary little- and big-endian, optionally gzip-compressed), read
// with Assimp for pbrt-v4's Shape "plymesh". Not part of the public interface (that is scene.h).
#pragma once

#include "scene/scene.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace canopy::detail {

// A PLY mesh as stored in the file: vertices in file order, faces triangulated (a polygon of n
// vertices becomes n - 2 triangles with its winding); nothing else is changed (no welding, no
// generated normals).
struct PlyMesh {
  std::vector<float3> positions;
  std::vector<uint32_t> indices; // 3 per triangle, into positions
  std::vector<float3> normals;   // per vertex (nx ny nz), as stored; empty if the file has none
  // Per vertex (u v, s t, texture_u texture_v or texture_s texture_t), as stored; empty if the
  // file has none. The plymesh's uv (pbrt/shapes.cpp).
  std::vector<float2> uv;
  size_t skipped_faces = 0; // faces of fewer than 3 vertices (points, lines)
};

// Reads `file`; a name ending in ".gz" must be gzip-compressed. Any problem (missing, unreadable,
// not a PLY file, malformed, truncated, an index out of range) is a one-line SceneError
// "<prefix><problem>", e.g. prefix "scene.pbrt:12: Shape \"plymesh\" \"x.ply\": ".
PlyMesh load_ply_mesh(const std::filesystem::path& file, const std::string& prefix);

} // namespace canopy::detail
