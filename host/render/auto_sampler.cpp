#include "render/auto_sampler.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

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

std::vector<int> plan_exploration(int spp, const std::vector<int>& wave_passes, int* renders) {
  *renders = 0;
  const int n = int(wave_passes.size());
  // At most 60% of the samples, or the least exploration (an untimed and a timed pass each: two
  // samples per pixel give a variance) where that is more; one left for the chosen candidate.
  const int budget = std::min(spp - 1, std::max(int(0.6 * double(spp)), 2 * n));
  const double want = double(std::accumulate(wave_passes.begin(), wave_passes.end(), 0));
  for (int r = 2; r >= 1; --r) {
    // Each candidate: 1 untimed pass + r timed renders of p passes, p scaled down to fit.
    const double room = double(budget - n) / double(r);
    if (room < double(n)) continue;
    const double f = std::min(1.0, room / want);
    std::vector<int> p(static_cast<size_t>(n));
    for (int c = 0; c < n; ++c)
      p[size_t(c)] = std::max(1, int(std::floor(double(wave_passes[size_t(c)]) * f)));
    if (n + r * std::accumulate(p.begin(), p.end(), 0) > budget) continue;
    *renders = r;
    return p;
  }
  return {};
}

namespace {

using Clock = std::chrono::steady_clock;
constexpr int kTiles = 8; // per film side: 64 tiles, 32 in each half

// A render of `rs` and its device seconds: the summed profiled times of its kernels. The
// exploration times its candidates by these, not by the wall clock: its renders are small (one
// sample on a third of the rows at a 1 s budget, 10-25 ms), and a render's fixed host cost
// (binding, fills, read-backs: about 5 ms) and the machine's jitter were a third to half of that
// wall time, which drew the candidates' costs together (cornell-1k's direct light: `tree` timed
// at 1.05x `power` per pass, 1.56x in the render). In a render of the user's samples the kernels
// are 95-97% of the wall time for every candidate, splitting ones included (docs/design.md).
Film timed_render(Renderer& renderer, const RenderSettings& rs, double* seconds) {
  auto device_seconds = [&renderer] {
    double s = 0.0;
    for (const auto& [stage, st] : renderer.stats().stages)
      s += st.seconds;
    return s;
  };
  const double before = device_seconds();
  Film film = renderer.render(rs);
  *seconds = device_seconds() - before;
  return film;
}

bool same_sampler(const RendererOptions& a, const RendererOptions& b) {
  return a.light_sampler == b.light_sampler && a.split_threshold == b.split_threshold &&
         a.max_cut == b.max_cut && a.orientation_term == b.orientation_term && a.mis == b.mis;
}

// Film `b`'s samples added to `a`'s (the same pixels), `b`'s sums scaled by `w` per pixel (sumsq
// by w^2) when given; its sample counts too unless `count` is false (samples that share the
// pixel's mass with `a`'s: their weights make up for them).
void add_samples(Film& a, const Film& b, const std::vector<double>* w = nullptr,
                 bool count = true) {
  for (size_t p = 0; p < a.sum.size(); ++p) {
    const double s = w ? (*w)[p] : 1.0;
    double4 &x = a.sum[p], &q = a.sumsq[p], &c = a.counts[p];
    const double4 &y = b.sum[p], &r = b.sumsq[p], &d = b.counts[p];
    x.x += s * y.x, x.y += s * y.y, x.z += s * y.z, x.w += count ? y.w : 0.0;
    q.x += s * s * r.x, q.y += s * s * r.y, q.z += s * s * r.z, q.w += count ? r.w : 0.0;
    c.x += d.x, c.y += d.y, c.z += d.z, c.w += d.w;
  }
}

// The tile of each of the film's pixels, row-major (kTiles x kTiles tiles: a division per row and
// column rather than per pixel, which the statistics below, run between renders, would pay
// several times per film).
std::vector<uint8_t> pixel_tiles(const Film& f) {
  static_assert(kTiles * kTiles <= 256, "a tile index fits a byte");
  std::vector<uint8_t> tiles(f.sum.size());
  std::vector<int> column(size_t(std::max(f.width, 0)));
  for (int x = 0; x < f.width; ++x)
    column[size_t(x)] = x * kTiles / f.width;
  for (size_t p = 0, y = 0; p < tiles.size(); ++y) {
    const int row = int(y) * kTiles / f.height * kTiles;
    for (int x = 0; x < f.width; ++x, ++p)
      tiles[p] = uint8_t(row + column[size_t(x)]);
  }
  return tiles;
}

// The half (0 or 1) of the film's checkerboard of tiles that tile t is in.
int half_of_tile(int t) {
  return (t / kTiles + t % kTiles) & 1;
}

} // namespace

namespace {

// A pixel's sample variance per sample, the mean over its three channels (k > 1 samples).
double pixel_variance(const Film& film, size_t p) {
  const double k = film.sum[p].w;
  const double s[3] = {film.sum[p].x, film.sum[p].y, film.sum[p].z};
  const double q[3] = {film.sumsq[p].x, film.sumsq[p].y, film.sumsq[p].z};
  double v = 0.0;
  for (int c = 0; c < 3; ++c)
    v += std::max(0.0, (q[c] - s[c] * s[c] / k) / (k - 1.0)) / 3.0;
  return v;
}

} // namespace

