#include "image/image_file.h"

#include "oiio/module.h"

#include <fmt/format.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>

namespace canopy {

DecodedImage read_image_file(const std::filesystem::path& file, uint64_t max_pixels) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ImageFileError(errno ? std::strerror(errno) : "cannot open");
  std::string head(8, '\0');
  in.read(head.data(), std::streamsize(head.size()));
  head.resize(size_t(in.gcount()));
  in.close();
  if (has_exr_signature(head)) return read_exr_file(file, max_pixels);
  if (has_png_signature(head)) return read_png_file(file, max_pixels);
  // A file named for a format read here that does not have its signature is not that format.
  std::string ext = file.extension().string();
  for (char& c : ext)
    c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".exr" || ext == ".png")
    throw ImageFileError(fmt::format("not a {} file", ext == ".exr" ? "EXR" : "PNG"));
  DecodedImage img;
  std::string error;
  const int r = oiio_module().read_image(file.c_str(), max_pixels, &img, &error);
  if (r == 2) throw ImageTooLarge(img.width, img.height);
  if (r != 0) throw ImageFileError(error.empty() ? "unknown format" : error);
  return img;
}

} // namespace canopy
