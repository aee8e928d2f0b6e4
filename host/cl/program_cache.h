// Compiled OpenCL programs kept on disk, so that a process loads the device binary of a program it
// (or the build, tools/precompile_kernels.cpp) compiled before instead of compiling it again.
//
// An entry is one file named by a digest of its key; the file holds the key itself, the binary and
// the binary's digest. The key names everything the binary depends on: the device, its driver
// (PoCL's version), the build options and the text of the kernel sources with every header they
// may include. An entry whose key, length or digest does not match is a miss (the caller rebuilds
// and overwrites it), never an error.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace canopy {

// A 128-bit digest of text as 32 hex digits (two independent 64-bit FNV-1a style hashes): a cache
// key, not a cryptographic hash.
class Digest {
public:
  void add(std::string_view bytes);
  std::string hex() const;

private:
  uint64_t a_ = 0xcbf29ce484222325ull;
  uint64_t b_ = 0x84222325cbf29ce4ull;
};

// The cache directory: $CANOPY_CACHE_DIR (empty: no cache), else $XDG_CACHE_HOME/canopy, else
// $HOME/.cache/canopy. Empty when there is none.
std::filesystem::path program_cache_dir();

class ProgramCache {
public:
  explicit ProgramCache(std::filesystem::path dir) : dir_(std::move(dir)) {}

  // The entry's file for `key`.
  std::filesystem::path entry_path(const std::string& key) const;
  // The binary stored under `key`, or nothing (no entry, or one that is truncated, corrupt or
  // written for another key).
  std::optional<std::vector<unsigned char>> load(const std::string& key) const;
  // Stores `binary` under `key` (written to a temporary file, then renamed: a concurrent reader
  // sees the old entry or the new one), then removes the least recently used entries beyond
  // `max_entries` (each kernel source change leaves entries nothing will load again). Returns
  // false if it could not be written.
  bool store(const std::string& key, const std::vector<unsigned char>& binary) const;

  size_t max_entries = 64; // a few scenes' programs, each 0.3-1 MB

private:
  void prune() const;

  std::filesystem::path dir_;
};

} // namespace canopy
