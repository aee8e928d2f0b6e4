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

// Each of the pilot's two timed renders of a candidate lasts about this long (or 2 spp, if longer).
constexpr double kTimedSeconds = 0.08;

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
  // The pilot film: the scene's view at a lower resolution, an eighth of its pixels (at most
  // 2^16), so that every part of the image counts as it does in the render.
  const int fw = renderer.scene().film.width, fh = renderer.scene().film.height;
  const double pixels = std::min(double(fw) * double(fh) / 8.0, 65536.0);
  const double scale = std::min(1.0, std::sqrt(pixels / (double(fw) * double(fh))));
  const int pw = std::max(8, int(std::lround(fw * scale)));
  const int ph = std::max(8, int(std::lround(fh * scale)));
  renderer.set_film_size(pw, ph);
  std::vector<PilotStats> stats;
  for (PilotResult& c : out.candidates) {
    if (&c != &out.candidates.front() || !same_sampler(renderer.options(), c.options))
      renderer.set_light_sampler(c.options);
    // Untimed: PoCL compiles each kernel on its first launch (or loads it from its cache).
    RenderSettings warm;
    warm.seed = seed + 1;
    warm.window = PixelWindow{0, 0, std::min(pw, 16), std::min(ph, 16)};
    renderer.render(warm);
    // Samples [0, 1), then two timed renders of m passes each, [1, 1 + m) and [1 + m, 1 + 2m), m
    // (>= 2) chosen from the first so that each lasts ~kTimedSeconds. The time per pass is the
    // smaller of the two: a pilot timed once on a machine with other work misjudged 2x
    // differences (glossy-cornell).
    RenderSettings rs;
    rs.seed = seed;
    rs.spp = 1;
    auto r0 = Clock::now();
    Film film = renderer.render(rs);
    const double t1 = std::chrono::duration<double>(Clock::now() - r0).count();
    const int m = int(std::clamp(std::ceil(kTimedSeconds / std::max(t1, 1e-4)), 2.0, 32.0));
    double timed = 0.0;
    auto time_passes = [&](int first, int passes, Film* into) {
      RenderSettings ts = rs;
      ts.spp = passes;
      double best = 0.0;
      for (int r = 0; r < 2; ++r) {
        ts.first_sample = first + r * passes;
        auto start = Clock::now();
        Film f = renderer.render(ts);
        const double t = std::chrono::duration<double>(Clock::now() - start).count();
        if (into) add_samples(*into, f);
        best = r == 0 ? t / passes : std::min(best, t / passes);
        timed += t;
      }
      return best;
    };
    const double per_pass = time_passes(1, m, &film);
    // The time of a pass at the film's size. A pass costs a fixed part (kernel launches, one per
    // stage and split pass: more for a splitting sampler) and a part per pixel. At the pilot's
    // size the fixed part weighs up to 8x more than in the render, which favours the sampler with
    // the fewest launches (spiral-fog: tree chosen at 0.82x brdf-mis'). So a pass is timed at a
    // quarter of the pilot's pixels too (the same view), and the affine fit through the two
    // sizes is read off at the film's pixels.
    const int qw = std::max(4, pw / 2), qh = std::max(4, ph / 2);
    const double pilot_px = double(pw) * double(ph), small_px = double(qw) * double(qh);
    double film_pass = per_pass;
    if (small_px < pilot_px) {
      renderer.set_film_size(qw, qh);
      const double small_pass = time_passes(1, m, nullptr);
      renderer.set_film_size(pw, ph);
      const double per_pixel = std::max(0.0, (per_pass - small_pass) / (pilot_px - small_px));
      film_pass = per_pass + per_pixel * (double(fw) * double(fh) - pilot_px);
    }
    stats.push_back(pilot_stats(film));
    c.variance = stats.back().variance;
    c.seconds = t1 + timed;
    c.pass_seconds = film_pass;
    c.efficiency = c.variance > 0.0 && film_pass > 0.0 ? 1.0 / (c.variance * film_pass) : 0.0;
  }
  renderer.set_film_size(fw, fh);
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
    s += fmt::format("{} {} {:.4g}{}", i ? "," : "", choice.candidates[i].label,
                     choice.candidates[i].efficiency,
                     choice.candidates[i].missed_tail ? " (missed its tail: not ranked)" : "");
  return s + ")";
}

} // namespace canopy
