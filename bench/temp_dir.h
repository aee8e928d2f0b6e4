// A per-process temporary directory for the files a benchmark generates, removed at exit.
#pragma once

#include <fmt/format.h>

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace canopy::bench {

struct TempDir {
  std::filesystem::path dir;
  explicit TempDir(const std::string& name) {
    dir = std::filesystem::temp_directory_path() /
          fmt::format("canopy-bench-{}-{}", name, ::getpid());
    std::filesystem::create_directories(dir);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
  }
};

} // namespace canopy::bench
