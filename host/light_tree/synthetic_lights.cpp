#include "light_tree/synthetic_lights.h"

#include "light_tree/cone.h" // lt_any_perpendicular
#include "rng.h"
#include "shading.h"

#include <cmath>

namespace canopy {
namespace {
struct R {
  LtRng rng;
  R(uint32_t seed, uint32_t stream) : rng(lt_rng_make(seed, stream)) {}
  float u() { return lt_rng_next(&rng); }
  float u(float lo, float hi) { return lo + (hi - lo) * u(); }
  float3 unit() { // uniform on the sphere
    float z = u(-1.0f, 1.0f);
    float phi = 2.0f * M_PI_F * u();
    float s = std::sqrt(std::fmax(0.0f, 1.0f - z * z));
    return make_float3(s * std::cos(phi), s * std::sin(phi), z);
  }
  float3 color(float lo, float hi) { return make_float3(u(lo, hi), u(lo, hi), u(lo, hi)); }
};
Light blank(int type) {
  Light l{};
  l.type = type;
  l.prim = -1;
  return l;
}
} // namespace

Light make_point_light(float3 p, float3 intensity) {
  Light l = blank(LIGHT_POINT);
  l.p = f4_from3(p, 0.0f);
  l.emission = f4_from3(intensity, 0.0f);
  return l;
}
Light make_spot_light(float3 p, float3 axis, float cos_outer, float cos_inner, float3 intensity) {
  Light l = blank(LIGHT_SPOT);
  l.p = f4_from3(p, 0.0f);
  l.e1 = f4_from3(normalize(axis), cos_outer);
  // 1 - cos of both half-angles: what the falloff reads (cl/types.h)
  l.e2 = make_float4(float(1.0 - double(cos_outer)), float(1.0 - double(cos_inner)), 0, cos_inner);
  l.emission = f4_from3(intensity, 0.0f);
  return l;
}
Light make_sphere_light(float3 c, float radius, float3 radiance) {
  Light l = blank(LIGHT_SPHERE);
  l.p = f4_from3(c, radius);
  l.emission = f4_from3(radiance, 0.0f);
  return l;
}
Light make_quad_light(float3 corner, float3 e1, float3 e2, float3 radiance, bool two_sided) {
  Light l = blank(LIGHT_QUAD);
  float3 c = cross(e1, e2);
  l.p = f4_from3(corner, 0.0f);
  l.e1 = f4_from3(e1, 0.0f);
  l.e2 = f4_from3(e2, 0.0f);
  l.n = f4_from3(normalize(c), length(c));
  l.emission = f4_from3(radiance, 0.0f);
  l.flags = two_sided ? LIGHT_FLAG_TWO_SIDED : 0;
  return l;
}
Light make_triangle_light(float3 v0, float3 v1, float3 v2, float3 radiance, bool two_sided) {
  Light l = blank(LIGHT_TRIANGLE);
  float3 e1 = v1 - v0, e2 = v2 - v0;
  float3 c = cross(e1, e2);
  l.p = f4_from3(v0, 0.0f);
  l.e1 = f4_from3(e1, 0.0f);
  l.e2 = f4_from3(e2, 0.0f);
  l.n = f4_from3(normalize(c), 0.5f * length(c));
  l.emission = f4_from3(radiance, 0.0f);
  l.flags = two_sided ? LIGHT_FLAG_TWO_SIDED : 0;
  return l;
}
Light make_disk_light(float3 c, float3 normal, float radius, float3 radiance, bool two_sided) {
  Light l = blank(LIGHT_DISK);
  float3 n = normalize(normal), t1, t2;
  onb_from(n, &t1, &t2);
  l.p = f4_from3(c, radius);
  l.e1 = f4_from3(t1, 0.0f);
  l.e2 = f4_from3(t2, 0.0f);
  l.n = f4_from3(n, float(M_PI * double(radius) * double(radius)));
  l.emission = f4_from3(radiance, 0.0f);
  l.flags = two_sided ? LIGHT_FLAG_TWO_SIDED : 0;
  return l;
}

std::vector<Light> random_point_lights(int n, uint32_t seed, float size) {
  R r(seed, 1);
  std::vector<Light> out;
  out.reserve(n);
  for (int i = 0; i < n; ++i) {
    float3 p = make_float3(r.u(0, size), r.u(0, size), r.u(0, size));
    out.push_back(make_point_light(p, r.color(0.1f, 10.0f)));
  }
  return out;
}

std::vector<Light> random_triangle_lights(int n, uint32_t seed, float size) {
  R r(seed, 2);
  std::vector<Light> out;
  out.reserve(n);
  float edge = size / std::cbrt(float(std::max(n, 1)));
  for (int i = 0; i < n; ++i) {
    float3 c = make_float3(r.u(0, size), r.u(0, size), r.u(0, size));
    float3 nrm = r.unit();
    float3 t = lt_any_perpendicular(nrm);
    float3 b = cross(nrm, t);
    float3 v0 = c + t * (0.5f * edge);
    float3 v1 = c + (b * 0.433f - t * 0.25f) * edge;
    float3 v2 = c - (b * 0.433f + t * 0.25f) * edge;
    out.push_back(make_triangle_light(v0, v1, v2, r.color(0.5f, 5.0f)));
  }
  return out;
}

std::vector<Light> city_lights(int n, uint32_t seed) {
  R r(seed, 3);
  std::vector<Light> out;
  out.reserve(n);
  // ~100 lights per building, buildings 20 x 20 m on a 30 m pitch.
  int buildings = std::max(1, n / 100);
  int side = std::max(1, int(std::ceil(std::sqrt(double(buildings)))));
  const float pitch = 30.0f, w = 20.0f;
  int i = 0;
  while (int(out.size()) < n) {
    int b = i++ % (side * side);
    float x0 = float(b % side) * pitch, z0 = float(b / side) * pitch;
    float h = 10.0f + 90.0f * r.u() * r.u();
    float k = r.u();
    if (k < 0.75f) { // a window on one of the four facades
      int face = int(r.u() * 4.0f) & 3;
      float s = r.u(0.5f, w - 1.5f), y = r.u(1.0f, h - 2.0f);
      float3 corner, e1, e2 = make_float3(0, 1.2f, 0);
      // e1 x e2 is the outward normal of the facade
      if (face == 0) {
        corner = make_float3(x0 + w, y, z0 + s + 1.0f);
        e1 = make_float3(0, 0, -1.0f);
      } else if (face == 1) {
        corner = make_float3(x0, y, z0 + s);
        e1 = make_float3(0, 0, 1.0f);
      } else if (face == 2) {
        corner = make_float3(x0 + s, y, z0 + w);
        e1 = make_float3(1.0f, 0, 0);
      } else {
        corner = make_float3(x0 + s + 1.0f, y, z0);
        e1 = make_float3(-1.0f, 0, 0);
      }
      out.push_back(make_quad_light(corner, e1, e2, r.color(0.5f, 3.0f)));
    } else if (k < 0.95f) { // street lamp
      float3 p = make_float3(x0 - 5.0f + r.u(0, 0.2f), 6.0f, z0 + r.u(0, pitch));
      if (r.u() < 0.5f) p = make_float3(x0 + r.u(0, pitch), 6.0f, z0 - 5.0f);
      out.push_back(
          make_spot_light(p, make_float3(0, -1, 0), 0.5f, 0.7f, make_float3(30.0f, 25.0f, 15.0f)));
    } else { // rooftop beacon
      out.push_back(make_point_light(make_float3(x0 + r.u(0, w), h + 0.5f, z0 + r.u(0, w)),
                                     r.color(1.0f, 20.0f)));
    }
  }
  return out;
}

std::vector<Light> spiral_lights(int n) {
  std::vector<Light> out;
  out.reserve(n);
  for (int i = 0; i < n; ++i) {
    float t = float(i) / float(std::max(n, 1));
    float ang = 40.0f * M_PI_F * t;
    float rad = 2.0f + 48.0f * t;
    out.push_back(make_point_light(make_float3(rad * std::cos(ang), 1.5f, rad * std::sin(ang)),
                                   make_float3(1.0f, 0.9f, 0.7f)));
  }
  return out;
}

std::vector<Light> mixed_lights(int n, uint32_t seed, float size) {
  // Every eighth light is a disk drawn from its own stream, so the other lights are the same
  // sequence (point, spot, sphere, quad, two-sided quad, two triangles) as without disks.
  R r(seed, 4), rd(seed, 5);
  std::vector<Light> out;
  out.reserve(n);
  for (int i = 0, j = 0; i < n; ++i) {
    if (i % 8 == 7) {
      float3 c = make_float3(rd.u(0, size), rd.u(0, size), rd.u(0, size));
      float s = size * rd.u(0.005f, 0.05f);
      float3 col = rd.color(0.1f, 5.0f);
      float3 nrm = rd.unit();
      out.push_back(make_disk_light(c, nrm, s, col, (i / 8) % 3 == 2)); // a third two-sided
      continue;
    }
    float3 c = make_float3(r.u(0, size), r.u(0, size), r.u(0, size));
    float s = size * r.u(0.005f, 0.05f);
    float3 col = r.color(0.1f, 5.0f);
    switch (j++ % 7) {
    case 0:
      out.push_back(make_point_light(c, col));
      break;
    case 1: {
      float co = r.u(-0.3f, 0.95f);
      out.push_back(make_spot_light(c, r.unit(), co, std::fmin(1.0f, co + 0.05f), col));
      break;
    }
    case 2:
      out.push_back(make_sphere_light(c, s, col));
      break;
    case 3:
    case 4: {
      float3 nrm = r.unit(), t = lt_any_perpendicular(nrm), b = cross(nrm, t);
      out.push_back(make_quad_light(c, t * s, b * (s * r.u(0.3f, 2.0f)), col, (j - 1) % 7 == 4));
      break;
    }
    default: {
      float3 v1 = c + r.unit() * s, v2 = c + r.unit() * s;
      out.push_back(make_triangle_light(c, v1, v2, col, r.u() < 0.2f));
    }
    }
  }
  return out;
}

} // namespace canopy
