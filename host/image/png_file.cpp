// PNG files through libpng: 8-bit sRGB RGB out; any PNG in (grey, grey + alpha, palette, RGB,
// RGBA; 1 to 16 bits), as float in [0, 1]. libpng reports errors through a callback that must not
// return; it longjmps back here with the reason kept, and nothing is printed.
#include "image/image_file.h"

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>

namespace canopy {

namespace {

// What libpng said: the error handler stores it and longjmps to the caller's setjmp.
struct PngErrors {
  char message[256] = "";
};

extern "C" void png_error_handler(png_structp png, png_const_charp msg) {
  auto* e = static_cast<PngErrors*>(png_get_error_ptr(png));
  std::snprintf(e->message, sizeof(e->message), "%s", msg ? msg : "unknown error");
  png_longjmp(png, 1);
}
extern "C" void png_warning_handler(png_structp, png_const_charp) {}

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f) std::fclose(f);
  }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

File open_file(const std::filesystem::path& file, const char* mode) {
  File f(std::fopen(file.c_str(), mode));
  if (!f) throw ImageFileError(std::strerror(errno));
  return f;
}

// The decoding between setjmp and a possible longjmp: only trivially destructible locals here
// (a longjmp skips destructors); the pixel buffers are the caller's.
// Returns 0 on success, 1 on a libpng error, 2 for more than max_pixels pixels (img has the size).
int decode_png(std::FILE* f, uint64_t max_pixels, PngErrors* errors, DecodedImage* img,
               std::vector<png_byte>* raw, std::vector<png_bytep>* rows) {
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, errors, png_error_handler, png_warning_handler);
  if (!png) return 1;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
    return 1;
  }
  png_init_io(png, f);
  png_read_info(png, info);
  // Palette to RGB, grey below 8 bits to 8, tRNS to alpha; 16-bit samples in host byte order.
  png_set_expand(png);
  if (png_get_bit_depth(png, info) == 16) png_set_swap(png);
  png_read_update_info(png, info);
  const png_uint_32 w = png_get_image_width(png, info), h = png_get_image_height(png, info);
  const int depth = png_get_bit_depth(png, info), channels = png_get_channels(png, info);
  const size_t row_bytes = png_get_rowbytes(png, info);
  img->width = int(w);
  img->height = int(h);
  img->channels = channels;
  img->floating = false;
  if (uint64_t(w) * uint64_t(h) > max_pixels) {
    png_destroy_read_struct(&png, &info, nullptr);
    return 2;
  }
  raw->resize(row_bytes * size_t(h));
  rows->resize(size_t(h));
  for (png_uint_32 y = 0; y < h; ++y)
    (*rows)[y] = raw->data() + size_t(y) * row_bytes;
  png_read_image(png, rows->data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  img->pixels.resize(size_t(w) * size_t(h) * size_t(channels));
  const size_t n = img->pixels.size();
  // Times the reciprocal, as OpenImageIO converts (a texture reads as it did through it).
  if (depth == 16) {
    const auto* s = reinterpret_cast<const uint16_t*>(raw->data());
    for (size_t i = 0; i < n; ++i)
      img->pixels[i] = float(s[i]) * (1.0f / 65535.0f);
  } else {
    for (size_t i = 0; i < n; ++i)
      img->pixels[i] = float((*raw)[i]) * (1.0f / 255.0f);
  }
  return 0;
}

} // namespace

bool has_png_signature(const std::string& bytes) {
  return bytes.size() >= 8 &&
         png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) == 0;
}

DecodedImage read_png_file(const std::filesystem::path& file, uint64_t max_pixels) {
  File f = open_file(file, "rb");
  PngErrors errors;
  DecodedImage img;
  std::vector<png_byte> raw;
  std::vector<png_bytep> rows;
  const int result = decode_png(f.get(), max_pixels, &errors, &img, &raw, &rows);
  if (result == 2) throw ImageTooLarge(img.width, img.height);
  if (result != 0) throw ImageFileError(errors.message[0] ? errors.message : "cannot decode");
  img.window = {0, 0, img.width, img.height};
  return img;
}

void write_png_file(const std::filesystem::path& file, int width, int height,
                    const unsigned char* rgb) {
  File f = open_file(file, "wb");
  PngErrors errors;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &errors, png_error_handler,
                                            png_warning_handler);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, info ? &info : nullptr);
    throw ImageFileError(errors.message[0] ? errors.message : "cannot encode");
  }
  png_init_io(png, f.get());
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y)
    png_write_row(png, rgb + size_t(y) * size_t(width) * 3);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fflush(f.get()) != 0) throw ImageFileError(std::strerror(errno));
}

} // namespace canopy
