#!/usr/bin/env python3
"""Start-up cost of `canopy render` per scene: the whole process's wall time minus the time spent
rendering (the render, and for the "auto" sampler its pilot), with the stages of the start-up
from --stats-json. Each scene is rendered once untimed (so the caches are warm), then --runs times;
the fastest run is reported (a loaded machine only adds time). Markdown table on stdout.

  scripts/startup-times.py --canopy build/canopy [--sampler tree|auto] [--runs 3] scenes/*.json
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time


def run(canopy, scene, sampler, out_dir):
    stats = os.path.join(out_dir, "stats.json")
    cmd = [canopy, "render", scene, "--spp", "1", "--quiet", "--stats-json", stats,
           "--out", os.path.join(out_dir, "out.exr")]
    if sampler:
        cmd += ["--light-sampler", sampler]
    t0 = time.monotonic()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.monotonic() - t0
    with open(stats) as f:
        j = json.load(f)
    w = j["wall_seconds"]
    pilot = j.get("auto", {}).get("pilot_seconds", 0.0)
    return {"wall": wall, "startup": wall - w["render"] - pilot, "pilot": pilot,
            "load": w["load"], "build": w["build"], "upload": w["upload"],
            "compile": w["compile"], "render": w["render"]}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--canopy", default="build/canopy")
    ap.add_argument("--sampler", default="tree", help="'auto' runs the pilot")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("scenes", nargs="+")
    a = ap.parse_args()
    print(f"| scene | start-up s | load s | build s | upload s | compile s | pilot s | render s |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    with tempfile.TemporaryDirectory() as d:
        for scene in a.scenes:
            run(a.canopy, scene, a.sampler, d)  # warm the caches
            best = min((run(a.canopy, scene, a.sampler, d) for _ in range(a.runs)),
                       key=lambda r: r["startup"])
            name = os.path.basename(scene)
            print(f"| {name} | {best['startup']:.3f} | {best['load']:.3f} | {best['build']:.3f} | "
                  f"{best['upload']:.3f} | {best['compile']:.3f} | {best['pilot']:.2f} | "
                  f"{best['render']:.2f} |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
