// Keeps an image library's own messages off the terminal while an image is read, so that a bad
// image file gives Canopy's one-line error and nothing else.
//
// Why a redirect: libpng's default error handler prints "libpng error: <reason>" with
// fprintf(stderr) before it gives up on a file. OpenImageIO's PNG reader (2.4) installs an error
// handler that records the reason and returns, and libpng then falls through to that default, so
// the line is printed whatever the caller does; neither library has a switch for it. What the
// library writes is captured instead and becomes part of Canopy's message.
#pragma once

#include <cstdio>
#include <string>

namespace canopy {

// While alive, whatever the process writes to its standard error (file descriptor 2) goes to a
// temporary file. The redirect is process-wide: use it only where no other thread prints (the
// renderer reads its images before any progress output). If the redirect cannot be set up,
// standard error is left as it is.
class StderrCapture {
public:
  StderrCapture();
  ~StderrCapture();
  StderrCapture(const StderrCapture&) = delete;
  StderrCapture& operator=(const StderrCapture&) = delete;

  // Ends the capture (standard error is restored) and returns what was written as one line:
  // its lines, trimmed, joined by "; " (at most the first 1000 bytes). Later calls return "".
  std::string finish();

private:
  int saved_ = -1;            // the original standard error while capturing
  std::FILE* file_ = nullptr; // the temporary file it goes to
};

} // namespace canopy
