// pbrt-v4 reader: the triangle meshes pbrt's shapes become, before they are transformed into the
// scene (winding and orientation as pbrt-v4's, and the tessellated sphere and disk).
#pragma once

#include "scene/loader_internal.h"

#include <cstdint>
#include <vector>

namespace canopy::pbrt {

using namespace detail;

// Swaps the winding of every triangle of m (with its normal and uv indices).
void reverse_winding(Mesh& m);

// The triangles of a polygon mesh whose vertices (and vertex normals and uv, if any, one per
// vertex) are in m: `idx` holds 3 indices a triangle, or with `bilinear` 4 a pbrt-v4
// BilinearPatch (p00 p10 p01 p11, whose normal cross(p10 - p00, p01 - p00) the triangles
// (p00 p10 p11) and (p00 p11 p01) keep). A bilinear patch without "uv" has pbrt-v4's default, its
// own parameterisation: (0, 0), (1, 0), (0, 1), (1, 1) at p00, p10, p01, p11 (a triangle's
// default, (0, 0), (1, 0), (1, 1), is Builder::add_mesh's). Then pbrt-v4's orientation: towards
// the vertex normals, else the winding (reversed by ReverseOrientation).
void add_polygons(Mesh& m, const std::vector<uint32_t>& idx, bool bilinear, int32_t material,
                  float3 emission, bool reverse);

// pbrt-v4's Sphere, tessellated, with its uv (in object space): u = phi / (2 pi), phi = atan2(y, x)
// in [0, 2 pi), and v = (theta - thetaZMin) / (thetaZMax - thetaZMin), which for the full sphere
// is 1 - theta / pi, theta = acos(z / r). The seam (u = 1 against u = 0) and the poles (one vertex,
// a u per triangle: the middle of its segment) have uv of their own, apart from the vertices.
Mesh sphere_mesh(float radius);

// pbrt's disk: radius r at z = height, normal +z (pbrt-v4 Disk), with its uv: u = phi / (2 pi),
// v = (radius - r) / (radius - innerradius) (innerradius 0 here: 1 at the centre, 0 on the rim).
// The seam and the centre have uv of their own, as the sphere's.
Mesh disk_mesh(float radius, float height);

} // namespace canopy::pbrt
