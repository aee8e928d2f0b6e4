// The OpenImageIO module's entry: image reading for the formats image/image_file.h leaves to
// OpenImageIO, and plots (plot.cpp). Errors come back as results: the module throws nothing.
#include "oiio/module.h"

#include <OpenImageIO/imageio.h>

#include <exception>

namespace canopy {

namespace {

std::string first_line(const std::string& s) {
  return s.substr(0, s.find('\n'));
}

int read_image(const char* file, uint64_t max_pixels, DecodedImage* out, std::string* error) {
  try {
    // Colour as stored, not multiplied by alpha (as the PNG reader, and pbrt-v4, read it).
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(file, &config);
    if (!in) {
      *error = first_line(OIIO::geterror());
      return 1;
    }
    const OIIO::ImageSpec& spec = in->spec();
    out->width = spec.width;
    out->height = spec.height;
    out->channels = spec.nchannels;
    if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1) {
      *error = "no pixels";
      return 1;
    }
    if (uint64_t(spec.width) * uint64_t(spec.height) > max_pixels) return 2;
    out->window = {spec.x - spec.full_x, spec.y - spec.full_y, spec.full_width, spec.full_height};
    const OIIO::TypeDesc::BASETYPE b = OIIO::TypeDesc::BASETYPE(spec.format.basetype);
    out->floating =
        b == OIIO::TypeDesc::FLOAT || b == OIIO::TypeDesc::HALF || b == OIIO::TypeDesc::DOUBLE;
    out->pixels.resize(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, out->pixels.data())) {
      *error = first_line(in->geterror());
      return 1;
    }
    for (const OIIO::ParamValue& p : spec.extra_attribs)
      out->attributes.emplace_back(p.name().string(), p.get_string());
    return 0;
  } catch (const std::exception& e) {
    *error = first_line(e.what());
    return 1;
  }
}

int write_plot(const char* file, const std::vector<PlotSeries>& series, const PlotOptions& options,
               std::string* error) {
  try {
    return draw_plot_png(file, series, options) ? 1 : 0;
  } catch (const std::exception& e) {
    *error = first_line(e.what());
    return -1;
  }
}

const OiioModule kModule = {read_image, write_plot};

} // namespace

} // namespace canopy

extern "C" __attribute__((visibility("default"))) const canopy::OiioModule* canopy_oiio_module() {
  return &canopy::kModule;
}
