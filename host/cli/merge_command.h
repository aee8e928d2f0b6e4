// `canopy merge OUT.exr IN.exr...`: merges partial renders (sample ranges, crops) by sample count
// into one image of the film (image/partial_image.h, docs/distributed.md).
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace canopy {

// Adds the `merge` subcommand to `app`. When it is parsed, `action` is set to the function that
// runs it and returns the exit code (0; bad or inconsistent input throws SceneError, exit 2).
CLI::App* add_merge_command(CLI::App& app, std::function<int()>& action);

} // namespace canopy
