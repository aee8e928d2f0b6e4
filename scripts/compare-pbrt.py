#!/usr/bin/env python3
"""Canopy's picture against pbrt-v4's on the same pbrt-v4 files (docs/pbrt-scenes.md, "Against
pbrt-v4"). Per scene: a copy of the scene's folder (symbolic links, so relative paths work) whose
main file has its film scaled to about --width pixels across; pbrt-v4 renders it (the binary is
the caller's: build pbrt-v4 from its source yourself, CPU only) and so does Canopy; then
`canopy compare --blocks 16` gives the image-mean ratio, the median ratio of 16x16-pixel block
means and the share of blocks within 10% (blocks brighter than 5% of the image mean), and a
side-by-side PNG (pbrt-v4 left, Canopy right) is written with OpenImageIO's oiiotool.

  scripts/compare-pbrt.py --pbrt /path/to/pbrt --canopy build/canopy --out out/pbrt-compare \\
      [--width 256] [--pbrt-spp 256] [--canopy-spp 256] SCENE.pbrt...

Prints a Markdown table. Python 3 standard library only.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time


def scaled_copy(scene, work, width):
    """A copy of the scene's folder of symlinks with the main file's Film resolution scaled so the
    width is about `width`; returns the copy's main file and its resolution."""
    src_dir = os.path.dirname(os.path.abspath(scene))
    name = os.path.splitext(os.path.basename(scene))[0]
    dst_dir = os.path.join(work, name, "scene")
    if os.path.exists(dst_dir):
        shutil.rmtree(dst_dir)
    os.makedirs(dst_dir)
    for entry in os.listdir(src_dir):
        os.symlink(os.path.join(src_dir, entry), os.path.join(dst_dir, entry))
    text = open(scene).read()

    def setting(key):  # the first occurrence outside a comment
        for m in re.finditer(r'"integer ' + key + r'"\s*\[?\s*(\d+)', text):
            line_start = text.rfind("\n", 0, m.start()) + 1
            if "#" not in text[line_start:m.start()]:
                return m
        return None

    xm, ym = setting("xresolution"), setting("yresolution")
    if not xm or not ym:
        sys.exit(f"compare-pbrt: {scene}: no Film xresolution/yresolution in the main file")
    x, y = int(xm.group(1)), int(ym.group(1))
    w = min(width, x)
    h = max(1, round(y * w / x))
    for m, v in sorted([(xm, w), (ym, h)], key=lambda e: -e[0].start(1)):  # last first
        text = text[:m.start(1)] + str(v) + text[m.end(1):]
    main = os.path.join(dst_dir, os.path.basename(scene))
    os.unlink(main)
    with open(main, "w") as f:
        f.write(text)
    return main, w, h


def timed(cmd, cwd):
    t0 = time.monotonic()
    p = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        sys.exit(f"compare-pbrt: {' '.join(cmd)} failed:\n{p.stderr.strip()[-2000:]}")
    return time.monotonic() - t0, p.stderr


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pbrt", required=True)
    ap.add_argument("--canopy", default="build/canopy")
    ap.add_argument("--out", default="out/pbrt-compare")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--pbrt-spp", type=int, default=256)
    ap.add_argument("--canopy-spp", type=int, default=256)
    ap.add_argument("scenes", nargs="+")
    a = ap.parse_args()
    canopy = os.path.abspath(a.canopy)
    os.makedirs(a.out, exist_ok=True)
    print("| scene | film | pbrt-v4 s | Canopy s | image mean ratio | median block ratio | "
          "blocks within 10% | blocks within 3% | blocks counted | Canopy warnings |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for scene in a.scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        main_file, w, h = scaled_copy(scene, a.out, a.width)
        d = os.path.dirname(main_file)
        pbrt_exr = os.path.abspath(os.path.join(a.out, name, "pbrt.exr"))
        canopy_exr = os.path.abspath(os.path.join(a.out, name, "canopy.exr"))
        tp, _ = timed([a.pbrt, "--quiet", "--spp", str(a.pbrt_spp), "--outfile", pbrt_exr,
                       main_file], d)
        tc, err = timed([canopy, "render", main_file, "--spp", str(a.canopy_spp), "--quiet",
                         "--out", canopy_exr], d)
        warnings = sum(1 for line in err.splitlines() if "warning:" in line)
        p = subprocess.run([canopy, "compare", "--json", "--blocks", "16", canopy_exr, pbrt_exr],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        if p.returncode != 0:
            sys.exit(f"compare-pbrt: compare failed: {p.stderr.strip()}")
        b = json.loads(p.stdout)["blocks"]
        side = os.path.join(a.out, f"{name}-side-by-side.png")
        if shutil.which("oiiotool"):
            subprocess.run(["oiiotool", pbrt_exr, "--colorconvert", "linear", "sRGB", canopy_exr,
                            "--colorconvert", "linear", "sRGB", "--mosaic", "2x1", "-d", "uint8",
                            "-o", side], check=False, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
        with open(os.path.join(a.out, name, "canopy-warnings.txt"), "w") as f:
            f.write(err)
        print(f"| {name} | {w}x{h} | {tp:.1f} | {tc:.1f} | {b['image_ratio']:.3f} | "
              f"{b['median_ratio']:.3f} | {100 * b['within_10_percent']:.0f}% | "
              f"{100 * b['within_3_percent']:.0f}% | {b['counted']} of {b['total']} | "
              f"{warnings} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
