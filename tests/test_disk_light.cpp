// Disk lights (LIGHT_DISK) and disk primitives (PRIM_DISK): the sampler against the closed-form
// irradiance of a coaxial disk and an independent quadrature off axis, the pdf against its
// integral over the sphere of directions, light_pdf against sample_light, and the ray-disk test
// against a double-precision reference, through the BVH too, with no self-intersection of rays
// leaving a disk or ending at a sampled point of it.
#include "accel/bvh.h"
#include "geometry.h"
#include "light_tree/synthetic_lights.h"
#include "lights/light_sample.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

using namespace canopy;

namespace {

struct Estimate {
  double mean, se;
};

// Irradiance at P (normal N) from light l by sample_light: mean and standard error over n samples.
Estimate irradiance(const Light& l, float3 P, float3 N, int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  double s = 0, s2 = 0;
  for (int i = 0; i < n; ++i) {
    float u1 = u(rng), u2 = u(rng);
    LightSample ls = sample_light(&l, P, u1, u2);
    double v = 0;
    if (ls.pdf > 0.0f) v = double(ls.Li.x) * std::max(0.0f, dot(N, ls.wi)) / double(ls.pdf);
    EXPECT_TRUE(std::isfinite(v));
    s += v;
    s2 += v * v;
  }
  double m = s / n;
  return {m, std::sqrt(std::max(0.0, s2 / n - m * m) / (n - 1))};
}

// Irradiance at P (normal N) from a one-sided disk (radiance L) by the polar midpoint rule over
// the disk's area in double, E = int L cos_r cos_l / d^2 dA, with its own tangent frame.
double irradiance_quadrature(double L, const double c[3], const double n_in[3], double r,
                             const double P[3], const double N[3], int nr, int nphi) {
  double nl = std::sqrt(n_in[0] * n_in[0] + n_in[1] * n_in[1] + n_in[2] * n_in[2]);
  double n[3] = {n_in[0] / nl, n_in[1] / nl, n_in[2] / nl};
  double a[3] = {1, 0, 0};
  if (std::fabs(n[0]) > 0.9) a[0] = 0, a[1] = 1;
  double t1[3] = {a[1] * n[2] - a[2] * n[1], a[2] * n[0] - a[0] * n[2], a[0] * n[1] - a[1] * n[0]};
  double tl = std::sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
  for (double& x : t1)
    x /= tl;
  double t2[3] = {n[1] * t1[2] - n[2] * t1[1], n[2] * t1[0] - n[0] * t1[2],
                  n[0] * t1[1] - n[1] * t1[0]};
  double sum = 0;
  for (int i = 0; i < nr; ++i) {
    double rho = r * (i + 0.5) / nr;
    for (int j = 0; j < nphi; ++j) {
      double phi = 2 * M_PI * (j + 0.5) / nphi;
      double x[3], d[3];
      for (int k = 0; k < 3; ++k) {
        x[k] = c[k] + rho * (std::cos(phi) * t1[k] + std::sin(phi) * t2[k]);
        d[k] = x[k] - P[k];
      }
      double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], dl = std::sqrt(d2);
      double cos_r = (d[0] * N[0] + d[1] * N[1] + d[2] * N[2]) / dl;
      double cos_l = -(d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / dl;
      if (cos_r > 0 && cos_l > 0) sum += cos_r * cos_l / d2 * rho;
    }
  }
  return L * sum * (r / nr) * (2 * M_PI / nphi);
}

Primitive disk_prim(const Light& l) {
  Primitive p{};
  p.v0 = l.p;
  p.e1 = f4_from3(xyz_of(l.n), 0.0f);
  p.type = PRIM_DISK;
  p.light = 0;
  return p;
}

float3 random_unit(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  float z = 2.0f * u(rng) - 1.0f, phi = 2.0f * float(M_PI) * u(rng);
  float s = std::sqrt(std::max(0.0f, 1.0f - z * z));
  return make_float3(s * std::cos(phi), s * std::sin(phi), z);
}

} // namespace

