// The "auto" light sampler: the render explores every candidate estimator on the film (the costly
// ones on bands of its rows), then the most efficient one renders the rest, and every sample of the
// exploration is part of the image.
// No single estimator is within 10% of the best on every shipped scene (docs/results.md): plain
// `tree` wins where a point's important lights are few, splitting where they are many, `power`
// where the tree's pick costs more than it buys. The exploration measures which case a scene is.
//
// The image stays unbiased (but for the choice's film-wide statistics, to which each pixel adds
// one part in the film's pixel count: docs/design.md), and the chosen candidate's samples stay
// stratified: every candidate explores the pixel's first sample indices, so the chosen one's
// exploration is the start of its own set and it renders the rest of the user's indices, on every
// pixel. Its set of spp samples is then whole: a stratified (Sobol) set loses its error
// cancellation when a few of its indices come from another estimator (9 of 256 from `tree` in a
// `power` render cost 1.8x the error on cornell-1k's direct light). The other candidates' samples
// are extra, at the same indices, and weighted against a sample of the chosen one: by their
// variance relative to it, and by the chosen one's stratification gain (what its whole set's error
// falls below the error of as many independent samples). The film is split into two halves (a
// checkerboard of tiles) and the weights in one half come from the other half's measurements
// only, so they are fixed before the samples they weight. Where stratification pays, an
// independent sample adds little and weighs little; a candidate far noisier than the rest (power
// on a city) adds almost nothing; near an emitter in view, whose edge the camera positions decide,
// the others' samples (the chosen one's first positions again) weigh nothing.
#pragma once

#include "render/renderer.h"

#include <string>
#include <vector>

