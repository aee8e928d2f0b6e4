// pbrt-v4's spectrum files: a "spectrum" parameter whose string names no built-in spectrum is a
// file of (wavelength in nm, value) pairs, '#' starting a comment (pbrt-v4 spectrum.cpp
// PiecewiseLinearSpectrum::Read). Canopy renders in RGB: the value at 650 nm, 550 nm and 450 nm,
// linearly interpolated (clamped to the ends), as its metal presets (scene/metal_presets.cpp).
#include "scene/pbrt/reader.h"

#include <fmt/format.h>

#include <fstream>
#include <sstream>

namespace canopy::pbrt {

std::optional<float3> Reader::spectrum_file(const Loc& loc, const std::string& what,
                                            const std::string& name) {
  std::filesystem::path f(name);
  if (f.is_relative()) f = dir_ / f;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(f, ec)) return std::nullopt;
  std::ifstream in(f);
  std::vector<std::pair<double, double>> v; // (nm, value)
  std::string line, text;
  while (std::getline(in, line)) {
    if (size_t c = line.find('#'); c != std::string::npos) line.resize(c);
    text += line + ' ';
  }
  std::istringstream ss(text);
  double l, x;
  while (ss >> l >> x) {
    if (!std::isfinite(l) || !std::isfinite(x) || (!v.empty() && !(l > v.back().first)))
      fail(loc, fmt::format("{}: spectrum file \"{}\": wavelengths must increase and values be "
                            "finite",
                            what, printable(name)));
    v.emplace_back(l, x);
  }
  if (!ss.eof() || v.size() < 2)
    fail(loc, fmt::format("{}: spectrum file \"{}\": not (wavelength, value) pairs", what,
                          printable(name)));
  auto at = [&](double nm) {
    if (nm <= v.front().first) return v.front().second;
    if (nm >= v.back().first) return v.back().second;
    size_t i = 1;
    while (v[i].first < nm)
      ++i;
    double t = (nm - v[i - 1].first) / (v[i].first - v[i - 1].first);
    return v[i - 1].second + t * (v[i].second - v[i - 1].second);
  };
  return make_float3(float(at(650.0)), float(at(550.0)), float(at(450.0)));
}

} // namespace canopy::pbrt
