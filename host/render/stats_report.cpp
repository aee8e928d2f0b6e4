#include "render/stats_report.h"

#include <fmt/format.h>

namespace canopy {

namespace {
// Cut members over all shading points: sum of k * histogram[k] (the last bin counts k or more, so
// the sum is exact only while it is empty).
struct CutTotals {
  uint64_t members = 0;
  bool exact = true;
};
CutTotals cut_totals(const RenderStats& s) {
  CutTotals t;
  const size_t bins = s.cut_size_histogram.size();
  for (size_t k = 0; k < bins; ++k)
    t.members += uint64_t(k) * s.cut_size_histogram[k];
  t.exact = bins == 0 || s.cut_size_histogram[bins - 1] == 0;
  return t;
}
} // namespace

nlohmann::json stats_to_json(const RenderStats& s, const RunTimings& run) {
  nlohmann::json j;
  j["wall_seconds"] = {{"total", run.total_seconds}, {"load", run.load_seconds},
                       {"build", s.build_seconds},   {"light_tree_build", s.light_tree_seconds},
                       {"upload", s.upload_seconds}, {"compile", s.compile_seconds},
                       {"render", s.render_seconds}};
  j["samples"] = s.samples;
  j["shading_points"] = s.shading_points;
  j["shadow_rays"] = s.shadow_rays;
  j["shadow_rays_per_shading_point"] =
      s.shading_points ? double(s.shadow_rays) / double(s.shading_points) : 0.0;
  // With a medium: surface points and ray segments apart (Conty Estevez & Kulla, Fig. 1: "7 shadow
  // rays per shading point, 45 for the volume integral")
  const uint64_t surface_rays = s.shadow_rays - s.medium_shadow_rays;
  j["medium_segments"] = s.medium_segments;
  j["medium_shadow_rays"] = s.medium_shadow_rays;
  j["shadow_rays_per_segment"] =
      s.medium_segments ? double(s.medium_shadow_rays) / double(s.medium_segments) : 0.0;
  j["shadow_rays_per_surface_point"] =
      s.shading_points ? double(surface_rays) / double(s.shading_points) : 0.0;
  j["nonfinite_samples"] = s.nonfinite_samples;
  j["overflowed_pixels"] = s.overflowed_pixels; // written as +-FLT_MAX
  j["emission_exponent"] = s.emission_exponent; // the device rendered emission * 2^-k
  j["kernel_options"] = s.kernel_options;
  // brdf-mis / brdf-oriented, over glossy shading points (Liu et al. 2019, Table 1 columns)
  j["glossy_points"] = s.glossy_points;
  j["brdf_mean_cut"] = s.glossy_points ? double(s.brdf_cut_sum) / double(s.glossy_points) : 0.0;
  j["brdf_mean_samples"] =
      s.glossy_points ? double(s.brdf_samples_sum) / double(s.glossy_points) : 0.0;
  j["brdf_rays"] = s.brdf_rays;
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [name, st] : s.stages)
    stages[name] = {{"seconds", st.seconds},
                    {"items", st.items},
                    {"launches", st.launches},
                    {"items_per_second", st.seconds > 0.0 ? double(st.items) / st.seconds : 0.0}};
  j["stages"] = stages;
  nlohmann::json hist = nlohmann::json::array();
  for (uint64_t c : s.cut_size_histogram)
    hist.push_back(c);
  // index k: shading points whose light cut had k members (clusters picked from or lights taken,
  // each a light_pick work item; a member yields at most one shadow ray). Last bin: k or more.
  j["cut_size_histogram"] = hist;
  const CutTotals ct = cut_totals(s);
  j["cut_members"] = ct.members; // a lower bound if cut_members_exact is false
  j["cut_members_exact"] = ct.exact;
  j["shadow_rays_per_cut_member"] = ct.members ? double(s.shadow_rays) / double(ct.members) : 0.0;
  return j;
}

std::string stats_to_table(const RenderStats& s, const RunTimings& run) {
  std::string out;
  out +=
      fmt::format("time: total {:.3f} s = load {:.3f} + build {:.3f} (light tree {:.3f}) + upload "
                  "{:.3f} + compile {:.3f} + render {:.3f}\n",
                  run.total_seconds, run.load_seconds, s.build_seconds, s.light_tree_seconds,
                  s.upload_seconds, s.compile_seconds, s.render_seconds);
  out += fmt::format("{:<20} {:>10} {:>14} {:>10} {:>14}\n", "stage", "seconds", "items",
                     "launches", "items/s");
  for (const auto& [name, st] : s.stages)
    out += fmt::format("{:<20} {:>10.4f} {:>14} {:>10} {:>14.4g}\n", name, st.seconds, st.items,
                       st.launches, st.seconds > 0.0 ? double(st.items) / st.seconds : 0.0);
  out += fmt::format("samples {}, shading points {}, shadow rays {} ({:.3f} per shading point), "
                     "non-finite samples {}, pixels beyond the float range {}, emission scale "
                     "2^{}\n",
                     s.samples, s.shading_points, s.shadow_rays,
                     s.shading_points ? double(s.shadow_rays) / double(s.shading_points) : 0.0,
                     s.nonfinite_samples, s.overflowed_pixels, -s.emission_exponent);
  if (s.medium_segments)
    out += fmt::format("medium: {} segments, {} shadow rays ({:.3f} per segment); surface points: "
                       "{} shadow rays ({:.3f} per point)\n",
                       s.medium_segments, s.medium_shadow_rays,
                       double(s.medium_shadow_rays) / double(s.medium_segments),
                       s.shadow_rays - s.medium_shadow_rays,
                       s.shading_points
                           ? double(s.shadow_rays - s.medium_shadow_rays) / double(s.shading_points)
                           : 0.0);
  const CutTotals ct = cut_totals(s);
  out += fmt::format("cut members {}{} ({:.1f}% yield a shadow ray)\n",
                     ct.exact ? "" : ">= ", ct.members,
                     ct.members ? 100.0 * double(s.shadow_rays) / double(ct.members) : 0.0);
  if (s.glossy_points)
    out += fmt::format("glossy points {}: BRDF-oriented cut {:.2f} clusters, {:.2f} BRDF-aware "
                       "samples per point on average ({} rays)\n",
                       s.glossy_points, double(s.brdf_cut_sum) / double(s.glossy_points),
                       double(s.brdf_samples_sum) / double(s.glossy_points), s.brdf_rays);
  out += "cut sizes (shading points by cut members):";
  for (size_t k = 0; k < s.cut_size_histogram.size(); ++k)
    if (s.cut_size_histogram[k])
      out += fmt::format(" {}{}:{}", k, k + 1 == s.cut_size_histogram.size() ? "+" : "",
                         s.cut_size_histogram[k]);
  out += "\n";
  return out;
}

} // namespace canopy
