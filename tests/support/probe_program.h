// A probe kernel for a device-against-host test: OpenCL C source that includes the shared headers
// of cl/, built with -Werror and the given feature options. A build error fails the test with the
// compiler's log (the returned program is then unbuilt: check HasFailure()).
#pragma once

#include "cl/kernel_source.h"
#include "cl/runtime.h"

#include <gtest/gtest.h>

#include <string>

namespace canopy::test {

inline cl::Program build_probe_program(ClRuntime& rt, const char* source,
                                       const std::string& options) {
  cl::Program program(rt.context(), expand_kernel_includes(source, "probe", kernel_dir()));
  std::string opts = "-cl-std=CL1.2 -Werror " + options;
  try {
    program.build({rt.device()}, opts.c_str());
  } catch (const cl::Error&) {
    ADD_FAILURE() << program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(rt.device());
  }
  return program;
}

} // namespace canopy::test
