#include "cl/program_cache.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <system_error>
#include <unistd.h>

namespace canopy {

namespace {

namespace fs = std::filesystem;

constexpr char kMagic[8] = {'C', 'A', 'N', 'O', 'P', 'Y', 'P', 'B'};
constexpr uint32_t kFormat = 1;

uint64_t finalize(uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

template <class T> void put(std::string& out, T v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(v));
}

template <class T> bool get(std::string_view& in, T* v) {
  if (in.size() < sizeof(T)) return false;
  std::memcpy(v, in.data(), sizeof(T));
  in.remove_prefix(sizeof(T));
  return true;
}

uint64_t payload_digest(std::string_view bytes) {
  Digest d;
  d.add(bytes);
  return std::stoull(d.hex().substr(0, 16), nullptr, 16);
}

} // namespace

void Digest::add(std::string_view bytes) {
  for (unsigned char c : bytes) {
    a_ = (a_ ^ c) * 0x100000001b3ull;
    b_ = ((b_ << 5) | (b_ >> 59)) ^ c;
    b_ *= 0x9e3779b97f4a7c15ull;
  }
  // The length too: "ab" + "c" and "a" + "bc" differ.
  const uint64_t n = bytes.size();
  a_ = (a_ ^ n) * 0x100000001b3ull;
  b_ = (b_ ^ n) * 0x9e3779b97f4a7c15ull;
}

std::string Digest::hex() const {
  return fmt::format("{:016x}{:016x}", finalize(a_), finalize(b_ ^ a_));
}

fs::path program_cache_dir() {
  if (const char* dir = std::getenv("CANOPY_CACHE_DIR")) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return fs::path(xdg) / "canopy";
  if (const char* home = std::getenv("HOME"); home && *home)
    return fs::path(home) / ".cache" / "canopy";
  return {};
}

fs::path ProgramCache::entry_path(const std::string& key) const {
  Digest d;
  d.add(key);
  return dir_ / (d.hex() + ".bin");
}

std::optional<std::vector<unsigned char>> ProgramCache::load(const std::string& key) const {
  std::error_code ec;
  const fs::path path = entry_path(key);
  if (!fs::is_regular_file(path, ec)) return std::nullopt;
  const std::string file = read_all(path);
  std::string_view in(file);
  if (in.size() < sizeof(kMagic) || std::memcmp(in.data(), kMagic, sizeof(kMagic)) != 0)
    return std::nullopt;
  in.remove_prefix(sizeof(kMagic));
  uint32_t format = 0;
  uint64_t key_size = 0, size = 0, digest = 0;
  if (!get(in, &format) || format != kFormat || !get(in, &key_size) || key_size > in.size())
    return std::nullopt;
  if (in.substr(0, key_size) != key) return std::nullopt;
  in.remove_prefix(key_size);
  if (!get(in, &size) || !get(in, &digest) || size != in.size() || size == 0) return std::nullopt;
  if (payload_digest(in) != digest) return std::nullopt;
  // Its use, for prune(): the modification time is the last use.
  fs::last_write_time(path, fs::file_time_type::clock::now(), ec);
  return std::vector<unsigned char>(in.begin(), in.end());
}

bool ProgramCache::store(const std::string& key, const std::vector<unsigned char>& binary) const {
  if (binary.empty()) return false;
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec) return false;
  const std::string_view payload(reinterpret_cast<const char*>(binary.data()), binary.size());
  std::string out(kMagic, sizeof(kMagic));
  put(out, kFormat);
  put(out, uint64_t(key.size()));
  out += key;
  put(out, uint64_t(payload.size()));
  put(out, payload_digest(payload));
  out += payload;
  const fs::path path = entry_path(key);
  const fs::path tmp =
      fs::path(path.string() + fmt::format(".{}.{}.tmp", getpid(), std::random_device{}()));
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f.write(out.data(), std::streamsize(out.size()));
    if (!f.flush()) {
      fs::remove(tmp, ec);
      return false;
    }
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    return false;
  }
  prune();
  return true;
}

void ProgramCache::prune() const {
  std::error_code ec;
  std::vector<std::pair<fs::file_time_type, fs::path>> entries;
  for (auto it = fs::directory_iterator(dir_, ec); !ec && it != fs::end(it); it.increment(ec))
    if (it->path().extension() == ".bin") entries.emplace_back(it->last_write_time(ec), it->path());
  if (entries.size() <= max_entries) return;
  std::sort(entries.begin(), entries.end(), std::greater<>());
  for (size_t i = max_entries; i < entries.size(); ++i)
    fs::remove(entries[i].second, ec);
}

} // namespace canopy