double stratification_gain(const Film& a, const Film& b, const std::vector<uint8_t>& near_emitter,
                           int half) {
  double independent = 0.0, whole = 0.0;
  const std::vector<uint8_t> tile_index = pixel_tiles(a);
  for (size_t p = 0; p < a.sum.size(); ++p) {
    const double na = a.sum[p].w, nb = b.sum[p].w;
    if (near_emitter[p] || half_of_tile(tile_index[p]) != half || na <= 0.0 || nb <= 0.0) continue;
    const double n = na + nb;
    const double sa[3] = {a.sum[p].x, a.sum[p].y, a.sum[p].z};
    const double sb[3] = {b.sum[p].x, b.sum[p].y, b.sum[p].z};
    const double q[3] = {a.sumsq[p].x + b.sumsq[p].x, a.sumsq[p].y + b.sumsq[p].y,
                         a.sumsq[p].z + b.sumsq[p].z};
    for (int ch = 0; ch < 3; ++ch) {
      const double s = sa[ch] + sb[ch], d = sa[ch] / na - sb[ch] / nb;
      independent += std::max(0.0, (q[ch] - s * s / n) / (n - 1.0)) / n;
      // Two independent parts: var(mean) = var(difference) x na nb / n^2.
      whole += d * d * na * nb / (n * n);
    }
  }
  // A whole set without error (a constant pixel, or perfect stratification): other samples
  // can only add error, and weigh nothing.
  return whole > 0.0 ? std::max(1.0, independent / whole) : independent > 0.0 ? HUGE_VAL : 1.0;
}

namespace {

// Per pixel: whether a neighbour's camera rays (in `a` or `b`, the chosen candidate's samples) saw
// an emitter. The pixel's own samples are left out, so the flag is independent of them.
std::vector<uint8_t> near_emitters(const Film& a, const Film& b) {
  const int w = a.width, h = a.height;
  std::vector<uint8_t> near(a.sum.size(), 0);
  auto seen = [&](int x, int y) {
    const size_t q = size_t(y) * size_t(w) + size_t(x);
    return a.counts[q].z > 0.0 || b.counts[q].z > 0.0;
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool any = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if ((dx || dy) && x + dx >= 0 && x + dx < w && y + dy >= 0 && y + dy < h)
            any = any || seen(x + dx, y + dy);
      near[size_t(y) * size_t(w) + size_t(x)] = any;
    }
  return near;
}

} // namespace

EmitterPool pool_emitters(const std::vector<Film>& films, const std::vector<uint8_t>& emitter) {
  EmitterPool pool;
  const size_t tiles = kTiles * kTiles;
  pool.variance.assign(tiles, 0.0);
  pool.share.assign(tiles, 0.0);
  pool.pixels.assign(tiles, 0.0);
  std::vector<double> n(tiles, 0.0);
  if (films.empty()) return pool;
  const std::vector<uint8_t> tile_index = pixel_tiles(films[0]);
  for (size_t p = 0; p < films[0].sum.size(); ++p) {
    const size_t t = tile_index[p];
    bool explored = false;
    for (const Film& f : films) {
      if (!(f.sum[p].w > 1.0)) continue;
      explored = true;
      if (emitter[p]) pool.variance[t] += pixel_variance(f, p), n[t] += 1.0;
    }
    pool.pixels[t] += explored ? 1.0 : 0.0;
    pool.share[t] += explored && emitter[p] ? 1.0 : 0.0;
  }
  for (size_t t = 0; t < tiles; ++t) {
    pool.variance[t] =
        n[t] > 0.0 ? pool.variance[t] / n[t] : std::numeric_limits<double>::quiet_NaN();
    pool.share[t] = pool.pixels[t] > 0.0 ? pool.share[t] / pool.pixels[t] : 0.0;
  }
  return pool;
}

double emitter_variance_scale(const std::string& path_sampler, int spp) {
  return path_sampler == "sobol" ? 1.0 / std::sqrt(double(std::max(1, spp))) : 1.0;
}

