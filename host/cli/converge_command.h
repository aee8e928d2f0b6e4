// `canopy converge SCENE --reference REF.exr --samplers LIST --budget SECONDS`: error against run
// time (DESIGN.md §8). For each sampler configuration it renders at growing spp (several seeds per
// point), records render wall time, spp, shadow rays and RMSE / relative MSE against the
// reference, and writes
//   PREFIX.csv          one row per render (with, for brdf-mis / brdf-oriented, the glossy
//                       points and the sums over them of cut size and BRDF-aware samples)
//   PREFIX-median.csv   one row per (configuration, spp): medians over the seeds, and the mean
//                       cut size and samples per glossy point (Liu et al. 2019, Table 1-2)
//   PREFIX-configs.csv  one row per configuration: build, light tree and compile times
//   PREFIX-time.png     log-log plot of median RMSE against render seconds, one curve per sampler
//   PREFIX-rays.png     the same against shadow rays
// It can also render the reference first (--reference-spp).
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace canopy {

// Adds the `converge` subcommand to `app`. When it is parsed, `action` is set to the function that
// runs it and returns the exit code (0; invalid input throws SceneError, which main maps to 2).
CLI::App* add_converge_command(CLI::App& app, std::function<int()>& action);

} // namespace canopy
