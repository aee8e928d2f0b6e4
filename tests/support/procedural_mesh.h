// Procedural geometry and ray batches shared by the intersect tests and benchmarks.
#pragma once

#include "types.h"

#include <cmath>
#include <random>
#include <vector>

namespace canopy::testing {

// A bumpy torus (nu x nv quads; 96 x 48 = 9216 triangles) plus random small triangles around it: a
// mesh with curved, concave and overlapping parts, and a wide range of triangle sizes.
inline std::vector<Primitive> make_mesh(int nu = 96, int nv = 48, int random_tris = 2000) {
  std::vector<Primitive> prims;
  auto tri = [&](float3 a, float3 b, float3 c) {
    Primitive p{};
    p.v0 = f4_from3(a, 0);
    p.e1 = f4_from3(b - a, 0);
    p.e2 = f4_from3(c - a, 0);
    p.type = PRIM_TRIANGLE;
    p.light = -1;
    prims.push_back(p);
  };
  auto torus = [nu, nv](int i, int j) {
    float u = 2.0f * float(M_PI) * float(i) / float(nu),
          v = 2.0f * float(M_PI) * float(j) / float(nv);
    float r = 0.4f * (1.0f + 0.15f * std::sin(5.0f * u) * std::cos(3.0f * v));
    return make_float3((1.0f + r * std::cos(v)) * std::cos(u), r * std::sin(v),
                       (1.0f + r * std::cos(v)) * std::sin(u));
  };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      float3 a = torus(i, j), b = torus(i + 1, j), c = torus(i + 1, j + 1), d = torus(i, j + 1);
      tri(a, b, c);
      tri(a, c, d);
    }
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(-2.0f, 2.0f), off(-0.2f, 0.2f);
  for (int k = 0; k < random_tris; ++k) {
    float3 a = make_float3(pos(rng), pos(rng), pos(rng));
    tri(a, a + make_float3(off(rng), off(rng), off(rng)),
        a + make_float3(off(rng), off(rng), off(rng)));
  }
  return prims;
}

struct Rays {
  std::vector<float4> o, d;
};

// Half the rays start anywhere in a box around the mesh with random directions; half are aimed at
// random points on random triangles, so most of those hit.
inline Rays make_rays(const std::vector<Primitive>& prims, int count = 100000) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), pos(-3.0f, 3.0f);
  std::uniform_int_distribution<size_t> pick(0, prims.size() - 1);
  Rays r;
  for (int i = 0; i < count; ++i) {
    float3 o = make_float3(pos(rng), pos(rng), pos(rng));
    float3 d;
    if (i % 2 == 0) {
      float z = 2.0f * u(rng) - 1.0f, phi = 2.0f * float(M_PI) * u(rng);
      float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
      d = make_float3(s * std::cos(phi), s * std::sin(phi), z);
    } else {
      const Primitive& p = prims[pick(rng)];
      float a = u(rng), b = u(rng);
      if (a + b > 1.0f) a = 1.0f - a, b = 1.0f - b;
      float3 target = xyz_of(p.v0) + xyz_of(p.e1) * a + xyz_of(p.e2) * b;
      d = normalize(target - o);
    }
    r.o.push_back(f4_from3(o, 0.0f));
    r.d.push_back(f4_from3(d, 0.0f));
  }
  return r;
}

// Shadow segments (o.w: the segment's length): from random points on random triangles, lifted
// 1e-4 off the surface towards the target, to random points in a box around the mesh (even i) or
// to random points on other triangles, ending 1e-4 short of them (odd i); some are occluded, some
// not.
inline Rays make_shadow_rays(const std::vector<Primitive>& prims, int count = 100000) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), pos(-3.0f, 3.0f);
  std::uniform_int_distribution<size_t> pick(0, prims.size() - 1);
  auto surface_point = [&](const Primitive& p) {
    float a = u(rng), b = u(rng);
    if (a + b > 1.0f) a = 1.0f - a, b = 1.0f - b;
    return xyz_of(p.v0) + xyz_of(p.e1) * a + xyz_of(p.e2) * b;
  };
  Rays r;
  for (int i = 0; i < count; ++i) {
    const Primitive& from = prims[pick(rng)];
    float3 o = surface_point(from);
    float3 target =
        i % 2 == 0 ? make_float3(pos(rng), pos(rng), pos(rng)) : surface_point(prims[pick(rng)]);
    float3 n = normalize(cross(xyz_of(from.e1), xyz_of(from.e2)));
    o = o + n * (dot(n, target - o) >= 0.0f ? 1e-4f : -1e-4f);
    float3 to = target - o;
    float dist = length(to);
    float tmax = i % 2 == 0 ? dist : dist - 1e-4f;
    r.o.push_back(f4_from3(o, tmax));
    r.d.push_back(f4_from3(to * (1.0f / dist), 0.0f));
  }
  return r;
}

} // namespace canopy::testing
