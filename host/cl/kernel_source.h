// Kernel source text made self-contained: every `#include "file"` of a kernel file replaced by the
// file's text, recursively, with `#line` directives naming each file by its path relative to the
// kernel directory (a compiler error still points at the header and line it is in).
//
// Why: the text PoCL compiles then holds no path of this machine. Built with "-I <dir>", the same
// kernels in two checkouts (a clean clone in CI, an installed copy) would differ in their options
// and miss both PoCL's compiled-kernel cache and ours (host/cl/program_cache.h); expanded, they
// hit.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace canopy {

// `text` (the contents of the file `name`, relative to `root`, or of a string source when `name`
// names no file) with its quoted includes expanded. An include is looked up next to the file that
// includes it, then in `root` (the compiler's order for "-I root"). Angle-bracket includes are
// kept as they are. An include the compiler would read as empty is left out: a guarded header
// already expanded where the compiler surely reads it (outside any #if), or a file already being
// expanded (a cycle). Throws ClError naming the including file, its line and the include when a
// file is missing.
std::string expand_kernel_includes(const std::string& text, const std::string& name,
                                   const std::filesystem::path& root);

// The files `names` (relative to `root`) read, expanded and joined as one translation unit.
std::string read_kernel_sources(const std::filesystem::path& root,
                                const std::vector<std::string>& names);

} // namespace canopy
