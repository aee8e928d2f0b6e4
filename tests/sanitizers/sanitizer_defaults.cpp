// Linked into every executable of a CANOPY_SANITIZE=ON build (CMakeLists.txt): default options
// the sanitizer runtimes read at start-up, so `ctest` needs no environment (docs/testing.md).
// ASAN_OPTIONS / LSAN_OPTIONS / UBSAN_OPTIONS in the environment still override them.

// PoCL and the LLVM it embeds keep compiler state (target machines, pass registries, compiled
// kernels) alive until exit and never free it; so does the OpenCL ICD loader. None of it is
// Canopy's memory; a leak with a Canopy frame below these libraries is still suppressed, which is
// why the suppressions name the libraries and nothing else. OpenImageIO 2.4 keeps the error
// message of a failed read (ImageInput::geterror) in per-thread storage it never frees.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libpocl.so\n"
         "leak:libLLVM\n"
         "leak:libclang-cpp\n"
         "leak:libOpenCL.so\n"
         "leak:libOpenImageIO.so\n";
}

// A used suppression is not news: its statistics would be lines on stderr besides the one-line
// error messages the CLI tests check.
extern "C" const char* __lsan_default_options() {
  return "print_suppressions=0";
}

// A UB report with the stack that led to it.
extern "C" const char* __ubsan_default_options() {
  return "print_stacktrace=1";
}
