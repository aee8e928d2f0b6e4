#include "render/equal_time.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace canopy {

double spp_for_seconds(const TimedRender& render, double target, int probe, int max_spp,
                       uint32_t seed, int* spp_out, int refine) {
  std::vector<std::pair<int, double>> points; // (spp, seconds)
  double spent = 0.0;
  auto time_at = [&](int spp) {
    const double t = std::max(1e-6, render(spp, seed));
    points.emplace_back(spp, t);
    spent += t;
    return t;
  };
  // The spp where the line through (s1, t1) and (s2, t2) reaches the target; where it does not
  // rise, the nearer point's time scaled.
  auto solve = [&](int s1, double t1, int s2, double t2) {
    const double slope = (t2 - t1) / double(s2 - s1);
    const double fixed = std::max(0.0, t1 - slope * double(s1));
    return slope > 0.0 ? (target - fixed) / slope : double(s2) * target / t2;
  };
  auto clamp_spp = [&](double spp) {
    return int(std::clamp(std::llround(spp), 1LL, (long long)max_spp));
  };
  probe = std::clamp(probe, 1, max_spp);
  const double t1 = time_at(probe);
  double spp = double(probe) * target / t1;
  if (t1 < 0.25 * target && probe < max_spp) {
    const int p2 = int(
        std::clamp(std::lround(0.5 * double(probe) * target / t1), long(probe) + 1, long(max_spp)));
    spp = solve(probe, t1, p2, time_at(p2));
  }
  for (int r = 0; r < refine; ++r) {
    const int s = clamp_spp(spp);
    if (std::any_of(points.begin(), points.end(), [&](const auto& p) { return p.first == s; }))
      break; // measured already
    const double t = time_at(s);
    if (std::abs(t - target) <= 0.1 * target) break;
    const auto& before = points[points.size() - 2]; // a secant step
    spp = solve(before.first, before.second, s, t);
  }
  *spp_out = clamp_spp(spp);
  return spent;
}

} // namespace canopy
