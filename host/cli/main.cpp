// canopy: the command-line front end.
//   canopy render SCENE [--spp N] [--out FILE.exr] [--png FILE.png] [--seed S]
//                       [--light-sampler NAME] [--device NAME]
//   canopy info
//   canopy compare A.exr B.exr      (cli/compare_command.cpp)
//   canopy converge SCENE ...       (cli/converge_command.cpp)
// Exit codes: 0 success, 2 invalid input (scene or arguments), 1 runtime failure.
#include "cl/runtime.h"
#include "cli/compare_command.h"
#include "cli/converge_command.h"
#include "image/image_io.h"
#include "render/renderer.h"
#include "render/stats_report.h"
#include "scene/scene.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

namespace {

using namespace canopy;
namespace fs = std::filesystem;

constexpr int kExitRuntime = 1;
constexpr int kExitBadInput = 2;

const char* kSamplers[] = {"uniform", "power", "tree", "tree-split", "exhaustive"};

struct RenderArgs {
  std::string scene;
  std::optional<int> spp;
  std::optional<uint32_t> seed;
  std::optional<std::string> light_sampler;
  std::optional<float> split_threshold;
  bool no_orientation = false;
  std::string out, png, device, stats_json, heatmap;
  bool stats = false;
};

// A progress bar on stderr, shown only once a render has run for a second.
class ProgressBar {
public:
  void update(double fraction) {
    double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    if (elapsed < 1.0 || (fraction < 1.0 && elapsed - last_ < 0.1)) return;
    last_ = elapsed;
    shown_ = true;
    int filled = int(fraction * 40.0 + 0.5);
    std::fprintf(stderr, "\r[%s%s] %5.1f%%  %.1f s", std::string(size_t(filled), '#').c_str(),
                 std::string(size_t(40 - filled), ' ').c_str(), 100.0 * fraction, elapsed);
    std::fflush(stderr);
  }
  void finish() {
    if (shown_) std::fprintf(stderr, "\n");
  }

private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point start_ = Clock::now();
  double last_ = -1.0;
  bool shown_ = false;
};

int run_render(const RenderArgs& args) {
  auto t_start = std::chrono::steady_clock::now();
  Scene scene = load_scene(args.scene);
  RunTimings timings;
  timings.load_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  if (args.spp) {
    if (*args.spp < 1 || *args.spp > 1000000)
      throw SceneError(fmt::format("--spp: must be in [1, 1000000], got {}", *args.spp));
    scene.integrator.spp = *args.spp;
  }
  if (args.seed) scene.integrator.seed = *args.seed;
  if (args.light_sampler) scene.integrator.light_sampler = *args.light_sampler;
  if (args.split_threshold) scene.integrator.split_threshold = *args.split_threshold;
  if (args.no_orientation && scene.integrator.light_sampler.rfind("tree", 0) != 0)
    throw SceneError(fmt::format(
        "--no-orientation: applies to the tree samplers only (tree, tree-split), not {}",
        scene.integrator.light_sampler));

  fs::path stem = fs::path(args.scene).stem();
  fs::path exr = args.out.empty() ? fs::path("out") / (stem.string() + ".exr") : fs::path(args.out);
  fs::path png = args.png.empty() ? fs::path(exr).replace_extension(".png") : fs::path(args.png);

  ClRuntime rt(args.device);
  RendererOptions ropt;
  ropt.light_sampler = scene.integrator.light_sampler;
  ropt.split_threshold = scene.integrator.split_threshold;
  ropt.orientation_term = !args.no_orientation;
  Renderer renderer(rt, scene, ropt);
  ProgressBar bar;
  RenderSettings settings;
  settings.spp = scene.integrator.spp;
  settings.seed = scene.integrator.seed;
  settings.progress = [&bar](double f) { bar.update(f); };
  Film film = renderer.render(settings);
  bar.finish();

  RgbImage img = film.mean();
  if (uint64_t n = renderer.stats().overflowed_pixels)
    std::fprintf(stderr,
                 "canopy: warning: %llu pixels exceed the float range of the image (3.4e38) and "
                 "are written as the largest finite float\n",
                 (unsigned long long)n);
  write_exr(exr, img,
            {{"canopy:scene", args.scene},
             {"canopy:light_sampler", scene.integrator.light_sampler},
             {"canopy:split_threshold", fmt::format("{}", scene.integrator.split_threshold)},
             {"canopy:orientation_term", args.no_orientation ? "off" : "on"},
             {"canopy:spp", std::to_string(scene.integrator.spp)},
             {"canopy:seed", std::to_string(scene.integrator.seed)}});
  write_png(png, img);
  if (!args.heatmap.empty()) write_png(args.heatmap, film.shadow_ray_heatmap());
  const RenderStats& st = renderer.stats();
  std::fprintf(stderr, "%s: %dx%d, %d spp, %zu lights, %zu primitives on %s\n", args.scene.c_str(),
               scene.film.width, scene.film.height, scene.integrator.spp, scene.lights.size(),
               renderer.geometry().prims.size(), rt.device_name().c_str());
  std::fprintf(stderr, "build %.3f s, compile %.3f s, render %.3f s%s\n", st.build_seconds,
               st.compile_seconds, st.render_seconds,
               st.nonfinite_samples
                   ? fmt::format(", {} non-finite samples dropped", st.nonfinite_samples).c_str()
                   : "");
  timings.total_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  if (args.stats) std::fprintf(stderr, "%s", stats_to_table(st, timings).c_str());
  if (!args.stats_json.empty()) {
    nlohmann::json j = stats_to_json(st, timings);
    j["scene"] = args.scene;
    j["light_sampler"] = scene.integrator.light_sampler;
    j["spp"] = scene.integrator.spp;
    j["film"] = {scene.film.width, scene.film.height};
    j["lights"] = scene.lights.size();
    j["device"] = rt.device_name();
    std::ofstream out(args.stats_json);
    if (!out) throw std::runtime_error(fmt::format("{}: cannot write", args.stats_json));
    out << j.dump(2) << "\n";
  }
  std::printf("wrote %s\nwrote %s\n", exr.string().c_str(), png.string().c_str());
  return 0;
}

int run_info() {
  std::vector<DeviceInfo> devices = list_devices();
  if (devices.empty()) {
    std::printf("no OpenCL platforms found\n");
    return kExitRuntime;
  }
  for (const DeviceInfo& d : devices)
    std::printf("platform %d: %s\n  device %d: %s (%s), %u compute units, %.1f GiB\n",
                d.platform_index, d.platform_name.c_str(), d.device_index, d.device_name.c_str(),
                d.version.c_str(), d.compute_units, double(d.global_mem) / (1024.0 * 1024 * 1024));
  std::printf("kernel sources: %s\n", kernel_dir().string().c_str());
  return 0;
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"Canopy: a many-light path tracer on OpenCL"};
  app.require_subcommand(1);

