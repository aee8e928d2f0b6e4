#include "oiio/plot.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace canopy {

namespace {

using OIIO::ImageBuf;
using OIIO::ImageSpec;
namespace IBA = OIIO::ImageBufAlgo;

// matplotlib's "tab10" palette.
const float kPalette[10][3] = {{0.122f, 0.467f, 0.706f}, {1.000f, 0.498f, 0.055f},
                               {0.173f, 0.627f, 0.173f}, {0.839f, 0.153f, 0.157f},
                               {0.580f, 0.404f, 0.741f}, {0.549f, 0.337f, 0.294f},
                               {0.890f, 0.467f, 0.761f}, {0.498f, 0.498f, 0.498f},
                               {0.737f, 0.741f, 0.133f}, {0.090f, 0.745f, 0.812f}};

constexpr int kSuper = 2; // supersampling: drawn at 2x, then filtered down

struct Axis {
  double lo = 0.0, hi = 1.0; // log10 range
  double map(double v, double p0, double p1) const {
    return p0 + (std::log10(v) - lo) / (hi - lo) * (p1 - p0);
  }
};

Axis make_axis(double vmin, double vmax) {
  Axis a;
  a.lo = std::log10(vmin);
  a.hi = std::log10(vmax);
  if (a.hi - a.lo < 0.3) { // at least 0.3 decades, centred
    double c = 0.5 * (a.lo + a.hi);
    a.lo = c - 0.15;
    a.hi = c + 0.15;
  }
  double pad = 0.05 * (a.hi - a.lo);
  a.lo -= pad;
  a.hi += pad;
  return a;
}

class Canvas {
public:
  Canvas(int w, int h) : buf_(ImageSpec(w * kSuper, h * kSuper, 3, OIIO::TypeDesc::FLOAT)) {
    const float white[3] = {1, 1, 1};
    IBA::fill(buf_, white);
  }
  ImageBuf& buf() { return buf_; }

  void line(double x0, double y0, double x1, double y1, const float* c, double width) {
    double r = 0.5 * width * kSuper;
    int ir = int(std::ceil(r));
    for (int dy = -ir; dy <= ir; ++dy)
      for (int dx = -ir; dx <= ir; ++dx) {
        if (dx * dx + dy * dy > r * r + 0.25) continue;
        IBA::render_line(buf_, int(std::lround(x0 * kSuper)) + dx,
                         int(std::lround(y0 * kSuper)) + dy, int(std::lround(x1 * kSuper)) + dx,
                         int(std::lround(y1 * kSuper)) + dy, OIIO::cspan<float>(c, 3));
      }
  }
  void box(double x0, double y0, double x1, double y1, const float* c, bool fill) {
    IBA::render_box(buf_, int(std::lround(x0 * kSuper)), int(std::lround(y0 * kSuper)),
                    int(std::lround(x1 * kSuper)), int(std::lround(y1 * kSuper)),
                    OIIO::cspan<float>(c, 3), fill);
  }
  // Returns false when the font is not available.
  bool text(double x, double y, const std::string& s, int size, const std::string& font,
            IBA::TextAlignX ax, IBA::TextAlignY ay) {
    if (!fonts_ok_) return false;
    const float black[3] = {0, 0, 0};
    fonts_ok_ = IBA::render_text(buf_, int(std::lround(x * kSuper)), int(std::lround(y * kSuper)),
                                 s, size * kSuper, font, OIIO::cspan<float>(black, 3), ax, ay);
    return fonts_ok_;
  }
  // Text rotated by 90 degrees (reading upwards), centred at (x, y).
  bool vertical_text(double x, double y, const std::string& s, int size, const std::string& font) {
    if (!fonts_ok_) return false;
    OIIO::ROI r = IBA::text_size(s, size * kSuper, font);
    if (!r.defined()) return fonts_ok_ = false;
    int w = r.width() + 4, h = r.height() + 4;
    ImageBuf tmp(ImageSpec(w, h, 3, OIIO::TypeDesc::FLOAT));
    const float white[3] = {1, 1, 1}, black[3] = {0, 0, 0};
    IBA::fill(tmp, white);
    IBA::render_text(tmp, w / 2, h / 2, s, size * kSuper, font, OIIO::cspan<float>(black, 3),
                     IBA::TextAlignX::Center, IBA::TextAlignY::Center);
    ImageBuf rot = IBA::rotate270(tmp); // reads bottom to top
    int px = int(std::lround(x * kSuper)) - rot.spec().width / 2;
    int py = int(std::lround(y * kSuper)) - rot.spec().height / 2;
    IBA::paste(buf_, px, py, 0, 0, rot);
    return true;
  }
  bool fonts_ok() const { return fonts_ok_; }

private:
  ImageBuf buf_;
  bool fonts_ok_ = true;
};

} // namespace

