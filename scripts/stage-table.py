#!/usr/bin/env python3
"""Per-stage throughput of the wavefront on every shipped scene, old build against new.

Runs `canopy render SCENE --spp S --stats-json F` for each scene with each build, alternating the
builds run by run (the machines are noisy: only same-run ratios mean anything), and prints a
markdown table per scene: each stage's items/s (median over the runs) and its share of the summed
stage time, for each build, and the render wall time.

    scripts/stage-table.py --build old=/path/old/canopy:/path/old/cl \
                           --build new=build/canopy:cl --runs 5 [--scenes default,city] [--spp 4]

A build is NAME=CANOPY_BINARY:KERNEL_DIR (the kernel sources it was built with, passed as
CANOPY_KERNEL_DIR). Scenes render at their own sampler (`auto` on the shipped scenes), depth and
resolution, 4 spp by default; `--light-sampler S` renders every scene with S instead.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

SCENES = ["default", "glossy-cornell", "showroom", "cornell-1k", "cornell-1m", "plane-10k",
          "spiral-10k", "city", "mesh-light", "spiral-fog", "city-fog"]


def run_once(binary, kernels, scene, spp, out_dir, sampler=None):
    stats = os.path.join(out_dir, "stats.json")
    env = dict(os.environ, CANOPY_KERNEL_DIR=kernels)
    cmd = [binary, "render", scene, "--spp", str(spp), "--stats-json", stats,
           "--out", os.path.join(out_dir, "image.exr")]
    if sampler:
        cmd += ["--light-sampler", sampler]
    r = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"stage-table: {' '.join(cmd)} failed:\n{r.stderr}")
    with open(stats) as f:
        return json.load(f)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", action="append", required=True,
                    help="NAME=CANOPY_BINARY:KERNEL_DIR (repeat for each build)")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--light-sampler", help="render every scene with this light sampler")
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--scene-dir", default=os.path.join(os.path.dirname(__file__), "..", "scenes"))
    a = ap.parse_args()
    builds = []
    for b in a.build:
        name, _, rest = b.partition("=")
        binary, _, kernels = rest.partition(":")
        if not name or not binary or not kernels:
            sys.exit(f"stage-table: --build {b}: expected NAME=CANOPY_BINARY:KERNEL_DIR")
        builds.append((name, os.path.abspath(binary), os.path.abspath(kernels)))

    print(f"{a.runs} runs per build and scene, alternated; medians; {a.spp} spp; "
          f"share = the stage's part of the summed stage seconds.\n")
    with tempfile.TemporaryDirectory() as tmp:
        for scene in a.scenes.split(","):
            path = os.path.join(a.scene_dir, scene + ".json")
            runs = {name: [] for name, _, _ in builds}
            for _ in range(a.runs):
                for name, binary, kernels in builds:
                    runs[name].append(run_once(binary, kernels, path, a.spp, tmp, a.light_sampler))
            first = runs[builds[0][0]][0]
            print(f"### {scene} ({first['lights']} lights, {first['light_sampler']}, "
                  f"{a.spp} spp)\n")
            stages = sorted({s for r in runs.values() for x in r for s in x["stages"]})
            head = "| stage | " + " | ".join(f"{n} items/s | {n} share" for n, _, _ in builds)
            print(head + " |")
            print("|---" * (1 + 2 * len(builds)) + "|")
            med = {}
            for name, _, _ in builds:
                total = statistics.median(sum(s["seconds"] for s in x["stages"].values())
                                          for x in runs[name])
                for st in stages:
                    secs = [x["stages"].get(st, {}).get("seconds", 0.0) for x in runs[name]]
                    items = [x["stages"].get(st, {}).get("items", 0) for x in runs[name]]
                    rate = statistics.median(i / s if s > 0 else 0.0 for i, s in zip(items, secs))
                    med[(name, st)] = (rate, statistics.median(secs) / total if total else 0.0)
            for st in stages:
                cells = []
                for name, _, _ in builds:
                    rate, share = med[(name, st)]
                    cells += [f"{rate / 1e6:.3g} M", f"{100 * share:.0f}%"]
                print(f"| {st} | " + " | ".join(cells) + " |")
            walls = [f"{n} {statistics.median(x['wall_seconds']['render'] for x in runs[n]):.3g} s"
                     for n, _, _ in builds]
            print(f"\nrender time (median): {', '.join(walls)}\n")


if __name__ == "__main__":
    main()
