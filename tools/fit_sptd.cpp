// fit-sptd: fits the Spherical Pivot Transformed Distribution (Dupuy, Heitz & Belcour 2017) of
// the GGX reflection lobe that cl/bsdf/cap_integral.h integrates over caps, and prints the table
// header cl/bsdf/sptd_table.h:
//   build/tools/fit-sptd > cl/bsdf/sptd_table.h
// (the SptdTableRegenerates test checks that the committed header is this program's output).
//
// Per cell (theta_o, roughness) of the grid, with wo = (sin theta_o, 0, cos theta_o):
// - albedo: the directional albedo of the Fresnel-free lobe f(wo, w) cos theta = D G2 / (4 cos_o)
//   (cl/bsdf/microfacet.h: GGX D, height-correlated Smith G2), by visible-normal sampling
//   (weight G2 / G1(wo)) on a 256 x 256 stratified grid; with it the Fresnel cosine c_eff,
//   (1 - c_eff)^5 = the lobe-weighted mean of (1 - wo.h)^5 (exact for a Schlick-shaped F).
// - pivot xi = (1 - gap) (sin angle, 0, cos angle): the model amplitude D_xi(w) [w.z > 0] with
//   D_xi(w) = (1 / 4 pi) ((1 - |xi|^2) / |w - xi|^2)^2 and the amplitude set so that its
//   hemisphere integral is the albedo, fitted by Nelder-Mead on the L2 distance to the lobe,
//   estimated with a fixed set of directions (visible-normal and cosine samples combined by the
//   balance heuristic). Each cell starts from its neighbour's optimum.
// Everything is double precision, single-threaded, from fixed stratified points: the output is
// the same bit for bit on every run. Printed with %.9e (float round-trips exactly).
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