  RenderArgs rargs;
  CLI::App* render = app.add_subcommand("render", "Render a scene to EXR and PNG");
  render->add_option("scene", rargs.scene, "Scene file (JSON, see docs/scene-format.md)")
      ->required();
  render->add_option("--spp", rargs.spp, "Samples per pixel (overrides the scene)");
  render->add_option("--out", rargs.out, "Output EXR (default out/<scene>.exr)");
  render->add_option("--png", rargs.png, "Output PNG (default: the EXR path with .png)");
  render->add_option("--seed", rargs.seed, "Random seed (overrides the scene)");
  render->add_option("--light-sampler", rargs.light_sampler, "Light sampler (overrides the scene)")
      ->check(CLI::IsMember(std::vector<std::string>(std::begin(kSamplers), std::end(kSamplers))));
  render
      ->add_option("--split-threshold", rargs.split_threshold,
                   "tree-split threshold in [0, 1] (overrides the scene; 0 never splits)")
      ->check(CLI::Range(0.0, 1.0));
  render->add_flag("--no-orientation", rargs.no_orientation,
                   "Tree samplers: rank clusters by energy / distance^2 only (ablation of the "
                   "orientation terms, paper Fig. 15-16)");
  render->add_option("--device", rargs.device, "OpenCL device name substring (see `canopy info`)");
  render->add_flag("--stats", rargs.stats, "Print per-stage times, throughput and cut sizes");
  render->add_option("--stats-json", rargs.stats_json, "Write the statistics as JSON to FILE");
  render->add_option("--heatmap", rargs.heatmap,
                     "Write a PNG heat map of shadow rays per shading point (paper Fig. 18)");

  CLI::App* info = app.add_subcommand("info", "List OpenCL platforms and devices");
  std::function<int()> action; // set by the subcommands defined in their own files
  add_compare_command(app, action);
  add_converge_command(app, action);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitBadInput;
  }

  try {
    if (render->parsed()) return run_render(rargs);
    if (info->parsed()) return run_info();
    if (action) return action();
  } catch (const SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "canopy: %s\n", e.what());
    return kExitRuntime;
  }
  return 0;
}
