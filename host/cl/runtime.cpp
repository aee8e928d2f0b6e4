#include "cl/runtime.h"

#include "cl/kernel_source.h"
#include "cl/program_cache.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <optional>
#include <sched.h>
#include <unistd.h>

namespace canopy {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

} // namespace

std::filesystem::path executable_dir() {
  char buf[4096];
  ssize_t n = readlink("/proc/self/exe", buf, sizeof(buf) - 1);
  if (n <= 0) return {};
  buf[n] = 0;
  return std::filesystem::path(buf).parent_path();
}

const char* cl_error_name(cl_int code) {
  switch (code) {
#define CANOPY_CL_ERR(x)                                                                           \
  case x:                                                                                          \
    return #x;
    CANOPY_CL_ERR(CL_DEVICE_NOT_FOUND)
    CANOPY_CL_ERR(CL_DEVICE_NOT_AVAILABLE)
    CANOPY_CL_ERR(CL_COMPILER_NOT_AVAILABLE)
    CANOPY_CL_ERR(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    CANOPY_CL_ERR(CL_OUT_OF_RESOURCES)
    CANOPY_CL_ERR(CL_OUT_OF_HOST_MEMORY)
    CANOPY_CL_ERR(CL_PROFILING_INFO_NOT_AVAILABLE)
    CANOPY_CL_ERR(CL_MEM_COPY_OVERLAP)
    CANOPY_CL_ERR(CL_IMAGE_FORMAT_MISMATCH)
    CANOPY_CL_ERR(CL_IMAGE_FORMAT_NOT_SUPPORTED)
    CANOPY_CL_ERR(CL_BUILD_PROGRAM_FAILURE)
    CANOPY_CL_ERR(CL_MAP_FAILURE)
    CANOPY_CL_ERR(CL_MISALIGNED_SUB_BUFFER_OFFSET)
    CANOPY_CL_ERR(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
    CANOPY_CL_ERR(CL_COMPILE_PROGRAM_FAILURE)
    CANOPY_CL_ERR(CL_LINKER_NOT_AVAILABLE)
    CANOPY_CL_ERR(CL_LINK_PROGRAM_FAILURE)
    CANOPY_CL_ERR(CL_INVALID_VALUE)
    CANOPY_CL_ERR(CL_INVALID_DEVICE_TYPE)
    CANOPY_CL_ERR(CL_INVALID_PLATFORM)
    CANOPY_CL_ERR(CL_INVALID_DEVICE)
    CANOPY_CL_ERR(CL_INVALID_CONTEXT)
    CANOPY_CL_ERR(CL_INVALID_QUEUE_PROPERTIES)
    CANOPY_CL_ERR(CL_INVALID_COMMAND_QUEUE)
    CANOPY_CL_ERR(CL_INVALID_HOST_PTR)
    CANOPY_CL_ERR(CL_INVALID_MEM_OBJECT)
    CANOPY_CL_ERR(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR)
    CANOPY_CL_ERR(CL_INVALID_IMAGE_SIZE)
    CANOPY_CL_ERR(CL_INVALID_SAMPLER)
    CANOPY_CL_ERR(CL_INVALID_BINARY)
    CANOPY_CL_ERR(CL_INVALID_BUILD_OPTIONS)
    CANOPY_CL_ERR(CL_INVALID_PROGRAM)
    CANOPY_CL_ERR(CL_INVALID_PROGRAM_EXECUTABLE)
    CANOPY_CL_ERR(CL_INVALID_KERNEL_NAME)
    CANOPY_CL_ERR(CL_INVALID_KERNEL_DEFINITION)
    CANOPY_CL_ERR(CL_INVALID_KERNEL)
    CANOPY_CL_ERR(CL_INVALID_ARG_INDEX)
    CANOPY_CL_ERR(CL_INVALID_ARG_VALUE)
    CANOPY_CL_ERR(CL_INVALID_ARG_SIZE)
    CANOPY_CL_ERR(CL_INVALID_KERNEL_ARGS)
    CANOPY_CL_ERR(CL_INVALID_WORK_DIMENSION)
    CANOPY_CL_ERR(CL_INVALID_WORK_GROUP_SIZE)
    CANOPY_CL_ERR(CL_INVALID_WORK_ITEM_SIZE)
    CANOPY_CL_ERR(CL_INVALID_GLOBAL_OFFSET)
    CANOPY_CL_ERR(CL_INVALID_EVENT_WAIT_LIST)
    CANOPY_CL_ERR(CL_INVALID_EVENT)
    CANOPY_CL_ERR(CL_INVALID_OPERATION)
    CANOPY_CL_ERR(CL_INVALID_GL_OBJECT)
    CANOPY_CL_ERR(CL_INVALID_BUFFER_SIZE)
    CANOPY_CL_ERR(CL_INVALID_MIP_LEVEL)
    CANOPY_CL_ERR(CL_INVALID_GLOBAL_WORK_SIZE)
    CANOPY_CL_ERR(CL_INVALID_PROPERTY)
#undef CANOPY_CL_ERR
  default:
    return "unknown OpenCL error";
  }
}

std::string describe_cl_error(const cl::Error& e, const std::string& context) {
  return fmt::format("{} failed with {} ({}){}{}", e.what(), cl_error_name(e.err()), e.err(),
                     context.empty() ? "" : ": ", context);
}

static void configure_pocl() {
  // PoCL specialises each kernel's work-group function for the grid size by default; the wavefront
  // launches kernels over queues whose length changes every time, so a render compiled thousands
  // of variants (measured: 3198 for an 8 spp Cornell box, 318 s instead of 4.9 s, and no faster
  // once cached). Generic work-group functions are compiled once per kernel. A value the user set
  // is kept.
  setenv("POCL_WORK_GROUP_SPECIALIZATION", "0", 0);
  // PoCL's worker threads, one per core, are pinned to their cores (POCL_AFFINITY: worker i to
  // CPU i). Unpinned, the scheduler keeps them on one core for the process's first 0.2-0.5 s of
  // kernels (a render of 1 sample on a third of default.json's rows took 23-56 ms there, 19-25 ms
  // after, and a contended atomic kernel ran faster: one thread did the work), so the estimator
  // choice timed the candidate it explored first up to 2x too slow. Only where the process may
  // run on every online CPU, so that CPU i exists for it; a value the user set is kept.
  cpu_set_t allowed;
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  if (online > 0 && sched_getaffinity(0, sizeof(allowed), &allowed) == 0 &&
      CPU_COUNT(&allowed) == online) {
    bool first_cpus = true;
    for (long i = 0; i < online && i < CPU_SETSIZE; ++i)
      first_cpus = first_cpus && CPU_ISSET(int(i), &allowed);
    if (first_cpus) setenv("POCL_AFFINITY", "1", 0);
  }
}

std::vector<DeviceInfo> list_devices() {
  configure_pocl();
  std::vector<DeviceInfo> out;
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error&) {
    return out; // CL_PLATFORM_NOT_FOUND_KHR: no ICD
  }
  for (size_t p = 0; p < platforms.size(); ++p) {
    std::vector<cl::Device> devices;
    try {
      platforms[p].getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;
    }
    for (size_t d = 0; d < devices.size(); ++d) {
      DeviceInfo info;
      info.platform_index = int(p);
      info.device_index = int(d);
      info.platform_name = platforms[p].getInfo<CL_PLATFORM_NAME>();
      info.device_name = devices[d].getInfo<CL_DEVICE_NAME>();
      info.version = devices[d].getInfo<CL_DEVICE_VERSION>();
      info.type = devices[d].getInfo<CL_DEVICE_TYPE>();
      info.compute_units = devices[d].getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
      info.global_mem = devices[d].getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
      out.push_back(info);
    }
  }
  return out;
}

std::filesystem::path kernel_dir() {
  namespace fs = std::filesystem;
  if (const char* env = std::getenv("CANOPY_KERNEL_DIR")) {
    if (fs::exists(fs::path(env) / "types.h")) return env;
    throw ClError(fmt::format("CANOPY_KERNEL_DIR={}: no kernel sources there", env));
  }
  fs::path installed = executable_dir() / ".." / "share" / "canopy" / "cl";
  if (fs::exists(installed / "types.h")) return fs::canonical(installed);
  if (fs::exists(fs::path(CANOPY_INSTALL_CL_DIR) / "types.h")) return CANOPY_INSTALL_CL_DIR;
  if (fs::exists(fs::path(CANOPY_SOURCE_CL_DIR) / "types.h")) return CANOPY_SOURCE_CL_DIR;
  throw ClError("cannot find the kernel sources (set CANOPY_KERNEL_DIR to the cl/ directory)");
}

ClRuntime::ClRuntime(const std::string& device_name) {
  std::vector<DeviceInfo> devices = list_devices();
  if (devices.empty())
    throw ClError(
        "no OpenCL device found (is pocl-opencl-icd installed? run scripts/install-deps.sh)");
  const DeviceInfo* chosen = nullptr;
  if (!device_name.empty()) {
    std::string want = lower(device_name);
    for (const auto& d : devices)
      if (lower(d.device_name).find(want) != std::string::npos ||
          lower(d.platform_name).find(want) != std::string::npos) {
        chosen = &d;
        break;
      }
    if (!chosen)
      throw ClError(fmt::format("no OpenCL device matches '{}' (see `canopy info`)", device_name));
  } else {
    for (const auto& d : devices)
      if ((d.type & CL_DEVICE_TYPE_CPU) &&
          lower(d.platform_name).find("portable") != std::string::npos) {
        chosen = &d;
        break;
      }
    if (!chosen)
      for (const auto& d : devices)
        if (d.type & CL_DEVICE_TYPE_CPU) {
          chosen = &d;
          break;
        }
    if (!chosen) chosen = &devices.front();
  }
  std::vector<cl::Platform> platforms;
  cl::Platform::get(&platforms);
  std::vector<cl::Device> devs;
  platforms[chosen->platform_index].getDevices(CL_DEVICE_TYPE_ALL, &devs);
  device_ = devs[chosen->device_index];
  context_ = cl::Context(device_);
  queue_ = cl::CommandQueue(context_, device_, CL_QUEUE_PROFILING_ENABLE);
}

std::string ClRuntime::device_name() const {
  return device_.getInfo<CL_DEVICE_NAME>();
}

std::string ClRuntime::device_signature() const {
  cl::Platform platform(device_.getInfo<CL_DEVICE_PLATFORM>());
  return fmt::format("device {}\ndevice version {}\ndriver {}\nplatform {}\n",
                     device_.getInfo<CL_DEVICE_NAME>(), device_.getInfo<CL_DEVICE_VERSION>(),
                     device_.getInfo<CL_DRIVER_VERSION>(), platform.getInfo<CL_PLATFORM_VERSION>());
}

std::string ClRuntime::build_options(const std::string& options) const {
  // No "-I": the sources come with their headers expanded (host/cl/kernel_source.h), so neither
  // the options nor the text name this checkout's path.
  std::string opts = fmt::format("-cl-std=CL1.2 -cl-kernel-arg-info {}", options);
  // The tests build kernels with -Werror (a warning in a kernel is a defect like one in the host
  // code); users' builds stay tolerant of whatever a newer PoCL clang may warn about.
  if (const char* w = std::getenv("CANOPY_KERNEL_WERROR"); w && *w && std::string(w) != "0")
    opts += " -Werror";
  return opts;
}

cl::Program ClRuntime::build_from_source(const std::string& source, const std::string& opts) const {
  cl::Program program(context_, source);
  try {
    program.build({device_}, opts.c_str());
  } catch (const cl::Error&) {
    std::string log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
    throw ClError(fmt::format("OpenCL program build failed (options: {}):\n{}", opts, log));
  }
  return program;
}

cl::Program ClRuntime::build_program(const std::vector<std::string>& files,
                                     const std::string& options, bool* from_cache) const {
  std::filesystem::path dir = kernel_dir();
  const std::string source = read_kernel_sources(dir, files);
  const std::string opts = build_options(options);
  if (from_cache) *from_cache = false;
  const std::filesystem::path cache_dir = program_cache_dir();
  if (cache_dir.empty()) return build_from_source(source, opts);

  // The source holds every header it includes: its text, the options and the device are the key.
  Digest text;
  text.add(source);
  const std::string key =
      fmt::format("{}options {}\nsource {}\n", device_signature(), opts, text.hex());
  const ProgramCache cache(cache_dir);
  if (std::optional<std::vector<unsigned char>> binary = cache.load(key)) {
    try {
      cl::Program program(context_, {device_}, cl::Program::Binaries{*binary});
      program.build({device_}, opts.c_str());
      if (from_cache) *from_cache = true;
      return program;
    } catch (const cl::Error&) { // an entry the driver refuses: rebuilt and replaced below
    }
  }
  cl::Program program = build_from_source(source, opts);
  // Asking for the binary makes PoCL compile every kernel's work-group function now.
  std::vector<std::vector<unsigned char>> binaries = program.getInfo<CL_PROGRAM_BINARIES>();
  if (binaries.size() == 1) cache.store(key, binaries[0]);
  return program;
}

cl::Program ClRuntime::build_program_source(const std::string& source,
                                            const std::string& options) const {
  return build_from_source(expand_kernel_includes(source, "source", kernel_dir()),
                           build_options(options));
}

cl::Event enqueue_1d(cl::CommandQueue& q, const cl::Kernel& k, size_t n, size_t local) {
  cl::Event ev;
  if (n == 0) return ev;
  size_t global = local > 0 ? (n + local - 1) / local * local : n;
  try {
    if (local > 0)
      q.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(global), cl::NDRange(local), nullptr,
                             &ev);
    else
      q.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n), cl::NullRange, nullptr, &ev);
  } catch (const cl::Error& e) {
    std::string name("?");
    try {
      name = k.getInfo<CL_KERNEL_FUNCTION_NAME>();
    } catch (const cl::Error&) { // keep "?": the error being reported matters more
    }
    throw ClError(describe_cl_error(
        e, fmt::format("kernel {} over {} work items (local size {})", name, global, local)));
  }
  return ev;
}

double event_seconds(const cl::Event& e) {
  if (e() == nullptr) return 0.0;
  cl_ulong start = e.getProfilingInfo<CL_PROFILING_COMMAND_START>();
  cl_ulong end = e.getProfilingInfo<CL_PROFILING_COMMAND_END>();
  return double(end - start) * 1e-9;
}

} // namespace canopy