ExploreStats explore_stats(const Film& film, const std::vector<uint8_t>& emitter, int half,
                           const std::vector<uint8_t>* in_view, const EmitterPool* pool) {
  std::vector<double> tile_sum(kTiles * kTiles, 0.0), tile_n(kTiles * kTiles, 0.0), v;
  // With a pool: per tile, the variance and count of the pixels not in view.
  std::vector<double> clear_sum(kTiles * kTiles, 0.0), clear_n(kTiles * kTiles, 0.0);
  double mean = 0.0, mean_var = 0.0;
  double split_sum[2] = {0.0, 0.0}, split_var[2] = {0.0, 0.0}, split_n[2] = {0.0, 0.0};
  size_t clear = 0;
  // Each row's rank among the rows with samples (-1: none), for the row split.
  const size_t width = size_t(std::max(film.width, 1));
  std::vector<int> rank(film.sum.size() / width, -1);
  for (size_t y = 0, r = 0; y < rank.size(); ++y)
    for (size_t x = 0; x < width; ++x)
      if (film.sum[y * width + x].w > 0.0) {
        rank[y] = int(r++);
        break;
      }
  const std::vector<uint8_t> tile_index = pixel_tiles(film);
  auto in_half = [&](size_t p) { return half < 0 || half_of_tile(tile_index[p]) == half; };
  bool any_clear = false;
  for (size_t p = 0; p < film.sum.size() && !any_clear; ++p)
    any_clear = in_half(p) && !emitter[p] && film.sum[p].w > 1.0;
  v.reserve(film.sum.size());
  for (size_t p = 0, row = 0, row_end = width; p < film.sum.size(); ++p) {
    if (p == row_end) ++row, row_end += width;
    if (!in_half(p)) continue;
    const double k = film.sum[p].w;
    if (!(k > 1.0)) continue;
    const double s[3] = {film.sum[p].x, film.sum[p].y, film.sum[p].z};
    const int t = tile_index[p];
    double vp = pixel_variance(film, p);
    if (in_view && pool && (*in_view)[p] && std::isfinite(pool->variance[size_t(t)])) {
      vp = pool->variance[size_t(t)];
    } else {
      clear_sum[size_t(t)] += vp, clear_n[size_t(t)] += 1.0;
    }
    v.push_back(vp);
    tile_sum[size_t(t)] += vp;
    tile_n[size_t(t)] += 1.0;
    if (any_clear && emitter[p]) continue;
    const double value = (s[0] + s[1] + s[2]) / (3.0 * k);
    mean += value;
    mean_var += vp / k;
    ++clear;
    const int side = rank[row] & 1;
    split_sum[side] += value, split_var[side] += vp / k, split_n[side] += 1.0;
  }
  ExploreStats st;
  if (v.empty()) return st;
  const double total = std::accumulate(v.begin(), v.end(), 0.0);
  const double n = double(v.size());
  st.variance = total / n;
  if (in_view && pool) {
    // The emitters alike for every candidate: each tile its pool's share of them, and the tiles
    // weighted by the pool's pixels. A tile where this candidate has only pixels in view counts its
    // mean over all its pixels not in view for the rest.
    const double clear_all = std::accumulate(clear_sum.begin(), clear_sum.end(), 0.0),
                 clear_all_n = std::accumulate(clear_n.begin(), clear_n.end(), 0.0);
    double w = 0.0, sum = 0.0, em = 0.0;
    for (size_t t = 0; t < tile_sum.size(); ++t) {
      if (tile_n[t] == 0.0) continue;
      const double share = std::isfinite(pool->variance[t]) ? pool->share[t] : 0.0;
      const double in_view_part = share > 0.0 ? share * pool->variance[t] : 0.0;
      const double rest = clear_n[t] > 0.0    ? clear_sum[t] / clear_n[t]
                          : clear_all_n > 0.0 ? clear_all / clear_all_n
                                              : 0.0;
      tile_n[t] = pool->pixels[t];
      tile_sum[t] = (in_view_part + (1.0 - share) * rest) * tile_n[t];
      w += tile_n[t], sum += tile_sum[t];
      em += in_view_part * tile_n[t];
    }
    if (w > 0.0) {
      st.variance = sum / w;
      st.emitter_variance = em / w;
    }
  }
  const double tiles_weight = std::accumulate(tile_n.begin(), tile_n.end(), 0.0);
  // The ratio estimate's standard error over the T tiles of the half: the tiles' pixel variances
  // are not identically distributed, so this is conservative for the mean.
  double dev = 0.0, tiles = 0.0;
  for (size_t t = 0; t < tile_sum.size(); ++t) {
    if (tile_n[t] == 0.0) continue;
    const double d = tile_sum[t] - st.variance * tile_n[t];
    dev += d * d;
    tiles += 1.0;
  }
  const double se = tiles > 1.0 ? std::sqrt(tiles / (tiles - 1.0) * dev) / tiles_weight : 0.0;
  st.variance_lo = std::max(0.0, st.variance - 1.96 * se);
  st.variance_hi = st.variance + 1.96 * se;
  const size_t worst = std::max<size_t>(1, size_t(std::ceil(0.001 * n)));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(worst - 1), v.end(), std::greater<>());
  const double top = std::accumulate(v.begin(), v.begin() + std::ptrdiff_t(worst), 0.0);
  st.tail_share = total > 0.0 ? top / total : 0.0;
  for (size_t t = 0; t < tile_sum.size(); ++t)
    st.tile_variance.push_back(tile_n[t] > 0.0 ? tile_sum[t] / tiles_weight
                                               : std::numeric_limits<double>::quiet_NaN());
  if (clear > 0) {
    st.mean = mean / double(clear);
    st.mean_variance = mean_var / (double(clear) * double(clear));
  }
  if (split_n[0] > 0.0 && split_n[1] > 0.0) {
    st.row_split = split_sum[0] / split_n[0] - split_sum[1] / split_n[1];
    st.row_split_variance =
        split_var[0] / (split_n[0] * split_n[0]) + split_var[1] / (split_n[1] * split_n[1]);
  }
  return st;
}

namespace {

// Every candidate is unbiased, so their image means agree within their standard errors unless one
// missed rare large samples (power on a city: a point's near lights are almost never picked): its
// variance, measured from the samples it drew, is then far too low. Such a candidate has a mean
// more than 4 standard errors below the others' (their means weighted by inverse variance: the
// most precise counts most, and a candidate's rare huge sample, which raises its mean, raises its
// variance too).
//
// Measured on different rows (interleaved), two candidates' means also differ by what those rows
// show: on default.json at 256 rows, every third row's non-emitter mean differs from the next
// one's by 2.5% (3-5 standard errors of 2 samples per pixel, whichever candidate renders them).
// That part of the variance is estimated from each candidate's own rows split in two (every other
// row: the difference beyond the samples' variance is the rows' structure; a missed tail lowers
// both sides alike) and halved (each side has half the rows of a candidate's set).
std::vector<bool> missed_tails(const std::vector<ExploreStats>& s) {
  std::vector<bool> out(s.size());
  double structure = 0.0, splits = 0.0;
  bool own_rows = false;
  for (const ExploreStats& x : s) {
    own_rows = own_rows || x.own_rows;
    if (x.row_split_variance <= 0.0) continue;
    structure += std::max(0.0, x.row_split * x.row_split - x.row_split_variance);
    splits += 1.0;
  }
  structure = own_rows && splits > 0.0 ? 0.5 * structure / splits : 0.0;
  for (size_t i = 0; i < s.size(); ++i) {
    double w = 0.0, wm = 0.0, plain = 0.0, n = 0.0;
    for (size_t j = 0; j < s.size(); ++j) {
      if (j == i) continue;
      plain += s[j].mean, n += 1.0;
      if (s[j].mean_variance > 0.0)
        w += 1.0 / s[j].mean_variance, wm += s[j].mean / s[j].mean_variance;
    }
    if (n == 0.0) continue;
    const double others = w > 0.0 ? wm / w : plain / n;
    const double se = std::sqrt(s[i].mean_variance + (w > 0.0 ? 1.0 / w : 0.0) + structure);
    out[i] = se > 0.0 && others - s[i].mean > 4.0 * se;
  }
  return out;
}

// Whether a's variance x ka is below b's x kb by more than 1.96 standard errors of the
// difference, estimated from the tiles' differences (a paired comparison: what a tile shows sets
// its variance for every candidate, and that spread cancels).
bool significantly_less(const ExploreStats& a, double ka, const ExploreStats& b, double kb) {
  const std::vector<double>&ta = a.tile_variance, &tb = b.tile_variance;
  std::vector<double> d; // per tile both measured
  for (size_t t = 0; t < std::min(ta.size(), tb.size()); ++t)
    if (std::isfinite(ta[t]) && std::isfinite(tb[t])) d.push_back(tb[t] * kb - ta[t] * ka);
  if (d.size() < 2 || ta.size() != tb.size()) return b.variance * kb - a.variance * ka > 0.0;
  const double tiles = double(d.size());
  const double diff = std::accumulate(d.begin(), d.end(), 0.0);
  double dev = 0.0;
  for (double x : d)
    dev += (x - diff / tiles) * (x - diff / tiles);
  return diff > 1.96 * std::sqrt(tiles / (tiles - 1.0) * dev);
}

} // namespace

