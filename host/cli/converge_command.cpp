#include "cli/converge_command.h"

#include "cl/runtime.h"
#include "cli/plot.h"
#include "image/image_compare.h"
#include "image/image_io.h"
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
  int seeds = 3;
  int spp_start = 1;
  int spp_factor = 2;
  int max_spp = 1 << 16;
  double film_scale = 1.0;
  double clamp = 0.0; // > 0: clamp render and reference to [0, clamp] before measuring
  int reference_spp = 0;
  std::string reference_sampler = "exhaustive";
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
};

constexpr std::string_view kNoOrientSuffix = "-noorient";
constexpr std::string_view kNoMisSuffix = "nomis";       // after a '/'
constexpr std::string_view kEqualSuffix = "equal";       // after a '/'
constexpr std::string_view kMidpointSuffix = "midpoint"; // after a '/'
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
};

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
};

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// `scene` gives the defaults: the tree's split threshold and the BRDF samplers' settings.
SamplerConfig parse_config(const std::string& text, const IntegratorSettings& scene,
                           const std::string& option) {
  SamplerConfig c;
  c.label = text;
  c.threshold = scene.split_threshold;
  c.brdf.delta = scene.brdf_delta;
  c.brdf.n_max = scene.brdf_n_max;
  c.brdf.lambda = scene.brdf_lambda;
  c.brdf.adaptive = true;
  std::string spec = text;
  bool equal = false;
  if (size_t slash = spec.find('/'); slash != std::string::npos) {
    std::stringstream suffixes(spec.substr(slash + 1));
    spec.resize(slash);
    std::string suffix;
    bool any = false;
    while (std::getline(suffixes, suffix, '/')) {
      any = true;
      if (suffix == kNoMisSuffix && c.mis) {
        c.mis = false;
      } else if (suffix == kEqualSuffix && !equal) {
        equal = true;
      } else if (suffix == kMidpointSuffix && !c.volume_midpoint) {
        c.volume_midpoint = true;
      } else {
        throw SceneError(fmt::format("{}: '{}': unknown or repeated suffix '/{}' (/{}: MIS off; "
                                     "/{}: brdf-mis with equal allocation; /{}: medium segments "
                                     "ranked at their midpoint)",
                                     option, printable(text, 256), printable(suffix, 256),
                                     kNoMisSuffix, kEqualSuffix, kMidpointSuffix));
      }
    }
    if (!any)
      throw SceneError(
          fmt::format("{}: '{}': empty suffix after '/'", option, printable(text, 256)));
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

RendererOptions renderer_options(const SamplerConfig& c, const Scene& base) {
  RendererOptions opt;
  opt.light_sampler = c.sampler;
  opt.split_threshold = c.threshold;
  opt.max_cut = base.integrator.max_cut;
  opt.orientation_term = c.orientation;
  opt.mis = c.mis;
  opt.brdf = c.brdf;
  return opt;
}

std::vector<SamplerConfig> parse_configs(const std::string& list, const IntegratorSettings& scene) {
  std::vector<SamplerConfig> out;
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(parse_config(item, scene, "--samplers"));
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

// Renders the reference as two independent halves (seeds S and S + 1) and writes their mean. The
// halves also measure the reference's own noise: for independent halves A and B,
// E[MSE(A, B)] = 2 σ² and the mean has variance σ² / 2, so its MSE is about MSE(A, B) / 4. The
// estimate uses the same --clamp as the measurements and is stored as canopy:reference_mse.
void render_reference(ClRuntime& rt, const Scene& base, const ConvergeArgs& a, Progress& progress) {
  SamplerConfig c = parse_config(a.reference_sampler, base.integrator, "--reference-sampler");
  Scene scene = base;
  scene.integrator.volume_importance = c.volume_midpoint ? "midpoint" : "segment";
  Renderer r(rt, scene, renderer_options(c, base));
  const int half_spp = std::max(1, a.reference_spp / 2);
  auto t0 = Clock::now();
  RgbImage halves[2];
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
    halves[h] = r.render(rs).mean();
  }
  RgbImage img = halves[0];
  for (size_t i = 0; i < img.rgb.size(); ++i)
    img.rgb[i] = 0.5f * (halves[0].rgb[i] + halves[1].rgb[i]);
  double noise_mse = (a.clamp > 0.0 ? compare_images(clamp_image(halves[0], float(a.clamp)),
                                                     clamp_image(halves[1], float(a.clamp)))
                                    : compare_images(halves[0], halves[1]))
                         .mse /
                     4.0;
  write_exr(a.reference, img,
            {{"canopy:scene", a.scene},
             {"canopy:light_sampler", c.sampler},
             {"canopy:split_threshold", fmt::format("{}", c.threshold)},
             {"canopy:orientation_term", c.orientation ? "on" : "off"},
             {"canopy:mis", c.mis ? "on" : "off"},
             {"canopy:spp", std::to_string(2 * half_spp)},
             {"canopy:seed",
              fmt::format("{} (spp/2) + {} (spp/2)", a.reference_seed, a.reference_seed + 1)},
             {"canopy:film", fmt::format("{}x{}", scene.film.width, scene.film.height)},
             {"canopy:render_seconds", fmt::format("{:.3f}", r.stats().render_seconds)},
             {"canopy:reference_mse", fmt::format("{:.6e}", noise_mse)},
             {"canopy:reference_mse_clamp", fmt::format("{}", a.clamp)}});
  write_png(fs::path(a.reference).replace_extension(".png"), img);
  progress.show(fmt::format("reference {} {} spp: {:.1f} s, estimated noise RMSE {:.3e}; wrote {}",
                            c.label, 2 * half_spp, r.stats().render_seconds, std::sqrt(noise_mse),
                            a.reference),
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

void write_csvs(const fs::path& prefix, const std::string& scene, double ref_mse, double clamp,
                const std::vector<ConfigResult>& results) {
  std::ofstream runs = open_out(prefix.string() + ".csv");
  runs << "scene,sampler,light_sampler,split_threshold,spp,seed,seconds,shadow_rays,shading_points,"
          "rmse,relmse,psnr,reference_mse,clamp,mis,brdf_delta,brdf_adaptive,glossy_points,"
          "brdf_cut_sum,brdf_samples_sum,brdf_rays\n";
  for (const ConfigResult& r : results)
    for (const RunRecord& x : r.runs)
      runs << fmt::format(
          "{},{},{},{},{},{},{:.6f},{},{},{:.6e},{:.6e},{:.4f},{:.6e},{},{},{},{},{},"
          "{},{},{}\n",
          scene, r.config.label, r.config.sampler, r.config.threshold, x.spp, x.seed, x.seconds,
          x.shadow_rays, x.shading_points, x.metrics.rmse, x.metrics.relmse, x.metrics.psnr,
          ref_mse, clamp, int(r.config.mis), r.config.brdf.delta, int(r.config.brdf.adaptive),
          x.glossy_points, x.brdf_cut_sum, x.brdf_samples_sum, x.brdf_rays);
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
         "compile_seconds,warmup_seconds,render_seconds,runs,max_spp,mis\n";
  for (const ConfigResult& r : results)
    cfg << fmt::format("{},{},{},{},{:.4f},{:.4f},{:.4f},{:.3f},{:.3f},{},{},{}\n", scene,
                       r.config.label, r.config.sampler, r.config.threshold, r.build_seconds,
                       r.light_tree_seconds, r.compile_seconds, r.warmup_seconds, r.render_seconds,
                       r.runs.size(), r.medians.empty() ? 0 : r.medians.back().spp,
                       int(r.config.mis));
}

int run_converge(const ConvergeArgs& a) {
  auto t_start = Clock::now();
  Scene base = load_scene(a.scene);
  if (a.film_scale != 1.0) {
    base.film.width = std::max(1, int(std::lround(base.film.width * a.film_scale)));
    base.film.height = std::max(1, int(std::lround(base.film.height * a.film_scale)));
  }
  std::vector<SamplerConfig> configs = parse_configs(a.samplers, base.integrator);
  if (a.spp_factor < 2) throw SceneError("--spp-factor: must be >= 2");
  fs::path prefix = a.out.empty()
                        ? fs::path("out") / (fs::path(a.scene).stem().string() + "-converge")
                        : fs::path(a.out);
  Progress progress;
  ClRuntime rt(a.device);

  if (a.reference_spp > 0) render_reference(rt, base, a, progress);
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
  double ref_mse = 0.0;
  if (auto it = ref_attrs.find("canopy:reference_mse"); it != ref_attrs.end())
    ref_mse = std::strtod(it->second.c_str(), nullptr);
  progress.line(fmt::format("reference {}: {}", a.reference, describe(ref_attrs)));
  progress.line(fmt::format("{}: {}x{}, {} lights; {} configurations, budget {:g} s of render "
                            "time each, {} seeds per point",
                            a.scene, base.film.width, base.film.height, base.lights.size(),
                            configs.size(), a.budget, a.seeds));

  // Every configuration gets its own renderer (its scene copy, light structures and kernels),
  // built and warmed up first. The renders then interleave: spp level by level, and within a
  // level seed by seed across the configurations, so that load from other processes on the
  // machine spreads over all the curves instead of distorting one.
  std::vector<ConfigResult> results(configs.size());
  std::vector<std::unique_ptr<Scene>> scenes;
  std::vector<std::unique_ptr<Renderer>> renderers;
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
        std::make_unique<Renderer>(rt, *scenes.back(), renderer_options(res.config, base)));
    Renderer& renderer = *renderers.back();
    res.build_seconds = renderer.stats().build_seconds;
    res.light_tree_seconds = renderer.stats().light_tree_seconds;
    res.compile_seconds = renderer.stats().compile_seconds;
    // Warm-up: PoCL compiles the work-group variants of the kernels on their first launch, so
    // the first render is slow. It is not recorded.
    RenderSettings rs;
    rs.spp = a.spp_start;
    rs.seed = 0xC0FFEEu;
    renderer.render(rs);
    res.warmup_seconds = renderer.stats().render_seconds;
    progress.show(fmt::format("[{}/{}] {:<16} build {:.3f} s (light tree {:.3f} s), compile "
                              "{:.2f} s, warm-up render {:.2f} s",
                              ci + 1, configs.size(), res.config.label, res.build_seconds,
                              res.light_tree_seconds, res.compile_seconds, res.warmup_seconds),
                  true);
  }

  std::vector<double> spent(configs.size(), 0.0);
  std::vector<bool> active(configs.size(), true);
  for (int spp = a.spp_start, level_index = 1;; spp *= a.spp_factor, ++level_index) {
    std::vector<double> level(configs.size(), 0.0);
    for (int s = 0; s < a.seeds; ++s)
      for (size_t ci = 0; ci < configs.size(); ++ci) {
        if (!active[ci]) continue;
        Renderer& renderer = *renderers[ci];
        ConfigResult& res = results[ci];
        RenderStats before = renderer.stats();
        RenderSettings rs;
        rs.spp = spp;
        rs.seed = uint32_t(1 + s);
        Film film = renderer.render(rs);
        const RenderStats& after = renderer.stats();
        RunRecord run;
        run.spp = spp;
        run.seed = rs.seed;
        run.seconds = after.render_seconds - before.render_seconds;
        run.shadow_rays = after.shadow_rays - before.shadow_rays;
        run.shading_points = after.shading_points - before.shading_points;
        run.glossy_points = after.glossy_points - before.glossy_points;
        run.brdf_cut_sum = after.brdf_cut_sum - before.brdf_cut_sum;
        run.brdf_samples_sum = after.brdf_samples_sum - before.brdf_samples_sum;
        run.brdf_rays = after.brdf_rays - before.brdf_rays;
        run.metrics = compare_images(
            a.clamp > 0.0 ? clamp_image(film.mean(), float(a.clamp)) : film.mean(), ref);
        res.runs.push_back(run);
        level[ci] += run.seconds;
        spent[ci] += run.seconds;
        progress.show(fmt::format("level {} ({} spp)  seed {}/{}  {:<16} render {:6.1f}/{:g} s  "
                                  "RMSE {:.3e}  elapsed {}",
                                  level_index, spp, s + 1, a.seeds, res.config.label, spent[ci],
                                  a.budget, run.metrics.rmse, fmt_clock(seconds_since(t_start))),
                      false);
      }
    // A configuration stops before its next level would overrun its budget (a level costs about
    // spp_factor times the previous one).
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
  renderers.clear();
  scenes.clear();

  std::string scene_name = fs::path(a.scene).stem().string();
  write_csvs(prefix, scene_name, ref_mse, a.clamp, results);
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
  po.title = title + ": RMSE against render time (median of " + std::to_string(a.seeds) + " seeds)";
  po.xlabel = "render time (s)";
  po.ylabel = "RMSE";
  bool text_ok = write_plot_png(prefix.string() + "-time.png", by_time, po);
  po.title = title + ": RMSE against shadow rays (median of " + std::to_string(a.seeds) + " seeds)";
  po.xlabel = "shadow rays";
  write_plot_png(prefix.string() + "-rays.png", by_rays, po);
  if (!text_ok)
    progress.line("warning: no TrueType font found (install fonts-dejavu-core): plots have no "
                  "labels");

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
  std::printf("equal-time RMSE at %.3g s of render time (the longest time every curve reaches):\n",
              t_eq);
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
  if (ref_mse > 0.0)
    std::printf("reference noise (estimated RMSE of the reference itself): %.3e\n",
                std::sqrt(ref_mse));
  for (const char* suffix : {".csv", "-median.csv", "-configs.csv", "-time.png", "-rays.png"})
    std::printf("wrote %s%s\n", prefix.string().c_str(), suffix);
  return 0;
}

} // namespace

CLI::App* add_converge_command(CLI::App& app, std::function<int()>& action) {
  auto a = std::make_shared<ConvergeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "converge", "Error against render time for several light samplers (CSV + log-log plots)");
  cmd->add_option("scene", a->scene, "Scene file (JSON)")->required();
  cmd->add_option("--reference", a->reference,
                  "Reference EXR (made with --reference-spp, or by `canopy render`)")
      ->required();
  cmd->add_option("--samplers", a->samplers,
                  "Comma-separated configurations: a light sampler (uniform, power, tree, "
                  "tree-split, exhaustive, ...); tree-split:T sets the split threshold T; "
                  "tree-noorient and tree-split-noorient[:T] drop the orientation terms of the "
                  "importance; a trailing /nomis switches MIS off (e.g. power/nomis, "
                  "tree-split:0.25/nomis; not for bsdf, brdf-mis, brdf-oriented), else MIS is on; "
                  "brdf-mis:D and brdf-oriented:D set the BRDF split threshold delta D; "
                  "brdf-mis/equal allocates BRDF-aware samples equally (else adaptively)")
      ->capture_default_str();
  cmd->add_option("--budget", a->budget, "Render seconds per configuration (all points and seeds)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--seeds", a->seeds, "Renders (seeds 1..N) per point; the curves are medians")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--spp-start", a->spp_start, "spp of the first point")
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
  cmd->add_option("--reference-sampler", a->reference_sampler,
                  "Light sampler of the reference, as in --samplers")
      ->capture_default_str();
  cmd->add_option("--reference-seed", a->reference_seed, "Seed of the reference render")
      ->capture_default_str();
  cmd->add_option("--device", a->device, "OpenCL device name substring (see `canopy info`)");
  cmd->callback([a, &action] { action = [a] { return run_converge(*a); }; });
  return cmd;
}

} // namespace canopy
