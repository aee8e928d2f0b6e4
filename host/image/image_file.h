// Reading and writing image files. EXR (OpenEXR) and PNG (libpng) are read and written here;
// every other format is read through OpenImageIO, which lives in a module loaded on first use
// (oiio/module.h): with Debian's plugins it pulls in about 260 shared libraries, whose relocation
// costs each process about 0.25 s before main(), and most runs never need it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace canopy {

// Where an image's pixels sit in a larger one: EXR's data window (origin x, y) inside its display
// window (full_width x full_height from 0, 0).
struct ImageWindow {
  int x = 0, y = 0, full_width = 0, full_height = 0;
};

using ImageAttributes = std::vector<std::pair<std::string, std::string>>;

// An image file's pixels as float, row-major, top row first, `channels` interleaved (an EXR's R, G,
// B and A first, in that order): floating-point samples as stored, integer samples divided by
// their maximum (so in [0, 1]).
struct DecodedImage {
  int width = 0, height = 0, channels = 0;
  ImageWindow window;         // the data window in the display window (EXR); else 0, 0, w, h
  bool floating = false;      // samples stored as floating point (linear by convention)
  std::vector<float> pixels;  // width * height * channels
  ImageAttributes attributes; // the file's string attributes (EXR header)
};

// Thrown with the reason alone (the caller names the file and what it was for).
struct ImageFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// An image of more pixels than the reader was allowed, found from its header (before decoding).
struct ImageTooLarge : ImageFileError {
  int width, height;
  ImageTooLarge(int w, int h) : ImageFileError("too many pixels"), width(w), height(h) {}
};

// Reads an image file of any format (by its signature: EXR, PNG, else OpenImageIO's readers).
// Throws ImageTooLarge for more than `max_pixels` pixels, else ImageFileError.
DecodedImage read_image_file(const std::filesystem::path& file, uint64_t max_pixels = uint64_t(1)
                                                                                      << 31);

// Writes `channels`-interleaved float pixels as a ZIP-compressed float EXR with string attributes,
// the pixels placed at `window` in its display window. Throws ImageFileError.
void write_exr_file(const std::filesystem::path& file, int width, int height, const float* rgb,
                    const ImageAttributes& attributes, const ImageWindow& window);
// Writes 8-bit RGB pixels as a PNG tagged sRGB. Throws ImageFileError.
void write_png_file(const std::filesystem::path& file, int width, int height,
                    const unsigned char* rgb);

// The format readers (exr_file.cpp, png_file.cpp): `bytes` the file's first bytes, to tell them.
bool has_exr_signature(const std::string& bytes);
bool has_png_signature(const std::string& bytes);
DecodedImage read_exr_file(const std::filesystem::path& file, uint64_t max_pixels);
DecodedImage read_png_file(const std::filesystem::path& file, uint64_t max_pixels);

} // namespace canopy
