#include "render/auto_sampler.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace canopy {

std::vector<PilotResult> auto_candidates(const RendererOptions& base) {
  std::vector<PilotResult> c(3);
  c[0].label = "power";
  c[1].label = "tree";
  c[2].label = fmt::format("brdf-mis/split={}", LT_DEFAULT_SPLIT_THRESHOLD);
  for (PilotResult& p : c) {
    p.options = base;
    p.options.light_sampler = p.label.substr(0, p.label.find('/'));
  }
  c[2].options.split_threshold = LT_DEFAULT_SPLIT_THRESHOLD;
  return c;
}

namespace {

using Clock = std::chrono::steady_clock;

bool same_sampler(const RendererOptions& a, const RendererOptions& b) {
  return a.light_sampler == b.light_sampler && a.split_threshold == b.split_threshold &&
         a.max_cut == b.max_cut && a.orientation_term == b.orientation_term && a.mis == b.mis;
}

// Film `b`'s samples added to `a`'s (the same pixels, disjoint sample ranges).
void add_samples(Film& a, const Film& b) {
  auto add = [](double4& x, const double4& y) {
    x.x += y.x;
    x.y += y.y;
    x.z += y.z;
    x.w += y.w;
  };
  for (size_t p = 0; p < a.sum.size(); ++p) {
    add(a.sum[p], b.sum[p]);
    add(a.sumsq[p], b.sumsq[p]);
    add(a.counts[p], b.counts[p]);
  }
}

// Over the pixels without an emitter in view (all pixels if each has one): the mean per-sample
// variance (of the three channels), the image's mean value and that mean's variance.
struct PilotStats {
  double variance = 0.0, mean = 0.0, mean_variance = 0.0;
};

PilotStats pilot_stats(const Film& film) {
  const std::vector<uint8_t> mask = film.emitter_mask();
  const bool any_clear = std::count(mask.begin(), mask.end(), uint8_t(0)) > 0;
  double var = 0.0, mean = 0.0, mean_var = 0.0;
  size_t n = 0;
  for (size_t p = 0; p < film.sum.size(); ++p) {
    if (any_clear && mask[p]) continue;
    const double k = film.sum[p].w;
    if (!(k > 1.0)) continue;
    const double s[3] = {film.sum[p].x, film.sum[p].y, film.sum[p].z};
    const double q[3] = {film.sumsq[p].x, film.sumsq[p].y, film.sumsq[p].z};
    double v = 0.0;
    for (int c = 0; c < 3; ++c)
      v += std::max(0.0, (q[c] - s[c] * s[c] / k) / (k - 1.0)) / 3.0;
    var += v;
    mean += (s[0] + s[1] + s[2]) / (3.0 * k);
    mean_var += v / k;
    ++n;
  }
  PilotStats st;
  if (n == 0) return st;
  st.variance = var / double(n);
  st.mean = mean / double(n);
  st.mean_variance = mean_var / (double(n) * double(n));
  return st;
}

} // namespace

