#!/usr/bin/env python3
"""Derives the RGB conductor presets of host/scene/metal_presets.cpp from measured optical constants.

Each metal's complex index n + ik is tabulated against wavelength (micrometres) in the
refractiveindex.info database (https://github.com/polyanskiy/refractiveindex.info-database,
CC0), files database/data-nk/main/<Metal>/<Set>.yml. The rows below are copied from those files
(only the visible range, 0.40-0.71 um, is needed). A preset's (eta, k) per RGB channel is the
table linearly interpolated in wavelength at 650 nm (R), 550 nm (G) and 450 nm (B), rounded to
3 decimals: a point sample per channel near the peak of each sRGB primary's spectrum.

Sources:
  Au, Ag, Cu: P. B. Johnson and R. W. Christy, Optical constants of the noble metals,
              Phys. Rev. B 6, 4370-4379 (1972)                               (Johnson.yml)
  Cr, Fe, Ni, Ti: P. B. Johnson and R. W. Christy, Optical constants of transition metals,
              Phys. Rev. B 9, 5056-5070 (1974)                               (Johnson.yml)
  Al:         A. D. Rakic, Algorithm for the determination of intrinsic optical constants of metal
              films: application to aluminum, Appl. Opt. 34, 4755-4767 (1995)  (Rakic.yml)

Usage: scripts/metal-presets.py                (prints the C++ table rows)
       scripts/metal-presets.py --check FILE   (exit 1 unless FILE's table has exactly these values;
                                                ctest SceneMetalPresetsMatchScript)
"""

import re
import sys

WAVELENGTHS_NM = (650.0, 550.0, 450.0)  # R, G, B

# name: (source, rows of (wavelength um, n, k))
TABLES = {
    "gold": ("Au/Johnson.yml", [
        (0.3974, 1.47, 1.952), (0.4133, 1.46, 1.958), (0.4305, 1.45, 1.948), (0.4509, 1.38, 1.914),
        (0.4714, 1.31, 1.849), (0.4959, 1.04, 1.833), (0.5209, 0.62, 2.081), (0.5486, 0.43, 2.455),
        (0.5821, 0.29, 2.863), (0.6168, 0.21, 3.272), (0.6595, 0.14, 3.697), (0.7045, 0.13, 4.103)]),
    "silver": ("Ag/Johnson.yml", [
        (0.3974, 0.05, 2.070), (0.4133, 0.05, 2.275), (0.4305, 0.04, 2.462), (0.4509, 0.04, 2.657),
        (0.4714, 0.05, 2.869), (0.4959, 0.05, 3.093), (0.5209, 0.05, 3.324), (0.5486, 0.06, 3.586),
        (0.5821, 0.05, 3.858), (0.6168, 0.06, 4.152), (0.6595, 0.05, 4.483), (0.7045, 0.04, 4.838)]),
    "copper": ("Cu/Johnson.yml", [
        (0.3974, 1.32, 2.116), (0.4133, 1.28, 2.207), (0.4305, 1.25, 2.305), (0.4509, 1.24, 2.397),
        (0.4714, 1.25, 2.483), (0.4959, 1.22, 2.564), (0.5209, 1.18, 2.608), (0.5486, 1.02, 2.577),
        (0.5821, 0.70, 2.704), (0.6168, 0.30, 3.205), (0.6595, 0.22, 3.747), (0.7045, 0.21, 4.205)]),
    "aluminium": ("Al/Rakic.yml", [
        (0.36466, 3.9877e-01, 4.3957), (0.41328, 5.2135e-01, 5.0008), (0.44280, 6.0790e-01, 5.3676),
        (0.47687, 7.2780e-01, 5.7781), (0.51660, 8.7340e-01, 6.2418), (0.56357, 1.0728, 6.7839),
        (0.61993, 1.3660, 7.4052), (0.65225, 1.5724, 7.7354), (0.68881, 1.8301, 8.0601)]),
    "chromium": ("Cr/Johnson.yml", [
        (0.397, 2.00, 2.83), (0.413, 2.08, 2.93), (0.431, 2.19, 3.04), (0.451, 2.33, 3.14),
        (0.471, 2.51, 3.24), (0.496, 2.75, 3.30), (0.521, 2.94, 3.33), (0.549, 3.18, 3.33),
        (0.582, 3.22, 3.30), (0.617, 3.17, 3.30), (0.659, 3.09, 3.34), (0.704, 3.05, 3.39)]),
    "iron": ("Fe/Johnson.yml", [
        (0.397, 2.24, 2.58), (0.413, 2.35, 2.65), (0.431, 2.48, 2.71), (0.451, 2.59, 2.77),
        (0.471, 2.67, 2.82), (0.496, 2.74, 2.88), (0.521, 2.86, 2.91), (0.549, 2.95, 2.93),
        (0.582, 2.94, 2.99), (0.617, 2.88, 3.05), (0.659, 2.92, 3.10), (0.704, 2.86, 3.19)]),
    "nickel": ("Ni/Johnson.yml", [
        (0.397, 1.72, 2.57), (0.413, 1.70, 2.69), (0.431, 1.71, 2.82), (0.451, 1.73, 2.95),
        (0.471, 1.78, 3.09), (0.496, 1.82, 3.25), (0.521, 1.85, 3.42), (0.549, 1.92, 3.61),
        (0.582, 1.96, 3.80), (0.617, 1.99, 4.02), (0.659, 1.99, 4.26), (0.704, 2.06, 4.50)]),
    "titanium": ("Ti/Johnson.yml", [
        (0.397, 2.08, 2.95), (0.413, 2.14, 2.98), (0.431, 2.21, 3.01), (0.451, 2.27, 3.04),
        (0.471, 2.32, 3.10), (0.496, 2.36, 3.19), (0.521, 2.44, 3.30), (0.549, 2.54, 3.43),
        (0.582, 2.60, 3.58), (0.617, 2.67, 3.72), (0.659, 2.76, 3.84), (0.704, 2.86, 3.96)]),
}


