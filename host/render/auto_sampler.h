// The "auto" light sampler: a short pilot render of each candidate estimator on the scene, and
// the one with the highest estimated efficiency, 1 / (variance per sample x seconds per sample),
// renders. No single estimator is within 10% of the best on every shipped scene
// (docs/results.md): plain `tree` wins where a point's important lights are few, splitting where
// they are many, `power` where the tree's pick costs more than it buys. The pilot measures which
// case a scene is.
#pragma once

#include "render/renderer.h"

#include <string>
#include <vector>

namespace canopy {

struct PilotResult {
  std::string label; // the candidate, as `canopy converge` names it (e.g. brdf-mis/split=0.25)
  RendererOptions options;
  double variance = 0.0;     // per sample: the mean over channels and non-emitter pixels
  double seconds = 0.0;      // of the pilot renders
  double pass_seconds = 0.0; // a sample pass over the film, timed in the pilot
  double efficiency = 0.0;   // 1 / (variance x pass_seconds); 0 if variance is 0
  // Its pilot image's mean is far below the others': it missed rare large samples, so its
  // measured variance is too low (see choose_light_sampler). Not ranked.
  bool missed_tail = false;
};

struct AutoChoice {
  PilotResult chosen;
  std::vector<PilotResult> candidates;
  double pilot_seconds = 0.0; // everything the choice took: switches, compiles, pilot renders
};

// The candidates for `base` (whose light sampler is ignored): power, tree, and brdf-mis with
// splitting at the renderer's default threshold (it renders as tree-split on a scene without a
// glossy material); each keeps base's other settings.
std::vector<PilotResult> auto_candidates(const RendererOptions& base);

// The pilot: per candidate, after an untimed pass over the film, two timed renders of the film
// itself, each with enough passes to fill one of the sampler's waves (Renderer::paths_per_wave:
// 4 passes of a 256x256 film for power and tree, 1 for a splitting sampler or a film of 2^18
// pixels). The faster gives the time per pass (robust to a moment of other load on the machine, and
// to the first one allocating the wave's buffers); each pixel's sample variance over all three,
// averaged over the pixels whose camera rays saw no emitter (their noise is the emitter's edge, the
// same for every sampler), gives the variance per sample. A candidate whose image mean is more than
// 4 standard errors below the median candidate's has missed rare large samples (its measured
// variance is then far too low) and is not ranked. Leaves `renderer` set to the winner, at the
// scene's film size, its render statistics zeroed. The choice depends on timings, so it can differ
// between runs where two candidates are close; every candidate is unbiased, so only the noise can
// change.
AutoChoice choose_light_sampler(Renderer& renderer, const RendererOptions& base, uint32_t seed);

// One line for logs: "auto: tree (pilot 0.84 s; efficiency power 12.3 (0.05 s/pass), tree 45.6
// (0.1 s/pass), ...)".
std::string describe(const AutoChoice& choice);

} // namespace canopy
