// The parts of Canopy that need OpenImageIO, built as a module (libcanopy_oiio.so) that a process
// loads on first use: reading the image formats that image/image_file.h does not read itself
// (JPEG, TGA, HDR, PFM, TIFF, ...) and drawing plots. OpenImageIO with Debian's plugins pulls in
// about 260 shared libraries; linked into `canopy` their relocation cost every process about
// 0.25 s before main(), though a render of a scene without such textures never uses them.
// The module's functions report errors through their results, not exceptions.
#pragma once

#include "image/image_file.h"
#include "oiio/plot.h"

#include <string>
#include <vector>

namespace canopy {

struct OiioModule {
  // As read_image_file: 0 read; 2 more than max_pixels pixels (out's width and height set);
  // 1 an error, the reason in *error.
  int (*read_image)(const char* file, uint64_t max_pixels, DecodedImage* out, std::string* error);
  // draw_plot_png: 1 drawn with its text, 0 without (no font), -1 an error in *error.
  int (*write_plot)(const char* file, const std::vector<PlotSeries>& series,
                    const PlotOptions& options, std::string* error);
};

// The loaded module (loaded by the first call; thread-safe). Looked for at $CANOPY_OIIO_MODULE,
// beside the executable, in the build tree and in the install prefix. Throws ImageFileError saying
// why if it cannot be loaded.
const OiioModule& oiio_module();

} // namespace canopy

// The module's one exported symbol.
extern "C" const canopy::OiioModule* canopy_oiio_module();