def interp(rows, wl_um):
    for (w0, n0, k0), (w1, n1, k1) in zip(rows, rows[1:]):
        if w0 <= wl_um <= w1:
            t = (wl_um - w0) / (w1 - w0)
            return n0 + t * (n1 - n0), k0 + t * (k1 - k0)
    raise ValueError(f"{wl_um} um is outside the table")


def normal_reflectance(n, k):
    return ((n - 1) ** 2 + k ** 2) / ((n + 1) ** 2 + k ** 2)


def presets():
    """name -> (eta triple, k triple), each value rounded to 3 decimals, in table order."""
    out = {}
    for name, (_, rows) in TABLES.items():
        nk = [interp(rows, w / 1000.0) for w in WAVELENGTHS_NM]
        out[name] = (tuple(round(n, 3) for n, _ in nk), tuple(round(k, 3) for _, k in nk))
    return out


def check(path):
    text = open(path, encoding="utf-8").read()
    num = r"\s*([0-9.]+)f\s*"
    row = re.compile(r'\{"(\w+)",\s*\{' + ",".join([num] * 3) + r"\},\s*\{" +
                     ",".join([num] * 3) + r"\}\}")
    found = {m.group(1): (tuple(float(m.group(i)) for i in (2, 3, 4)),
                          tuple(float(m.group(i)) for i in (5, 6, 7)))
             for m in row.finditer(text)}
    want = presets()
    if list(found) != list(want):
        print(f"{path}: presets {list(found)}, expected {list(want)}")
        return 1
    bad = [n for n in want if found[n] != want[n]]
    for n in bad:
        print(f"{path}: {n}: eta, k = {found[n]}, the data give {want[n]}")
    return 1 if bad else 0


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--check":
        sys.exit(check(sys.argv[2]))
    for name, (src, rows) in TABLES.items():
        nk = [interp(rows, w / 1000.0) for w in WAVELENGTHS_NM]
        eta = ", ".join(f"{n:.3f}f" for n, _ in nk)
        k = ", ".join(f"{kk:.3f}f" for _, kk in nk)
        r0 = " ".join(f"{normal_reflectance(n, kk):.3f}" for n, kk in nk)
        print(f'    {{"{name}", {{{eta}}}, {{{k}}}}}, // {src}; R(0) = {r0}')


if __name__ == "__main__":
    main()
