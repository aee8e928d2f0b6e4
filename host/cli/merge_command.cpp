#include "cli/merge_command.h"

#include "image/partial_image.h"
#include "scene/scene.h"

#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace canopy {

namespace {

struct MergeArgs {
  std::string out;
  std::vector<std::string> inputs;
};

int run_merge(const MergeArgs& a) {
  if (std::filesystem::path(a.out).extension() != ".exr")
    throw SceneError(fmt::format("merge: {}: the output must end in .exr", printable(a.out, 1024)));
  std::vector<std::string> names;
  for (const std::string& in : a.inputs) {
    if (std::filesystem::path(in) == std::filesystem::path(a.out))
      throw SceneError(
          fmt::format("merge: {}: is both an input and the output", printable(in, 1024)));
    names.push_back(printable(in, 1024));
  }
  // One input in memory at a time (a farm's pieces may each hold the whole film).
  MergeResult r;
  try {
    PartialMerger merger;
    for (size_t i = 0; i < a.inputs.size(); ++i)
      merger.add(read_partial_exr(a.inputs[i]), names[i]);
    r = merger.finish();
  } catch (const MergeError& e) {
    throw SceneError(e.what());
  }
  if (r.mixed_versions)
    std::fprintf(stderr,
                 "canopy: warning: merge: the inputs come from different Canopy versions\n");
  std::vector<std::pair<std::string, std::string>> extra = {
      {"canopy:merged_inputs", std::to_string(a.inputs.size())},
      {"canopy:spp", r.min_samples == r.max_samples
                         ? std::to_string(r.max_samples)
                         : fmt::format("{}..{}", r.min_samples, r.max_samples)}};
  if (r.uniform) {
    write_partial_exr(a.out, r.image, r.info, extra);
  } else {
    // Unequal coverage: the film's facts without a sample range (not a partial image any more).
    std::vector<std::pair<std::string, std::string>> meta;
    for (auto& kv : partial_metadata(r.info))
      if (kv.first != "canopy:samples" && kv.first != "canopy:seed") meta.push_back(kv);
    meta.insert(meta.end(), extra.begin(), extra.end());
    write_exr(a.out, r.image, meta);
  }
  std::printf("merged %zu images into %s: %dx%d, %u samples per pixel%s\n", a.inputs.size(),
              printable(a.out, 1024).c_str(), r.image.width, r.image.height, r.max_samples,
              r.uniform ? fmt::format(" (samples {}:{} of seed {})", r.info.sample_begin,
                                      r.info.sample_end, r.info.seed)
                              .c_str()
                        : "");
  if (r.short_pixels > 0)
    std::printf("missing coverage: %llu of %zu pixels have fewer samples (as few as %u) than the "
                "most covered (%u)\n",
                (unsigned long long)r.short_pixels, r.samples.size(), r.min_samples, r.max_samples);
  return 0;
}

} // namespace

CLI::App* add_merge_command(CLI::App& app, std::function<int()>& action) {
  auto args = std::make_shared<MergeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "merge", "Merge partial renders (--samples ranges, --crop windows) by sample count");
  cmd->add_option("out", args->out, "Merged EXR of the whole film (written atomically)")
      ->required();
  cmd->add_option("inputs", args->inputs, "EXRs written by `canopy render` of the same scene")
      ->required();
  cmd->footer("Each pixel is the mean of the inputs that cover it, weighted by their sample "
              "counts. Refused (exit 2): inputs of different scenes or film sizes, inputs holding "
              "the same samples (seed and sample indices) of the same pixels, and missing, "
              "truncated or non-Canopy files. Pixels with fewer samples than the most covered "
              "are reported. See docs/distributed.md.");
  cmd->callback([args, &action] { action = [args] { return run_merge(*args); }; });
  return cmd;
}

} // namespace canopy