size_t choose_candidate(std::vector<PilotResult>& c, std::string* reason) {
  std::vector<ExploreStats> stats; // of the candidates not pruned
  for (const PilotResult& p : c)
    if (!p.pruned) stats.push_back(p.stats);
  const std::vector<bool> missed = missed_tails(stats);
  for (size_t i = 0, k = 0; i < c.size(); ++i) {
    c[i].missed_tail = !c[i].pruned && missed[k++];
    const double t = c[i].pass_seconds, v = c[i].stats.variance;
    c[i].efficiency = v > 0.0 && t > 0.0 ? 1.0 / (v * t) : 0.0;
    c[i].efficiency_lo = c[i].stats.variance_hi > 0.0 && t > 0.0
                             ? 1.0 / (c[i].stats.variance_hi * t)
                             : c[i].efficiency;
    c[i].efficiency_hi = c[i].stats.variance_lo > 0.0 && t > 0.0
                             ? 1.0 / (c[i].stats.variance_lo * t)
                             : std::numeric_limits<double>::infinity();
  }
  auto ranked = [&](size_t i) {
    return !c[i].pruned && !c[i].missed_tail && c[i].efficiency > 0.0;
  };
  size_t best = c.size();
  for (size_t i = 0; i < c.size(); ++i)
    if (ranked(i) && (best == c.size() || c[i].efficiency > c[best].efficiency)) best = i;
  if (best == c.size()) { // nothing measured: the fastest
    best = 0;
    for (size_t i = 1; i < c.size(); ++i)
      if (!c[i].pruned && c[i].pass_seconds < c[best].pass_seconds) best = i;
    *reason = "no variance measured: the fastest";
    return best;
  }
  *reason = "the most efficient";
  size_t lighter = c.size();
  for (size_t i = 0; i < c.size(); ++i) {
    if (i == best || !ranked(i)) continue;
    if (!significantly_less(c[best].stats, c[best].pass_seconds, c[i].stats, c[i].pass_seconds) &&
        c[i].stats.tail_share <= 0.5 * c[best].stats.tail_share &&
        (lighter == c.size() || c[i].efficiency > c[lighter].efficiency))
      lighter = i;
  }
  if (lighter != c.size()) {
    *reason = fmt::format("not significantly less efficient than {}, lighter tail", c[best].label);
    best = lighter;
  }
  // A candidate at most half as costly per pass that is not significantly less efficient, with a
  // tail no heavier: the cheapest such. A render of the user's spp then ends at least twice as
  // soon for no significant loss; between candidates of similar cost the more efficient stays.
  size_t cheaper = c.size();
  for (size_t i = 0; i < c.size(); ++i) {
    if (!ranked(i) || !(c[i].pass_seconds <= kCheaperFactor * c[best].pass_seconds) ||
        c[i].stats.tail_share > c[best].stats.tail_share ||
        significantly_less(c[best].stats, c[best].pass_seconds, c[i].stats, c[i].pass_seconds))
      continue;
    if (cheaper == c.size() || c[i].pass_seconds < c[cheaper].pass_seconds) cheaper = i;
  }
  if (cheaper != c.size()) {
    *reason = fmt::format("not significantly less efficient than {}, cheaper", c[best].label);
    best = cheaper;
  }
  return best;
}

std::vector<double> exploration_weights(std::vector<PilotResult> other) {
  std::string reason;
  const size_t ref = choose_candidate(other, &reason);
  std::vector<double> w(other.size(), 0.0);
  for (size_t i = 0; i < other.size(); ++i) {
    if (other[i].pruned) { // its probe's samples: as good as any unbiased estimator's
      w[i] = 1.0;
      continue;
    }
    if (other[i].missed_tail) continue;
    // The typical tile's excess, the median over tiles of the variance ratio to the predicted
    // choice: the image's variance can be a few pixels' (the edges of small bright emitters in
    // view, the same for every candidate), whose noise would make the ratio of the means, and so
    // the weights, unequal where the samples are equally good, which adds variance.
    const ExploreStats &si = other[i].stats, &sr = other[ref].stats;
    std::vector<double> ratio;
    for (size_t t = 0; t < std::min(si.tile_variance.size(), sr.tile_variance.size()); ++t)
      if (sr.tile_variance[t] > 0.0 && std::isfinite(si.tile_variance[t]))
        ratio.push_back(si.tile_variance[t] / sr.tile_variance[t]);
    double excess = sr.variance > 0.0 ? si.variance / sr.variance : 1.0;
    if (!ratio.empty()) {
      std::nth_element(ratio.begin(), ratio.begin() + std::ptrdiff_t(ratio.size() / 2),
                       ratio.end());
      excess = ratio[ratio.size() / 2];
    }
    w[i] = excess > 1.0 ? 1.0 / excess : 1.0;
  }
  return w;
}