TEST(DiskLightSample, OnAxisIrradianceMatchesTheClosedForm) {
  // A one-sided disk facing down at height h above P: E = pi L r^2 / (r^2 + h^2).
  struct Case {
    float r, h;
  };
  for (Case cs : {Case{0.5f, 1.0f}, Case{2.0f, 0.3f}, Case{0.01f, 5.0f}, Case{1.0f, 0.2f}}) {
    Light l = make_disk_light(make_float3(0, 0, cs.h), make_float3(0, 0, -1), cs.r,
                              make_float3(2.0f, 2.0f, 2.0f));
    Estimate e = irradiance(l, make_float3(0, 0, 0), make_float3(0, 0, 1), 200000, 1);
    double r2 = double(cs.r) * cs.r, h2 = double(cs.h) * cs.h;
    double exact = M_PI * 2.0 * r2 / (r2 + h2);
    EXPECT_NEAR(e.mean, exact, 5.0 * e.se + 1e-5 * exact) << "r " << cs.r << " h " << cs.h;
    EXPECT_LT(e.se, 0.01 * exact); // the check has teeth
  }
}

TEST(DiskLightSample, OffAxisIrradianceMatchesQuadrature) {
  // Tilted disks off P's axis, entirely above P's horizon and facing P (the integrand is smooth),
  // against a 400 x 800 polar midpoint rule (its error bounded by the 200 x 400 rule's).
  struct Case {
    float3 c, n;
    float r;
  };
  const Case cases[] = {
      {make_float3(0.7f, -0.3f, 1.2f), make_float3(-0.3f, 0.2f, -1.0f), 0.4f},
      {make_float3(-1.5f, 0.5f, 0.8f), make_float3(1.0f, -0.2f, -0.4f), 0.6f},
      {make_float3(0.2f, 0.1f, 0.5f), make_float3(0.0f, 0.6f, -0.8f), 0.3f},
  };
  const float3 P = make_float3(0.1f, 0.05f, 0.0f), N = make_float3(0, 0, 1);
  uint32_t seed = 2;
  for (const Case& cs : cases) {
    Light l = make_disk_light(cs.c, cs.n, cs.r, make_float3(1.5f, 1.5f, 1.5f));
    Estimate e = irradiance(l, P, N, 200000, seed++);
    const double c[3] = {cs.c.x, cs.c.y, cs.c.z}, n[3] = {cs.n.x, cs.n.y, cs.n.z},
                 p[3] = {P.x, P.y, P.z}, nn[3] = {N.x, N.y, N.z};
    double q1 = irradiance_quadrature(1.5, c, n, cs.r, p, nn, 400, 800);
    double q2 = irradiance_quadrature(1.5, c, n, cs.r, p, nn, 200, 400);
    EXPECT_NEAR(e.mean, q1, 5.0 * e.se + std::fabs(q1 - q2) + 1e-5 * q1);
    EXPECT_LT(e.se + std::fabs(q1 - q2), 0.01 * q1);
  }
}

