// Render statistics as a human-readable table (--stats) and as JSON (--stats-json).
#pragma once

#include "render/renderer.h"

#include <nlohmann/json.hpp>

#include <string>

namespace canopy {

struct RunTimings {
  double load_seconds = 0.0;  // scene parse + light sets + OBJ
  double total_seconds = 0.0; // wall time of the whole command
};

nlohmann::json stats_to_json(const RenderStats& stats, const RunTimings& run);
std::string stats_to_table(const RenderStats& stats, const RunTimings& run);

} // namespace canopy
