#include "cli/compare_command.h"

#include "image/block_agreement.h"
#include "image/error_stats.h"
#include "image/image_compare.h"
#include "image/image_io.h"
#include "scene/scene.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>

namespace canopy {

namespace {

struct CompareArgs {
  std::string test, reference, error_image;
  std::string mask; // a PNG: white pixels (an emitter in view) are left out of the masked MSE
  double error_scale = 0.0;
  double clamp = 0.0; // > 0: clamp both images to [0, clamp] first
  int blocks = 0;     // > 0: block-mean agreement over blocks of this many pixels a side
  bool relative = false;
  bool json = false;
};

// Reads an image; a missing or unreadable file is invalid input (exit code 2).
RgbImage read_input(const std::string& file) {
  try {
    return read_image(file);
  } catch (const std::exception& e) {
    throw SceneError(e.what());
  }
}

// "light_sampler power, spp 16, seed 1, scene scenes/x.json" from the canopy:* attributes.
std::string describe(const std::map<std::string, std::string>& attrs) {
  std::string s;
  for (const auto& [k, v] : attrs) {
    if (!s.empty()) s += ", ";
    s += k.substr(k.find(':') + 1) + " " + v;
  }
  return s.empty() ? "no canopy metadata" : s;
}

int run_compare(const CompareArgs& a) {
  RgbImage test = read_input(a.test);
  RgbImage ref = read_input(a.reference);
  if (test.width != ref.width || test.height != ref.height)
    throw SceneError(fmt::format("{}: size {}x{} differs from {} ({}x{})", a.reference, ref.width,
                                 ref.height, a.test, test.width, test.height));
  auto test_attrs = read_image_attributes(a.test);
  auto ref_attrs = read_image_attributes(a.reference);
  if (a.clamp > 0.0) {
    test = clamp_image(test, float(a.clamp));
    ref = clamp_image(ref, float(a.clamp));
  }
  ImageMetrics m = compare_images(test, ref);
  // With a mask: the MSE over all pixels and over the unmasked ones (the yardstick's two sets).
  std::optional<PixelErrorStats> all, clear;
  if (!a.mask.empty()) {
    std::vector<uint8_t> mask = mask_from_image(read_input(a.mask));
    if (mask.size() != size_t(ref.width) * size_t(ref.height))
      throw SceneError(fmt::format("{}: size differs from {} ({}x{})", a.mask, a.reference,
                                   ref.width, ref.height));
    all = pixel_error_stats(test, ref);
    clear = pixel_error_stats(test, ref, mask);
  }

  std::optional<BlockAgreement> agree;
  if (a.blocks > 0) agree = block_agreement(test, ref, a.blocks);

  double used_scale = 0.0;
  if (!a.error_image.empty()) {
    RgbImage err =
        error_image(test, ref, a.relative ? ErrorMetric::Relative : ErrorMetric::Absolute,
                    a.error_scale, &used_scale);
    write_png(a.error_image, err);
  }

  if (a.json) {
    nlohmann::json j;
    j["test"] = {{"file", a.test}, {"metadata", test_attrs}};
    j["reference"] = {{"file", a.reference}, {"metadata", ref_attrs}};
    j["width"] = test.width;
    j["height"] = test.height;
    if (a.clamp > 0.0) j["clamp"] = a.clamp;
    j["rmse"] = m.rmse;
    j["mse"] = m.mse;
    j["relmse"] = m.relmse;
    j["psnr_peak"] = m.peak;
    j["psnr"] = std::isfinite(m.psnr) ? nlohmann::json(m.psnr) : nlohmann::json("inf");
    j["max_abs_error"] = m.max_abs;
    j["nonfinite"] = m.nonfinite;
    if (!a.error_image.empty()) j["error_image"] = {{"file", a.error_image}, {"scale", used_scale}};
    if (all) {
      j["mask"] = a.mask;
      j["pixel_mse"] = all->mse;
      j["pixel_mse_unmasked"] = clear->mse;
      j["unmasked_pixels"] = clear->pixels;
      j["top_share"] = all->top_share;
    }
    if (agree)
      j["blocks"] = {{"size", a.blocks},
                     {"counted", agree->blocks},
                     {"total", agree->all_blocks},
                     {"image_ratio", agree->image_ratio},
                     {"median_ratio", agree->median_ratio},
                     {"within_10_percent", agree->within_10},
                     {"within_3_percent", agree->within_3}};
    std::printf("%s\n", j.dump(2).c_str());
    return 0;
  }
  std::printf("test       %s (%s)\n", a.test.c_str(), describe(test_attrs).c_str());
  std::printf("reference  %s (%s)\n", a.reference.c_str(), describe(ref_attrs).c_str());
  std::printf("pixels     %dx%d\n", test.width, test.height);
  if (a.clamp > 0.0) std::printf("clamp      both images to [0, %g]\n", a.clamp);
  std::printf("RMSE       %.6e\n", m.rmse);
  std::printf("relMSE     %.6e\n", m.relmse);
  if (std::isfinite(m.psnr))
    std::printf("PSNR       %.3f dB (peak %.4g)\n", m.psnr, m.peak);
  else
    std::printf("PSNR       inf dB\n");
  std::printf("max |A-B|  %.6e\n", m.max_abs);
  if (m.nonfinite) std::printf("non-finite %zu values in %s\n", m.nonfinite, a.test.c_str());
  if (all)
    std::printf("pixel MSE  %.6e (all), %.6e (the %zu pixels %s leaves out)\n", all->mse,
                clear->mse, clear->pixels, a.mask.c_str());
  if (agree)
    std::printf("blocks     %dx%d pixels, %zu of %zu brighter than 5%% of the mean: image mean "
                "ratio %.4f, median block ratio %.4f, %.1f%% of blocks within 10%%, %.1f%% within "
                "3%%\n",
                a.blocks, a.blocks, agree->blocks, agree->all_blocks, agree->image_ratio,
                agree->median_ratio, 100.0 * agree->within_10, 100.0 * agree->within_3);
  if (!a.error_image.empty())
    std::printf("wrote %s (%s error, scale %.4g = white)\n", a.error_image.c_str(),
                a.relative ? "relative" : "absolute", used_scale);
  return 0;
}

} // namespace

CLI::App* add_compare_command(CLI::App& app, std::function<int()>& action) {
  auto args = std::make_shared<CompareArgs>();
  CLI::App* cmd = app.add_subcommand(
      "compare", "Error of an image against a reference: RMSE, relative MSE, PSNR");
  cmd->add_option("test", args->test, "Image to measure (EXR or anything OpenImageIO reads)")
      ->required();
  cmd->add_option("reference", args->reference, "Reference image of the same size")->required();
  cmd->add_option("--error-image", args->error_image,
                  "Write a false-colour PNG of the per-pixel error (black = 0, white = scale)");
  cmd->add_option("--error-scale", args->error_scale,
                  "Error mapped to white (default: the 99th percentile)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--relative", args->relative,
                "Error image shows |A-B| / sqrt(B^2 + 0.01) instead of |A-B|");
  cmd->add_option("--clamp", args->clamp,
                  "Clamp both images to [0, V] before measuring (display-referred error)")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--json", args->json, "Print the results as JSON");
  cmd->add_option("--blocks", args->blocks,
                  "Also compare means over N x N pixel blocks (those brighter than 5% of the "
                  "reference's mean): image and median block ratios, share within 10% and 3% "
                  "(renders of one scene by different renderers)")
      ->check(CLI::Range(1, 4096));
  cmd->add_option("--mask", args->mask,
                  "An emitter mask PNG (render --emitter-mask): also report the per-pixel MSE "
                  "over all pixels and over the black ones (no emitter in view)");
  cmd->footer("Definitions: RMSE = sqrt(mean (A-B)^2) over pixels and RGB channels; relMSE = "
              "mean (A-B)^2 / (B^2 + 0.01); PSNR = 10 log10(peak^2 / MSE) with peak = max(1, "
              "largest value in A or B), as OpenImageIO's idiff.");
  cmd->callback([args, &action] { action = [args] { return run_compare(*args); }; });
  return cmd;
}

} // namespace canopy