RowBands exploration_bands(int width, int height, int period) {
  if (period <= 0) // as many as keep kExploredPixels or more, and a band in every tile
    period =
        std::min(std::clamp(int(double(width) * double(height) / double(kExploredPixels)), 1, 4),
                 std::max(1, height / (kTiles * kExploreBandRows)));
  RowBands b;
  b.height = kExploreBandRows;
  b.period = std::min(period, std::max(1, height / kExploreBandRows));
  return b;
}

bool may_beat(double emitter_variance, double pass_seconds, double best_efficiency) {
  return emitter_variance * pass_seconds * best_efficiency < 1.0;
}

namespace {

// The rows of the film that bands `b` do not cover, as bands.
std::vector<RowBands> other_rows(const RowBands& b) {
  std::vector<RowBands> out;
  if (b.all()) return out;
  if (b.first > 0) out.push_back(RowBands{b.height, b.period, 0, b.first});
  if (b.first + b.count < b.period)
    out.push_back(RowBands{b.height, b.period, b.first + b.count, b.period - b.first - b.count});
  return out;
}

Film empty_like(const Film& f) {
  Film e = f;
  std::fill(e.sum.begin(), e.sum.end(), double4{});
  std::fill(e.sumsq.begin(), e.sumsq.end(), double4{});
  std::fill(e.counts.begin(), e.counts.end(), double4{});
  return e;
}

// A candidate's rows `b` (count 1) in kProbeParts parts, each one band in kProbeParts of its:
// the probe's two first; empty when they would cover none of the film's `rows`.
std::vector<RowBands> probe_parts(const RowBands& b, int rows) {
  std::vector<RowBands> parts;
  for (int j = 0; j < kProbeParts; ++j)
    parts.push_back(RowBands{b.height, kProbeParts * b.period, b.first + j * b.period, 1});
  if (b.count != 1 || covered_rows(parts[0].packed(), rows) == 0 ||
      covered_rows(parts[1].packed(), rows) == 0)
    parts.clear();
  return parts;
}

// The candidates' measurements from their exploration films, over the film and, with `halves`,
// over each half (the weights need them; the costly candidate's probe decisions do not).
struct Measured {
  std::vector<ExploreStats> film, half[2];
};

Measured measure(const std::vector<Film>& films, double emitter_scale, bool halves) {
  Measured m;
  if (films.empty()) return m;
  // The image means compare over the same pixels: those no candidate's camera rays saw an emitter
  // at, and that every candidate explored (a banded candidate's rows show another part of the
  // image than the film's mean); on interleaved rows, where no pixel is common, each over its own
  // rows.
  std::vector<uint8_t> emitter(films[0].sum.size(), 0), off_mean(emitter.size(), 0);
  bool any_common = false;
  for (size_t p = 0; p < emitter.size(); ++p) {
    bool common = true;
    for (const Film& f : films) {
      emitter[p] |= f.counts[p].z > 0.0 ? 1 : 0;
      common = common && f.sum[p].w > 1.0;
    }
    any_common = any_common || common;
    off_mean[p] = emitter[p] || !common;
  }
  if (!any_common) off_mean = emitter;
  // The pixels whose camera rays saw an emitter: their variance is the emitters' antialiasing,
  // the same per sample for every candidate (the same camera samples) but, from a few samples, a
  // handful of huge values that fall on one candidate's pixels or another's by chance (a tiny,
  // bright light in view: nearly all of a candidate's measured variance on Veach's MIS scene). It
  // is measured once, pooled over the candidates per tile, and each candidate counts that, scaled
  // to what the render's spp will show of it (emitter_variance_scale).
  EmitterPool pool = pool_emitters(films, emitter);
  for (double& v : pool.variance)
    v *= emitter_scale;
  for (const Film& f : films) {
    m.film.push_back(explore_stats(f, off_mean, -1, &emitter, &pool));
    m.film.back().own_rows = !any_common;
    for (int h = 0; h < (halves ? 2 : 0); ++h) {
      m.half[h].push_back(explore_stats(f, off_mean, h, &emitter, &pool));
      m.half[h].back().own_rows = !any_common;
    }
  }
  return m;
}

// The most efficient of the candidates before `i` (measured in `m`) that did not miss their
// tail; `i` if none.
size_t best_explored(const std::vector<PilotResult>& cand, size_t i, const Measured& m) {
  std::vector<ExploreStats> before(m.film.begin(), m.film.begin() + std::ptrdiff_t(i));
  const std::vector<bool> missed = missed_tails(before);
  size_t best = i;
  double e_best = 0.0;
  for (size_t j = 0; j < i; ++j) {
    const double e = m.film[j].variance > 0.0 && cand[j].pass_seconds > 0.0
                         ? 1.0 / (m.film[j].variance * cand[j].pass_seconds)
                         : 0.0;
    if (!missed[j] && e > e_best) best = j, e_best = e;
  }
  return best;
}

// Whether candidate `i`, at `pass_seconds` per pass, may be more efficient than `b`, the best
// explored before it (best_explored; `i` if none): its variance is at least the emitter pixels'
// part, which every candidate has (may_beat).
bool may_beat_best(const std::vector<PilotResult>& cand, size_t i, size_t b, const Measured& m,
                   double pass_seconds) {
  return b == i || may_beat(m.film[b].emitter_variance, pass_seconds,
                            1.0 / (m.film[b].variance * cand[b].pass_seconds));
}

// The time per pass of `tree` among the candidates before `i`, 0 if it was not explored. The
// costly candidate splits tree's light tree (a cut member is a pick of tree's), so its pass costs
// at least that: with may_beat_best, a bound on its efficiency before it renders anything. Where
// emitters in view hold most of the error (default.json's and the Cornell boxes' direct light) its
// program, first launches and probe are spared.
double tree_pass_seconds(const std::vector<PilotResult>& cand, size_t i) {
  for (size_t j = 0; j < i; ++j)
    if (cand[j].options.light_sampler == "tree" && !cand[j].pruned) return cand[j].pass_seconds;
  return 0.0;
}

// Candidate `i` (its probe measured in `m.film[i]`, at `pass_seconds` per pass) against the best
// before it: -1 if that is significantly more efficient, 1 if `i` is, else 0 (the paired tile
// comparison of choose_candidate).
int against_best(const std::vector<PilotResult>& cand, size_t i, const Measured& m,
                 double pass_seconds) {
  const size_t b = best_explored(cand, i, m);
  if (b == i) return 0;
  if (significantly_less(m.film[b], cand[b].pass_seconds, m.film[i], pass_seconds)) return -1;
  if (significantly_less(m.film[i], pass_seconds, m.film[b], cand[b].pass_seconds)) return 1;
  return 0;
}

} // namespace

