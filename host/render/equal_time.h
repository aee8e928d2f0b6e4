// The spp of a render of about a given time, for comparisons at equal time (`canopy converge
// --equal-time`, its references' --reference-time).
#pragma once

#include <cstdint>
#include <functional>

namespace canopy {

// One render of `spp` samples with seed `seed`; returns its seconds.
using TimedRender = std::function<double(int spp, uint32_t seed)>;

// The spp for which one render takes about `target` seconds (>= 1, <= max_spp). Render time is
// close to affine in spp (a fixed cost per render plus a cost per sample), so a first render at
// `probe` spp that is short against the target is followed by a second one at about half the
// target, and the line through both is solved for the target. Then, at most `refine` times, a
// render at that spp checks it: off by more than 10%, the line through it and the render before it
// is solved again (a secant step). `auto`'s time is affine only piecewise (it explores differently
// below kFilmExplorationMinSpp spp, and a fixed cost of exploring dominates a short render), so a
// line from 16 spp can miss a 1 s budget by several times. Returns the seconds spent.
double spp_for_seconds(const TimedRender& render, double target, int probe, int max_spp,
                       uint32_t seed, int* spp_out, int refine = 0);

} // namespace canopy
