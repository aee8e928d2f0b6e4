#include "cli/converge_command.h"

#include "cl/runtime.h"
#include "image/error_stats.h"
#include "image/image_compare.h"
#include "image/image_io.h"
#include "oiio/plot.h"
#include "render/auto_sampler.h"
#include "render/equal_time.h"
#include "render/renderer.h"
#include "scene/scene.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace canopy {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct ConvergeArgs {
  std::string scene, reference, samplers = "uniform,power,tree,tree-split", out, device, title;
  double budget = 30.0;
  int seeds = 8;
  double equal_time = 0.0;     // > 0: one point per configuration, spp for ~this many seconds
  int max_depth = 0;           // > 0: overrides the scene's integrator.max_depth
  double reference_time = 0.0; // > 0: the reference's spp from a timing render
  int spp_start = 1;
  int spp_factor = 2;
  int max_spp = 1 << 16;
  double film_scale = 1.0;
  double clamp = 0.0; // > 0: clamp render and reference to [0, clamp] before measuring
  int reference_spp = 0;
  std::string reference_sampler = "exhaustive";
  std::string path_sampler{kDefaultPathSampler}; // --sampler
  uint32_t reference_seed = 1000003;
};

// One sampler configuration: "tree-split:0.5" = light sampler tree-split, threshold 0.5;
// "tree-noorient" = tree without Eq. 3's orientation terms (importance E / d^2: the ablation);
// a trailing "/nomis" (e.g. "power/nomis", "tree-split:0.25/nomis") switches MIS off. Without it
// MIS is on, whatever the scene's integrator says, so that a label names one configuration.
// For the BRDF-oriented samplers (Liu et al. 2019) ":D" is the cut's split threshold delta on the
// cap integral S_C (Eq. 5) instead, and "brdf-mis/equal" is brdf-mis with equal allocation, one
// sample per technique (their Fig. 8); without /equal the allocation is adaptive (Alg. 1),
// whatever the scene says. N_max and lambda come from the scene.
struct SamplerConfig {
  std::string label, sampler;
  float threshold = 0.0f;
  bool orientation = true;
  bool mis = true;
  BrdfSettings brdf;
  // With a medium: "/midpoint" ranks light clusters for a ray segment by the surface importance
  // at its midpoint (the ablation of Conty Estevez & Kulla's segment importance, Eq. 7).
  bool volume_midpoint = false;
  int max_cut = kDefaultMaxCut; // "/maxcut=N": tree-split's cut cap per shading point
  // The camera paths' numbers (RendererOptions::path_sampler): --sampler, or "/sobol",
  // "/independent".
  std::string path_sampler{kDefaultPathSampler};
};

constexpr std::string_view kNoOrientSuffix = "-noorient";
constexpr std::string_view kNoMisSuffix = "nomis";       // after a '/'
constexpr std::string_view kEqualSuffix = "equal";       // after a '/'
constexpr std::string_view kMidpointSuffix = "midpoint"; // after a '/'
constexpr std::string_view kSplitSuffix = "split=";      // after a '/', then the threshold
constexpr std::string_view kNmaxSuffix = "nmax=";        // after a '/', then brdf-mis' N_max
constexpr std::string_view kMaxCutSuffix = "maxcut=";    // after a '/', then max_cut
constexpr float kMaxBrdfDelta = 1000.0f;                 // as `canopy render --brdf-delta`

bool is_brdf_sampler(const std::string& sampler) {
  return sampler == "brdf-mis" || sampler == "brdf-oriented";
}

struct RunRecord {
  int spp = 0;
  uint32_t seed = 0;
  double seconds = 0.0;
  uint64_t shadow_rays = 0, shading_points = 0;
  // BRDF samplers: glossy points and the sums over them of cut size and sample count N
  uint64_t glossy_points = 0, brdf_cut_sum = 0, brdf_samples_sum = 0, brdf_rays = 0;
  ImageMetrics metrics;
  PixelErrorStats all, ne; // every pixel; the pixels without an emitter in view
};

// A point's statistics over its seeds, for one pixel set.
struct SetStats {
  double mse = NAN, eff = NAN;
  Interval mse_ci{NAN, NAN}, eff_ci{NAN, NAN};
  double top_mean = NAN, top_max = NAN, worst_max = NAN;
  double floor = NAN; // the reference's error floor (NaN: unknown)
  int resolved = -1;  // 1: mse > kResolvedFactor x floor; 0: not (no verdict); -1: floor unknown
  size_t pixels = 0;
};

struct PointStats {
  int spp = 0;
  size_t runs = 0;
  double seconds = 0.0, shadow_rays = 0.0;
  SetStats all, ne;
};

// A point is resolved when its mean MSE is more than this many times the reference's floor:
// closer to it, the reference's own noise would be a large part of the measured error.
constexpr double kResolvedFactor = 10.0;
// Checks of the equal-time spp by a render at it (spp_for_seconds).
constexpr int kTimingRefinements = 3;

struct MedianPoint {
  int spp = 0;
  double seconds = 0.0, shadow_rays = 0.0, rmse = 0.0, relmse = 0.0;
};

