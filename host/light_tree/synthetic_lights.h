// Synthetic light sets for the light-tree tests and benchmarks (deterministic for a given seed on
// every platform: they use the counter-based LtRng, not <random> distributions).
#pragma once

#include "rng.h"   // cl/: LtRng
#include "types.h" // cl/types.h: Light

#include <cstdint>
#include <vector>

namespace canopy {

// Light records (fields as documented in cl/types.h).
Light make_point_light(float3 p, float3 intensity);
Light make_spot_light(float3 p, float3 axis, float cos_outer, float cos_inner, float3 intensity);
Light make_sphere_light(float3 c, float radius, float3 radiance);
Light make_quad_light(float3 corner, float3 e1, float3 e2, float3 radiance, bool two_sided = false);
Light make_triangle_light(float3 v0, float3 v1, float3 v2, float3 radiance, bool two_sided = false);
// A disk (centre, normal of any length, radius) with the loader's field layout.
Light make_disk_light(float3 c, float3 normal, float radius, float3 radiance,
                      bool two_sided = false);

// n point lights uniform in the cube [0, size]^3, intensities in [0.1, 10] per channel.
std::vector<Light> random_point_lights(int n, uint32_t seed, float size = 100.0f);
// n one-sided triangles with random centres in [0, size]^3 and uniformly random orientations,
// edge length about the mean spacing.
std::vector<Light> random_triangle_lights(int n, uint32_t seed, float size = 100.0f);
// A city-like layout: a grid of blocks of buildings whose facades carry window quads (normals
// along +-x / +-z), street-lamp spots pointing down and a few point lights, over an area that grows
// with sqrt(n), so the density stays city-like.
std::vector<Light> city_lights(int n, uint32_t seed);
// The spiral of the paper's Fig. 11: n point lights along a planar spiral, each above an object.
std::vector<Light> spiral_lights(int n);
// Every light of every type (point, spot, sphere, one- and two-sided quad, triangle, one- and
// two-sided disk), random.
std::vector<Light> mixed_lights(int n, uint32_t seed, float size = 10.0f);

} // namespace canopy
