// OpenCL runtime: device selection (PoCL CPU by default), program builds from cl/ with build logs
// on failure, and an in-order command queue with profiling enabled.
#pragma once

#include <CL/opencl.hpp>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace canopy {

class ClError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

// The symbolic name of an OpenCL error code, e.g. "CL_MEM_OBJECT_ALLOCATION_FAILURE".
const char* cl_error_name(cl_int code);

// A one-line description of a failed OpenCL call: "clCreateBuffer failed with
// CL_INVALID_BUFFER_SIZE (-61)" plus `context` (the buffer or kernel and its size) if given.
std::string describe_cl_error(const cl::Error& e, const std::string& context = "");

struct DeviceInfo {
  int platform_index;
  int device_index;
  std::string platform_name;
  std::string device_name;
  std::string version;
  cl_device_type type;
  cl_uint compute_units;
  cl_ulong global_mem;
};

// Every device of every platform (empty when no ICD is installed).
std::vector<DeviceInfo> list_devices();

// The directory holding the kernel sources: $CANOPY_KERNEL_DIR if set, else the installed
// share/canopy/cl next to the binary's prefix, else the source tree's cl/.
std::filesystem::path kernel_dir();

// The directory of the running executable (/proc/self/exe); empty if unknown.
std::filesystem::path executable_dir();

class ClRuntime {
public:
  // `device_name` empty: the first PoCL CPU device (else the first CPU device, else any).
  // Otherwise the first device whose device or platform name contains it (case-insensitive).
  explicit ClRuntime(const std::string& device_name = "");

  // Builds a program from the given files (relative to kernel_dir(), their includes expanded:
  // host/cl/kernel_source.h) with "-cl-kernel-arg-info" (kernel arguments are bound by name,
  // host/cl/kernel_args.h) and `options` appended. Throws ClError holding the build log on failure.
  // The program is loaded from the program cache (host/cl/program_cache.h) when it holds it;
  // otherwise it is compiled, every kernel included (PoCL compiles a kernel's work-group function
  // when asked for the binary, not at its first launch), and stored there. `from_cache`, if given,
  // tells which happened.
  cl::Program build_program(const std::vector<std::string>& files, const std::string& options = "",
                            bool* from_cache = nullptr) const;
  // The same for source text (test and benchmark kernels that include headers from cl/).
  cl::Program build_program_source(const std::string& source,
                                   const std::string& options = "") const;

  const cl::Context& context() const { return context_; }
  const cl::Device& device() const { return device_; }
  cl::CommandQueue& queue() { return queue_; }
  std::string device_name() const;
  // What a program binary for this device depends on besides its source and options: the device,
  // its OpenCL version and its driver's (PoCL's) version.
  std::string device_signature() const;

private:
  std::string build_options(const std::string& options) const;
  cl::Program build_from_source(const std::string& source, const std::string& opts) const;

  cl::Context context_;
  cl::Device device_;
  cl::CommandQueue queue_;
};

// Launch helper: global size rounded up to a multiple of `local`; kernels ignore the padding items
// (`if (i >= count) return`). With POCL_WORK_GROUP_SPECIALIZATION=0 (set by ClRuntime) PoCL
// compiles one generic work-group function per kernel, used for every local size.
constexpr size_t kDefaultLocalSize = 64;
cl::Event enqueue_1d(cl::CommandQueue& q, const cl::Kernel& k, size_t n,
                     size_t local = kDefaultLocalSize);

// Nanoseconds between a finished event's start and end (profiling).
double event_seconds(const cl::Event& e);

} // namespace canopy