namespace {

constexpr int kNTheta = 32, kNAlpha = 32;
constexpr double kPi = 3.14159265358979323846;
constexpr double kThetaMax = 89.5 * kPi / 180.0; // last theta_o node
constexpr double kRoughMin = 0.01;               // first roughness node: alpha = 1e-4

struct V3 {
  double x, y, z;
};
V3 operator+(V3 a, V3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
V3 operator-(V3 a, V3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
V3 operator*(V3 a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
double dot(V3 a, V3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
V3 normalize(V3 a) {
  return a * (1.0 / std::sqrt(dot(a, a)));
}

// GGX as in cl/bsdf/microfacet.h, in double.
double ggx_d(V3 h, double a) {
  double a2 = a * a;
  double s = (h.x * h.x + h.y * h.y) / a2 + h.z * h.z;
  return 1.0 / (kPi * a2 * s * s);
}
double lambda_len(V3 w, double a) {
  return std::sqrt(w.z * w.z + a * a * (w.x * w.x + w.y * w.y));
}
// f cos theta_i without Fresnel, 0 below the horizon.
double lobe(V3 wo, V3 wi, double a) {
  if (wi.z <= 0.0) return 0.0;
  V3 h = wo + wi;
  double l2 = dot(h, h);
  if (!(l2 > 0.0)) return 0.0;
  h = h * (1.0 / std::sqrt(l2));
  double den = wi.z * lambda_len(wo, a) + wo.z * lambda_len(wi, a);
  return ggx_d(h, a) / (2.0 * den) * wi.z;
}
// Visible normal (Dupuy & Benyoub 2023, as ggx_sample_visible_normal).
V3 sample_vndf(V3 wo, double a, double u1, double u2) {
  V3 ws = normalize({a * wo.x, a * wo.y, wo.z});
  double opz = 1.0 + ws.z, t = u2 * opz;
  double st = std::sqrt(std::fmax(0.0, t * (2.0 - t))), phi = 2.0 * kPi * u1;
  V3 hs = {st * std::cos(phi) + ws.x, st * std::sin(phi) + ws.y, opz * (1.0 - u2)};
  return normalize({a * hs.x, a * hs.y, hs.z});
}
V3 reflect(V3 wo, V3 h) {
  return h * (2.0 * dot(wo, h)) - wo;
}
// Solid-angle density of reflect(wo, visible normal) at wi (any wi with wo.h > 0).
double pdf_vndf(V3 wo, V3 wi, double a) {
  V3 h = wo + wi;
  double l2 = dot(h, h);
  if (!(l2 > 0.0)) return 0.0;
  h = h * (1.0 / std::sqrt(l2));
  if (dot(wo, h) <= 0.0) return 0.0;
  return ggx_d(h, a) / (2.0 * (wo.z + lambda_len(wo, a)));
}

// The albedo, and the cosine c_eff at which a Schlick-shaped Fresnel F0 + (1 - F0)(1 - c)^5
// gives the lobe's Fresnel-weighted albedo: (1 - c_eff)^5 = the lobe's mean of (1 - wo.h)^5.
double albedo(V3 wo, double a, double* cos_eff) {
  const int n = 256;
  double sum = 0.0, sum5 = 0.0;
  double lo = lambda_len(wo, a);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      V3 h = sample_vndf(wo, a, (i + 0.5) / n, (j + 0.5) / n);
      V3 wi = reflect(wo, h);
      if (wi.z <= 0.0) continue;
      double li = lambda_len(wi, a);
      double wgt = wi.z * (wo.z + lo) / (wi.z * lo + wo.z * li);
      double x = 1.0 - std::fmin(std::fmax(dot(wo, h), 0.0), 1.0);
      sum += wgt;
      sum5 += wgt * x * x * x * x * x;
    }
  *cos_eff = sum > 0.0 ? 1.0 - std::pow(sum5 / sum, 0.2) : wo.z;
  return sum / (double(n) * n);
}

// Cap machinery of cl/bsdf/cap_integral.h in double (see the comments there).
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double omc(double s, double c) { return c > 0.0 ? s * s / (1.0 + c) : 1.0 - c; }
double lens_area(V3 a, double sa, double ca, V3 b, double sb, double cb) {
  double cd = std::fmin(std::fmax(dot(a, b), -1.0), 1.0);
  V3 x3 = cross(a, b);
  double sd = std::sqrt(dot(x3, x3));
  double ra = std::atan2(sa, ca), rb = std::atan2(sb, cb), d = std::atan2(sd, cd);
  double oa = omc(sa, ca), ob = omc(sb, cb);
  if (d >= ra + rb) return 0.0;
  if (d + ra <= rb) return 2.0 * kPi * oa;
  if (d + rb <= ra) return 2.0 * kPi * ob;
  double x = (cb - cd) + cd * oa, y = (ca - cd) + cd * ob, h = sa * sd;
  double v = std::sqrt(std::fmax(0.0, (h - x) * (h + x)));
  double e = 2.0 * std::atan2(v, 1.0 + cd + ca + cb);
  double lens = 2.0 * (std::atan2(v, x) * oa + std::atan2(v, y) * ob - e);
  return std::fmin(std::fmax(lens, 0.0), 2.0 * kPi * std::fmin(oa, ob));
}
double intersection_area(V3 a, double sa, double ca, V3 b, double sb, double cb) {
  V3 na = a * -1.0, nb = b * -1.0;
  if (ca < 0.0 && cb < 0.0) return std::fmax(-2.0 * kPi * (ca + cb) + lens_area(na, sa, -ca, nb, sb, -cb), 0.0);
  if (cb < 0.0) return std::fmax(2.0 * kPi * omc(sa, ca) - lens_area(a, sa, ca, nb, sb, -cb), 0.0);
  if (ca < 0.0) return std::fmax(2.0 * kPi * omc(sb, cb) - lens_area(na, sa, -ca, b, sb, cb), 0.0);
  return lens_area(a, sa, ca, b, sb, cb);
}
V3 pivot_cap(V3 xi, double m, V3 a, double s, double c, double* so, double* co) {
  double xa = dot(xi, a), delta = c - xa;
  V3 nv = xi * (2.0 * delta) - a * m;
  double e = delta * (2.0 - m) - m * xa, len = std::sqrt(dot(nv, nv));
  *so = m * s / len;
  *co = e / len;
  return nv * (1.0 / len);
}

struct TestCap {
  V3 c;
  double s, co; // sin, cos of the half-angle
  double ref;   // the lobe's integral over it (from the fit's directions)
  double inv_w; // 1 / the error weight
};

struct Sample {
  V3 w;
  double weight; // 1 / (sum of the techniques' sample counts times densities)
  double target; // the lobe there
};

struct Cell {
  double gap_over_alpha, angle, albedo, cos_eff;
};

// params: log(gap / alpha), angle.
struct Model {
  V3 wo;
  double alpha, rho;
  const std::vector<Sample>* samples;
  const std::vector<TestCap>* caps;
  bool pivot(const double* p, V3* xi, double* m) const {
    double gap = std::exp(p[0]) * alpha;
    if (!(gap > 1e-7 && gap <= 1.0)) return false;
    *xi = V3{std::sin(p[1]), 0.0, std::cos(p[1])} * (1.0 - gap);
    *m = gap * (2.0 - gap);
    return true;
  }
  // Squared errors of the model's cap integrals against the lobe's, each relative to the
  // integral plus 10% of the albedo: relative for the caps holding most of the lobe (what
  // ranks the lights that matter), absolute for the tails.
  double error(const double* p) const {
    V3 xi;
    double m;
    if (!pivot(p, &xi, &m)) return 1e300;
    double hs, hc;
    V3 ha = pivot_cap(xi, m, V3{0, 0, 1}, 1.0, 0.0, &hs, &hc);
    double amp = rho / (2.0 * kPi * omc(hs, hc));
    double e = 0.0;
    for (const TestCap& c : *caps) {
      double ps, pc;
      V3 pa = pivot_cap(xi, m, c.c, c.s, c.co, &ps, &pc);
      double r = (amp * intersection_area(pa, ps, pc, ha, hs, hc) - c.ref) * c.inv_w;
      e += r * r;
    }
    return e;
  }
};

// Nelder-Mead (standard coefficients), fixed iteration budget and a relative stop.
void nelder_mead(const Model& model, double* p, const double* step, int iters) {
  std::array<std::array<double, 2>, 3> x;
  std::array<double, 3> f;
  for (int i = 0; i < 3; ++i) {
    x[i] = {p[0], p[1]};
    if (i > 0) x[i][i - 1] += step[i - 1];
    f[i] = model.error(x[i].data());
  }
  for (int it = 0; it < iters; ++it) {
    // order
    for (int i = 0; i < 3; ++i)
      for (int j = i + 1; j < 3; ++j)
        if (f[j] < f[i]) {
          std::swap(f[i], f[j]);
          std::swap(x[i], x[j]);
        }
    if (f[2] - f[0] <= 1e-12 * std::fabs(f[0]) + 1e-300) break;
    std::array<double, 2> c = {(x[0][0] + x[1][0]) / 2, (x[0][1] + x[1][1]) / 2};
    auto lerp = [&](double t) {
      return std::array<double, 2>{c[0] + t * (x[2][0] - c[0]), c[1] + t * (x[2][1] - c[1])};
    };
    std::array<double, 2> xr = lerp(-1.0);
    double fr = model.error(xr.data());
    if (fr < f[0]) {
      std::array<double, 2> xe = lerp(-2.0);
      double fe = model.error(xe.data());
      if (fe < fr) {
        x[2] = xe;
        f[2] = fe;
      } else {
        x[2] = xr;
        f[2] = fr;
      }
    } else if (fr < f[1]) {
      x[2] = xr;
      f[2] = fr;
    } else {
      std::array<double, 2> xc = fr < f[2] ? lerp(-0.5) : lerp(0.5);
      double fc = model.error(xc.data());
      if (fc < std::fmin(fr, f[2])) {
        x[2] = xc;
        f[2] = fc;
      } else {
        for (int i = 1; i < 3; ++i) {
          x[i] = {(x[0][0] + x[i][0]) / 2, (x[0][1] + x[i][1]) / 2};
          f[i] = model.error(x[i].data());
        }
      }
    }
  }
  int best = 0;
  for (int i = 1; i < 3; ++i)
    if (f[i] < f[best]) best = i;
  p[0] = x[best][0];
  p[1] = x[best][1];
}

Cell fit_cell(double theta, double alpha, double* p) {
  V3 wo = {std::sin(theta), 0.0, std::cos(theta)};
  double cos_eff;
  Model model{wo, alpha, albedo(wo, alpha, &cos_eff), nullptr, nullptr};
  // The fit's directions: n x n visible-normal reflections and n x n cosine-distributed
  // directions, each weighted by the balance heuristic 1 / (N p_vndf + N p_cos).
  const int n = 48;
  const double count = double(n) * n;
  std::vector<Sample> samples;
  samples.reserve(2 * n * n);
  auto add = [&](V3 w) {
    if (w.z <= 0.0) return; // the lobe and the model are 0 there
    double pdf = count * (pdf_vndf(wo, w, alpha) + w.z / kPi);
    samples.push_back({w, 1.0 / pdf, lobe(wo, w, alpha)});
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      double u1 = (i + 0.5) / n, u2 = (j + 0.5) / n;
      add(reflect(wo, sample_vndf(wo, alpha, u1, u2)));
      double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
      add({r * std::cos(phi), r * std::sin(phi), std::sqrt(std::fmax(0.0, 1.0 - u1))});
    }
  model.samples = &samples;
  // Test caps: centred on the mirror direction, the normal, the fit's visible-normal directions
  // (a 4 x 4 subset) and cosine directions (4 x 4); half-angles 0.5, 1, 2 and 4 lobe widths
  // (2 alpha) and 0.1, 0.3, 0.6, 1.0, 1.5 rad.
  std::vector<V3> centres = {{-wo.x, -wo.y, wo.z}, {0, 0, 1}};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      double u1 = (i + 0.5) / 4, u2 = (j + 0.5) / 4;
      V3 w = reflect(wo, sample_vndf(wo, alpha, u1, u2));
      if (w.z > 0.0) centres.push_back(w);
      double r = std::sqrt(u1), phi = 2.0 * kPi * u2 + 0.3;
      centres.push_back({r * std::cos(phi), r * std::sin(phi), std::sqrt(std::fmax(0.0, 1.0 - u1))});
    }
  std::vector<double> radii = {0.1, 0.3, 0.6, 1.0, 1.5};
  for (double k : {0.5, 1.0, 2.0, 4.0})
    if (2.0 * alpha * k < 0.08) radii.push_back(2.0 * alpha * k);
  std::vector<TestCap> caps;
  for (V3 c : centres)
    for (double r : radii) {
      TestCap t{c, std::sin(r), std::cos(r), 0.0, 0.0};
      double o = omc(t.s, t.co);
      for (const Sample& smp : samples)
        if (1.0 - dot(smp.w, c) <= o) t.ref += smp.weight * smp.target;
      t.inv_w = 1.0 / (t.ref + 0.1 * model.rho);
      caps.push_back(t);
    }
  model.caps = &caps;
  const double step[2] = {0.3, 0.05};
  nelder_mead(model, p, step, 300);
  nelder_mead(model, p, step, 300); // a restart: Nelder-Mead can stall on a collapsed simplex
  return {std::exp(p[0]), p[1], model.rho, cos_eff};
}

} // namespace

int main() {
  std::vector<Cell> cells(kNTheta * kNAlpha);
  // Start: normal incidence, roughness 0.01. Near the peak the GGX lobe in the reflected
  // direction falls off as 1 / ((2 alpha)^2 + theta^2)^2 and D_xi as 1 / (gap^2 + theta^2)^2:
  // gap = 2 alpha.
  double row_start[2] = {std::log(2.0), 0.0};
  for (int i = 0; i < kNTheta; ++i) {
    double theta = kThetaMax * i / (kNTheta - 1);
    double p[2] = {row_start[0], row_start[1]};
    for (int j = 0; j < kNAlpha; ++j) {
      double rough = kRoughMin + (1.0 - kRoughMin) * j / (kNAlpha - 1);
      cells[i * kNAlpha + j] = fit_cell(theta, rough * rough, p);
      if (j == 0) {
        row_start[0] = p[0];
        row_start[1] = p[1];
      }
    }
  }
  std::printf(
      "// Generated by tools/fit_sptd.cpp -- do not edit. Regenerate with\n"
      "//   build/tools/fit-sptd > cl/bsdf/sptd_table.h\n"
      "// (the SptdTableRegenerates test checks this file is its output).\n"
      "// SPTD fit of the Fresnel-free GGX lobe, used by cl/bsdf/cap_integral.h. Cell (i, j):\n"
      "// theta_o = SPTD_THETA_MAX i / (SPTD_N_THETA - 1), roughness = sqrt(alpha) =\n"
      "// SPTD_ROUGH_MIN + (1 - SPTD_ROUGH_MIN) j / (SPTD_N_ALPHA - 1); four floats each:\n"
      "// (1 - |xi|) / alpha, the pivot's signed angle from the normal (wo at positive\n"
      "// angles), the lobe's directional albedo, the cosine at which to take Fresnel.\n"
      "#ifndef CANOPY_CL_BSDF_SPTD_TABLE_H\n"
      "#define CANOPY_CL_BSDF_SPTD_TABLE_H\n\n"
      "#define SPTD_N_THETA %d\n#define SPTD_N_ALPHA %d\n"
      "#define SPTD_THETA_MAX %.9ef\n#define SPTD_ROUGH_MIN %.9ef\n"
      "#define SPTD_ALPHA_MIN %.9ef\n\n",
      kNTheta, kNAlpha, kThetaMax, kRoughMin, kRoughMin * kRoughMin);
  std::printf("#ifdef __OPENCL_C_VERSION__\nCONSTANT float sptd_table[%d] = {\n#else\n"
              "inline constexpr float sptd_table[%d] = {\n#endif\n",
              kNTheta * kNAlpha * 4, kNTheta * kNAlpha * 4);
  for (int i = 0; i < kNTheta; ++i) {
    std::printf("    // theta_o node %d\n", i);
    for (int j = 0; j < kNAlpha; ++j) {
      const Cell& c = cells[i * kNAlpha + j];
      std::printf("    %.9ef, %.9ef, %.9ef, %.9ef,\n", float(c.gap_over_alpha), float(c.angle),
                  float(c.albedo), float(c.cos_eff));
    }
  }
  std::printf("};\n\n#endif // CANOPY_CL_BSDF_SPTD_TABLE_H\n");
  return 0;
}