TEST(DiskLightSample, PdfIntegratesToOneOverTheSolidAngle) {
  // Jittered directions stratified over the sphere (z, phi); a direction that hits the disk adds
  // light_pdf at the hit point times its solid angle. The sum estimates the pdf's integral over
  // the disk's solid angle, 1 for a disk that emits towards P (one- and two-sided, P in front;
  // a two-sided disk from behind). Bound: 5 standard errors of the unstratified estimator (which
  // overestimates the stratified one's).
  struct Case {
    float3 c, n, P;
    bool two_sided;
  };
  const Case cases[] = {
      {make_float3(0, 0, 1), make_float3(0.2f, 0.1f, -1), make_float3(0.1f, 0.2f, 0), false},
      {make_float3(0.5f, 0.3f, 0.4f), make_float3(-1, 0, 0.3f), make_float3(0, 0, 0), true},
      {make_float3(0, 0, 1), make_float3(0, 0.3f, 1), make_float3(0.3f, 0, 0), true},
  };
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const Case& cs : cases) {
    Light l = make_disk_light(cs.c, cs.n, 0.5f, make_float3(1, 1, 1), cs.two_sided);
    Primitive prim = disk_prim(l);
    const int nz = 1000, nphi = 2000;
    const double dw = 4.0 * M_PI / (double(nz) * nphi);
    double s = 0, s2 = 0;
    int hits = 0;
    for (int i = 0; i < nz; ++i)
      for (int j = 0; j < nphi; ++j) {
        float z = -1.0f + 2.0f * (float(i) + u(rng)) / float(nz);
        float phi = 2.0f * float(M_PI) * (float(j) + u(rng)) / float(nphi);
        float sr = std::sqrt(std::max(0.0f, 1.0f - z * z));
        float3 d = make_float3(sr * std::cos(phi), sr * std::sin(phi), z);
        float t, uu, vv;
        if (!ray_primitive(&prim, cs.P, d, 0.0f, FLT_INF, &t, &uu, &vv)) continue;
        ++hits;
        double v = double(light_pdf(&l, cs.P, cs.P + d * t)) * dw;
        s += v;
        s2 += v * v;
      }
    const double n = double(nz) * nphi;
    double se = std::sqrt(std::max(0.0, s2 - s * s / n) * n / (n - 1));
    EXPECT_GT(hits, 10000);
    EXPECT_NEAR(s, 1.0, 5.0 * se + 1e-4) << "hits " << hits;
    EXPECT_LT(se, 0.005);
  }
}

TEST(DiskLightSample, LightPdfMirrorsTheSamplerAndEmissionIsOneSided) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int front = 0, back = 0;
  for (int i = 0; i < 20000; ++i) {
    float3 c = (make_float3(u(rng), u(rng), u(rng)) - make_float3(0.5f, 0.5f, 0.5f)) * 4.0f;
    float3 n = random_unit(rng);
    float r = std::pow(10.0f, 2.0f * u(rng) - 1.5f);
    bool two = i % 3 == 0;
    Light l = make_disk_light(c, n, r, make_float3(1, 2, 3), two);
    float3 P = c + random_unit(rng) * (r * std::pow(10.0f, 3.0f * u(rng) - 1.0f));
    float u1 = u(rng), u2 = u(rng);
    LightSample s = sample_light(&l, P, u1, u2);
    ASSERT_EQ(light_pdf(&l, P, s.x), s.pdf) << i;
    ASSERT_TRUE(std::isfinite(s.pdf) && std::isfinite(s.dist));
    double side = double(dot(n, P - c));
    if (side > 0 || two) {
      if (std::fabs(side) > 1e-5 * r) {
        ASSERT_GT(s.pdf, 0.0f) << i;
        ASSERT_EQ(s.Li.z, 3.0f);
      }
      ++front;
    } else {
      // behind a one-sided disk: no emission, pdf 0 (a BSDF ray hitting its back gets no weight)
      ASSERT_EQ(s.pdf, 0.0f) << i;
      ASSERT_EQ(s.Li.x, 0.0f);
      if (side < -1e-3 * r) {
        ASSERT_EQ(light_emitted_radiance(&l, n, normalize(P - s.x)).x, 0.0f);
      }
      ++back;
    }
    if (s.pdf > 0.0f) {
      // the sampled point lies on the disk (within rounding) and emits towards P
      float3 q = s.x - c;
      ASSERT_LE(std::fabs(dot(q, n)), 1e-4f * (r + length(P - c) + length(c)));
      ASSERT_LE(length(q - n * dot(q, n)), r * 1.0001f);
      ASSERT_EQ(light_emitted_radiance(&l, n, -s.wi).y, 2.0f);
    }
  }
  EXPECT_GT(front, 10000);
  EXPECT_GT(back, 3000);
}

