// A small log-log line plot written as PNG through OpenImageIO (ImageBufAlgo::render_line /
// render_box / render_text), drawn in the OpenImageIO module (oiio/module.h). Text needs a
// TrueType font: OpenImageIO searches the system font directories for `font` (Debian:
// fonts-dejavu-core, pulled in by OpenImageIO); without one the plot is still drawn, only without
// labels, and `write_plot_png` returns false.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace canopy {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y; // points in drawing order; non-positive values are skipped (log axes)
};

struct PlotOptions {
  std::string title, xlabel, ylabel;
  int width = 960, height = 640; // output pixels
  std::string font = "DejaVuSans";
};

// Writes the plot (through the module). Returns true when the text was drawn too. Throws
// std::runtime_error naming the file when it cannot be written.
bool write_plot_png(const std::filesystem::path& file, const std::vector<PlotSeries>& series,
                    const PlotOptions& options);
// The drawing itself, in the module: as write_plot_png.
bool draw_plot_png(const std::filesystem::path& file, const std::vector<PlotSeries>& series,
                   const PlotOptions& options);

// Tick values for a log axis over [lo, hi]: decades, plus 2 and 5 when the range is short.
std::vector<double> log_ticks(double lo, double hi);
// "0.01", "1", "300", "1e-05", "2e+06": short labels for tick values.
std::string tick_label(double v);

} // namespace canopy