struct ConfigResult {
  SamplerConfig config;
  double build_seconds = 0.0, light_tree_seconds = 0.0, compile_seconds = 0.0;
  double warmup_seconds = 0.0; // the first (unrecorded) render: PoCL finishes kernel builds
  double render_seconds = 0.0; // summed over the runs
  std::vector<RunRecord> runs;
  std::vector<MedianPoint> medians; // by spp, increasing
  std::vector<PointStats> points;   // by spp, increasing
  double timing_seconds = 0.0;      // --equal-time: the timing renders that chose the spp
  // "auto": the configurations its explorations chose in the recorded runs (render/auto_sampler.h:
  // "tree x6, power x2") and their mean seconds. Each run's seconds are the whole auto render's,
  // its exploration and sampler switches included.
  std::string auto_choice;
  double pilot_seconds = 0.0;
  std::map<std::string, int> auto_choices;
};

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// `scene` gives the defaults: the tree's split threshold and the BRDF samplers' settings.
SamplerConfig parse_config(const std::string& text, const IntegratorSettings& scene,
                           const std::string& option, const std::string& path_sampler) {
  SamplerConfig c;
  c.label = text;
  c.path_sampler = path_sampler;
  c.threshold = scene.split_threshold;
  c.brdf.delta = scene.brdf_delta;
  c.brdf.n_max = scene.brdf_n_max;
  c.brdf.lambda = scene.brdf_lambda;
  c.brdf.adaptive = true;
  c.max_cut = scene.max_cut;
  std::string spec = text;
  bool equal = false, split_set = false, nmax_set = false, cut_set = false, path_set = false;
  // The integer after "/name=", in [lo, hi].
  auto suffix_int = [&](const std::string& suffix, std::string_view name, long lo, long hi) {
    std::string t = suffix.substr(name.size());
    char* end = nullptr;
    long v = std::strtol(t.c_str(), &end, 10);
    if (t.empty() || *end != '\0' || v < lo || v > hi)
      throw SceneError(fmt::format("{}: '{}': /{}N: N must be an integer in [{}, {}]", option,
                                   printable(text, 256), name, lo, hi));
    return int(v);
  };
  if (size_t slash = spec.find('/'); slash != std::string::npos) {
    std::stringstream suffixes(spec.substr(slash + 1));
    spec.resize(slash);
    std::string suffix;
    bool any = false;
    while (std::getline(suffixes, suffix, '/')) {
      any = true;
      if (suffix == kNoMisSuffix && c.mis) {
        c.mis = false;
      } else if (!path_set && std::find(kPathSamplerNames.begin(), kPathSamplerNames.end(),
                                        suffix) != kPathSamplerNames.end()) {
        c.path_sampler = suffix; // "/sobol", "/independent": the camera paths' numbers
        path_set = true;
      } else if (suffix == kEqualSuffix && !equal) {
        equal = true;
      } else if (suffix == kMidpointSuffix && !c.volume_midpoint) {
        c.volume_midpoint = true;
      } else if (suffix.starts_with(kSplitSuffix) && !split_set) {
        // "/split=T": tree-split's threshold T where ":T" means something else (brdf-mis'
        // delta), e.g. brdf-mis/split=0.25 at the renderer's default threshold.
        std::string t = suffix.substr(kSplitSuffix.size());
        char* end = nullptr;
        double v = std::strtod(t.c_str(), &end);
        if (t.empty() || *end != '\0' || !(v >= 0.0 && v <= 1.0))
          throw SceneError(fmt::format("{}: '{}': /{}T: T must be a number in [0, 1]", option,
                                       printable(text, 256), kSplitSuffix));
        c.threshold = float(v);
        split_set = true;
      } else if (suffix.starts_with(kNmaxSuffix) && !nmax_set) {
        // "/nmax=N": the BRDF samplers' most BRDF-aware samples per glossy point (Eq. 9).
        c.brdf.n_max = suffix_int(suffix, kNmaxSuffix, 1, kMaxBrdfSamples);
        nmax_set = true;
      } else if (suffix.starts_with(kMaxCutSuffix) && !cut_set) {
        // "/maxcut=N": the most lights tree-split samples per shading point.
        c.max_cut = suffix_int(suffix, kMaxCutSuffix, 1, kMaxMaxCut);
        cut_set = true;
      } else {
        throw SceneError(fmt::format("{}: '{}': unknown or repeated suffix '/{}' (/{}: MIS off; "
                                     "/{}: brdf-mis with equal allocation; /{}: medium segments "
                                     "ranked at their midpoint; /{}T: split threshold T; "
                                     "/{}N: brdf-mis' N_max; /{}N: cut cap; /sobol, "
                                     "/independent: the path sampler)",
                                     option, printable(text, 256), printable(suffix, 256),
                                     kNoMisSuffix, kEqualSuffix, kMidpointSuffix, kSplitSuffix,
                                     kNmaxSuffix, kMaxCutSuffix));
      }
    }
    if (!any)
      throw SceneError(
          fmt::format("{}: '{}': empty suffix after '/'", option, printable(text, 256)));
  }
  if (spec == kAutoLightSampler) { // chosen per scene by a pilot (render/auto_sampler.h)
    if (spec != text && !(path_set && text == spec + "/" + c.path_sampler))
      throw SceneError(fmt::format("{}: '{}': auto takes no suffix", option, printable(text, 256)));
    c.sampler = spec;
    return c;
  }
  size_t colon = spec.find(':');
  c.sampler = spec.substr(0, colon);
  if (c.sampler.size() > kNoOrientSuffix.size() && c.sampler.ends_with(kNoOrientSuffix)) {
    c.sampler.resize(c.sampler.size() - kNoOrientSuffix.size());
    c.orientation = false;
    if (c.sampler.rfind("tree", 0) != 0)
      throw SceneError(
          fmt::format("{}: '{}': {} applies to tree samplers only", option, text, kNoOrientSuffix));
  }
  if (!c.mis && c.sampler == "bsdf")
    throw SceneError(fmt::format("{}: '{}': /{} does not apply to bsdf (BSDF sampling only: "
                                 "there is no light sample to combine with)",
                                 option, printable(text, 256), kNoMisSuffix));
  if (!c.mis && is_brdf_sampler(c.sampler))
    throw SceneError(fmt::format("{}: '{}': /{} does not apply to {} (it weights its own "
                                 "techniques; brdf-oriented is the one without MIS)",
                                 option, printable(text, 256), kNoMisSuffix, c.sampler));
  if (equal && c.sampler != "brdf-mis")
    throw SceneError(fmt::format("{}: '{}': /{} applies to brdf-mis only (equal allocation "
                                 "between its BRDF-oriented and BSDF samples)",
                                 option, printable(text, 256), kEqualSuffix));
  c.brdf.adaptive = !equal;
  if (std::find(kLightSamplerNames.begin(), kLightSamplerNames.end(), c.sampler) ==
      kLightSamplerNames.end())
    throw SceneError(fmt::format("{}: unknown light sampler '{}' (one of {}; tree samplers take "
                                 "-noorient; /nomis switches MIS off; brdf-mis takes /equal)",
                                 option, c.sampler, fmt::join(kLightSamplerNames, ", ")));
  if (colon != std::string::npos) {
    std::string t = spec.substr(colon + 1);
    char* end = nullptr;
    double v = std::strtod(t.c_str(), &end);
    bool brdf = is_brdf_sampler(c.sampler);
    double hi = brdf ? double(kMaxBrdfDelta) : 1.0;
    if (t.empty() || *end != '\0' || !(v >= 0.0 && v <= hi))
      throw SceneError(fmt::format("{}: '{}': {} must be a number in [0, {}]", option, text,
                                   brdf ? "the BRDF split threshold delta" : "the split threshold",
                                   hi));
    if (brdf)
      c.brdf.delta = float(v);
    else
      c.threshold = float(v);
  }
  return c;
}

RendererOptions renderer_options(const SamplerConfig& c) {
  RendererOptions opt;
  opt.light_sampler = c.sampler;
  opt.split_threshold = c.threshold;
  opt.max_cut = c.max_cut;
  opt.orientation_term = c.orientation;
  opt.mis = c.mis;
  opt.brdf = c.brdf;
  opt.path_sampler = c.path_sampler;
  // auto: the first candidate; the pilot then switches
  return c.sampler == kAutoLightSampler ? auto_candidates(opt).front().options : opt;
}

