// Guards on everything the loader takes from outside: user strings echoed in messages, files
// opened by name, and the coordinates the float pipeline must represent (docs/limits.md).
#include "scene/loader_internal.h"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace canopy {

std::string printable(std::string_view s, size_t max_chars) {
  std::string out;
  out.reserve(std::min(s.size(), max_chars) + 8);
  size_t chars = 0;
  const auto* p = reinterpret_cast<const unsigned char*>(s.data());
  const size_t n = s.size();
  for (size_t i = 0; i < n;) {
    if (chars == max_chars) {
      out += "\u2026"; // …
      break;
    }
    ++chars;
    unsigned char c = p[i];
    if (c < 0x80) {
      if (c == '\n')
        out += "\\n";
      else if (c == '\r')
        out += "\\r";
      else if (c == '\t')
        out += "\\t";
      else if (c < 0x20 || c == 0x7f)
        out += fmt::format("\\x{:02x}", c);
      else
        out += char(c);
      ++i;
      continue;
    }
    // A well-formed UTF-8 sequence (no overlongs, no surrogates, <= U+10FFFF) is kept unless it is
    // a C1 control or a line/paragraph separator, which terminals may treat as a line break.
    int len = c >= 0xf0 ? 4 : c >= 0xe0 ? 3 : c >= 0xc0 ? 2 : 0;
    uint32_t cp = len == 4 ? c & 0x07u : len == 3 ? c & 0x0fu : c & 0x1fu;
    bool ok = len > 0 && i + size_t(len) <= n;
    for (int k = 1; ok && k < len; ++k) {
      if ((p[i + size_t(k)] & 0xc0) != 0x80) ok = false;
      cp = (cp << 6) | (p[i + size_t(k)] & 0x3fu);
    }
    if (ok) {
      const uint32_t min_cp[5] = {0, 0, 0x80, 0x800, 0x10000};
      ok = cp >= min_cp[len] && cp <= 0x10ffff && !(cp >= 0xd800 && cp <= 0xdfff);
    }
    if (!ok) {
      out += fmt::format("\\x{:02x}", c);
      ++i;
      continue;
    }
    if ((cp >= 0x80 && cp <= 0x9f) || cp == 0x2028 || cp == 0x2029)
      out += fmt::format("\\u{:04x}", cp);
    else
      out.append(s.substr(i, size_t(len)));
    i += size_t(len);
  }
  return out;
}

namespace detail {

namespace {

const char* file_kind(mode_t m) {
  if (S_ISDIR(m)) return "a directory";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISSOCK(m)) return "a socket";
  return "not a regular file";
}

std::string size_text(uint64_t bytes) {
  if (bytes >= (uint64_t(1) << 30) && bytes % (uint64_t(1) << 30) == 0)
    return fmt::format("{} GiB", bytes >> 30);
  return fmt::format("{} MiB", bytes >> 20);
}

} // namespace

std::string read_input_file(const std::filesystem::path& file, uint64_t max_bytes,
                            const std::string& prefix) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer; the type is checked on the open
  // descriptor (fstat), so what is checked is what is read.
  int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    int e = errno;
    if (e == ENOENT) throw SceneError(fmt::format("{}cannot open file", prefix));
    throw SceneError(fmt::format("{}cannot open file ({})", prefix, std::strerror(e)));
  }
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0)
    throw SceneError(fmt::format("{}cannot read file ({})", prefix, std::strerror(errno)));
  if (!S_ISREG(st.st_mode))
    throw SceneError(fmt::format("{}cannot open file (it is {}, not a regular file)", prefix,
                                 file_kind(st.st_mode)));
  if (uint64_t(st.st_size) > max_bytes)
    throw SceneError(fmt::format("{}file is too large ({} bytes, the limit is {})", prefix,
                                 uint64_t(st.st_size), size_text(max_bytes)));
  // Back to blocking reads for a regular file (O_NONBLOCK has no effect on them anyway).
  std::string text;
  text.resize(size_t(st.st_size));
  size_t got = 0;
  while (got < text.size()) {
    ssize_t r = ::read(fd, text.data() + got, text.size() - got);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0)
      throw SceneError(fmt::format("{}cannot read file ({})", prefix, std::strerror(errno)));
    if (r == 0) break; // shrank while reading: take what is there
    got += size_t(r);
  }
  text.resize(got);
  return text;
}

std::string check_coordinate(float3 p, double3 origin) {
  const float c[3] = {p.x, p.y, p.z};
  for (float x : c)
    if (!(std::fabs(x) <= kMaxCoordinate)) {
      // The user knows the world position, not the rebased one: quote that, at float precision.
      float3 w = to_float3(dvec(p) + origin);
      return fmt::format("[{}, {}, {}] is outside the supported coordinate range |x| <= {:g} "
                         "(docs/limits.md)",
                         w.x, w.y, w.z, double(kMaxCoordinate));
    }
  return {};
}

std::string check_light_extent(const Light& l, double3 origin) {
  float3 p = xyz_of(l.p);
  std::string e;
  switch (l.type) {
  case LIGHT_SPHERE: {
    float r = l.p.w;
    for (float3 q : {p + make_float3(r, r, r), p - make_float3(r, r, r)})
      if (!(e = check_coordinate(q, origin)).empty()) return "its bounds " + e;
    return {};
  }
  case LIGHT_DISK: {
    float r = l.p.w;
    for (float3 q : {p + make_float3(r, r, r), p - make_float3(r, r, r)})
      if (!(e = check_coordinate(q, origin)).empty()) return "its bounds " + e;
    return {};
  }
  case LIGHT_QUAD:
  case LIGHT_TRIANGLE: {
    float3 e1 = xyz_of(l.e1), e2 = xyz_of(l.e2);
    float3 corners[4] = {p, p + e1, p + e2, p + e1 + e2};
    int nc = l.type == LIGHT_QUAD ? 4 : 3;
    for (int i = 0; i < nc; ++i)
      if (!(e = check_coordinate(corners[i], origin)).empty()) return "a corner " + e;
    return {};
  }
  default:
    if (!(e = check_coordinate(p, origin)).empty()) return "its position " + e;
    return {};
  }
}

} // namespace detail
} // namespace canopy
