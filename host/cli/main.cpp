// canopy: the command-line front end.
//   canopy render SCENE [--spp N] [--out FILE.exr] [--png FILE.png] [--seed S]
//                       [--light-sampler NAME] [--sampler independent|sobol] [--no-mis]
//                       [--device NAME]
//   canopy info
//   canopy compare A.exr B.exr      (cli/compare_command.cpp)
//   canopy converge SCENE ...       (cli/converge_command.cpp)
//   canopy merge OUT.exr IN.exr...  (cli/merge_command.cpp)
// Exit codes: 0 success, 2 invalid input (scene or arguments, unwritable outputs, work that does
// not fit the device's or host's memory), 1 runtime failure (OpenCL errors and the like).
#include "cl/runtime.h"
#include "cli/compare_command.h"
#include "cli/converge_command.h"
#include "cli/merge_command.h"
#include "image/error_stats.h"
#include "image/image_io.h"
#include "image/partial_image.h"
#include "render/auto_sampler.h"
#include "render/memory_budget.h"
#include "render/renderer.h"
#include "render/stats_report.h"
#include "scene/scene.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <unistd.h>

namespace {

using namespace canopy;
namespace fs = std::filesystem;

constexpr int kExitRuntime = 1;
constexpr int kExitBadInput = 2;

struct RenderArgs {
  std::string scene;
  std::optional<int> spp;
  std::optional<uint32_t> seed;
  std::optional<std::string> light_sampler;
  std::string path_sampler{kDefaultPathSampler};
  std::optional<float> split_threshold;
  std::optional<int> max_cut;
  std::optional<int> max_depth;
  bool no_orientation = false;
  bool no_mis = false;
  std::optional<float> brdf_delta, brdf_lambda;
  std::optional<int> brdf_n_max;
  bool brdf_equal = false;
  std::optional<std::string> volume_importance;
  std::optional<std::string> samples, crop; // "A:B", "x0,y0,x1,y1"
  std::optional<double> film_scale;
  std::string out, png, device, stats_json, heatmap, emitter_mask;
  bool stats = false;
  bool quiet = false;
  bool strict = false; // scene warnings are errors
};

// Render progress on stderr, once a render has run for a second: a bar redrawn in place on a
// terminal; whole lines (every 10% and at the end, with the elapsed time) otherwise, so that a log
// file (a Slurm task's, say) reads cleanly; nothing with --quiet.
class Progress {
public:
  explicit Progress(bool quiet) : quiet_(quiet), terminal_(::isatty(STDERR_FILENO) == 1) {}
  void update(double fraction) {
    if (quiet_) return;
    double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    if (elapsed < 1.0) return;
    if (!terminal_) {
      int tenth = int(fraction * 10.0 + 1e-9);
      if (tenth <= last_tenth_) return;
      last_tenth_ = tenth;
      shown_ = true;
      std::fprintf(stderr, "canopy: %3d%% rendered, %.1f s\n", 10 * tenth, elapsed);
      std::fflush(stderr);
      return;
    }
    if (fraction < 1.0 && elapsed - last_ < 0.1) return;
    last_ = elapsed;
    shown_ = true;
    int filled = int(fraction * 40.0 + 0.5);
    std::fprintf(stderr, "\r[%s%s] %5.1f%%  %.1f s", std::string(size_t(filled), '#').c_str(),
                 std::string(size_t(40 - filled), ' ').c_str(), 100.0 * fraction, elapsed);
    std::fflush(stderr);
  }
  void finish() {
    if (shown_ && terminal_) std::fprintf(stderr, "\n");
  }

private:
  using Clock = std::chrono::steady_clock;
  bool quiet_, terminal_;
  Clock::time_point start_ = Clock::now();
  double last_ = -1.0;
  int last_tenth_ = 0;
  bool shown_ = false;
};

// --samples A:B: the sample indices [A, B) of every pixel, 0 <= A < B <= kMaxSpp.
std::pair<int, int> parse_sample_range(const std::string& text) {
  size_t colon = text.find(':');
  auto number = [](const std::string& s, long long& v) {
    if (s.empty() || s.size() > 12 || s.find_first_not_of("0123456789") != std::string::npos)
      return false;
    v = std::stoll(s);
    return true;
  };
  long long a = 0, b = 0;
  if (colon == std::string::npos || !number(text.substr(0, colon), a) ||
      !number(text.substr(colon + 1), b) || a >= b || b > kMaxSpp)
    throw SceneError(fmt::format("--samples: '{}': want A:B with 0 <= A < B <= {}",
                                 printable(text, 100), kMaxSpp));
  return {int(a), int(b)};
}

// --crop x0,y0,x1,y1: the pixels [x0, x1) x [y0, y1), inside the film and not empty.
PixelWindow parse_crop(const std::string& text, int width, int height) {
  PixelWindow w;
  int* v[4] = {&w.x0, &w.y0, &w.x1, &w.y1};
  size_t pos = 0;
  bool ok = true;
  for (int i = 0; i < 4 && ok; ++i) {
    size_t end = i < 3 ? text.find(',', pos) : text.size();
    std::string part = end == std::string::npos ? "" : text.substr(pos, end - pos);
    ok = !part.empty() && part.size() <= 6 &&
         part.find_first_not_of("0123456789") == std::string::npos;
    if (ok) *v[i] = std::stoi(part);
    pos = end == std::string::npos ? end : end + 1;
  }
  if (!ok || w.x0 >= w.x1 || w.y0 >= w.y1 || w.x1 > width || w.y1 > height)
    throw SceneError(fmt::format("--crop: '{}': want x0,y0,x1,y1 with 0 <= x0 < x1 <= {} and "
                                 "0 <= y0 < y1 <= {} (the film)",
                                 printable(text, 100), width, height));
  return w;
}

std::string lower_ext(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

// The EXR and PNG paths. --out names the EXR (FILE.exr) or the PNG (FILE.png); the other format is
// written beside it with the other extension unless --png names the PNG. Each format is written
// once, and never under the other's extension. Without --out: the scene's own output
// (`scene_output`, pbrt's Film "filename", .exr or .png), else out/<scene>.exr.
std::pair<fs::path, fs::path> output_paths(const RenderArgs& args,
                                           const std::string& scene_output) {
  fs::path stem = fs::path(args.scene).stem();
  fs::path exr, png;
  if (args.out.empty() && !scene_output.empty()) {
    exr = scene_output;
    if (lower_ext(exr) == ".png") {
      if (args.png.empty()) png = exr;
      exr.replace_extension(".exr");
    }
  } else if (args.out.empty()) {
    exr = fs::path("out") / (stem.string() + ".exr");
  } else {
    fs::path out(args.out);
    std::string e = lower_ext(out);
    if (e == ".exr") {
      exr = out;
    } else if (e == ".png") {
      if (!args.png.empty())
        throw SceneError(fmt::format("--out: {}: names a PNG and so does --png; give --out an "
                                     ".exr name",
                                     printable(args.out, 1024)));
      png = out;
      exr = fs::path(out).replace_extension(".exr");
    } else {
      throw SceneError(
          fmt::format("--out: {}: must end in .exr or .png", printable(args.out, 1024)));
    }
  }
  if (!args.png.empty()) {
    if (lower_ext(args.png) != ".png")
      throw SceneError(fmt::format("--png: {}: must end in .png", printable(args.png, 1024)));
    png = args.png;
  }
  if (png.empty()) png = fs::path(exr).replace_extension(".png");
  return {exr, png};
}

// Checked before rendering so a render never runs for nothing: the file is a regular file or
// absent, and its directory exists (it is created if missing) and takes a new file.
void check_writable(const fs::path& file, const char* option) {
  auto fail = [&](const std::string& problem) {
    throw SceneError(fmt::format("{}: {}: {}", option, printable(file.string(), 1024), problem));
  };
  std::error_code ec;
  fs::file_status st = fs::status(file, ec);
  if (fs::exists(st) && !fs::is_regular_file(st)) fail("exists and is not a regular file");
  fs::path dir = file.parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::exists(dir, ec)) {
    fs::create_directories(dir, ec);
    if (ec) fail(fmt::format("cannot create the directory ({})", ec.message()));
  }
  if (!fs::is_directory(dir, ec))
    fail(fmt::format("its directory {} is not a directory", printable(dir.string(), 1024)));
  std::string probe = (dir / ".canopy-write-test-XXXXXX").string();
  std::vector<char> name(probe.begin(), probe.end());
  name.push_back('\0');
  int fd = ::mkstemp(name.data());
  if (fd < 0) fail(fmt::format("the directory is not writable ({})", std::strerror(errno)));
  ::close(fd);
  ::unlink(name.data());
}

// "sampler tree-split (threshold 0.5, max cut 64)": what the summary line says of the light
// sampler; only the settings that apply to it.
std::string sampler_summary(const IntegratorSettings& in, bool orientation_term) {
  std::string s = "sampler " + in.light_sampler;
  std::vector<std::string> parts;
  if (in.light_sampler == "tree-split" || in.light_sampler == "brdf-mis" ||
      in.light_sampler == "brdf-oriented") { // (the BRDF samplers are tree-split at diffuse points)
    parts.push_back(fmt::format("threshold {}", in.split_threshold));
    parts.push_back(fmt::format("max cut {}", in.max_cut));
  }
  if (in.light_sampler == "brdf-mis" || in.light_sampler == "brdf-oriented")
    parts.push_back(fmt::format("delta {}", in.brdf_delta));
  if (in.light_sampler == "brdf-mis") {
    if (in.brdf_adaptive)
      parts.push_back(fmt::format("N_max {}, lambda {}", in.brdf_n_max, in.brdf_lambda));
    else
      parts.push_back("equal allocation");
  }
  if (!orientation_term) parts.push_back("no orientation");
  if (!in.mis) parts.push_back("no MIS");
  if (parts.empty()) return s;
  s += " (";
  for (size_t i = 0; i < parts.size(); ++i)
    s += (i ? ", " : "") + parts[i];
  return s + ")";
}

int run_render(const RenderArgs& args) {
  auto t_start = std::chrono::steady_clock::now();
  Scene scene = load_scene(args.scene, SceneLoadOptions{args.strict});
  for (const std::string& w : scene.warnings)
    std::fprintf(stderr, "canopy: warning: %s\n", w.c_str());
  RunTimings timings;
  timings.load_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  if (args.spp) {
    if (*args.spp < 1 || *args.spp > kMaxSpp)
      throw SceneError(fmt::format("--spp: must be in [1, {}], got {}", kMaxSpp, *args.spp));
    scene.integrator.spp = *args.spp;
  }
  int first_sample = 0;
  if (args.samples) {
    if (args.spp)
      throw SceneError("--samples and --spp: give one (--samples A:B renders B - A spp)");
    auto [a, b] = parse_sample_range(*args.samples);
    first_sample = a;
    scene.integrator.spp = b - a;
  }
  // Before --crop, whose pixels are those of the scaled film.
  if (args.film_scale) {
    scale_film(scene.film, *args.film_scale);
    if (scene.film.width > kMaxFilmSide || scene.film.height > kMaxFilmSide)
      throw SceneError(fmt::format("--film-scale: {}x{} exceeds the largest film side, {}",
                                   scene.film.width, scene.film.height, kMaxFilmSide));
  }
  PixelWindow window;
  if (args.crop) window = parse_crop(*args.crop, scene.film.width, scene.film.height);
  if (args.seed) scene.integrator.seed = *args.seed;
  if (std::find(kPathSamplerNames.begin(), kPathSamplerNames.end(), args.path_sampler) ==
      kPathSamplerNames.end())
    throw SceneError(fmt::format("--sampler: '{}': must be independent or sobol",
                                 printable(args.path_sampler, 256)));
  if (args.light_sampler) scene.integrator.light_sampler = *args.light_sampler;
  if (args.split_threshold) scene.integrator.split_threshold = *args.split_threshold;
  if (args.max_cut) {
    if (*args.max_cut < 1 || *args.max_cut > kMaxMaxCut)
      throw SceneError(
          fmt::format("--max-cut: must be in [1, {}], got {}", kMaxMaxCut, *args.max_cut));
    scene.integrator.max_cut = *args.max_cut;
  }
  if (args.max_depth) {
    if (*args.max_depth < 1 || *args.max_depth > kMaxDepth)
      throw SceneError(
          fmt::format("--max-depth: must be in [1, {}], got {}", kMaxDepth, *args.max_depth));
    scene.integrator.max_depth = *args.max_depth;
  }
  if (args.no_orientation && scene.integrator.light_sampler.rfind("tree", 0) != 0)
    throw SceneError(fmt::format(
        "--no-orientation: applies to the tree samplers only (tree, tree-split), not {}",
        scene.integrator.light_sampler));
  if (args.no_mis) scene.integrator.mis = false;
  if (args.brdf_delta) {
    if (!(*args.brdf_delta >= 0.0f && *args.brdf_delta <= 1e3f))
      throw SceneError(fmt::format("--brdf-delta: must be in [0, 1000], got {}", *args.brdf_delta));
    scene.integrator.brdf_delta = *args.brdf_delta;
  }
  if (args.brdf_n_max) {
    if (*args.brdf_n_max < 1 || *args.brdf_n_max > kMaxBrdfSamples)
      throw SceneError(fmt::format("--brdf-nmax: must be in [1, {}], got {}", kMaxBrdfSamples,
                                   *args.brdf_n_max));
    scene.integrator.brdf_n_max = *args.brdf_n_max;
  }
  if (args.brdf_lambda) {
    if (!(*args.brdf_lambda >= 1e-3f && *args.brdf_lambda <= 1e6f))
      throw SceneError(
          fmt::format("--brdf-lambda: must be in [0.001, 1e6], got {}", *args.brdf_lambda));
    scene.integrator.brdf_lambda = *args.brdf_lambda;
  }
  if (args.brdf_equal) scene.integrator.brdf_adaptive = false;
  if (args.volume_importance) scene.integrator.volume_importance = *args.volume_importance;

  auto [exr, png] = output_paths(args, scene.film.output);
  check_writable(exr, args.out.empty() ? "output" : "--out");
  check_writable(png, args.png.empty() ? "output" : "--png");
  if (!args.heatmap.empty()) {
    if (lower_ext(args.heatmap) != ".png")
      throw SceneError(
          fmt::format("--heatmap: {}: must end in .png", printable(args.heatmap, 1024)));
    fs::path h(args.heatmap);
    if (h == exr || h == png)
      throw SceneError(
          fmt::format("--heatmap: {}: is also the image output", printable(args.heatmap, 1024)));
    check_writable(h, "--heatmap");
  }
  if (!args.emitter_mask.empty()) {
    if (lower_ext(args.emitter_mask) != ".png")
      throw SceneError(
          fmt::format("--emitter-mask: {}: must end in .png", printable(args.emitter_mask, 1024)));
    fs::path m(args.emitter_mask);
    if (m == exr || m == png)
      throw SceneError(fmt::format("--emitter-mask: {}: is also the image output",
                                   printable(args.emitter_mask, 1024)));
    check_writable(m, "--emitter-mask");
  }
  if (!args.stats_json.empty()) check_writable(args.stats_json, "--stats-json");

  const std::string scene_name = printable(args.scene, 1024);
  if (scene.lights.empty() && scene.infinite_lights.empty())
    std::fprintf(
        stderr, "canopy: warning: %s: the scene has no emitters%s; the image is black\n",
        scene_name.c_str(),
        scene.skipped_lights
            ? fmt::format(" ({} lights with zero emission skipped)", scene.skipped_lights).c_str()
            : "");

  ClRuntime rt(args.device);
  check_scene_memory(rt.device(), scene);
  RendererOptions ropt;
  ropt.light_sampler = scene.integrator.light_sampler;
  ropt.split_threshold = scene.integrator.split_threshold;
  ropt.max_cut = scene.integrator.max_cut;
  ropt.orientation_term = !args.no_orientation;
  ropt.mis = scene.integrator.mis;
  ropt.path_sampler = args.path_sampler;
  ropt.brdf.delta = scene.integrator.brdf_delta;
  ropt.brdf.n_max = scene.integrator.brdf_n_max;
  ropt.brdf.lambda = scene.integrator.brdf_lambda;
  ropt.brdf.adaptive = scene.integrator.brdf_adaptive;
  // "auto": the renderer starts with the first candidate; the exploration leaves it at the chosen
  // one, which the summary, the metadata and the stats then name.
  // A partial render (--samples, --crop) takes the last candidate without exploring: the choice
  // depends on timings, and a partial render's estimator must be determined by the scene, the seed
  // and the range, so that parts rendered anywhere merge into exactly the single render.
  bool automatic = scene.integrator.light_sampler == kAutoLightSampler;
  if (automatic && (args.samples || args.crop)) {
    automatic = false;
    ropt = auto_candidates(ropt).back().options;
    scene.integrator.light_sampler = ropt.light_sampler;
    scene.integrator.split_threshold = ropt.split_threshold;
  }
  if (automatic) {
    // A film that cannot fit fails now, not after the exploration.
    check_film_memory(rt.device(), uint64_t(scene.film.width) * uint64_t(scene.film.height),
                      scene.path.string());
    ropt = auto_candidates(ropt).front().options;
  }
  Renderer renderer(rt, scene, ropt);
  Progress progress(args.quiet);
  RenderSettings settings;
  settings.spp = scene.integrator.spp;
  settings.seed = scene.integrator.seed;
  settings.first_sample = first_sample;
  settings.window = window;
  settings.progress = [&progress](double f) { progress.update(f); };
  std::optional<AutoChoice> choice;
  Film film;
  if (automatic) {
    // The exploration's samples are part of the image (render/auto_sampler.h).
    AutoRender a = render_auto(renderer, ropt, settings);
    film = std::move(a.film);
    choice = std::move(a.choice);
    scene.integrator.light_sampler = choice->chosen.options.light_sampler;
    scene.integrator.split_threshold = choice->chosen.options.split_threshold;
  } else {
    film = renderer.render(settings);
  }
  progress.finish();
  if (choice && !args.quiet) std::fprintf(stderr, "canopy: %s\n", describe(*choice).c_str());

  RgbImage img = film.mean();
  if (scene.film.image_scale != 1.0f) // (pbrt's Film scale and iso) FLT_MAX stays finite below
    for (float& v : img.rgb)
      v = std::clamp(v * scene.film.image_scale, -FLT_MAX, FLT_MAX);
  if (uint64_t n = renderer.stats().overflowed_pixels)
    std::fprintf(stderr,
                 "canopy: warning: %llu pixels exceed the float range of the image (3.4e38) and "
                 "are written as the largest finite float\n",
                 (unsigned long long)n);
  // Every image is a partial render (image/partial_image.h): `canopy merge` combines them.
  PartialInfo part;
  part.scene = args.scene;
  part.scene_hash = scene_file_hash(args.scene);
  part.version = canopy_version();
  part.seed = scene.integrator.seed;
  part.film_width = scene.film.width;
  part.film_height = scene.film.height;
  part.x0 = film.x0;
  part.y0 = film.y0;
  part.x1 = film.x0 + film.width;
  part.y1 = film.y0 + film.height;
  part.sample_begin = first_sample;
  part.sample_end = first_sample + scene.integrator.spp;
  write_partial_exr(
      exr, img, part,
      {{"canopy:light_sampler", scene.integrator.light_sampler},
       {"canopy:split_threshold", fmt::format("{}", scene.integrator.split_threshold)},
       {"canopy:max_cut", std::to_string(scene.integrator.max_cut)},
       {"canopy:max_depth", std::to_string(scene.integrator.max_depth)},
       {"canopy:orientation_term", args.no_orientation ? "off" : "on"},
       {"canopy:mis", scene.integrator.mis ? "on" : "off"},
       {"canopy:sampler", args.path_sampler},
       {"canopy:spp", std::to_string(scene.integrator.spp)},
       {"canopy:auto", choice ? describe(*choice) : std::string("off")}});
  write_png(png, img);
  if (!args.heatmap.empty()) write_png(args.heatmap, film.shadow_ray_heatmap());
  if (!args.emitter_mask.empty())
    write_png(args.emitter_mask, mask_to_image(film.emitter_mask(), film.width, film.height));
  const RenderStats& st = renderer.stats();
  std::string skipped =
      (scene.infinite_lights.empty()
           ? std::string()
           : fmt::format(" and {} at infinity", scene.infinite_lights.size())) +
      (scene.skipped_lights ? fmt::format(" ({} with zero emission skipped)", scene.skipped_lights)
                            : std::string());
  std::string part_text;
  if (args.samples)
    part_text += fmt::format(" (samples {}:{})", part.sample_begin, part.sample_end);
  if (args.crop) part_text += fmt::format(", crop {},{},{},{}", part.x0, part.y0, part.x1, part.y1);
  std::fprintf(stderr,
               "%s: %dx%d, %d spp%s, %s, max depth %d, %zu lights%s, %zu primitives on %s\n",
               scene_name.c_str(), scene.film.width, scene.film.height, scene.integrator.spp,
               part_text.c_str(), sampler_summary(scene.integrator, !args.no_orientation).c_str(),
               scene.integrator.max_depth, scene.lights.size(), skipped.c_str(),
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
    if (choice) {
      nlohmann::json a;
      a["chosen"] = choice->chosen.label;
      a["reason"] = choice->reason;
      a["pilot_seconds"] = choice->pilot_seconds;
      a["explored_samples"] = choice->explored_samples;
      // JSON has no infinity: a gain without a measurable error is written as null.
      auto finite = [](double g) {
        return std::isfinite(g) ? nlohmann::json(g) : nlohmann::json();
      };
      a["stratification_gain"] = {finite(choice->gain[0]), finite(choice->gain[1])};
      for (const PilotResult& c : choice->candidates)
        a["candidates"].push_back(
            {{"label", c.label},
             {"samples", c.samples},
             {"variance", c.stats.variance},
             {"variance_interval", {c.stats.variance_lo, c.stats.variance_hi}},
             {"emitter_variance", c.stats.emitter_variance},
             {"tail_share", c.stats.tail_share},
             {"seconds", c.seconds},
             {"pass_seconds", c.pass_seconds},
             {"efficiency", c.efficiency},
             {"efficiency_lo", c.efficiency_lo},
             {"missed_tail", bool(c.missed_tail)},
             {"pruned", bool(c.pruned)},
             {"weight", {c.weight[0], c.weight[1]}}});
      j["auto"] = a;
    }
    j["split_threshold"] = scene.integrator.split_threshold;
    j["max_cut"] = scene.integrator.max_cut;
    j["max_depth"] = scene.integrator.max_depth;
    j["mis"] = scene.integrator.mis;
    j["sampler"] = args.path_sampler;
    j["brdf_delta"] = scene.integrator.brdf_delta;
    j["brdf_n_max"] = scene.integrator.brdf_n_max;
    j["brdf_lambda"] = scene.integrator.brdf_lambda;
    j["brdf_adaptive"] = scene.integrator.brdf_adaptive;
    j["spp"] = scene.integrator.spp;
    j["film"] = {scene.film.width, scene.film.height};
    j["lights"] = scene.lights.size();
    j["infinite_lights"] = scene.infinite_lights.size();
    j["device"] = rt.device_name();
    std::ofstream out(args.stats_json);
    if (!out) throw std::runtime_error(fmt::format("{}: cannot write", args.stats_json));
    out << j.dump(2) << "\n";
  }
  std::printf("wrote %s\nwrote %s\n", printable(exr.string(), 1024).c_str(),
              printable(png.string(), 1024).c_str());
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
  // CLI11 reads "nan" and "inf" as numbers, and NaN passes every range check.
  const CLI::Validator finite_number(
      [](std::string& s) -> std::string {
        char* end = nullptr;
        double d = std::strtod(s.c_str(), &end);
        if (end == s.c_str() || *end != '\0' || !std::isfinite(d)) return "must be a finite number";
        return {};
      },
      "FINITE");
  app.require_subcommand(1);

  RenderArgs rargs;
  CLI::App* render = app.add_subcommand("render", "Render a scene to EXR and PNG");
  render->add_option("scene", rargs.scene, "Scene file (JSON or .pbrt; docs/scene-format.md)")
      ->required();
  render->add_option("--spp", rargs.spp, "Samples per pixel (overrides the scene)");
  render->add_option("--samples", rargs.samples,
                     "A:B renders the sample indices [A, B) of every pixel (B - A spp): renders of "
                     "disjoint ranges merge into the render of all of them (`canopy merge`)");
  render->add_option("--crop", rargs.crop,
                     "x0,y0,x1,y1 renders the film's pixels [x0, x1) x [y0, y1) only, the same as "
                     "in the full render (a tile for `canopy merge`)");
  render
      ->add_option("--film-scale", rargs.film_scale,
                   "Scale the scene's film resolution, e.g. 0.25 for a preview (before --crop)")
      ->check(CLI::Range(0.01, 4.0));
  render->add_flag("--quiet", rargs.quiet, "No progress report");
  render->add_flag("--strict", rargs.strict,
                   "Scene warnings (pbrt constructs not read, unknown parameters) are errors");
  render->add_option("--out", rargs.out,
                     "Output image: FILE.exr, or FILE.png; the other format is written beside it "
                     "with the other extension (default out/<scene>.exr). Written to a temporary "
                     "file in the same directory, then renamed");
  render->add_option("--png", rargs.png, "Output PNG (default: the EXR path with .png)");
  render->add_option("--seed", rargs.seed, "Random seed (overrides the scene)");
  render->add_option("--sampler", rargs.path_sampler,
                     "The camera paths' numbers: sobol (Owen-scrambled Sobol points, stratified "
                     "per pixel) or independent (a PCG stream per path); default sobol");
  render->add_option("--light-sampler", rargs.light_sampler, "Light sampler (overrides the scene)")
      ->check(CLI::IsMember(
          std::vector<std::string>(kLightSamplerChoices.begin(), kLightSamplerChoices.end())));
  render
      ->add_option("--split-threshold", rargs.split_threshold,
                   "tree-split threshold in [0, 1] (overrides the scene; 0 never splits)")
      ->check(finite_number) // before the range: "not finite" says more than "not in range"
      ->check(CLI::Range(0.0, 1.0));
  render->add_option("--max-cut", rargs.max_cut,
                     fmt::format("tree-split: at most this many lights per shading point, 1 .. {} "
                                 "(overrides the scene; default {})",
                                 kMaxMaxCut, kDefaultMaxCut));
  render->add_option("--max-depth", rargs.max_depth,
                     fmt::format("Path vertices after the camera hit, 1 .. {}; 1 = direct light "
                                 "only (overrides the scene)",
                                 kMaxDepth));
  render->add_flag("--no-orientation", rargs.no_orientation,
                   "Tree samplers: rank clusters by energy / distance^2 only (ablation of the "
                   "orientation terms, paper Fig. 15-16)");
  render->add_option("--brdf-delta", rargs.brdf_delta,
                     "brdf-mis/brdf-oriented: split clusters while the BRDF cap integral exceeds "
                     "this (default 0.5)");
  render->add_option("--brdf-nmax", rargs.brdf_n_max,
                     "brdf-mis: BRDF-aware samples per glossy point at most (default 50)");
  render->add_option("--brdf-lambda", rargs.brdf_lambda,
                     "brdf-mis: weight of BSDF hits in the adaptive allocation (default 10)");
  render
      ->add_option("--volume-importance", rargs.volume_importance,
                   "With a medium: rank light clusters for a ray segment by the segment importance "
                   "(segment, the default) or by the surface importance at its midpoint (midpoint)")
      ->check(CLI::IsMember({"segment", "midpoint"}));
  render->add_flag("--brdf-equal", rargs.brdf_equal,
                   "brdf-mis: one sample of each technique instead of adaptive allocation");
  render->add_flag("--no-mis", rargs.no_mis,
                   "No multiple importance sampling: light sampling alone gives direct light at "
                   "non-delta vertices, and BSDF-sampled rays that hit an emitter count only after "
                   "delta bounces (overrides the scene's integrator mis; no effect on the bsdf "
                   "sampler; the ablation of docs/results.md)");
  render->add_option("--device", rargs.device, "OpenCL device name substring (see `canopy info`)");
  render->add_flag("--stats", rargs.stats, "Print per-stage times, throughput and cut sizes");
  render->add_option("--stats-json", rargs.stats_json, "Write the statistics as JSON to FILE");
  render->add_option("--heatmap", rargs.heatmap,
                     "Write a PNG heat map of shadow rays per shading point (paper Fig. 18)");
  render->add_option("--emitter-mask", rargs.emitter_mask,
                     "Write a black/white PNG: white where a camera ray of the pixel hit an "
                     "emitter directly (the pixels `canopy converge` leaves out of its "
                     "non-emitter metrics)");

  CLI::App* info = app.add_subcommand("info", "List OpenCL platforms and devices");
  std::function<int()> action; // set by the subcommands defined in their own files
  add_compare_command(app, action);
  add_converge_command(app, action);
  add_merge_command(app, action);

  // Every floating-point option of every subcommand refuses NaN and infinities.
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
    for (CLI::Option* opt : sub->get_options())
      if (opt->get_type_name().rfind("FLOAT", 0) == 0) opt->check(finite_number);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, whatever the user typed (CLI11's own messages may quote it raw).
    std::fprintf(stderr, "canopy: %s (see --help)\n",
                 printable(e.what(), std::string::npos).c_str());
    return kExitBadInput;
  }

  try {
    if (render->parsed()) return run_render(rargs);
    if (info->parsed()) return run_info();
    if (action) return action();
  } catch (const SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return kExitBadInput;
  } catch (const MemoryLimitError& e) {
    std::fprintf(stderr, "%s\n", printable(e.what(), std::string::npos).c_str());
    return kExitBadInput;
  } catch (const cl::Error& e) {
    std::fprintf(stderr, "canopy: OpenCL: %s\n",
                 printable(describe_cl_error(e), std::string::npos).c_str());
    return kExitRuntime;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "canopy: out of host memory (see docs/limits.md)\n");
    return kExitRuntime;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "canopy: %s\n", printable(e.what(), std::string::npos).c_str());
    return kExitRuntime;
  }
  return 0;
}
