#include "image/stderr_capture.h"

#include <unistd.h>

namespace canopy {

StderrCapture::StderrCapture() {
  std::fflush(stderr);
  file_ = std::tmpfile();
  if (!file_) return;
  saved_ = dup(STDERR_FILENO);
  if (saved_ < 0 || dup2(fileno(file_), STDERR_FILENO) < 0) {
    if (saved_ >= 0) close(saved_);
    saved_ = -1;
    std::fclose(file_);
    file_ = nullptr;
  }
}

StderrCapture::~StderrCapture() {
  finish();
}

std::string StderrCapture::finish() {
  if (!file_) return {};
  std::fflush(stderr);
  dup2(saved_, STDERR_FILENO);
  close(saved_);
  saved_ = -1;
  char buf[1000];
  std::rewind(file_);
  size_t n = std::fread(buf, 1, sizeof(buf), file_);
  std::fclose(file_);
  file_ = nullptr;
  std::string out, line;
  auto flush_line = [&] {
    size_t b = line.find_first_not_of(" \t\r");
    size_t e = line.find_last_not_of(" \t\r");
    if (b != std::string::npos) {
      if (!out.empty()) out += "; ";
      out += line.substr(b, e - b + 1);
    }
    line.clear();
  };
  for (size_t i = 0; i < n; ++i) {
    if (buf[i] == '\n')
      flush_line();
    else
      line.push_back(buf[i]);
  }
  flush_line();
  return out;
}

} // namespace canopy