AutoChoice choose_light_sampler(Renderer& renderer, const RendererOptions& base, uint32_t seed) {
  const auto t0 = Clock::now();
  AutoChoice out;
  out.candidates = auto_candidates(base);
  // The pilot renders the film itself: a pass's cost depends on the film's size (its kernel
  // launches are shared by all of a wave's paths, and a splitting sampler's waves hold fewer paths
  // than the others'), which renders at a lower resolution misjudged by 10-20% either way
  // (docs/design.md, "Choosing the estimator per scene"). Each timed render holds at least one
  // full wave of paths, as the render's passes do.
  const int fw = renderer.scene().film.width, fh = renderer.scene().film.height;
  const double npix = double(fw) * double(fh);
  const RenderSettings defaults;
  std::vector<PilotStats> stats;
  for (PilotResult& c : out.candidates) {
    if (&c != &out.candidates.front() || !same_sampler(renderer.options(), c.options))
      renderer.set_light_sampler(c.options);
    // Enough passes to fill one of this sampler's waves (2^18 paths: 4 passes of a 256x256 film;
    // a splitting sampler's 16,384: 1 pass).
    const double wave = double(renderer.paths_per_wave(defaults.wave_size));
    const int passes = int(std::clamp(std::ceil(wave / npix), 1.0, 256.0));
    // Untimed, samples [0, 1): PoCL compiles each kernel on its first launch (or loads it from its
    // cache), and the first render over the film touches the scene's memory for the first time.
    RenderSettings rs;
    rs.seed = seed;
    Film film = renderer.render(rs);
    // Samples [1, 1 + passes) and [1 + passes, 1 + 2 passes), each render timed: the faster gives
    // the time per pass. The first may allocate the wave's buffers (render() keeps them for the
    // next), and a pilot timed once, on a machine with other work, misjudged 2x differences.
    rs.spp = passes;
    double timed = 0.0, per_pass = 0.0;
    for (int r = 0; r < 2; ++r) {
      rs.first_sample = 1 + r * passes;
      const auto start = Clock::now();
      Film f = renderer.render(rs);
      const double t = std::chrono::duration<double>(Clock::now() - start).count();
      per_pass = r == 0 ? t / passes : std::min(per_pass, t / passes);
      timed += t;
      add_samples(film, f);
    }
    stats.push_back(pilot_stats(film));
    c.variance = stats.back().variance;
    c.seconds = timed;
    c.pass_seconds = per_pass;
    c.efficiency = c.variance > 0.0 && per_pass > 0.0 ? 1.0 / (c.variance * per_pass) : 0.0;
  }
  // Every candidate is unbiased, so their image means agree within their standard errors unless
  // one missed rare large samples (power on a city: the near lights are almost never picked): its
  // variance, measured from the samples it drew, is then far too low. Such a candidate (mean more
  // than 4 standard errors below the median of the three) is not ranked.
  std::vector<double> means;
  for (const PilotStats& s : stats)
    means.push_back(s.mean);
  std::vector<double> sorted = means;
  std::sort(sorted.begin(), sorted.end());
  const size_t med =
      size_t(std::find(means.begin(), means.end(), sorted[sorted.size() / 2]) - means.begin());
  for (size_t i = 0; i < out.candidates.size(); ++i) {
    const double se = std::sqrt(stats[i].mean_variance + stats[med].mean_variance);
    out.candidates[i].missed_tail = means[med] - means[i] > 4.0 * se && se > 0.0;
  }
  // The most efficient of the ranked; a candidate with no measured variance (a black or
  // emitter-only pilot) cannot be ranked by it: then the fastest.
  auto rank = [](const PilotResult& c) { return !c.missed_tail && c.efficiency > 0.0; };
  const bool ranked = std::any_of(out.candidates.begin(), out.candidates.end(), rank);
  auto best = out.candidates.end();
  for (auto it = out.candidates.begin(); it != out.candidates.end(); ++it) {
    if (ranked && !rank(*it)) continue;
    if (best == out.candidates.end() ||
        (ranked ? it->efficiency > best->efficiency : it->seconds < best->seconds))
      best = it;
  }
  out.chosen = *best;
  if (best != out.candidates.end() - 1) renderer.set_light_sampler(best->options);
  renderer.reset_render_stats();
  out.pilot_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return out;
}

std::string describe(const AutoChoice& choice) {
  std::string s = fmt::format("auto: {} (pilot {:.2f} s; efficiency", choice.chosen.label,
                              choice.pilot_seconds);
  for (size_t i = 0; i < choice.candidates.size(); ++i)
    s += fmt::format("{} {} {:.4g} ({:.3g} s/pass){}", i ? "," : "", choice.candidates[i].label,
                     choice.candidates[i].efficiency, choice.candidates[i].pass_seconds,
                     choice.candidates[i].missed_tail ? " (missed its tail: not ranked)" : "");
  return s + ")";
}

} // namespace canopy
