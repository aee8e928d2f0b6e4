#!/usr/bin/env python3
"""Per-pixel variance over seeds of groups of renders, and where it sits.

    for k in 1 2 3 4 5 6 7 8; do
      canopy render smooth.json --max-depth 1 --spp 4 --seed $k --light-sampler tree \\
          --out tree-smooth-$k.exr --quiet
    done
    ...
    python3 scripts/pixel-variance.py tree-smooth='tree-smooth-*.exr' tree-flat='tree-flat-*.exr' \\
        --changed tree-smooth tree-flat

For each group (NAME=GLOB, the renders of one configuration with different seeds): the variance
of each pixel's value over the group's images (channel mean, unbiased), averaged over the pixels;
the share of that sum held by the 25 worst pixels; the worst pixel. `--changed A B` restricts every
group to the pixels whose values differ between the first images of groups A and B (renders of two
scene variants with the same seed and sampler: the pixels the difference between the variants
reaches, e.g. the spheres of scripts/gen-smooth-spheres.py's smooth.json and flat.json, whose
floor pixels are the same in both). Reads EXRs with `oiiotool --dumpdata` (openimageio-tools);
standard library otherwise.
"""
import argparse
import glob
import re
import subprocess
import sys

PIXEL = re.compile(r"Pixel \((\d+), (\d+)\):\s+(\S+)\s+(\S+)\s+(\S+)")


def read_exr(path):
    """{(x, y): channel mean} of an RGB EXR."""
    out = subprocess.run(["oiiotool", "--dumpdata", path], check=True, capture_output=True,
                         text=True).stdout
    pixels = {}
    for m in PIXEL.finditer(out):
        x, y = int(m.group(1)), int(m.group(2))
        pixels[(x, y)] = (float(m.group(3)) + float(m.group(4)) + float(m.group(5))) / 3.0
    if not pixels:
        sys.exit(f"{path}: no pixels read")
    return pixels


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("groups", nargs="+", help="NAME=GLOB: the renders of one configuration")
    ap.add_argument("--changed", nargs=2, metavar=("A", "B"),
                    help="only the pixels whose values differ between groups A and B's first images")
    ap.add_argument("--worst", type=int, default=25, help="how many worst pixels to sum (25)")
    a = ap.parse_args()
    groups = {}
    for g in a.groups:
        name, sep, pattern = g.partition("=")
        files = sorted(glob.glob(pattern))
        if not sep or len(files) < 2:
            sys.exit(f"{g}: want NAME=GLOB matching at least 2 files")
        groups[name] = [read_exr(f) for f in files]
    keys = sorted(next(iter(groups.values()))[0])
    if a.changed:
        for n in a.changed:
            if n not in groups:
                sys.exit(f"--changed: no group {n}")
        ia, ib = groups[a.changed[0]][0], groups[a.changed[1]][0]
        keys = [k for k in keys if ia[k] != ib[k]]
        print(f"{len(keys)} pixels differ between {a.changed[0]} and {a.changed[1]}")
    for name, images in groups.items():
        n = len(images)
        var = []
        for k in keys:
            v = [im[k] for im in images]
            m = sum(v) / n
            var.append((sum((x - m) ** 2 for x in v) / (n - 1), k))
        total = sum(x for x, _ in var)
        var.sort(reverse=True)
        worst = sum(x for x, _ in var[:a.worst])
        share = worst / total if total > 0 else 0.0
        print(f"{name}: {n} images, mean per-pixel variance {total / len(var):.4e}, "
              f"worst {a.worst} pixels hold {100 * share:.1f}%, worst pixel {var[0][1]} "
              f"({var[0][0]:.4e})")


if __name__ == "__main__":
    main()