namespace canopy {

// A candidate's measurements over a set of pixels (the film, or one half of it).
struct ExploreStats {
  // Per sample, over all pixels (emitters in view included: their antialiasing noise is part of
  // the image the user gets): the mean over pixels and channels of each pixel's sample variance,
  // and its 95% interval from the spread between tiles (a ratio estimate over tiles).
  double variance = 0.0, variance_lo = 0.0, variance_hi = 0.0;
  // The share of the summed pixel variance held by the worst 0.1% of pixels (at least one).
  double tail_share = 0.0;
  // The part of `variance` from the pixels whose camera rays saw an emitter (counted with the
  // pooled variance): the emitters' antialiasing noise, which every candidate has.
  double emitter_variance = 0.0;
  // Over the pixels whose camera rays saw no emitter: the image's mean value and that mean's
  // variance (the missed-tail test).
  double mean = 0.0, mean_variance = 0.0;
  // The same mean over every other row with samples minus the mean over the rows between, and
  // that difference's variance from the samples: what the image's own structure from row to row
  // adds to the difference of two candidates' means where they were measured on different rows
  // (interleaved rows, `own_rows`), for the missed-tail test.
  double row_split = 0.0, row_split_variance = 0.0;
  bool own_rows = false;
  // Per tile of the film (8 x 8): the sum of its pixels' variances, divided by the pixel count
  // (so they add up to `variance`); NaN for a tile without measured pixels (of the other half, or
  // off the candidate's bands of rows). Candidates are compared tile by tile: a tile's variance
  // depends mostly on what the tile shows, the same for every candidate.
  std::vector<double> tile_variance;
};

// Per tile of the film (8 x 8), over every candidate's explored pixels: the mean sample variance
// of the pixels whose camera rays saw an emitter (the emitters' antialiasing noise, which every
// candidate shares, measured from all candidates' samples; NaN for a tile without such a pixel),
// the share of the tile's explored pixels that saw one, and how many pixels were explored there.
struct EmitterPool {
  std::vector<double> variance, share, pixels;
};
EmitterPool pool_emitters(const std::vector<Film>& films, const std::vector<uint8_t>& emitter);

// A candidate's measurements from its film: over the pixels of the film's half `half` (0 or 1, a
// checkerboard of 8 x 8 tiles over the film) or over all (-1). `emitter` marks the pixels left out
// of the image mean: those whose camera rays saw an emitter (in any candidate's samples), or that
// not every candidate explored.
// With `in_view` and `pool`, the emitters count alike for every candidate: a tile's variance is
// the pool's share of its pooled emitter variance plus the rest of the mean variance of the
// candidate's own pixels not marked in `in_view`, and tiles weigh as the pool's pixel counts.
// Candidates on interleaved rows see the few rows of a small emitter in view in unequal numbers
// (on Veach's MIS scene that part differed by 23% between `power` and `tree`, and decided).
ExploreStats explore_stats(const Film& film, const std::vector<uint8_t>& emitter, int half,
                           const std::vector<uint8_t>* in_view = nullptr,
                           const EmitterPool* pool = nullptr);

// The emitters' antialiasing error in a render of `spp` samples per pixel, relative to what their
// per-sample variance predicts (variance / spp): 1 with independent camera samples (path sampler
// "independent"). With stratified ones ("sobol") an edge in the pixel falls faster: the variance
// of Owen-scrambled points on a discontinuity falls as spp^-3/2, so the factor is spp^-1/2
// (measured on Veach's MIS scene, docs/design.md "Choosing the estimator per scene"). The
// estimator choice scales the pooled emitter variance by it: measured per sample from two
// samples, that noise otherwise counts several times what the user's render will show, and
// pushes the choice to the cheapest candidate.
double emitter_variance_scale(const std::string& path_sampler, int spp);

struct PilotResult {
  std::string label; // the candidate, as `canopy converge` names it (e.g. brdf-mis/split=0.25)
  RendererOptions options;
  int first_sample = 0, samples = 0; // the sample indices it rendered in the exploration
  RowBands bands;                    // on these rows (exploration_bands), or all
  double explored_share = 1.0;       // of the film's pixels
  ExploreStats stats;                // over the film
  double seconds = 0.0;              // of its timed exploration renders, on the device
  double pass_seconds = 0.0;         // a sample pass over the film, device seconds (exploration)
  // 1 / (variance x pass_seconds), 0 if the variance is 0, and its interval from the variance's
  double efficiency = 0.0, efficiency_lo = 0.0, efficiency_hi = 0.0;
  // Its image mean is far below the others': it missed rare large samples, so its measured
  // variance is too low. Not ranked, and its samples weigh nothing.
  bool missed_tail = false;
  // It rendered its probe only (kProbeParts): it could not be the most efficient. Not ranked;
  // its samples weigh as an independent sample of the chosen candidate.
  bool pruned = false;
  // The weight of each of its exploration samples in the two halves of the film, against an
  // independent sample of the chosen candidate (the image divides it by the chosen one's
  // stratification gain; see the file comment).
  double weight[2] = {0.0, 0.0};
};

// The chosen candidate's stratification gain over one half of the film (0 or 1), over the pixels
// not marked in `near_emitter` with samples in both parts of the set, `a` and `b`: the error of its
// pixel means as independent samples would make it (their sample variance / spp) over the error
// its whole set has, estimated from the difference of the parts' means as if they were
// independent (which overstates it where the set's error falls faster than 1 / spp). At least 1;
// 1 where no pixel counts.
double stratification_gain(const Film& a, const Film& b, const std::vector<uint8_t>& near_emitter,
                           int half);

struct AutoChoice {
  PilotResult chosen;
  std::vector<PilotResult> candidates; // empty: no exploration (see render_auto)
  double pilot_seconds = 0.0;          // the exploration: switches, compiles, renders
  int explored_samples = 0;            // the most sample indices per pixel a candidate explored
  double gain[2] = {1.0, 1.0};         // of the chosen candidate, over each half of the film
  std::string reason;                  // why this candidate, in a few words
};

struct AutoRender {
  Film film;
  AutoChoice choice;
};

// The candidates for `base` (whose light sampler is ignored): power, tree, and brdf-mis with
// splitting at the renderer's default threshold (it renders as tree-split on a scene without a
// glossy material); each keeps base's other settings. The last is the one a partial render
// (`--samples`, `--crop`) takes without exploring; kFewSamplesCandidate renders 1 or 2 spp.
std::vector<PilotResult> auto_candidates(const RendererOptions& base);
constexpr size_t kFewSamplesCandidate = 1; // tree

// How many passes each candidate's two timed exploration renders hold, for a render of `spp`
// samples per pixel: `wave_passes` (one per candidate) fills one of its waves. A candidate renders
// 1 untimed pass (the first launches and allocations) and then up to two timed renders of
// those passes; the exploration takes at most 60% of the samples (or 2 per candidate, the least
// that measures a variance, if that is more) and leaves at least one for the chosen candidate.
// Returns the passes per timed render and sets `renders` (1 or 2); empty when spp is too small to
// explore (spp <= 2 x candidates: then the last candidate renders everything).
std::vector<int> plan_exploration(int spp, const std::vector<int>& wave_passes, int* renders);

// Marks the candidates that missed their tail (mean more than 4 standard errors below the
// others', weighted by inverse variance), then returns the chosen one's index: the most efficient
// of the rest, unless a candidate that it does not beat significantly has at most half its tail
// share (the lighter tail is taken: a heavy tail's variance from a few samples is unreliable);
// then, the cheapest candidate of at most kCheaperFactor times its time per pass that it does not
// beat significantly and whose tail is no heavier: its render of the user's spp ends much sooner
// at no significant loss. "Significantly": the difference of variance x seconds per pass, summed
// over tiles, exceeds 1.96 standard errors of that sum estimated from the tiles' differences (a
// paired comparison: the spread between tiles that every candidate shares cancels). Without a
// measured variance (a black image), the fastest. Pruned candidates take no part. Sets `reason`.
size_t choose_candidate(std::vector<PilotResult>& candidates, std::string* reason);
constexpr double kCheaperFactor = 0.5;

// The weights of the candidates' samples in one half of the film, from `other`: the candidates
// with their measurements over the other half (and their seconds per pass). The choice those
// measurements predict (choose_candidate) is the reference: a candidate that missed its tail
// weighs 0, the others min(1, 1 / m), m the median over tiles of its variance over the
// reference's. Inverse-variance weights relative to the samples that will render the rest, at
// most 1 so the rest's weight is at least 1; the typical tile's ratio rather than the ratio of the
// image means, which a few noisy pixels can swing: unequal weights on equally good samples add
// variance.
std::vector<double> exploration_weights(std::vector<PilotResult> other);

// A candidate whose waves are small (a splitting sampler's) explores bands of kExploreBandRows
// rows, one in every `period` (RowBands), so that the cost of its exploration does not grow with
// the film, while its measurements keep at least kExploredPixels pixels (a ranking from fewer chose
// wrong on the heavy-tail test scene) and a pass over the bands fills one of its waves (a pass
// that does not weighs the per-wave costs more than the render does). `period` <= 0: the most of
// 1 to 4 that keeps that many pixels and a band in every tile of the film's 8 x 8.
constexpr int kExploreBandRows = 8;
// From kFilmExplorationMinSpp samples per pixel the candidates explore the film (or its bands,
// plan_exploration), where that costs at most kFilmExplorationShare of the samples. Else, down to
// kInterleavedMinSpp, each candidate renders k samples on its own interleaved rows (every third
// row: the rows of all candidates show the same image), k = max(2, spp /
// kInterleavedSamplesDivisor), and the chosen one the rest: the exploration then costs about k spp
// of the render, where on the film it costs at least 6 spp of each candidate, and the film's full
// waves 17 of 32 spp on a 256 x 256 film.
constexpr int kFilmExplorationMinSpp = 32;
constexpr double kFilmExplorationShare = 0.25;
constexpr int kInterleavedSamplesDivisor = 16;
constexpr int kInterleavedMinSpp = 3;
constexpr int kExploredPixels = 16384;
RowBands exploration_bands(int width, int height, int period = 0);

// The last candidate is the costly one (a splitting sampler's pass costs 4 to 18 times tree's on
// the shipped scenes). It first renders its first pass on two in kProbeParts of its rows (the
// probe: one that loads its kernels, one timed) and explores further only if it can still be the
// most efficient: its variance is at least the emitter pixels' (ExploreStats::emitter_variance,
// the same for every candidate), so 1 / (that x its time per pass) bounds its efficiency. If the
// bound is below the best explored candidate's efficiency it is pruned. Where the emitters'
// antialiasing is most of the error (small, bright lights in view), a costly sample cannot pay,
// and the probe is all it costs. The probe's samples stay in the image.
constexpr int kProbeParts = 8;
// Where the rest of its exploration would cost more than this share of the render that the best
// candidate so far would make of the user's samples, the costly candidate explores no further
// unless its probe shows it significantly more efficient (on interleaved rows, where the probe
// measures a variance), and on the film not at all: its exploration would otherwise be most of a
// short render (on the showroom two samples on a third of the rows cost 0.6 s, as much as a
// 16-spp render with `power`).
constexpr double kCostlyExplorationShare = 0.25;
// Whether a candidate whose pass takes `pass_seconds` may be more efficient than `best` (1 /
// (variance x seconds per pass)), when its variance is at least `emitter_variance`.
bool may_beat(double emitter_variance, double pass_seconds, double best_efficiency);

// Renders samples [settings.first_sample, + settings.spp) of the whole film with the chosen
// candidate after exploring all on those first indices, some on bands of rows
// (exploration_bands(film, explore_period); see the file comment); the others' samples are extra,
// weighted in so that the film's mean is the unbiased image. Its count per pixel is spp. Leaves
// `renderer` set to the chosen candidate. Where the film's exploration would cost more than
// kFilmExplorationShare of the samples (always below kFilmExplorationMinSpp spp), down to
// kInterleavedMinSpp, the candidates explore on interleaved rows; below that kFewSamplesCandidate
// renders it all, and in a window the last candidate. `probe_cost` multiplies the probe's measured
// time (tests: a candidate as if that many times costlier). `chosen_samples`, if given, receives
// the chosen candidate's own samples (tests: they are its render of the user's samples).
AutoRender render_auto(Renderer& renderer, const RendererOptions& base,
                       const RenderSettings& settings, int explore_period = 0,
                       double probe_cost = 1.0, Film* chosen_samples = nullptr);

// One line for logs: "auto: tree (exploration 3 of 16 spp in 0.84 s; efficiency power 12.3 (0.05
// s/pass, weight 0.1), ...)".
std::string describe(const AutoChoice& choice);

} // namespace canopy
