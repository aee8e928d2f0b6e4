#!/usr/bin/env python3
"""Whole-process efficiency: 1 / (MSE x wall seconds of the `canopy render` process), start-up,
kernel builds and auto's exploration included, per light-sampler configuration and spp, over
seeds, with 95% bootstrap intervals; over all pixels and over the pixels without an emitter in
view. The clock a user waits on, beside the render-only efficiency of `canopy converge`.

  scripts/whole-process-efficiency.py SCENE --configs auto,power,tree,brdf-mis:0.25 \\
      --spp 16,64 --seeds 8 --reference REF.exr [--canopy build/canopy] [--work DIR]

A configuration is a --light-sampler name with an optional :T split threshold. Without REF.exr
the reference is made: two halves of --reference-spp samples (tree-split at 0.5, other seeds'
sample ranges), merged; its error floor MSE(A, B) / 4 is printed, and a configuration's MSE
within 10x of it is marked unresolved. Runs alternate configurations within each seed so that
load from other processes spreads over all of them; an untimed run of each configuration first
fills the kernel cache. Python 3 standard library only.
"""

import argparse
import json
import os
import random
import subprocess
import sys
import time


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        sys.exit(f"whole-process-efficiency: {' '.join(cmd)} failed:\n{p.stderr.strip()}")
    return p


def compare(canopy, test, ref, mask):
    out = run([canopy, "compare", "--json", "--mask", mask, test, ref]).stdout
    j = json.loads(out)
    return j["pixel_mse"], j["pixel_mse_unmasked"]


def render_args(config):
    name, _, threshold = config.partition(":")
    args = ["--light-sampler", name]
    if threshold:
        args += ["--split-threshold", threshold]
    return args


def make_reference(a, ref):
    half = a.reference_spp // 2
    mask = ref[:-4] + ".mask.png"
    parts = []
    for h in range(2):
        part = os.path.join(a.work, f"ref-half{h}.exr")
        cmd = [a.canopy, "render", a.scene, "--light-sampler", "tree-split", "--split-threshold",
               "0.5", "--samples", f"{h * half}:{(h + 1) * half}", "--seed", "4242", "--out", part,
               "--png", part[:-4] + ".png", "--quiet"]
        if h == 0:
            cmd += ["--emitter-mask", mask]
        run(cmd)
        parts.append(part)
    run([a.canopy, "merge", ref] + parts)
    floor_all, floor_clear = compare(a.canopy, parts[0], parts[1], mask)
    return floor_all / 4.0, floor_clear / 4.0


def bootstrap(mse, secs, resamples=2000, seed=12345):
    rng = random.Random(seed)
    n = len(mse)
    eff = []
    for _ in range(resamples):
        idx = [rng.randrange(n) for _ in range(n)]
        m = sum(mse[i] for i in idx) / n
        s = sum(secs[i] for i in idx) / n
        eff.append(1.0 / (m * s) if m > 0 else float("inf"))
    eff.sort()
    return eff[int(0.025 * resamples)], eff[int(0.975 * resamples) - 1]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--configs", default="auto,power,tree,brdf-mis:0.25")
    ap.add_argument("--spp", default="16")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--reference", required=True)
    ap.add_argument("--reference-spp", type=int, default=1024)
    ap.add_argument("--canopy", default="build/canopy")
    ap.add_argument("--work", default="out/whole-process")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    ref = a.reference
    mask = ref[:-4] + ".mask.png"
    if not os.path.exists(ref):
        floors = make_reference(a, ref)
        print(f"reference {ref}: error floor {floors[0]:.3e} (all), {floors[1]:.3e} (no emitter)")
    configs = a.configs.split(",")
    spps = [int(x) for x in a.spp.split(",")]
    rows = []
    # One untimed run per configuration first (8 spp: auto explores) fills the kernel cache, as
    # on a user's second render (the first on a fresh machine is measured apart).
    for c in configs:
        out = os.path.join(a.work, "warm-up")
        run([a.canopy, "render", a.scene, "--spp", "8", "--out", out + ".exr", "--quiet"] +
            render_args(c))
    for spp in spps:
        res = {c: {"mse": [], "clear": [], "secs": [], "chosen": []} for c in configs}
        for seed in range(1, a.seeds + 1):
            for c in configs:
                out = os.path.join(a.work, f"{c.replace('/', '_').replace(':', '_')}-{spp}-{seed}")
                stats = out + ".json"
                cmd = [a.canopy, "render", a.scene, "--spp", str(spp), "--seed", str(seed),
                       "--out", out + ".exr", "--png", out + ".png", "--quiet", "--stats-json",
                       stats] + render_args(c)
                t0 = time.monotonic()
                run(cmd)
                secs = time.monotonic() - t0
                m_all, m_clear = compare(a.canopy, out + ".exr", ref, mask)
                r = res[c]
                r["mse"].append(m_all)
                r["clear"].append(m_clear)
                r["secs"].append(secs)
                with open(stats) as f:
                    j = json.load(f)
                r["chosen"].append(j.get("auto", {}).get("chosen", ""))
                print(f"spp {spp} seed {seed} {c}: {secs:.2f} s, MSE {m_all:.4e} "
                      f"(no emitter {m_clear:.4e})", file=sys.stderr)
        for c in configs:
            r = res[c]
            n = len(r["secs"])
            secs = sum(r["secs"]) / n
            mse, clear = sum(r["mse"]) / n, sum(r["clear"]) / n
            lo, hi = bootstrap(r["mse"], r["secs"])
            clo, chi = bootstrap(r["clear"], r["secs"])
            chosen = {}
            for x in r["chosen"]:
                if x:
                    chosen[x] = chosen.get(x, 0) + 1
            rows.append((spp, c, secs, mse, 1 / (mse * secs), lo, hi, clear, 1 / (clear * secs),
                         clo, chi, ", ".join(f"{k} x{v}" for k, v in sorted(chosen.items()))))
    print("| spp | configuration | wall s | MSE (all) | efficiency (all) [95%] | "
          "MSE (no emitter) | efficiency (no emitter) [95%] | auto chose |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]} | {r[2]:.2f} | {r[3]:.3e} | {r[4]:.4g} [{r[5]:.4g}, {r[6]:.4g}] "
              f"| {r[7]:.3e} | {r[8]:.4g} [{r[9]:.4g}, {r[10]:.4g}] | {r[11]} |")


if __name__ == "__main__":
    main()
