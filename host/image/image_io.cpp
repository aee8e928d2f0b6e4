#include "image/image_io.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <functional>
#include <stdexcept>
#include <sys/stat.h>
#include <unistd.h>

namespace canopy {

float srgb_decode(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

float srgb_encode(float x) {
  x = std::clamp(x, 0.0f, 1.0f);
  return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

namespace {

mode_t current_umask() {
  mode_t m = ::umask(0);
  ::umask(m);
  return m;
}

// The temporary file being written, for the signal handler: on SIGINT/SIGTERM/SIGHUP during a
// write it is removed (unlink is async-signal-safe) and the signal re-raised with its default
// action, so an interrupted write leaves neither a partial file nor a stray temporary.
char g_temp_path[4096];
volatile sig_atomic_t g_temp_active = 0;

extern "C" void remove_temp_and_reraise(int sig) {
  if (g_temp_active) ::unlink(g_temp_path);
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

class TempFileGuard {
public:
  explicit TempFileGuard(const std::string& path) : path_(path) {
    if (path.size() < sizeof(g_temp_path)) {
      std::memcpy(g_temp_path, path.c_str(), path.size() + 1);
      g_temp_active = 1;
    }
    struct sigaction sa {};
    sa.sa_handler = remove_temp_and_reraise;
    sigemptyset(&sa.sa_mask);
    for (int i = 0; i < 3; ++i)
      ::sigaction(kSignals[i], &sa, &old_[i]);
  }
  ~TempFileGuard() {
    for (int i = 0; i < 3; ++i)
      ::sigaction(kSignals[i], &old_[i], nullptr);
    if (!committed_) ::unlink(path_.c_str());
    g_temp_active = 0;
  }
  void commit() { committed_ = true; }

private:
  static constexpr int kSignals[3] = {SIGINT, SIGTERM, SIGHUP};
  std::string path_;
  struct sigaction old_[3];
  bool committed_ = false;
};

// Writes through a temporary file in the destination directory, then rename(2)s it over `file`:
// a reader (or a second render to the same path) sees the previous image or the new one, never a
// partial file, and an interrupted write leaves the previous file intact.
void write_through_temporary(const std::filesystem::path& file,
                             const std::function<void(const std::filesystem::path&)>& write) {
  std::filesystem::path parent = file.parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  std::string tmpl = (parent.empty() ? std::filesystem::path(".") : parent).string() + "/." +
                     file.filename().string() + ".tmp-XXXXXX" + file.extension().string();
  std::vector<char> name(tmpl.begin(), tmpl.end());
  name.push_back('\0');
  int fd = ::mkstemps(name.data(), int(file.extension().string().size()));
  if (fd < 0)
    throw std::runtime_error(fmt::format("{}: cannot create a temporary file ({})", file.string(),
                                         std::strerror(errno)));
  const std::string tmp(name.data());
  TempFileGuard guard(tmp);
  ::fchmod(fd,
           0644 & ~current_umask()); // mkstemp creates 0600; an image is as readable as any file
  try {
    write(tmp);
  } catch (const ImageFileError& e) {
    ::close(fd);
    throw std::runtime_error(fmt::format("{}: cannot write ({})", file.string(), e.what()));
  }
  // The data reaches the disk before the name points at it.
  ::fsync(fd);
  ::close(fd);
  if (::rename(tmp.c_str(), file.c_str()) != 0)
    throw std::runtime_error(
        fmt::format("{}: cannot write (rename: {})", file.string(), std::strerror(errno)));
  guard.commit();
}

} // namespace

void write_exr(const std::filesystem::path& file, const RgbImage& img,
               const std::vector<std::pair<std::string, std::string>>& metadata,
               const std::optional<ImageWindow>& window) {
  const ImageWindow w = window ? *window : ImageWindow{0, 0, img.width, img.height};
  write_through_temporary(file, [&](const std::filesystem::path& tmp) {
    write_exr_file(tmp, img.width, img.height, img.rgb.data(), metadata, w);
  });
}

void write_png(const std::filesystem::path& file, const RgbImage& img) {
  std::vector<unsigned char> px(img.rgb.size());
  for (size_t i = 0; i < px.size(); ++i)
    px[i] = (unsigned char)std::lround(255.0f * srgb_encode(img.rgb[i]));
  write_through_temporary(file, [&](const std::filesystem::path& tmp) {
    write_png_file(tmp, img.width, img.height, px.data());
  });
}

RgbImage read_image(const std::filesystem::path& file) {
  DecodedImage d;
  try {
    d = read_image_file(file);
  } catch (const ImageFileError& e) {
    throw std::runtime_error(fmt::format("{}: cannot read image ({})", file.string(), e.what()));
  }
  if (d.channels < 3)
    throw std::runtime_error(fmt::format("{}: need at least 3 channels", file.string()));
  RgbImage img;
  img.width = d.width;
  img.height = d.height;
  img.rgb.resize(size_t(d.width) * d.height * 3);
  for (size_t p = 0; p < size_t(d.width) * d.height; ++p)
    for (int c = 0; c < 3; ++c)
      img.rgb[3 * p + c] = d.pixels[p * d.channels + c];
  return img;
}

} // namespace canopy
