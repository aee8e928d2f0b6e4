#include "render/memory_budget.h"

#include "render/renderer.h"

#include <fmt/format.h>

#include <unistd.h>

namespace canopy {

namespace {

std::string bytes_text(uint64_t b) {
  const double gib = 1024.0 * 1024.0 * 1024.0;
  if (b >= uint64_t(1) << 30) return fmt::format("{} bytes ({:.2f} GiB)", b, double(b) / gib);
  return fmt::format("{} bytes ({:.1f} MiB)", b, double(b) / (1024.0 * 1024.0));
}

uint64_t sum_bytes(const std::vector<MemoryNeed>& v) {
  uint64_t s = 0;
  for (const MemoryNeed& m : v)
    s += m.bytes;
  return s;
}

std::string largest(const std::vector<MemoryNeed>& v) {
  const MemoryNeed* best = nullptr;
  for (const MemoryNeed& m : v)
    if (!best || m.bytes > best->bytes) best = &m;
  return best ? fmt::format("{}: {}", best->name, bytes_text(best->bytes)) : std::string();
}

} // namespace

MemoryLimits memory_limits(const cl::Device& device) {
  MemoryLimits l;
  l.max_alloc = device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
  l.global_mem = device.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
  long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  l.host_mem = pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : UINT64_MAX;
  return l;
}

void check_memory(const MemoryLimits& limits, const std::vector<MemoryNeed>& device_buffers,
                  const std::vector<MemoryNeed>& host_buffers, const std::string& what) {
  for (const MemoryNeed& m : device_buffers)
    if (m.bytes > limits.max_alloc)
      throw MemoryLimitError(
          fmt::format("{}: device buffer {} needs {}, more than the device's largest allocation "
                      "(CL_DEVICE_MAX_MEM_ALLOC_SIZE {}); see docs/limits.md",
                      what, m.name, bytes_text(m.bytes), bytes_text(limits.max_alloc)));
  if (uint64_t total = sum_bytes(device_buffers); total > limits.global_mem)
    throw MemoryLimitError(fmt::format(
        "{}: device buffers need {} together (largest {}), more than the device's memory "
        "(CL_DEVICE_GLOBAL_MEM_SIZE {}); see docs/limits.md",
        what, bytes_text(total), largest(device_buffers), bytes_text(limits.global_mem)));
  if (uint64_t total = sum_bytes(host_buffers); total > limits.host_mem)
    throw MemoryLimitError(
        fmt::format("{}: host buffers need {} together (largest {}), more than the host's physical "
                    "memory ({}); see docs/limits.md",
                    what, bytes_text(total), largest(host_buffers), bytes_text(limits.host_mem)));
}

void check_memory(const cl::Device& device, const std::vector<MemoryNeed>& device_buffers,
                  const std::vector<MemoryNeed>& host_buffers, const std::string& what) {
  check_memory(memory_limits(device), device_buffers, host_buffers, what);
}

void check_scene_memory(const cl::Device& device, const Scene& scene) {
  const uint64_t n = scene.lights.size();
  const uint64_t tris = scene.triangle_count();
  uint64_t area_lights = 0; // analytic area lights get a primitive of their own
  for (const Light& l : scene.lights)
    if (l.type != LIGHT_POINT && l.type != LIGHT_SPOT && !(l.flags & LIGHT_FLAG_FROM_MESH))
      ++area_lights;
  // Lower bounds of what the renderer uploads: one record per light and per primitive (triangles
  // plus one per analytic area light), the alias table's two words per light. The light tree and
  // the BVH come on top; these alone already decide the cases that cannot fit.
  std::vector<MemoryNeed> dev = {
      {"lights", n * sizeof(Light)},
      {"alias_prob", n * sizeof(float)},
      {"alias_index", n * sizeof(int)},
      {"power_pmf", n * sizeof(float)},
      {"prims", (tris + area_lights) * sizeof(Primitive)},
  };
  std::vector<MemoryNeed> host = {
      {"lights", n * sizeof(Light)},
      {"prims", (tris + area_lights) * sizeof(Primitive)},
  };
  check_memory(device, dev, host, printable(scene.path.string(), 1024));
}

void check_film_memory(const cl::Device& device, uint64_t pixels, const std::string& what) {
  check_memory(
      device,
      {{"film_sum", pixels * sizeof(double4)},
       {"film_sumsq", pixels * sizeof(double4)},
       {"film_counts", pixels * sizeof(double4)}},
      {{"film (host copy)", pixels * 3 * sizeof(double4)}, {"image", pixels * 3 * sizeof(float)}},
      printable(what, 1024));
}

} // namespace canopy
