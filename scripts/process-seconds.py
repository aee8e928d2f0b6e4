#!/usr/bin/env python3
"""The wall seconds of the whole `canopy render` process at the spp that `canopy converge
--equal-time` chose per configuration: start-up (load, light tree, kernel programs from the cache),
auto's exploration and the output files included, the clock a user waits on. Reads converge's
<out>-points.csv and, after an untimed round that fills the kernel cache, renders each
configuration RUNS times as a fresh process (configurations alternate within a round so that load
from elsewhere spreads over all of them; other seeds than converge's, which changes nothing but
the noise). Writes <out>-process.csv: per configuration the mean, min and max wall seconds and the
mean seconds the process spent outside render().

  scripts/process-seconds.py --canopy build/canopy --scene scenes/default.json \\
      --film-scale 0.5 [--max-depth 1] --points docs/results/default-d1-points.csv \\
      --out docs/results/default-d1-process.csv [--runs 3]

A configuration label is converge's: a --light-sampler name, ":T" a split threshold for
tree-split, "/split=T" for brdf-mis. Python 3 standard library only.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time


def render_args(label):
    """converge's configuration label -> `canopy render` options."""
    name, _, rest = label.partition("/")
    args = []
    if ":" in name:
        name, threshold = name.split(":", 1)
        if name != "tree-split":
            sys.exit(f"process-seconds: {label}: ':T' is a threshold for tree-split only here")
        args += ["--split-threshold", threshold]
    for suffix in filter(None, rest.split("/")):
        if suffix.startswith("split="):
            args += ["--split-threshold", suffix[len("split="):]]
        else:
            sys.exit(f"process-seconds: {label}: suffix /{suffix} has no render option here")
    return ["--light-sampler", name] + args


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--canopy", default="build/canopy")
    ap.add_argument("--scene", required=True)
    ap.add_argument("--film-scale", default="1")
    ap.add_argument("--max-depth")
    ap.add_argument("--points", required=True, help="converge's <out>-points.csv")
    ap.add_argument("--out", required=True)
    ap.add_argument("--runs", type=int, default=3)
    a = ap.parse_args()
    with open(a.points, newline="") as f:
        rows = list(csv.DictReader(f))
    times = {r["sampler"]: [] for r in rows}
    outside = {r["sampler"]: [] for r in rows}
    with tempfile.TemporaryDirectory() as d:
        # An untimed round first, as a user who has rendered the scene before: the kernel programs
        # of every configuration are then in the cache (docs/performance.md has the cold start).
        for k in [-1] + list(range(a.runs)):
            for r in rows:
                stats = os.path.join(d, "stats.json")
                cmd = [a.canopy, "render", a.scene, "--film-scale", a.film_scale, "--spp",
                       r["spp"], "--seed", str(7000 + max(k, 0)), "--quiet", "--stats-json", stats,
                       "--out", os.path.join(d, "out.exr")] + render_args(r["sampler"])
                if a.max_depth:
                    cmd += ["--max-depth", a.max_depth]
                t0 = time.monotonic()
                p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                   text=True)
                wall = time.monotonic() - t0
                if p.returncode != 0:
                    sys.exit(f"process-seconds: {' '.join(cmd)} failed:\n{p.stderr.strip()}")
                if k < 0:
                    continue
                with open(stats) as f:
                    j = json.load(f)
                # Outside the render: auto's exploration counts as its render here only where
                # render() ran; switches between candidates count as outside.
                render = j["wall_seconds"]["render"]
                times[r["sampler"]].append(wall)
                outside[r["sampler"]].append(wall - render)
    with open(a.out, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["sampler", "spp", "runs", "wall_seconds", "wall_min", "wall_max",
                    "outside_render_seconds"])
        for r in rows:
            t, o = times[r["sampler"]], outside[r["sampler"]]
            w.writerow([r["sampler"], r["spp"], len(t), f"{sum(t) / len(t):.4f}",
                        f"{min(t):.4f}", f"{max(t):.4f}", f"{sum(o) / len(o):.4f}"])
    return 0


if __name__ == "__main__":
    sys.exit(main())
