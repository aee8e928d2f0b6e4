// pbrt-v4's "blackbody" spectra as linear sRGB (blackbody_rgb, declared in scene/pbrt_reader.h).
#include "scene/pbrt_reader.h"

#include <algorithm>
#include <cmath>

namespace canopy {

namespace {

// CIE 1931 2-degree colour matching functions, the multi-lobe piecewise-Gaussian fit of C. Wyman,
// P.-P. Sloan and P. Shirley, "Simple Analytic Approximations to the CIE XYZ Color Matching
// Functions", JCGT 2(2), 2013, Eq. 2-4 (within a few percent of the tabulated functions, far
// below what three RGB channels keep of a spectrum).
double lobe(double l, double mu, double s1, double s2) {
  double t = (l - mu) / (l < mu ? s1 : s2);
  return std::exp(-0.5 * t * t);
}
double cie_x(double l) {
  return 1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) -
         0.065 * lobe(l, 501.1, 20.4, 26.2);
}
double cie_y(double l) {
  return 0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1);
}
double cie_z(double l) {
  return 1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8);
}

// Planck's law (pbrt-v4 Blackbody()), spectral radiance at wavelength `nm`.
double planck(double nm, double kelvin) {
  const double c = 299792458.0, h = 6.62606957e-34, kb = 1.3806488e-23;
  double l = nm * 1e-9;
  double e = std::expm1((h * c) / (l * kb * kelvin));
  if (!std::isfinite(e)) return 0.0;
  return (2.0 * h * c * c) / (std::pow(l, 5) * e);
}

} // namespace

float3 blackbody_rgb(double kelvin) {
  // pbrt-v4 BlackbodySpectrum: B(lambda, T) / B(lambda_max, T), Wien's displacement law giving
  // lambda_max; XYZ as pbrt's SpectrumToXYZ (1 nm steps over 360..830 nm, divided by the y-bar
  // integral), then XYZ -> linear sRGB (IEC 61966-2-1 matrix).
  if (!(kelvin > 0.0) || !std::isfinite(kelvin)) return make_float3(0, 0, 0);
  double peak = planck(2.8977721e-3 / kelvin * 1e9, kelvin);
  if (!(peak > 0.0) || !std::isfinite(peak)) return make_float3(0, 0, 0);
  double X = 0, Y = 0, Z = 0, yint = 0;
  for (int nm = 360; nm <= 830; ++nm) {
    double l = double(nm), b = planck(l, kelvin) / peak;
    X += cie_x(l) * b;
    Y += cie_y(l) * b;
    Z += cie_z(l) * b;
    yint += cie_y(l);
  }
  X /= yint;
  Y /= yint;
  Z /= yint;
  double r = 3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z;
  double g = -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z;
  double bl = 0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z;
  return make_float3(float(std::max(r, 0.0)), float(std::max(g, 0.0)), float(std::max(bl, 0.0)));
}

} // namespace canopy
