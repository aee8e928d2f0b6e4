// `canopy compare A.exr B.exr`: RMSE, relative MSE and PSNR of A against the reference B
// (definitions in image/image_compare.h), the canopy:* metadata of both files, and optionally a
// false-colour error image.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace canopy {

// Adds the `compare` subcommand to `app`. When it is parsed, `action` is set to the function that
// runs it and returns the exit code (0; invalid input throws SceneError, which main maps to 2).
CLI::App* add_compare_command(CLI::App& app, std::function<int()>& action);

} // namespace canopy