std::vector<SamplerConfig> parse_configs(const std::string& list, const IntegratorSettings& scene,
                                         const std::string& path_sampler) {
  std::vector<SamplerConfig> out;
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(parse_config(item, scene, "--samplers", path_sampler));
  if (out.empty()) throw SceneError("--samplers: no sampler given");
  return out;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::vector<MedianPoint> medians_by_spp(const std::vector<RunRecord>& runs) {
  std::vector<MedianPoint> out;
  std::vector<int> spps;
  for (const RunRecord& r : runs)
    if (std::find(spps.begin(), spps.end(), r.spp) == spps.end()) spps.push_back(r.spp);
  std::sort(spps.begin(), spps.end());
  for (int spp : spps) {
    std::vector<double> t, rays, rmse, rel;
    for (const RunRecord& r : runs)
      if (r.spp == spp) {
        t.push_back(r.seconds);
        rays.push_back(double(r.shadow_rays));
        rmse.push_back(r.metrics.rmse);
        rel.push_back(r.metrics.relmse);
      }
    out.push_back({spp, median(t), median(rays), median(rmse), median(rel)});
  }
  return out;
}

SetStats set_stats(const std::vector<const RunRecord*>& runs, PixelErrorStats RunRecord::*set,
                   double floor) {
  SetStats st;
  std::vector<double> mse, secs;
  st.top_mean = 0.0;
  st.top_max = st.worst_max = 0.0;
  for (const RunRecord* r : runs) {
    const PixelErrorStats& e = r->*set;
    mse.push_back(e.mse);
    secs.push_back(r->seconds);
    st.top_mean += e.top_share / double(runs.size());
    st.top_max = std::max(st.top_max, e.top_share);
    st.worst_max = std::max(st.worst_max, e.worst);
    st.pixels = e.pixels;
  }
  st.mse = 0.0;
  for (double m : mse)
    st.mse += m / double(mse.size());
  st.mse_ci = bootstrap_mean_interval(mse);
  st.eff = efficiency(mse, secs);
  st.eff_ci = bootstrap_efficiency_interval(mse, secs);
  st.floor = floor;
  if (std::isfinite(floor)) st.resolved = st.mse > kResolvedFactor * floor ? 1 : 0;
  return st;
}

// Per spp: means over the seeds with bootstrap intervals (error_stats.h), for both pixel sets.
std::vector<PointStats> point_stats(const std::vector<RunRecord>& runs, double floor_all,
                                    double floor_ne) {
  std::vector<int> spps;
  for (const RunRecord& r : runs)
    if (std::find(spps.begin(), spps.end(), r.spp) == spps.end()) spps.push_back(r.spp);
  std::sort(spps.begin(), spps.end());
  std::vector<PointStats> out;
  for (int spp : spps) {
    std::vector<const RunRecord*> sel;
    PointStats p;
    p.spp = spp;
    for (const RunRecord& r : runs)
      if (r.spp == spp) {
        sel.push_back(&r);
        p.seconds += r.seconds;
        p.shadow_rays += double(r.shadow_rays);
      }
    p.runs = sel.size();
    p.seconds /= double(sel.size());
    p.shadow_rays /= double(sel.size());
    p.all = set_stats(sel, &RunRecord::all, floor_all);
    p.ne = set_stats(sel, &RunRecord::ne, floor_ne);
    out.push_back(p);
  }
  return out;
}

// Median RMSE at time t by log-log interpolation of a curve; outside the measured range, the
// Monte Carlo rate RMSE ~ t^(-1/2) from the nearest end (`extrapolated` is set).
double rmse_at(const std::vector<MedianPoint>& pts, double t, bool* extrapolated) {
  std::vector<MedianPoint> p = pts;
  std::sort(p.begin(), p.end(),
            [](const MedianPoint& a, const MedianPoint& b) { return a.seconds < b.seconds; });
  *extrapolated = false;
  if (p.empty()) return NAN;
  if (t <= p.front().seconds || p.size() == 1) {
    const MedianPoint& e = t <= p.front().seconds ? p.front() : p.back();
    *extrapolated = std::abs(t - e.seconds) > 1e-9 * e.seconds;
    return e.rmse * std::sqrt(e.seconds / t);
  }
  if (t >= p.back().seconds) {
    *extrapolated = t > p.back().seconds * (1 + 1e-9);
    return p.back().rmse * std::sqrt(p.back().seconds / t);
  }
  for (size_t i = 1; i < p.size(); ++i)
    if (t <= p[i].seconds) {
      double f = std::log(t / p[i - 1].seconds) / std::log(p[i].seconds / p[i - 1].seconds);
      return std::exp((1 - f) * std::log(p[i - 1].rmse) + f * std::log(p[i].rmse));
    }
  return p.back().rmse;
}

std::string describe(const std::map<std::string, std::string>& attrs) {
  std::string s;
  for (const auto& [k, v] : attrs) {
    if (!s.empty()) s += ", ";
    s += k.substr(k.find(':') + 1) + " " + v;
  }
  return s.empty() ? "no canopy metadata" : s;
}

// Status line on stderr: rewritten in place on a terminal, one line per update otherwise.
class Progress {
public:
  Progress() : tty_(isatty(fileno(stderr)) != 0) {}
  void show(const std::string& line, bool final_line) {
    if (tty_) {
      std::fprintf(stderr, "\r\033[K%s%s", line.c_str(), final_line ? "\n" : "");
    } else if (final_line || seconds_since(last_) > 5.0) {
      std::fprintf(stderr, "%s\n", line.c_str());
      last_ = Clock::now();
    }
    std::fflush(stderr);
  }
  void line(const std::string& text) {
    if (tty_) std::fprintf(stderr, "\r\033[K");
    std::fprintf(stderr, "%s\n", text.c_str());
  }

private:
  bool tty_;
  Clock::time_point last_ = Clock::now() - std::chrono::hours(1);
};

std::string fmt_clock(double s) {
  int t = int(s + 0.5);
  return fmt::format("{}:{:02d}", t / 60, t % 60);
}

std::ofstream open_out(const fs::path& file) {
  if (fs::path parent = file.parent_path(); !parent.empty()) fs::create_directories(parent);
  std::ofstream out(file);
  if (!out) throw std::runtime_error(fmt::format("{}: cannot write", file.string()));
  return out;
}

// Where the reference's emitter mask is stored, next to it: REF.mask.png.
fs::path mask_path(const std::string& reference) {
  return fs::path(reference).replace_extension(".mask.png");
}

// Renders the reference as two independent halves (seeds S and S + 1) and writes their mean. The
// halves also measure the reference's own error floor: for independent halves A and B of
// per-pixel variance σ², E[MSE(A, B)] = 2σ² and the mean (A + B) / 2 has variance σ² / 2, so
// MSE_floor = MSE(A, B) / 4 (reference_floor_mse). It is computed over every pixel and over the
// pixels without an emitter in view, with the same --clamp as the measurements, and stored as
// canopy:reference_mse and canopy:reference_mse_nonemitter. The emitter mask (a pixel is an
// emitter pixel when a camera ray of either half hit an emitter: the reference's many samples
// make it the most complete) goes to REF.mask.png, so a reused reference keeps it.
void render_reference(ClRuntime& rt, const Scene& base, const ConvergeArgs& a, Progress& progress) {
  SamplerConfig c =
      parse_config(a.reference_sampler, base.integrator, "--reference-sampler", a.path_sampler);
  Scene scene = base;
  scene.integrator.volume_importance = c.volume_midpoint ? "midpoint" : "segment";
  Renderer r(rt, scene, renderer_options(c));
  int total_spp = a.reference_spp;
  if (a.reference_time > 0.0) {
    // Warm-up (kernel builds), then the timing renders: the spp of the whole reference.
    RenderSettings warm;
    warm.spp = 1;
    warm.seed = 0xC0FFEEu;
    r.render(warm);
    progress.show(fmt::format("reference {}: timing renders for {:g} s", c.label, a.reference_time),
                  false);
    spp_for_seconds(
        [&](int spp, uint32_t seed) {
          const double before = r.stats().render_seconds;
          RenderSettings rs;
          rs.spp = spp;
          rs.seed = seed;
          r.render(rs);
          return r.stats().render_seconds - before;
        },
        a.reference_time, std::max(1, a.spp_start), 1 << 24, 0xC0FFEEu + 1, &total_spp);
  }
  const int half_spp = std::max(1, total_spp / 2);
  auto t0 = Clock::now();
  const double seconds_before = r.stats().render_seconds;
  RgbImage halves[2];
  std::vector<uint8_t> mask;
  for (int h = 0; h < 2; ++h) {
    RenderSettings rs;
    rs.spp = half_spp;
    rs.seed = a.reference_seed + uint32_t(h);
    rs.progress = [&, h](double f) {
      double el = seconds_since(t0), done = 0.5 * (h + f);
      progress.show(fmt::format("reference {} {} spp: {:5.1f}%  {} elapsed, ~{} left", c.label,
                                2 * half_spp, 100.0 * done, fmt_clock(el),
                                fmt_clock(done > 0 ? el * (1 - done) / done : 0.0)),
                    false);
    };
    Film film = r.render(rs);
    halves[h] = film.mean();
    std::vector<uint8_t> m = film.emitter_mask();
    if (mask.empty()) mask.assign(m.size(), 0);
    for (size_t i = 0; i < m.size(); ++i)
      mask[i] |= m[i];
  }
  const double ref_seconds = r.stats().render_seconds - seconds_before;
  RgbImage img = halves[0];
  for (size_t i = 0; i < img.rgb.size(); ++i)
    img.rgb[i] = 0.5f * (halves[0].rgb[i] + halves[1].rgb[i]);
  if (a.clamp > 0.0)
    for (RgbImage& h : halves)
      h = clamp_image(h, float(a.clamp));
  const double floor_all = reference_floor_mse(halves[0], halves[1]);
  const double floor_ne = reference_floor_mse(halves[0], halves[1], mask);
  const size_t emitter_pixels = size_t(std::count(mask.begin(), mask.end(), uint8_t(1)));
  write_exr(a.reference, img,
            {{"canopy:scene", a.scene},
             {"canopy:light_sampler", c.sampler},
             {"canopy:sampler_config", c.label},
             {"canopy:split_threshold", fmt::format("{}", c.threshold)},
             {"canopy:orientation_term", c.orientation ? "on" : "off"},
             {"canopy:mis", c.mis ? "on" : "off"},
             {"canopy:max_depth", std::to_string(scene.integrator.max_depth)},
             {"canopy:spp", std::to_string(2 * half_spp)},
             {"canopy:seed",
              fmt::format("{} (spp/2) + {} (spp/2)", a.reference_seed, a.reference_seed + 1)},
             {"canopy:film", fmt::format("{}x{}", scene.film.width, scene.film.height)},
             {"canopy:render_seconds", fmt::format("{:.3f}", ref_seconds)},
             {"canopy:reference_mse", fmt::format("{:.6e}", floor_all)},
             {"canopy:reference_mse_nonemitter", fmt::format("{:.6e}", floor_ne)},
             {"canopy:reference_mse_clamp", fmt::format("{}", a.clamp)},
             {"canopy:emitter_pixels", std::to_string(emitter_pixels)},
             {"canopy:emitter_mask", mask_path(a.reference).filename().string()}});
  write_png(fs::path(a.reference).replace_extension(".png"), img);
  write_png(mask_path(a.reference), mask_to_image(mask, img.width, img.height));
  progress.show(fmt::format("reference {} {} spp, max depth {}: {:.1f} s; error floor (MSE of the "
                            "mean of two halves = MSE(A, B) / 4): all pixels {:.3e}, non-emitter "
                            "pixels {:.3e} ({} emitter pixels); wrote {}",
                            c.label, 2 * half_spp, scene.integrator.max_depth, ref_seconds,
                            floor_all, floor_ne, emitter_pixels, a.reference),
                true);
}

// Mean BRDF-oriented cut size and BRDF-aware sample count per glossy point over `runs` (Liu et
// al. 2019, Table 1-2 columns); 0 without glossy points (a sampler that is not brdf-mis or
// brdf-oriented, or a scene without a glossy material).
struct BrdfMeans {
  uint64_t glossy_points = 0;
  double cut = 0.0, samples = 0.0;
};

template <class Pred> BrdfMeans brdf_means(const std::vector<RunRecord>& runs, Pred include) {
  BrdfMeans m;
  uint64_t cut = 0, samples = 0;
  for (const RunRecord& r : runs)
    if (include(r)) {
      m.glossy_points += r.glossy_points;
      cut += r.brdf_cut_sum;
      samples += r.brdf_samples_sum;
    }
  if (m.glossy_points > 0) {
    m.cut = double(cut) / double(m.glossy_points);
    m.samples = double(samples) / double(m.glossy_points);
  }
  return m;
}

std::string csv_num(double v) {
  return std::isfinite(v) ? fmt::format("{:.6e}", v) : "";
}

// One pixel set's columns of the points CSV (see its header).
std::string set_columns(const SetStats& s) {
  return fmt::format("{},{},{},{},{},{},{:.6f},{:.6f},{},{},{},{}", csv_num(s.mse),
                     csv_num(s.mse_ci.lo), csv_num(s.mse_ci.hi), csv_num(s.eff),
                     csv_num(s.eff_ci.lo), csv_num(s.eff_ci.hi), s.top_mean, s.top_max,
                     csv_num(s.worst_max), csv_num(s.floor),
                     s.resolved < 0 ? std::string() : std::to_string(s.resolved), s.pixels);
}

void write_csvs(const fs::path& prefix, const std::string& scene, double ref_mse, double clamp,
                int max_depth, const std::string& mode, const std::vector<ConfigResult>& results) {
  std::ofstream runs = open_out(prefix.string() + ".csv");
  runs << "scene,sampler,light_sampler,split_threshold,spp,seed,seconds,shadow_rays,shading_points,"
          "rmse,relmse,psnr,reference_mse,clamp,mis,brdf_delta,brdf_adaptive,glossy_points,"
          "brdf_cut_sum,brdf_samples_sum,brdf_rays,max_depth,mode,mse,top_share,worst_pixel,mse_ne,"
          "top_share_ne,worst_pixel_ne\n";
  for (const ConfigResult& r : results)
    for (const RunRecord& x : r.runs)
      runs << fmt::format(
          "{},{},{},{},{},{},{:.6f},{},{},{:.6e},{:.6e},{:.4f},{:.6e},{},{},{},{},{},"
          "{},{},{},{},{},{:.6e},{:.6f},{:.6e},{:.6e},{:.6f},{:.6e}\n",
          scene, r.config.label, r.config.sampler, r.config.threshold, x.spp, x.seed, x.seconds,
          x.shadow_rays, x.shading_points, x.metrics.rmse, x.metrics.relmse, x.metrics.psnr,
          ref_mse, clamp, int(r.config.mis), r.config.brdf.delta, int(r.config.brdf.adaptive),
          x.glossy_points, x.brdf_cut_sum, x.brdf_samples_sum, x.brdf_rays, max_depth, mode,
          x.all.mse, x.all.top_share, x.all.worst, x.ne.mse, x.ne.top_share, x.ne.worst);
  std::ofstream med = open_out(prefix.string() + "-median.csv");
  med << "scene,sampler,spp,runs,seconds,shadow_rays,rmse,relmse,glossy_points,brdf_mean_cut,"
         "brdf_mean_samples\n";
  for (const ConfigResult& r : results)
    for (const MedianPoint& p : r.medians) {
      size_t n = size_t(std::count_if(r.runs.begin(), r.runs.end(),
                                      [&](const RunRecord& x) { return x.spp == p.spp; }));
      BrdfMeans bm = brdf_means(r.runs, [&](const RunRecord& x) { return x.spp == p.spp; });
      med << fmt::format("{},{},{},{},{:.6f},{:.0f},{:.6e},{:.6e},{},{:.4f},{:.4f}\n", scene,
                         r.config.label, p.spp, n, p.seconds, p.shadow_rays, p.rmse, p.relmse,
                         bm.glossy_points, bm.cut, bm.samples);
    }
  std::ofstream cfg = open_out(prefix.string() + "-configs.csv");
  cfg << "scene,sampler,light_sampler,split_threshold,build_seconds,light_tree_seconds,"
         "compile_seconds,warmup_seconds,render_seconds,runs,max_spp,mis,max_depth,mode,"
         "timing_seconds,auto_choice,pilot_seconds\n";
  for (const ConfigResult& r : results)
    cfg << fmt::format(
        "{},{},{},{},{:.4f},{:.4f},{:.4f},{:.3f},{:.3f},{},{},{},{},{},{:.3f},{},{:.3f}\n", scene,
        r.config.label, r.config.sampler, r.config.threshold, r.build_seconds, r.light_tree_seconds,
        r.compile_seconds, r.warmup_seconds, r.render_seconds, r.runs.size(),
        r.medians.empty() ? 0 : r.medians.back().spp, int(r.config.mis), max_depth, mode,
        r.timing_seconds, r.auto_choice, r.pilot_seconds);
  // Per point: means over the seeds with 95% bootstrap intervals, for every pixel and for the
  // pixels without an emitter in view (_ne). efficiency = 1 / (mean MSE x mean seconds).
  std::ofstream pts = open_out(prefix.string() + "-points.csv");
  std::string set_cols = "mse,mse_lo,mse_hi,efficiency,efficiency_lo,efficiency_hi,"
                         "top_share_mean,top_share_max,worst_pixel_max,reference_floor,resolved,"
                         "pixels";
  std::string ne_cols;
  {
    std::stringstream ss(set_cols);
    std::string col;
    while (std::getline(ss, col, ','))
      ne_cols += (ne_cols.empty() ? "" : ",") + col + "_ne";
  }
  pts << "scene,sampler,light_sampler,split_threshold,mis,max_depth,mode,spp,runs,seconds,"
         "shadow_rays,"
      << set_cols << "," << ne_cols << "\n";
  for (const ConfigResult& r : results)
    for (const PointStats& p : r.points)
      pts << fmt::format("{},{},{},{},{},{},{},{},{},{:.6f},{:.0f},{},{}\n", scene, r.config.label,
                         r.config.sampler, r.config.threshold, int(r.config.mis), max_depth, mode,
                         p.spp, p.runs, p.seconds, p.shadow_rays, set_columns(p.all),
                         set_columns(p.ne));
}

std::string fmt_ci(const Interval& i) {
  return fmt::format("[{:.2e}, {:.2e}]", i.lo, i.hi);
}

std::string resolved_text(int resolved) {
  return resolved < 0 ? "floor unknown" : resolved ? "resolved" : "UNRESOLVED";
}

int run_converge(const ConvergeArgs& a) {
  auto t_start = Clock::now();
  Scene base = load_scene(a.scene);
  if (a.film_scale != 1.0) scale_film(base.film, a.film_scale);
  if (a.max_depth > 0) base.integrator.max_depth = a.max_depth;
  std::vector<SamplerConfig> configs = parse_configs(a.samplers, base.integrator, a.path_sampler);
  if (a.spp_factor < 2) throw SceneError("--spp-factor: must be >= 2");
  if (a.reference_spp > 0 && a.reference_time > 0.0)
    throw SceneError("--reference-spp and --reference-time: give one of them");
  const bool equal_time = a.equal_time > 0.0;
  const std::string mode = equal_time ? "equal-time" : "curve";
  fs::path prefix = a.out.empty()
                        ? fs::path("out") / (fs::path(a.scene).stem().string() + "-converge")
                        : fs::path(a.out);
  Progress progress;
  ClRuntime rt(a.device);

  if (a.reference_spp > 0 || a.reference_time > 0.0) render_reference(rt, base, a, progress);
  RgbImage ref;
  try {
    ref = read_image(a.reference);
  } catch (const std::exception& e) {
    throw SceneError(e.what());
  }
  if (ref.width != base.film.width || ref.height != base.film.height)
    throw SceneError(fmt::format("{}: size {}x{} differs from the render ({}x{}); see --film-scale",
                                 a.reference, ref.width, ref.height, base.film.width,
                                 base.film.height));
  if (a.clamp > 0.0) ref = clamp_image(ref, float(a.clamp));
  auto ref_attrs = read_image_attributes(a.reference);
  auto attr_number = [&](const char* key) {
    auto it = ref_attrs.find(key);
    return it == ref_attrs.end() ? NAN : std::strtod(it->second.c_str(), nullptr);
  };
  // A reference of another path depth converges to another image: no error would be meaningful.
  if (double d = attr_number("canopy:max_depth");
      std::isfinite(d) && int(d) != base.integrator.max_depth)
    throw SceneError(fmt::format("{}: rendered with max depth {}, the measurements use {} (see "
                                 "--max-depth)",
                                 a.reference, int(d), base.integrator.max_depth));
  double ref_mse = attr_number("canopy:reference_mse");
  const double floor_all = ref_mse;
  const double floor_ne = attr_number("canopy:reference_mse_nonemitter");
  if (!std::isfinite(ref_mse)) ref_mse = 0.0; // the CSVs' reference_mse column, as before
  std::vector<uint8_t> mask;
  if (fs::path mp = mask_path(a.reference); fs::exists(mp)) {
    RgbImage m = read_image(mp);
    if (m.width != ref.width || m.height != ref.height)
      throw SceneError(fmt::format("{}: size {}x{} differs from the reference ({}x{})", mp.string(),
                                   m.width, m.height, ref.width, ref.height));
    mask = mask_from_image(m);
  } else {
    progress.line(fmt::format("warning: {} does not exist (a reference from `canopy render`, or "
                              "from before emitter masks): the non-emitter metrics are over "
                              "every pixel",
                              mp.string()));
  }
  const size_t emitter_pixels = size_t(std::count(mask.begin(), mask.end(), uint8_t(1)));
  progress.line(fmt::format("reference {}: {}", a.reference, describe(ref_attrs)));
  progress.line(fmt::format("reference error floor (MSE of the mean of two halves = MSE(A, B) / "
                            "4): all pixels {}, non-emitter pixels {}; {} of {} pixels see an "
                            "emitter",
                            std::isfinite(floor_all) ? fmt::format("{:.3e}", floor_all) : "unknown",
                            std::isfinite(floor_ne) ? fmt::format("{:.3e}", floor_ne) : "unknown",
                            emitter_pixels, size_t(ref.width) * size_t(ref.height)));
  progress.line(
      equal_time
          ? fmt::format("{}: {}x{}, {} lights, max depth {}; {} configurations at equal time "
                        "({:g} s per render), {} seeds each",
                        a.scene, base.film.width, base.film.height, base.lights.size(),
                        base.integrator.max_depth, configs.size(), a.equal_time, a.seeds)
          : fmt::format("{}: {}x{}, {} lights, max depth {}; {} configurations, budget {:g} s of "
                        "render time each, {} seeds per point",
                        a.scene, base.film.width, base.film.height, base.lights.size(),
                        base.integrator.max_depth, configs.size(), a.budget, a.seeds));

  // Every configuration gets its own renderer (its scene copy, light structures and kernels),
  // built and warmed up first. The renders then interleave: spp level by level, and within a
  // level seed by seed across the configurations, so that load from other processes on the
  // machine spreads over all the curves instead of distorting one.
  std::vector<ConfigResult> results(configs.size());
  std::vector<std::unique_ptr<Scene>> scenes;
  std::vector<std::unique_ptr<Renderer>> renderers;
  std::vector<int> equal_spp(configs.size(), a.spp_start);
  std::vector<AutoChoice> last_choice(configs.size());
  // One render of configuration ci; returns its seconds (auto: the whole render_auto, exploration
  // and switches included) and its film in `film` if given.
  auto timed_render = [&](size_t ci, int spp, uint32_t seed, Film* film) {
    Renderer& renderer = *renderers[ci];
    RenderSettings rs;
    rs.spp = spp;
    rs.seed = seed;
    if (results[ci].config.sampler == kAutoLightSampler) {
      const auto t0 = Clock::now();
      AutoRender r = render_auto(renderer, renderer_options(results[ci].config), rs);
      const double t = seconds_since(t0);
      last_choice[ci] = r.choice;
      if (film) *film = std::move(r.film);
      return t;
    }
    const double before = renderer.stats().render_seconds;
    Film f = renderer.render(rs);
    if (film) *film = std::move(f);
    return renderer.stats().render_seconds - before;
  };
  for (size_t ci = 0; ci < configs.size(); ++ci) {
    ConfigResult& res = results[ci];
    res.config = configs[ci];
    progress.show(fmt::format("[{}/{}] {:<16} build, compile and warm-up render", ci + 1,
                              configs.size(), res.config.label),
                  false);
    scenes.push_back(std::make_unique<Scene>(base));
    scenes.back()->integrator.volume_importance =
        res.config.volume_midpoint ? "midpoint" : "segment";
    renderers.push_back(
        std::make_unique<Renderer>(rt, *scenes.back(), renderer_options(res.config)));
    Renderer& renderer = *renderers.back();
    res.build_seconds = renderer.stats().build_seconds;
    res.light_tree_seconds = renderer.stats().light_tree_seconds;
    res.compile_seconds = renderer.stats().compile_seconds;
    // Warm-up: PoCL compiles the work-group variants of the kernels on their first launch, so
    // the first render is slow. It is not recorded. auto's explores (every candidate's kernels).
    const bool automatic = res.config.sampler == kAutoLightSampler;
    const int warm_spp = automatic ? std::max(a.spp_start, 16) : a.spp_start;
    res.warmup_seconds = timed_render(ci, warm_spp, 0xC0FFEEu, nullptr);
    std::string timing;
    if (equal_time) {
      // Timing renders (not recorded, their own seed): the spp of one render of ~equal_time s
      // (auto probes from 16 spp: with fewer it has no room to explore).
      res.timing_seconds = spp_for_seconds(
          [&](int spp, uint32_t seed) { return timed_render(ci, spp, seed, nullptr); },
          a.equal_time, warm_spp, a.max_spp, 0xC0FFEEu + 1, &equal_spp[ci], kTimingRefinements);
      timing = fmt::format(", timing {:.2f} s: {} spp", res.timing_seconds, equal_spp[ci]);
    }
    progress.show(fmt::format("[{}/{}] {:<16} build {:.3f} s (light tree {:.3f} s), compile "
                              "{:.2f} s, warm-up render {:.2f} s{}",
                              ci + 1, configs.size(), res.config.label, res.build_seconds,
                              res.light_tree_seconds, res.compile_seconds, res.warmup_seconds,
                              timing),
                  true);
  }

  // One render of configuration ci, measured against the reference over both pixel sets.
  auto render_one = [&](size_t ci, int spp, int s) -> const RunRecord& {
    Renderer& renderer = *renderers[ci];
    ConfigResult& res = results[ci];
    RenderStats before = renderer.stats();
    Film film;
    RunRecord run;
    run.seconds = timed_render(ci, spp, uint32_t(1 + s), &film);
    if (res.config.sampler == kAutoLightSampler) {
      ++res.auto_choices[last_choice[ci].chosen.label];
      res.pilot_seconds += last_choice[ci].pilot_seconds;
    }
    const RenderStats& after = renderer.stats();
    run.spp = spp;
    run.seed = uint32_t(1 + s);
    run.shadow_rays = after.shadow_rays - before.shadow_rays;
    run.shading_points = after.shading_points - before.shading_points;
    run.glossy_points = after.glossy_points - before.glossy_points;
    run.brdf_cut_sum = after.brdf_cut_sum - before.brdf_cut_sum;
    run.brdf_samples_sum = after.brdf_samples_sum - before.brdf_samples_sum;
    run.brdf_rays = after.brdf_rays - before.brdf_rays;
    RgbImage img = a.clamp > 0.0 ? clamp_image(film.mean(), float(a.clamp)) : film.mean();
    run.metrics = compare_images(img, ref);
    run.all = pixel_error_stats(img, ref);
    run.ne = pixel_error_stats(img, ref, mask);
    res.runs.push_back(run);
    return res.runs.back();
  };

  if (equal_time) {
    for (int s = 0; s < a.seeds; ++s)
      for (size_t ci = 0; ci < configs.size(); ++ci) {
        const RunRecord& run = render_one(ci, equal_spp[ci], s);
        progress.show(fmt::format("equal time  seed {}/{}  {:<16} {} spp  {:.2f} s  MSE {:.3e} "
                                  "(non-emitter {:.3e})  elapsed {}",
                                  s + 1, a.seeds, configs[ci].label, run.spp, run.seconds,
                                  run.all.mse, run.ne.mse, fmt_clock(seconds_since(t_start))),
                      false);
      }
    for (ConfigResult& res : results) {
      for (const RunRecord& x : res.runs)
        res.render_seconds += x.seconds;
      res.medians = medians_by_spp(res.runs);
    }
  } else {
    std::vector<double> spent(configs.size(), 0.0);
    std::vector<bool> active(configs.size(), true);
    for (int spp = a.spp_start, level_index = 1;; spp *= a.spp_factor, ++level_index) {
      std::vector<double> level(configs.size(), 0.0);
      for (int s = 0; s < a.seeds; ++s)
        for (size_t ci = 0; ci < configs.size(); ++ci) {
          if (!active[ci]) continue;
          const RunRecord& run = render_one(ci, spp, s);
          level[ci] += run.seconds;
          spent[ci] += run.seconds;
          progress.show(fmt::format("level {} ({} spp)  seed {}/{}  {:<16} render {:6.1f}/{:g} s "
                                    " RMSE {:.3e}  elapsed {}",
                                    level_index, spp, s + 1, a.seeds, configs[ci].label, spent[ci],
                                    a.budget, run.metrics.rmse, fmt_clock(seconds_since(t_start))),
                        false);
        }
      // A configuration stops before its next level would overrun its budget (a level costs
      // about spp_factor times the previous one).
      bool any = false;
      for (size_t ci = 0; ci < configs.size(); ++ci) {
        if (!active[ci]) continue;
        if (spent[ci] + level[ci] * a.spp_factor > a.budget || spp > a.max_spp / a.spp_factor) {
          active[ci] = false;
          ConfigResult& res = results[ci];
          res.render_seconds = spent[ci];
          res.medians = medians_by_spp(res.runs);
          const MedianPoint& last = res.medians.back();
          progress.show(fmt::format("{:<16} done: {} points up to {} spp ({:.2f} s per image), "
                                    "RMSE {:.3e}",
                                    res.config.label, res.medians.size(), last.spp, last.seconds,
                                    last.rmse),
                        true);
        }
        any = any || active[ci];
      }
      if (!any) break;
    }
  }
  renderers.clear();
  scenes.clear();
  for (ConfigResult& res : results) {
    res.points = point_stats(res.runs, floor_all, floor_ne);
    for (const auto& [label, n] : res.auto_choices)
      res.auto_choice += fmt::format("{}{} x{}", res.auto_choice.empty() ? "" : " ", label, n);
    if (!res.runs.empty()) res.pilot_seconds /= double(res.runs.size());
  }

  std::string scene_name = fs::path(a.scene).stem().string();
  write_csvs(prefix, scene_name, ref_mse, a.clamp, base.integrator.max_depth, mode, results);
  std::vector<std::string> written = {".csv", "-median.csv", "-configs.csv", "-points.csv"};

  if (!equal_time) {
    std::vector<PlotSeries> by_time, by_rays;
    for (const ConfigResult& r : results) {
      PlotSeries t{r.config.label, {}, {}}, s{r.config.label, {}, {}};
      for (const MedianPoint& p : r.medians) {
        t.x.push_back(p.seconds);
        t.y.push_back(p.rmse);
        s.x.push_back(p.shadow_rays);
        s.y.push_back(p.rmse);
      }
      by_time.push_back(t);
      by_rays.push_back(s);
    }
    std::string title = a.title.empty() ? scene_name : a.title;
    PlotOptions po;
    po.title =
        title + ": RMSE against render time (median of " + std::to_string(a.seeds) + " seeds)";
    po.xlabel = "render time (s)";
    po.ylabel = "RMSE";
    bool text_ok = write_plot_png(prefix.string() + "-time.png", by_time, po);
    po.title =
        title + ": RMSE against shadow rays (median of " + std::to_string(a.seeds) + " seeds)";
    po.xlabel = "shadow rays";
    write_plot_png(prefix.string() + "-rays.png", by_rays, po);
    if (!text_ok)
      progress.line("warning: no TrueType font found (install fonts-dejavu-core): plots have no "
                    "labels");
    written.push_back("-time.png");
    written.push_back("-rays.png");

    // Equal-time summary at the longest time every curve reaches.
    double t_eq = INFINITY;
    for (const ConfigResult& r : results) {
      double tmax = 0.0;
      for (const MedianPoint& p : r.medians)
        tmax = std::max(tmax, p.seconds);
      t_eq = std::min(t_eq, tmax);
    }
    const ConfigResult* baseline = nullptr;
    for (const ConfigResult& r : results)
      if (r.config.label == "power") baseline = &r;
    if (!baseline) baseline = &results.front();
    bool ex = false;
    double base_rmse = rmse_at(baseline->medians, t_eq, &ex);
    std::printf(
        "equal-time RMSE at %.3g s of render time (the longest time every curve reaches):\n", t_eq);
    for (const ConfigResult& r : results) {
      double v = rmse_at(r.medians, t_eq, &ex);
      BrdfMeans bm = brdf_means(r.runs, [](const RunRecord&) { return true; });
      std::string brdf = bm.glossy_points > 0 ? fmt::format("  (per glossy point: cut {:.2f}, "
                                                            "BRDF-aware samples {:.2f})",
                                                            bm.cut, bm.samples)
                                              : std::string();
      std::printf("  %-16s %.4e  %.3fx %s%s%s\n", r.config.label.c_str(), v, v / base_rmse,
                  baseline->config.label.c_str(), ex ? "  (extrapolated as t^-1/2)" : "",
                  brdf.c_str());
    }
  }

  // The yardstick: per configuration, its last point (the only one at equal time).
  std::printf("%s, max depth %d, %d seeds; mean over seeds [95%% bootstrap interval]; efficiency "
              "= 1 / (mean MSE x mean seconds):\n",
              equal_time ? fmt::format("equal time {:g} s", a.equal_time).c_str()
                         : "largest spp of each curve",
              base.integrator.max_depth, a.seeds);
  for (const ConfigResult& r : results) {
    if (r.points.empty()) continue;
    const PointStats& p = r.points.back();
    std::printf("  %-16s %6d spp %7.3f s\n", r.config.label.c_str(), p.spp, p.seconds);
    for (const auto& [name, st] : {std::pair<const char*, const SetStats&>{"non-emitter", p.ne},
                                   std::pair<const char*, const SetStats&>{"all pixels", p.all}})
      std::printf("      %-11s MSE %.3e %s  efficiency %.3e %s  top 0.1%% share %.2f (max %.2f)  "
                  "worst pixel %.3e  %s\n",
                  name, st.mse, fmt_ci(st.mse_ci).c_str(), st.eff, fmt_ci(st.eff_ci).c_str(),
                  st.top_mean, st.top_max, st.worst_max, resolved_text(st.resolved).c_str());
  }
  if (std::isfinite(floor_all))
    std::printf("reference error floor (MSE(A, B) / 4 of its halves): all pixels %.3e, "
                "non-emitter %.3e; a point within %gx of it is unresolved\n",
                floor_all, floor_ne, kResolvedFactor);
  for (const std::string& suffix : written)
    std::printf("wrote %s%s\n", prefix.string().c_str(), suffix.c_str());
  return 0;
}

} // namespace

