#include "render/auto_sampler.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

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

// Mean per-sample variance of the film's pixels without an emitter in view (all pixels if every
// one has one), over the three channels.
double pilot_variance(const Film& film) {
  const std::vector<uint8_t> mask = film.emitter_mask();
  const bool any_clear = std::count(mask.begin(), mask.end(), uint8_t(0)) > 0;
  double sum = 0.0;
  size_t n = 0;
  for (size_t p = 0; p < film.sum.size(); ++p) {
    if (any_clear && mask[p]) continue;
    const double k = film.sum[p].w;
    if (!(k > 1.0)) continue;
    const double s[3] = {film.sum[p].x, film.sum[p].y, film.sum[p].z};
    const double q[3] = {film.sumsq[p].x, film.sumsq[p].y, film.sumsq[p].z};
    for (int c = 0; c < 3; ++c)
      sum += std::max(0.0, (q[c] - s[c] * s[c] / k) / (k - 1.0));
    n += 3;
  }
  return n ? sum / double(n) : 0.0;
}

bool same_sampler(const RendererOptions& a, const RendererOptions& b) {
  return a.light_sampler == b.light_sampler && a.split_threshold == b.split_threshold &&
         a.max_cut == b.max_cut && a.orientation_term == b.orientation_term && a.mis == b.mis;
}

} // namespace

AutoChoice choose_light_sampler(Renderer& renderer, const RendererOptions& base, uint32_t seed,
                                int pilot_spp) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  AutoChoice out;
  out.candidates = auto_candidates(base);
  pilot_spp = std::max(2, pilot_spp);
  // Four windows, each half the film's width and height over two (a quarter of its pixels in all),
  // centred in the four quadrants.
  std::vector<PixelWindow> windows;
  const int fw = renderer.scene().film.width, fh = renderer.scene().film.height;
  const int ww = std::max(1, fw / 4), wh = std::max(1, fh / 4);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      int x0 = std::clamp((2 * i + 1) * fw / 4 - ww / 2, 0, fw - ww);
      int y0 = std::clamp((2 * j + 1) * fh / 4 - wh / 2, 0, fh - wh);
      windows.push_back(PixelWindow{x0, y0, x0 + ww, y0 + wh});
    }
  for (PilotResult& c : out.candidates) {
    if (&c != &out.candidates.front() || !same_sampler(renderer.options(), c.options))
      renderer.set_light_sampler(c.options);
    // Untimed: PoCL compiles each kernel on its first launch (or loads it from its cache).
    RenderSettings warm;
    warm.seed = seed + 1;
    warm.window = windows.front();
    renderer.render(warm);
    double var = 0.0, seconds = 0.0;
    for (const PixelWindow& w : windows) {
      RenderSettings rs;
      rs.spp = pilot_spp;
      rs.seed = seed;
      rs.window = w;
      const auto r0 = Clock::now();
      Film film = renderer.render(rs);
      seconds += std::chrono::duration<double>(Clock::now() - r0).count();
      var += pilot_variance(film) / double(windows.size());
    }
    c.variance = var;
    c.seconds = seconds;
    c.efficiency = var > 0.0 && seconds > 0.0 ? 1.0 / (var * seconds / pilot_spp) : 0.0;
  }
  // The most efficient; a candidate with no measured variance (a black or emitter-only pilot)
  // cannot be ranked by it: then the fastest.
  const bool ranked = std::any_of(out.candidates.begin(), out.candidates.end(),
                                  [](const PilotResult& c) { return c.efficiency > 0.0; });
  auto best = out.candidates.begin();
  for (auto it = out.candidates.begin(); it != out.candidates.end(); ++it)
    if (ranked ? it->efficiency > best->efficiency : it->seconds < best->seconds) best = it;
  out.chosen = *best;
  if (&*best != &out.candidates.back()) renderer.set_light_sampler(best->options);
  out.pilot_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return out;
}

std::string describe(const AutoChoice& choice) {
  std::string s = fmt::format("auto: {} (pilot {:.2f} s; efficiency", choice.chosen.label,
                              choice.pilot_seconds);
  for (size_t i = 0; i < choice.candidates.size(); ++i)
    s += fmt::format("{} {} {:.4g}", i ? "," : "", choice.candidates[i].label,
                     choice.candidates[i].efficiency);
  return s + ")";
}

} // namespace canopy