TEST(DiskLightSample, ShadowRayToASampleIsNotOccludedByItsOwnDisk) {
  // The shadow ray of light_pick (P to the sample, tmax short of it by the float error of the
  // point and the distance) must not hit the disk's own primitive: near and far, grazing and
  // head-on, disks far from the origin.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int tested = 0;
  for (int i = 0; i < 100000; ++i) {
    float far = std::pow(10.0f, 6.0f * u(rng) - 2.0f);
    float3 c = random_unit(rng) * far;
    float3 n = random_unit(rng);
    float r = std::pow(10.0f, 4.0f * u(rng) - 2.0f);
    Light l = make_disk_light(c, n, r, make_float3(1, 1, 1), i % 2 == 0);
    Primitive prim = disk_prim(l);
    // P at a random distance and angle; a fifth of them grazing (|cos| down to 1e-6)
    float3 w = random_unit(rng);
    if (i % 5 == 0) w = normalize(w - n * (dot(w, n) * (1.0f - std::pow(10.0f, -6.0f * u(rng)))));
    float3 P = c + w * (r * std::pow(10.0f, 5.0f * u(rng) - 2.0f));
    LightSample s = sample_light(&l, P, u(rng), u(rng));
    if (!(s.pdf > 0.0f)) continue;
    float3 to = s.x - P;
    float dist = length(to);
    float tmax = dist - fp_gamma(6) * (max_abs3(s.x) + dist);
    float t, uu, vv;
    ++tested;
    ASSERT_FALSE(ray_primitive(&prim, P, to / dist, 0.0f, std::max(tmax, 0.0f), &t, &uu, &vv))
        << i << ": t " << t << " tmax " << tmax << " dist " << dist << " |c| " << length(c) << " r "
        << r << " cos " << dot(n, to / dist);
  }
  EXPECT_GT(tested, 50000);
}

TEST(IntersectDisk, RaysMatchADoublePrecisionReference) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int hits = 0, misses = 0, front_hits = 0, back_hits = 0;
  for (int i = 0; i < 200000; ++i) {
    float3 c = (make_float3(u(rng), u(rng), u(rng)) - make_float3(0.5f, 0.5f, 0.5f)) * 10.0f;
    float3 n = random_unit(rng);
    float r = 0.1f + 2.0f * u(rng);
    Light l = make_disk_light(c, n, r, make_float3(1, 1, 1));
    Primitive prim = disk_prim(l);
    float3 o = c + random_unit(rng) * (4.0f * u(rng) + 0.01f);
    float3 target = c + random_unit(rng) * (1.5f * r);
    float3 d = normalize(target - o);
    float t = -1, uu, vv;
    int hit = ray_primitive(&prim, o, d, 0.0f, FLT_INF, &t, &uu, &vv);
    // reference: the plane of the stored normal, in double
    double nd = double(n.x) * d.x + double(n.y) * d.y + double(n.z) * d.z;
    double num = double(n.x) * (double(c.x) - o.x) + double(n.y) * (double(c.y) - o.y) +
                 double(n.z) * (double(c.z) - o.z);
    double tr = num / nd;
    double q[3] = {o.x + tr * d.x - c.x, o.y + tr * d.y - c.y, o.z + tr * d.z - c.z};
    double rho = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    bool ref_hit = tr > 0 && rho < r;
    // skip rays within rounding of the rim, grazing the plane or starting on it
    if (std::fabs(rho - r) < 1e-4 * r || std::fabs(nd) < 1e-3 || std::fabs(tr) < 1e-5) continue;
    ASSERT_EQ(hit != 0, ref_hit) << i << ": t " << tr << " rho " << rho << " r " << r;
    if (!hit) {
      ++misses;
      continue;
    }
    ++hits;
    (nd < 0 ? front_hits : back_hits)++;
    ASSERT_NEAR(t, tr, 1e-5 * (tr + 10.0) / std::fabs(nd)) << i;
    // the hit point and its error bound: on the plane within the bound
    Hit h{t, 0, uu, vv};
    float3 err;
    float3 p = primitive_hit_point(&prim, o, d, h, &err);
    double off = double(n.x) * (double(p.x) - c.x) + double(n.y) * (double(p.y) - c.y) +
                 double(n.z) * (double(p.z) - c.z);
    ASSERT_LE(std::fabs(off), double(dot(fabs(n), err))) << i;
    ASSERT_EQ(primitive_normal(&prim, p).z, l.n.z);
    // a ray leaving the hit point on either side does not hit the disk again
    float3 w = random_unit(rng);
    float3 side = dot(w, n) >= 0.0f ? n : -n;
    float3 po = offset_ray_origin(p, err, side);
    float t2;
    ASSERT_FALSE(ray_primitive(&prim, po, w, 0.0f, FLT_INF, &t2, &uu, &vv))
        << i << ": re-hit at " << t2 << ", cos " << dot(w, n);
  }
  EXPECT_GT(hits, 40000);
  EXPECT_GT(misses, 40000);
  EXPECT_GT(front_hits, 15000); // both faces
  EXPECT_GT(back_hits, 15000);
}