std::vector<double> log_ticks(double lo, double hi) {
  std::vector<double> ticks;
  if (!(lo > 0.0) || !(hi > lo)) return ticks;
  double decades = std::log10(hi / lo);
  std::vector<int> mult = {1};
  if (decades < 1.2)
    mult = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  else if (decades < 3.0)
    mult = {1, 2, 5};
  int step = decades > 8.0 ? 2 : 1;
  for (int e = int(std::floor(std::log10(lo))); e <= int(std::ceil(std::log10(hi))); e += step)
    for (int m : mult) {
      double v = m * std::pow(10.0, e);
      if (v >= lo * (1 - 1e-9) && v <= hi * (1 + 1e-9)) ticks.push_back(v);
    }
  return ticks;
}

std::string tick_label(double v) {
  double e = std::floor(std::log10(v) + 1e-9);
  if (e >= -3 && e <= 4) {
    int decimals = e < 0 ? int(-e) : 0;
    return fmt::format("{:.{}f}", v, decimals);
  }
  double m = v / std::pow(10.0, e);
  if (std::abs(m - 1.0) < 1e-6) return fmt::format("1e{}", int(e));
  return fmt::format("{:.0f}e{}", m, int(e));
}

bool draw_plot_png(const std::filesystem::path& file, const std::vector<PlotSeries>& series,
                   const PlotOptions& o) {
  const int W = o.width, H = o.height;
  const double left = 92, right = 24, top = o.title.empty() ? 20 : 48, bottom = 66;
  const double x0 = left, x1 = W - right, y0 = H - bottom, y1 = top; // plot box (y up)

  double xmin = INFINITY, xmax = 0, ymin = INFINITY, ymax = 0;
  for (const PlotSeries& s : series)
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!(s.x[i] > 0.0) || !(s.y[i] > 0.0) || !std::isfinite(s.x[i]) || !std::isfinite(s.y[i]))
        continue;
      xmin = std::min(xmin, s.x[i]);
      xmax = std::max(xmax, s.x[i]);
      ymin = std::min(ymin, s.y[i]);
      ymax = std::max(ymax, s.y[i]);
    }
  if (!(xmax > 0.0)) xmin = 1, xmax = 10, ymin = 1, ymax = 10; // nothing to draw: empty axes
  Axis ax = make_axis(xmin, xmax), ay = make_axis(ymin, ymax);
  // Leave room at the top right for the legend.
  ay.hi += 0.12 * (ay.hi - ay.lo) * double(series.size() > 4 ? 2 : 1);

  Canvas cv(W, H);
  const float grid[3] = {0.88f, 0.88f, 0.88f}, black[3] = {0, 0, 0};
  const int fs = 15; // font size (output pixels)
  using AX = IBA::TextAlignX;
  using AY = IBA::TextAlignY;

  // Grid and ticks.
  double xlo = std::pow(10.0, ax.lo), xhi = std::pow(10.0, ax.hi);
  double ylo = std::pow(10.0, ay.lo), yhi = std::pow(10.0, ay.hi);
  for (double t : log_ticks(xlo, xhi)) {
    double px = ax.map(t, x0, x1);
    cv.line(px, y0, px, y1, grid, 1.0);
    cv.line(px, y0, px, y0 + 6, black, 1.0);
    cv.text(px, y0 + 10, tick_label(t), fs, o.font, AX::Center, AY::Top);
  }
  for (double t : log_ticks(ylo, yhi)) {
    double py = ay.map(t, y0, y1);
    cv.line(x0, py, x1, py, grid, 1.0);
    cv.line(x0 - 6, py, x0, py, black, 1.0);
    cv.text(x0 - 10, py, tick_label(t), fs, o.font, AX::Right, AY::Center);
  }
  // Frame.
  cv.box(x0, y1, x1, y0, black, false);

  // Series: lines with square markers.
  for (size_t k = 0; k < series.size(); ++k) {
    const PlotSeries& s = series[k];
    const float* c = kPalette[k % 10];
    double px_prev = 0, py_prev = 0;
    bool have_prev = false;
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!(s.x[i] > 0.0) || !(s.y[i] > 0.0) || !std::isfinite(s.x[i]) || !std::isfinite(s.y[i]))
        continue;
      double px = ax.map(s.x[i], x0, x1), py = ay.map(s.y[i], y0, y1);
      if (have_prev) cv.line(px_prev, py_prev, px, py, c, 2.2);
      cv.box(px - 3.5, py - 3.5, px + 3.5, py + 3.5, c, true);
      px_prev = px, py_prev = py, have_prev = true;
    }
  }

  // Legend (top right, inside the frame).
  if (!series.empty()) {
    const double row = 21, lw = 30;
    size_t longest = 0;
    for (const PlotSeries& s : series)
      longest = std::max(longest, s.label.size());
    double bw = lw + 18 + 8.2 * double(longest), bh = row * double(series.size()) + 10;
    double bx1 = x1 - 10, bx0 = bx1 - bw, by0 = y1 + 10;
    const float white[3] = {1, 1, 1}, frame[3] = {0.6f, 0.6f, 0.6f};
    cv.box(bx0, by0, bx1, by0 + bh, white, true);
    cv.box(bx0, by0, bx1, by0 + bh, frame, false);
    for (size_t k = 0; k < series.size(); ++k) {
      double yy = by0 + 5 + row * (double(k) + 0.5);
      const float* c = kPalette[k % 10];
      cv.line(bx0 + 8, yy, bx0 + 8 + lw, yy, c, 2.2);
      cv.box(bx0 + 8 + lw / 2 - 3.5, yy - 3.5, bx0 + 8 + lw / 2 + 3.5, yy + 3.5, c, true);
      cv.text(bx0 + 16 + lw, yy, series[k].label, fs - 1, o.font, AX::Left, AY::Center);
    }
  }

  // Labels.
  if (!o.title.empty()) cv.text(0.5 * (x0 + x1), 14, o.title, fs + 2, o.font, AX::Center, AY::Top);
  if (!o.xlabel.empty())
    cv.text(0.5 * (x0 + x1), H - 10, o.xlabel, fs, o.font, AX::Center, AY::Bottom);
  if (!o.ylabel.empty()) cv.vertical_text(18, 0.5 * (y0 + y1), o.ylabel, fs, o.font);

  ImageBuf out = IBA::resize(cv.buf(), "", 0.0f, OIIO::ROI(0, W, 0, H, 0, 1, 0, 3));
  if (std::filesystem::path parent = file.parent_path(); !parent.empty())
    std::filesystem::create_directories(parent);
  out.set_write_format(OIIO::TypeDesc::UINT8);
  if (!out.write(file.string()))
    throw std::runtime_error(fmt::format("{}: cannot write ({})", file.string(), out.geterror()));
  return cv.fonts_ok();
}

} // namespace canopy