AutoRender render_auto(Renderer& renderer, const RendererOptions& base,
                       const RenderSettings& settings, int explore_period, double probe_cost,
                       Film* chosen_samples) {
  const auto t0 = Clock::now();
  AutoRender out;
  AutoChoice& choice = out.choice;
  std::vector<PilotResult> cand = auto_candidates(base);
  const int fw = renderer.scene().film.width, fh = renderer.scene().film.height;
  const RowBands bands = exploration_bands(fw, fh, explore_period);
  const double film_pixels = double(fw) * double(fh);
  const double band_pixels = double(fw) * double(covered_rows(bands.packed(), fh));
  std::vector<int> wave_passes;
  for (PilotResult& c : cand) {
    // The passes that fill one of the sampler's waves (2^18 paths: 4 passes of a 256x256 film;
    // a splitting sampler's about split_queue_items / max_cut, 16,384: 1 pass; the renderer's
    // paths_per_wave also counts a medium segment's cut and the distant lights). A render of at
    // least one wave has the render's own wave structure (docs/design.md, "Choosing the estimator
    // per scene"): a candidate explores on bands of rows only if a pass over them still fills
    // one of its waves (the costly splitting samplers, whose waves are small), else on the film.
    const RendererOptions& o = c.options;
    const bool splits = o.light_sampler != "power" && o.light_sampler != "tree";
    const double wave = splits ? double(o.split_queue_items) / double(std::max(1, o.max_cut))
                               : double(settings.wave_size);
    if (!bands.all() && wave <= band_pixels) c.bands = bands;
    const double npix = c.bands.all() ? film_pixels : band_pixels;
    c.explored_share = npix / film_pixels;
    wave_passes.push_back(int(std::clamp(std::ceil(wave / npix), 1.0, 256.0)));
  }
  int renders = 0;
  std::vector<int> passes = settings.window.empty() && settings.spp >= kFilmExplorationMinSpp
                                ? plan_exploration(settings.spp, wave_passes, &renders)
                                : std::vector<int>();
  const int n = int(cand.size());
  // The film's exploration only where its full waves are at most kFilmExplorationShare of the
  // samples: the candidates not chosen weigh little in the image, so their samples are mostly
  // lost (17 of 32 spp explored on a 256 x 256 film: `auto` was 0.72x of `power` at 1 s on
  // cornell-1k's direct light).
  const int film_samples = n + renders * std::accumulate(passes.begin(), passes.end(), 0);
  if (double(film_samples) > kFilmExplorationShare * double(settings.spp)) passes.clear();
  // Else each candidate renders k samples (2, or a 16th of the render's from 32 spp) on its own
  // interleaved rows (every n-th row), the chosen one the rest of every pixel.
  const bool interleaved =
      passes.empty() && settings.window.empty() && settings.spp >= kInterleavedMinSpp && fh >= n;
  const int k = std::max(2, settings.spp / kInterleavedSamplesDivisor);
  if (interleaved) {
    passes.assign(cand.size(), k - 1);
    renders = 1;
    for (int i = 0; i < n; ++i) {
      cand[size_t(i)].bands = RowBands{1, n, i, 1};
      cand[size_t(i)].explored_share =
          double(covered_rows(cand[size_t(i)].bands.packed(), fh)) / double(fh);
    }
  }
  RenderSettings rs = settings;
  rs.progress = nullptr;
  if (passes.empty()) {
    // No room to explore. A window is a partial render: the last candidate, as `canopy render
    // --crop` takes, so that partial renders merge. 1 or 2 spp: the cheap `tree`; a preview that
    // short cannot afford the costly candidate's samples (3 s for one on glossy-cornell).
    choice.chosen = settings.window.empty() ? cand[kFewSamplesCandidate] : cand.back();
    choice.reason = "too few samples to explore";
    if (!same_sampler(renderer.options(), choice.chosen.options))
      renderer.set_light_sampler(choice.chosen.options);
    out.film = renderer.render(settings);
    return out;
  }

  // The exploration: per candidate, one untimed pass (PoCL loads a kernel at its first launch,
  // and the first render allocates the wave's buffers and touches the scene's memory), then
  // `renders` timed renders of its passes.
  // The faster gives the time per pass (robust to a moment of other load on the machine). The
  // last, costly candidate's first pass starts with its probe (kProbeParts), timed.
  const double emitter_scale = emitter_variance_scale(base.path_sampler, settings.spp);
  int next = settings.first_sample;
  std::vector<Film> films;
  for (size_t i = 0; i < cand.size(); ++i) {
    PilotResult& c = cand[i];
    // The last, costly candidate against the most efficient explored before it.
    const bool costly_candidate = i + 1 == cand.size() && i > 0;
    const Measured before = costly_candidate ? measure(films, emitter_scale, false) : Measured{};
    const size_t b = costly_candidate ? best_explored(cand, i, before) : i;
    const double tree_pass = tree_pass_seconds(cand, i);
    if (costly_candidate && tree_pass > 0.0 &&
        !may_beat_best(cand, i, b, before, probe_cost * tree_pass)) {
      // Pruned before it renders (its program is not even loaded): the chosen candidate renders
      // its sample indices on its rows.
      c.pruned = true;
      c.first_sample = settings.first_sample;
      c.explored_share = 0.0;
      films.push_back(empty_like(films[0]));
      continue;
    }
    if (!same_sampler(renderer.options(), c.options)) renderer.set_light_sampler(c.options);
    // Every candidate explores the pixel's first sample indices: the chosen one's exploration is
    // then the start of its own set of the user's samples (see the file comment).
    next = settings.first_sample;
    c.first_sample = next;
    rs.first_sample = next;
    rs.spp = 1;
    const std::vector<RowBands> parts =
        costly_candidate ? probe_parts(c.bands, fh) : std::vector<RowBands>();
    Film film;
    double first_pass = 0.0; // device seconds of the first pass
    int rendered = 1;        // samples per pixel on its rows before the timed renders
    if (!parts.empty()) {
      const int s0 = c.first_sample;
      const double share1 = double(covered_rows(parts[1].packed(), fh)) / double(fh);
      auto render_part = [&](size_t j, int first, int spp) { // its device seconds
        rs.bands = parts[j];
        rs.first_sample = first;
        rs.spp = spp;
        double t = 0.0;
        add_samples(film, timed_render(renderer, rs, &t));
        return t;
      };
      // Part 0 loads its kernels (PoCL loads a kernel at its first launch), part 1 is timed.
      rs.bands = parts[0];
      film = renderer.render(rs);
      const double probe = render_part(1, s0, 1);
      double pass = probe / share1;
      // Against the most efficient candidate so far: its variance bounds this one's from below
      // where emitters are in view (may_beat), and the rest of this one's exploration, in passes
      // over the film, is weighed against kCostlyExplorationShare of the render that the best
      // would make of the user's samples.
      bool keep = may_beat_best(cand, i, b, before, probe_cost * pass);
      const double share0 = double(covered_rows(parts[0].packed(), fh)) / double(fh);
      const double rest = interleaved
                              ? double(k) * c.explored_share - share0 - 2.0 * share1
                              : c.explored_share * (1.0 + renders * passes[i]) - share0 - share1;
      const bool costly =
          b < i && probe_cost * pass * rest >
                       kCostlyExplorationShare * double(settings.spp) * cand[b].pass_seconds;
      int probed = 1; // samples on part 1
      if (keep && interleaved) {
        // On interleaved rows it renders k >= 2 samples in all: the second on part 1 first, which
        // measures a variance there. Significantly less efficient than the best, it is pruned; if
        // the rest of its exploration is costly, unless it is significantly more efficient.
        pass = std::min(pass, render_part(1, s0 + 1, 1) / share1);
        probed = 2;
        std::vector<Film> with = films;
        with.push_back(film);
        const int verdict =
            against_best(cand, i, measure(with, emitter_scale, false), probe_cost * pass);
        keep = costly ? verdict > 0 : verdict >= 0;
      } else if (keep) {
        keep = !costly; // one sample per pixel: no variance to weigh against the cost
      }
      if (!keep) { // its probe is all it renders
        c.pruned = true;
        c.pass_seconds = pass;
        c.seconds = probe;
        c.samples = probed;
        c.explored_share = share0 + share1;
        films.push_back(std::move(film));
        continue;
      }
      // The rest of its first pass, with a variance probe also of its second.
      double rest_seconds = 0.0, rest_rows = 0.0;
      for (size_t j = 2; j < parts.size(); ++j)
        if (covered_rows(parts[j].packed(), fh) > 0) {
          rest_seconds += render_part(j, s0, probed);
          rest_rows += double(covered_rows(parts[j].packed(), fh));
        }
      if (probed == 2) {
        render_part(0, s0 + 1, 1);
        if (rest_rows > 0.0) pass = std::min(pass, rest_seconds / (2.0 * rest_rows / double(fh)));
      }
      rendered = probed;
      first_pass = pass * c.explored_share;
      c.pass_seconds = pass;
    } else {
      rs.bands = c.bands;
      film = timed_render(renderer, rs, &first_pass);
    }
    rs.bands = c.bands;
    next += rendered;
    rs.spp = passes[i] - (rendered - 1); // the passes a probe left
    for (int r = 0; r < (rs.spp > 0 ? renders : 0); ++r) {
      rs.first_sample = next;
      double t = 0.0;
      const Film f = timed_render(renderer, rs, &t);
      const double per_pass = t / rs.spp / c.explored_share; // a pass over the whole film
      c.pass_seconds = r == 0 && rendered == 1 ? per_pass : std::min(c.pass_seconds, per_pass);
      c.seconds += t;
      add_samples(film, f);
      next += rs.spp;
    }
    // On interleaved rows the untimed pass is the timed passes' size too: the faster counts.
    if (interleaved) c.pass_seconds = std::min(c.pass_seconds, first_pass / c.explored_share);
    c.samples = next - c.first_sample;
    films.push_back(std::move(film));
  }
  for (const PilotResult& c : cand)
    choice.explored_samples = std::max(choice.explored_samples, c.samples);

  // Measurements over the film and over each half.
  const Measured m = measure(films, emitter_scale, true);
  std::vector<ExploreStats> halves[2];
  for (size_t i = 0; i < cand.size(); ++i) {
    cand[i].stats = m.film[i];
    for (int h = 0; h < 2; ++h)
      halves[h].push_back(m.half[h][i]);
  }
  // Half h's samples are weighted by the other half's measurements.
  for (int h = 0; h < 2; ++h) {
    std::vector<PilotResult> other = cand;
    for (size_t i = 0; i < cand.size(); ++i)
      other[i].stats = halves[1 - h][i];
    const std::vector<double> w = exploration_weights(other);
    for (size_t i = 0; i < cand.size(); ++i)
      cand[i].weight[h] = w[i];
  }
  const size_t best = choose_candidate(cand, &choice.reason);
  choice.chosen = cand[best];
  choice.candidates = cand;
  if (!same_sampler(renderer.options(), cand[best].options))
    renderer.set_light_sampler(cand[best].options);
  choice.pilot_seconds = std::chrono::duration<double>(Clock::now() - t0).count();

  // The chosen candidate renders the rest of every pixel's set of the user's sample indices, in
  // two parts for the gain measurement: [first, mid) (its exploration on its rows, the rest
  // everywhere) and [mid, end).
  const PilotResult& c = cand[best];
  const int first = settings.first_sample, end = first + settings.spp;
  const int mid = first + std::max(c.samples, settings.spp / 2);
  rs = settings;
  auto render_range = [&](Film& to, int from, int until, const RowBands& b) {
    if (until <= from || covered_rows(b.packed(), fh) == 0) return;
    rs.first_sample = from;
    rs.spp = until - from;
    rs.bands = b;
    Film f = renderer.render(rs);
    if (to.sum.empty())
      to = std::move(f);
    else
      add_samples(to, f);
  };
  Film part[2];
  part[0] = films[best];
  render_range(part[0], first + c.samples, mid, RowBands{});
  for (const RowBands& b : other_rows(c.bands))
    render_range(part[0], first, first + c.samples, b);
  render_range(part[1], mid, end, RowBands{});
  if (part[1].sum.empty()) part[1] = empty_like(part[0]);

  // The other candidates' samples, at the same indices as the chosen one's, are extra. Each is
  // weighted against a sample of the chosen one by its relative inverse variance (its weight in
  // the pixel's half) divided by the chosen one's stratification gain, both measured on the other
  // half of the film. Near an emitter in view they weigh nothing: there the error is the emitter's
  // edge, set by the camera positions, and theirs are the chosen one's first positions again (at
  // 16 spp on cornell-1k's direct light, weighted by the gain there, they added 4% to the MSE over
  // all pixels). "Near": a neighbour's camera rays saw one, so that the weights at a pixel depend
  // on none of its own samples and the image stays unbiased.
  const size_t npixels = part[0].sum.size();
  const std::vector<uint8_t> near = near_emitters(part[0], part[1]);
  for (int h = 0; h < 2; ++h)
    choice.gain[h] = stratification_gain(part[0], part[1], near, h);
  std::vector<std::vector<double>> wc(cand.size(), std::vector<double>(npixels, 0.0));
  std::vector<double> scale(npixels, 1.0);
  const std::vector<uint8_t> tile_index = pixel_tiles(part[0]);
  for (size_t p = 0; p < npixels; ++p) {
    if (near[p]) continue;
    const int h = half_of_tile(tile_index[p]);
    double extra = 0.0; // the other candidates' samples at p, in samples of the chosen one
    for (size_t i = 0; i < cand.size(); ++i) {
      if (i == best) continue;
      wc[i][p] = cand[i].weight[h] / choice.gain[1 - h];
      extra += wc[i][p] * films[i].sum[p].w;
    }
    scale[p] = settings.spp / (settings.spp + extra);
    for (size_t i = 0; i < cand.size(); ++i)
      wc[i][p] *= scale[p];
  }
  out.film = std::move(part[0]);
  add_samples(out.film, part[1]);
  if (chosen_samples) *chosen_samples = out.film;
  for (size_t p = 0; p < npixels; ++p) {
    double4 &x = out.film.sum[p], &q = out.film.sumsq[p];
    const double w = scale[p];
    x.x *= w, x.y *= w, x.z *= w;
    q.x *= w * w, q.y *= w * w, q.z *= w * w;
  }
  for (size_t i = 0; i < cand.size(); ++i)
    if (i != best) add_samples(out.film, films[i], &wc[i], /*count=*/false);
  return out;
}