CLI::App* add_converge_command(CLI::App& app, std::function<int()>& action) {
  auto a = std::make_shared<ConvergeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "converge", "Error against render time for several light samplers (CSV + log-log plots)");
  cmd->add_option("scene", a->scene, "Scene file (JSON)")->required();
  cmd->add_option(
         "--reference", a->reference,
         "Reference EXR (made with --reference-spp or --reference-time, or by `canopy render`; "
         "its emitter mask is REF.mask.png)")
      ->required();
  cmd->add_option("--samplers", a->samplers,
                  "Comma-separated configurations: a light sampler (uniform, power, tree, "
                  "tree-split, exhaustive, ...); tree-split:T sets the split threshold T; "
                  "tree-noorient and tree-split-noorient[:T] drop the orientation terms of the "
                  "importance; a trailing /nomis switches MIS off (e.g. power/nomis, "
                  "tree-split:0.25/nomis; not for bsdf, brdf-mis, brdf-oriented), else MIS is on; "
                  "brdf-mis:D and brdf-oriented:D set the BRDF split threshold delta D; "
                  "brdf-mis/equal allocates BRDF-aware samples equally (else adaptively); "
                  "/split=T sets the split threshold where :T means delta; /nmax=N the BRDF "
                  "samplers' most BRDF-aware samples per glossy point; /maxcut=N the most "
                  "lights tree-split samples per shading point")
      ->capture_default_str();
  cmd->add_option("--budget", a->budget, "Render seconds per configuration (all points and seeds)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--seeds", a->seeds,
                  "Renders (seeds 1..N) per point: the curves are medians, the statistics "
                  "(-points.csv) means with bootstrap intervals")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--equal-time", a->equal_time,
                  "Equal time: after the warm-up, timing renders choose each configuration's spp "
                  "so that one render takes about this many seconds; then --seeds renders at "
                  "that spp (one point per configuration; --budget is not used)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-depth", a->max_depth,
                  "Path depth for every configuration and the reference (overrides the scene's "
                  "integrator.max_depth; 1 = direct light)")
      ->check(CLI::Range(1, kMaxDepth));
  cmd->add_option("--spp-start", a->spp_start, "spp of the first point (and of the probe renders)")
      ->check(CLI::Range(1, 1 << 24))
      ->capture_default_str();
  cmd->add_option("--spp-factor", a->spp_factor, "spp grows by this factor per point")
      ->check(CLI::Range(2, 64))
      ->capture_default_str();
  cmd->add_option("--max-spp", a->max_spp, "Largest spp")
      ->check(CLI::Range(1, 1 << 24))
      ->capture_default_str();
  cmd->add_option("--film-scale", a->film_scale,
                  "Scale the scene's film resolution (the reference must match)")
      ->check(CLI::Range(0.01, 4.0))
      ->capture_default_str();
  cmd->add_option("--clamp", a->clamp,
                  "Clamp renders and reference to [0, V] before measuring (display-referred "
                  "error: visible emitters do not dominate)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--out", a->out, "Output prefix (default out/<scene>-converge)");
  cmd->add_option("--title", a->title, "Plot title (default: the scene's name)");
  cmd->add_option("--reference-spp", a->reference_spp,
                  "Render the reference first with this many spp (overwrites --reference)")
      ->check(CLI::Range(1, 1 << 24));
  cmd->add_option("--reference-time", a->reference_time,
                  "Render the reference first, its spp chosen by timing renders so that it takes "
                  "about this many seconds (overwrites --reference)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--sampler", a->path_sampler,
                  "The camera paths' numbers of every configuration without a /sobol or "
                  "/independent suffix: sobol (default) or independent")
      ->check(CLI::IsMember({"sobol", "independent"}));
  cmd->add_option("--reference-sampler", a->reference_sampler,
                  "Configuration of the reference, as in --samplers: preferably an estimator "
                  "other than the ones judged, else at >= 64x their spp")
      ->capture_default_str();
  cmd->add_option("--reference-seed", a->reference_seed, "Seed of the reference render")
      ->capture_default_str();
  cmd->add_option("--device", a->device, "OpenCL device name substring (see `canopy info`)");
  cmd->callback([a, &action] { action = [a] { return run_converge(*a); }; });
  return cmd;
}

} // namespace canopy