TEST(IntersectDisk, BvhOverDisksAndTrianglesMatchesBruteForce) {
  // A scene of disk lights and triangles: build_primitives adds one PRIM_DISK per disk light with
  // a box that contains it (rim points checked), and the BVH's closest hit equals the brute-force
  // closest hit over every primitive.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Scene scene;
  scene.materials.push_back(diffuse_material("m", make_float3(0.5f, 0.5f, 0.5f)));
  for (int i = 0; i < 300; ++i) {
    float3 c = make_float3(u(rng), u(rng), u(rng)) * 10.0f;
    scene.lights.push_back(make_disk_light(c, random_unit(rng), 0.05f + 0.5f * u(rng),
                                           make_float3(1, 1, 1), i % 2 == 0));
  }
  for (int i = 0; i < 300; ++i) {
    float3 a = make_float3(u(rng), u(rng), u(rng)) * 10.0f;
    uint32_t base = uint32_t(scene.vertices.size());
    scene.vertices.push_back(a);
    scene.vertices.push_back(a + random_unit(rng) * 0.8f);
    scene.vertices.push_back(a + random_unit(rng) * 0.8f);
    scene.indices.insert(scene.indices.end(), {base, base + 1, base + 2});
    scene.triangle_material.push_back(0);
    scene.triangle_light.push_back(-1);
  }
  std::vector<Material> materials = {scene.materials[0].gpu};
  std::vector<Primitive> prims = build_primitives(scene, materials);
  ASSERT_EQ(prims.size(), 600u);
  Bvh bvh = build_bvh(prims);
  int disks = 0;
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    ASSERT_GE(l.prim, 0);
    const Primitive& p = prims[size_t(l.prim)];
    ASSERT_EQ(p.type, PRIM_DISK);
    ASSERT_EQ(p.light, int(i));
    ++disks;
  }
  EXPECT_EQ(disks, 300);
  int hits = 0, disk_hits = 0;
  for (int i = 0; i < 20000; ++i) {
    float3 o = make_float3(u(rng), u(rng), u(rng)) * 12.0f - make_float3(1, 1, 1);
    float3 d = random_unit(rng);
    Hit h;
    bvh_intersect(bvh.nodes.data(), bvh.leaf_blocks.data(), prims.data(), o, d, 0.0f, FLT_INF, 0,
                  &h);
    int best = -1;
    float best_t = FLT_INF;
    for (size_t k = 0; k < prims.size(); ++k) {
      float t, uu, vv;
      if (ray_primitive(&prims[k], o, d, 0.0f, best_t, &t, &uu, &vv)) {
        best_t = t;
        best = int(k);
      }
    }
    ASSERT_EQ(h.prim, best) << i;
    if (best >= 0) {
      ASSERT_EQ(h.t, best_t);
      ++hits;
      disk_hits += prims[size_t(best)].type == PRIM_DISK;
      // an any-hit query finds some hit too
      Hit ha;
      ASSERT_GE(bvh_intersect(bvh.nodes.data(), bvh.leaf_blocks.data(), prims.data(), o, d, 0.0f,
                              FLT_INF, 1, &ha),
                0);
    }
  }
  EXPECT_GT(disk_hits, 1000);
  EXPECT_GT(hits - disk_hits, 1000);
}