std::string describe(const AutoChoice& choice) {
  if (choice.candidates.empty())
    return fmt::format("auto: {} ({})", choice.chosen.label, choice.reason);
  std::string s =
      fmt::format("auto: {} ({}; exploration {} spp in {:.2f} s; efficiency", choice.chosen.label,
                  choice.reason, choice.explored_samples, choice.pilot_seconds);
  for (size_t i = 0; i < choice.candidates.size(); ++i) {
    const PilotResult& c = choice.candidates[i];
    s += fmt::format(
        "{} {} {:.4g} [{:.3g}, {:.3g}] ({:.3g} s/pass, {:.0f}% of the film, tail {:.2f}, weight "
        "{:.2g}/{:.2g}){}",
        i ? "," : "", c.label, c.efficiency, c.efficiency_lo, c.efficiency_hi, c.pass_seconds,
        100.0 * c.explored_share, c.stats.tail_share, c.weight[0], c.weight[1],
        c.missed_tail                ? " (missed its tail: not ranked)"
        : c.pruned && c.samples == 0 ? " (pruned before it rendered: it costs more than `tree`)"
        : c.pruned                   ? " (pruned after its probe)"
                                     : "");
  }
  return s + fmt::format("; stratification gain {:.3g}/{:.3g})", choice.gain[0], choice.gain[1]);
}

} // namespace canopy
