// Memory checks before a render: every device buffer must fit the device's
// CL_DEVICE_MAX_MEM_ALLOC_SIZE, all of them together its CL_DEVICE_GLOBAL_MEM_SIZE, and the host
// copies the host's physical memory. Failing early, with the buffer named, replaces a bare
// clCreateBuffer error or std::bad_alloc after minutes of work (docs/limits.md).
#pragma once

#include "cl/runtime.h"
#include "scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace canopy {

// Thrown when the work does not fit: the message is one line naming the buffer, the bytes it
// needs and the limit. The CLI reports it with exit code 2 (the input asks for more than this
// machine has; a smaller film or fewer lights fit).
class MemoryLimitError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

struct MemoryNeed {
  std::string name; // e.g. "film_sum"
  uint64_t bytes;
};

struct MemoryLimits {
  uint64_t max_alloc = 0;  // CL_DEVICE_MAX_MEM_ALLOC_SIZE
  uint64_t global_mem = 0; // CL_DEVICE_GLOBAL_MEM_SIZE
  uint64_t host_mem = 0;   // physical memory of the host
};

MemoryLimits memory_limits(const cl::Device& device);

// Throws MemoryLimitError if a device buffer exceeds max_alloc, the device buffers together
// exceed global_mem, or the host buffers together exceed host_mem. `what` starts the message
// (e.g. the scene file name).
void check_memory(const MemoryLimits& limits, const std::vector<MemoryNeed>& device_buffers,
                  const std::vector<MemoryNeed>& host_buffers, const std::string& what);
void check_memory(const cl::Device& device, const std::vector<MemoryNeed>& device_buffers,
                  const std::vector<MemoryNeed>& host_buffers, const std::string& what);

// The scene's largest device buffers known before the acceleration structures are built (lights
// and the per-light sampler tables, triangles), checked before any of them is built.
void check_scene_memory(const cl::Device& device, const Scene& scene);

// The film of a render of `pixels` pixels (its three double4 accumulators on the device, their
// host copies and the image), checked before anything renders (the auto sampler's pilot comes
// first); Renderer::render checks it again with the wave's buffers.
void check_film_memory(const cl::Device& device, uint64_t pixels, const std::string& what);

} // namespace canopy
