// Loads the OpenImageIO module (oiio/module.h) on first use, and the functions that go through it.
#include "cl/runtime.h"
#include "oiio/module.h"

#include <fmt/format.h>

#include <dlfcn.h>

#include <cstdlib>
#include <mutex>

namespace canopy {

namespace {

constexpr const char* kModuleFile = "libcanopy_oiio.so";

const OiioModule* load() {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("CANOPY_OIIO_MODULE"); env && *env)
    candidates.push_back(env);
  else
    candidates = {executable_dir() / kModuleFile,
                  executable_dir() / ".." / "lib" / "canopy" / kModuleFile,
                  fs::path(CANOPY_OIIO_MODULE_BUILD_DIR) / kModuleFile,
                  fs::path(CANOPY_OIIO_MODULE_INSTALL_DIR) / kModuleFile};
  std::string why;
  for (const fs::path& p : candidates) {
    std::error_code ec;
    if (!fs::exists(p, ec)) continue;
    void* handle = dlopen(p.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* e = dlerror();
      why = e ? e : p.string();
      continue;
    }
    using Entry = const OiioModule* (*)();
    if (auto entry = reinterpret_cast<Entry>(dlsym(handle, "canopy_oiio_module"))) return entry();
    why = fmt::format("{}: no canopy_oiio_module", p.string());
  }
  throw ImageFileError(
      fmt::format("cannot load the OpenImageIO module {} ({}; set CANOPY_OIIO_MODULE to its path)",
                  kModuleFile, why.empty() ? "not found" : why));
}

} // namespace

const OiioModule& oiio_module() {
  static std::once_flag once;
  static const OiioModule* module = nullptr;
  std::call_once(once, [] { module = load(); });
  return *module;
}

bool write_plot_png(const std::filesystem::path& file, const std::vector<PlotSeries>& series,
                    const PlotOptions& options) {
  std::string error;
  const int r = oiio_module().write_plot(file.c_str(), series, options, &error);
  if (r < 0) throw std::runtime_error(error); // names the file
  return r == 1;
}

} // namespace canopy
