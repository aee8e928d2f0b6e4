#!/usr/bin/env python3
"""Writes docs/results.md (to stdout) from the outputs of `canopy converge` in docs/results/:
<scene>.csv, <scene>-median.csv, <scene>-configs.csv, <scene>-reference.json and the PNGs.
Run by scripts/make-results.sh; standard library only.

Two groups of scenes: the many-light scenes of issues 5 and 10 (SCENES: light samplers and split
thresholds, the targets and the paper's claims) and the glossy scenes of issue 11 (GLOSSY_SCENES:
tree-split, power and BSDF-only sampling, each light sampler with and without MIS; the baseline of
issue 12). A group's summary covers only its own scenes. Issue 12 (BRDF-oriented many-light
sampling, Liu, Xu & Yan 2019) adds the brdf-* configurations on the glossy scenes, the diffuse
default scene (DIFFUSE_SCENES: tree-split against brdf-mis) and the scalability runs
(scalability-<lights>.csv: render seconds of a fixed spp against the light count). Issue 13
(participating media) adds the fog scenes (FOG_SCENES: power, tree and tree-split with the segment
importance and with the midpoint ablation, and <scene>-stats-{segment,midpoint}.json from
`canopy render --stats-json`: shadow rays per ray segment and per surface point).

Equal-time error: each configuration's median curve (RMSE against render seconds) is interpolated
in log-log; outside its measured range it is extended with the Monte Carlo rate RMSE ~ t^-1/2 from
the nearest end (marked with *).
"""
import argparse
import csv
import datetime
import json
import math
import os
import platform
import subprocess

SCENES = [
    ("spiral-10k", "Spiral of 10,000 point lights (paper Fig. 11-12)"),
    ("cornell-1m", "Cornell box with 10^6 ceiling lights (paper Fig. 17)"),
    ("city", "Procedural city, about 3 x 10^5 lights, one indirect bounce (paper Fig. 1 and 14)"),
    ("mesh-light", "Toroidal mesh light, 5,120 emissive triangles (paper Fig. 6, 15, 16)"),
    ("plane-10k", "10,000 point lights over a diffuse plane (pbrt-v4's many-light test; "
                  "scripts/gen-plane-lights.py)"),
]
# Issue 11: glossy scenes (Liu, Xu & Yan 2019), rendered with GLOSSY_CONFIGS (make-results.sh).
GLOSSY_SCENES = [
    ("glossy-cornell", "Plastic objects in a Cornell box lit by 10^4 tiny sphere lights on the side "
                       "walls (Liu et al. 2019, Fig. 14; scripts/gen-glossy-cornell.py)"),
    ("showroom", "A gold car-like object on a polished floor, 3,744 small disk lights around and "
                 "above it and one large quad light (Liu et al. 2019, Fig. 1; "
                 "scripts/gen-showroom.py)"),
]
# Configuration labels of the glossy scenes: "/nomis" is the same light sampler with MIS off;
# "bsdf" samples the BSDF only (no light sampling, so no MIS variant). "tree-split" has the
# scene's (default) threshold.
GLOSSY_TREE = "tree-split"
GLOSSY_LIGHT_SAMPLERS = ["tree-split", "power"]
NOMIS = "/nomis"
# The configurations of issue 11's baseline (the best of them is the baseline to beat).
ISSUE11_LABELS = [l + m for l in GLOSSY_LIGHT_SAMPLERS for m in ("", NOMIS)] + ["bsdf"]
# Issue 12: the diffuse default scene, where brdf-mis must cost nothing over tree-split.
DIFFUSE_SCENES = [
    ("default", "Canopy's default scene: a diffuse Cornell box lit by 256 small ceiling quads "
                "(no glossy material: brdf-mis renders as tree-split there)"),
]
# Issue 13: participating media (Conty Estevez & Kulla 2018, §5.2), rendered with SAMPLERS_FOG
# (make-results.sh). "/midpoint" ranks light clusters for a ray segment by the surface importance
# at the segment's midpoint instead of the segment importance (Eq. 7).
FOG_SCENES = [
    ("spiral-fog", "A long spiral mesh light (5,760 emissive triangles) over a ground with a "
                   "column and boxes in unbounded homogeneous fog, one indirect bounce (paper "
                   "Fig. 9; scripts/gen-spiral-fog.py)"),
    ("city-fog", "The procedural city (about 3 x 10^5 lights, one indirect bounce) in a 30 m deep "
                 "layer of ground fog that the camera looks into from above (paper Fig. 1; "
                 "scripts/gen-city.py --fog)"),
]
MIDPOINT = "/midpoint"
# tree-split at the renderer's default threshold (the scenes' own is 0.85).
FOG_DEFAULT_SPLIT = "tree-split:0.25"
# The metric the media claims are judged by, per scene. spiral-fog's emissive tube is in view and a
# few pixels wide: its anti-aliasing noise, the same for every light sampler, dominates the RMSE
# even clamped (power, tree and tree/midpoint have the same RMSE curve there), while relMSE weighs
# the fog (values ~0.1-0.3) about 30 times more than the tube (clamped to 1).
FOG_METRIC = {"spiral-fog": "relMSE", "city-fog": "RMSE"}
# Labels of the BRDF-oriented configurations (make-results.sh SAMPLERS_GLOSSY): brdf-mis has
# delta 0.5 (LT_BRDF_DEFAULT_DELTA), N_max 50 and lambda 10 (the paper's settings), adaptive
# allocation; brdf-mis:D sweeps delta (Table 2).
BRDF_MIS = "brdf-mis"
BRDF_ORIENTED = "brdf-oriented"
BRDF_EQUAL = "brdf-mis/equal"
BRDF_DEFAULT_DELTA = 0.5
# Issue 12's targets (equal-time RMSE ratios, render-time ratio).
TARGET_GLOSSY = 0.8
TARGET_SCALE = 1.5
PAPER_SCALE = 20.0 / 11.0  # Fig. 10: 11 s -> 20 s from 10^3 to 10^5 lights
TARGET_DIFFUSE = 1.05
# A ratio within this of 1 is not a difference: the seed-to-seed noise of the medians (as above).
NOISE_MARGIN = 0.05
# The default split threshold (LT_DEFAULT_SPLIT_THRESHOLD in cl/light_tree/split.h).
DEFAULT_THRESHOLD = "tree-split:0.25"
THRESHOLDS = ["tree-split:0.0", "tree-split:0.25", "tree-split:0.5", "tree-split:0.85", "tree-split:0.95"]


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def curve(median_rows, label, metric="rmse"):
    pts = [(float(r["seconds"]), float(r[metric]), float(r["shadow_rays"]), int(r["spp"]))
           for r in median_rows if r["sampler"] == label]
    return sorted(pts)


def rmse_at(pts, t, rate=0.5):
    """(value, extrapolated) at time t; outside the curve value ~ t^-rate (RMSE 1/2, MSE 1)."""
    if not pts:
        return (math.nan, True)
    if t <= pts[0][0]:
        return (pts[0][1] * (pts[0][0] / t) ** rate, t < pts[0][0] * (1 - 1e-9))
    if t >= pts[-1][0]:
        return (pts[-1][1] * (pts[-1][0] / t) ** rate, t > pts[-1][0] * (1 + 1e-9))
    for (t0, r0, _, _), (t1, r1, _, _) in zip(pts, pts[1:]):
        if t <= t1:
            f = math.log(t / t0) / math.log(t1 / t0) if t1 > t0 else 0.0
            return (math.exp((1 - f) * math.log(r0) + f * math.log(r1)), False)
    return (pts[-1][1], False)


def fmt_e(v):
    return "n/a" if v is None or math.isnan(v) else f"{v:.3e}"


def fmt_r(v):
    return "n/a" if v is None or math.isnan(v) else f"{v:.2f}x"


def machine():
    cpu = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} logical cores"


def git_commit():
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


class Scene:
    def __init__(self, docs, name):
        self.name = name
        self.runs = read_csv(os.path.join(docs, f"{name}.csv"))
        self.median = read_csv(os.path.join(docs, f"{name}-median.csv"))
        self.configs = read_csv(os.path.join(docs, f"{name}-configs.csv"))
        self.labels = [c["sampler"] for c in self.configs]
        self.curves = {l: curve(self.median, l) for l in self.labels}
        ref = os.path.join(docs, f"{name}-reference.json")
        self.reference = json.load(open(ref)) if os.path.exists(ref) else {}
        # Equal time: the longest time every curve reaches.
        self.t_eq = min(c[-1][0] for c in self.curves.values() if c)
        self.eq = {l: rmse_at(c, self.t_eq) for l, c in self.curves.items()}
        # Equal shadow rays (the paper's Fig. 12-13 axis).
        # (A sampler without light samples, "bsdf", traces no shadow rays: it has no such curve.)
        self.ray_curves = {l: sorted((p[2], p[1], p[0], p[3]) for p in c)
                           for l, c in self.curves.items() if c and c[-1][2] > 0}
        self.r_eq = min(c[-1][0] for c in self.ray_curves.values() if c)
        self.eq_rays = {l: rmse_at(c, self.r_eq) for l, c in self.ray_curves.items()}
        self.rel_curves = {l: curve(self.median, l, "relmse") for l in self.labels}
        self.rel_eq = {l: rmse_at(c, self.t_eq, 1.0) for l, c in self.rel_curves.items()}

    def ratio(self, a, b, t=None):
        t = self.t_eq if t is None else t
        ra, rb = rmse_at(self.curves.get(a, []), t)[0], rmse_at(self.curves.get(b, []), t)[0]
        return ra / rb if rb else math.nan

    def rays_per_point(self, label):
        rays = sum(float(r["shadow_rays"]) for r in self.runs if r["sampler"] == label)
        pts = sum(float(r["shading_points"]) for r in self.runs if r["sampler"] == label)
        return rays / pts if pts else math.nan

    def mse_time(self, label):
        """Inverse efficiency, MSE x render seconds, at the curve's last (highest-spp) point: for a
        Monte Carlo estimator it does not depend on the time, so it compares configurations that
        reach different spp (lower is better)."""
        pts = self.curves.get(label, [])
        if not pts:
            return math.nan
        t, r, _, _ = pts[-1]
        return r * r * t

    def seeds(self):
        return len({r["seed"] for r in self.runs})

    def brdf_means(self, label):
        """(mean BRDF-oriented cut size, mean BRDF-aware samples) per glossy point over every
        render of the configuration (Liu et al.'s Table 1-2 columns); None before issue 12's
        columns or without glossy points."""
        rows = [r for r in self.runs if r["sampler"] == label and "glossy_points" in r]
        pts = sum(int(r["glossy_points"]) for r in rows)
        if not pts:
            return None
        return (sum(int(r["brdf_cut_sum"]) for r in rows) / pts,
                sum(int(r["brdf_samples_sum"]) for r in rows) / pts)

    def seconds_per_spp(self, label):
        """Median render seconds per sample per pixel at the curve's last (highest-spp) point,
        where fixed per-render costs weigh least."""
        pts = self.curves.get(label, [])
        return pts[-1][0] / pts[-1][3] if pts else math.nan

    def best_split(self):
        cands = [l for l in THRESHOLDS if l in self.eq]
        return min(cands, key=lambda l: self.eq[l][0]) if cands else None

    def beats_everywhere(self, a, others):
        """a's median points: is a's RMSE below every other curve at each of a's times?"""
        worst = 0.0
        for (t, r, _, _) in self.curves.get(a, []):
            for o in others:
                ro = rmse_at(self.curves.get(o, []), t)[0]
                worst = max(worst, r / ro)
        return worst < 1.0, worst


def scene_section(s, clamp, seeds, docs, glossy=False, other=None):
    out = []
    meta = s.reference.get("test", {}).get("metadata", {})
    ref_desc = ", ".join(f"{k.split(':', 1)[1]} {v}" for k, v in sorted(meta.items())
                         if k.split(":", 1)[1] in ("light_sampler", "split_threshold", "spp",
                                                    "seed", "film", "render_seconds"))
    ref_mse = float(meta.get("canopy:reference_mse", "nan"))
    clamp = s.runs[0].get("clamp", "0") if s.runs else "0"
    if clamp not in ("0", "", "0.0"):
        out.append(f"**Clamped:** both images are clamped to [0, {clamp}] before measuring: the "
                   f"emitters are in view and sub-pixel, and their anti-aliasing noise (the same "
                   f"for every light sampler) would otherwise dominate the RMSE.\n")
    out.append(f"![{s.name} reference](results/{s.name}.png)\n")
    out.append(f"Reference: {ref_desc}. Its own noise, estimated from its two independent halves, "
               f"is RMSE {fmt_e(math.sqrt(ref_mse)) if ref_mse == ref_mse else 'n/a'} "
               f"(the floor of every curve).\n")
    out.append(f"Equal-time RMSE at **{s.t_eq:.3g} s** of render time per image (the longest time "
               f"every curve reaches; values marked * are extended from the curve's end with "
               f"the t^-1/2 Monte Carlo rate):\n")
    # The second ratio column: against uniform for the many-light scenes, against tree-split
    # (with MIS, the renderer's default) for the glossy ones.
    other = other or (GLOSSY_TREE if glossy else "uniform")
    if glossy:
        out.append("| configuration | MIS | RMSE | vs power | vs tree-split | relMSE | vs power "
                   "| MSE × time (s) | shadow rays / shading point | light tree build (s) "
                   "| points (max spp) |")
        out.append("|---|---|---|---|---|---|---|---|---|---|---|")
    else:
        out.append(f"| configuration | RMSE | vs power | vs {other} | relMSE | vs power "
                   "| shadow rays / shading point | light tree build (s) | points (max spp) |")
        out.append("|---|---|---|---|---|---|---|---|---|")
    cfg = {c["sampler"]: c for c in s.configs}
    for l in s.labels:
        r, ex = s.eq[l]
        c = cfg[l]
        tree_build = float(c["light_tree_seconds"])
        rel, rex = s.rel_eq[l]
        relp = s.rel_eq.get("power", (math.nan, False))[0]
        mis = ""
        if glossy:
            mis = ("n/a" if c.get("light_sampler") == "bsdf" else
                   "on" if c.get("mis", "1" if NOMIS not in l else "0") == "1" else "off") + " | "
        eff = f"{fmt_e(s.mse_time(l))} | " if glossy else ""
        out.append(f"| {l} | {mis}{fmt_e(r)}{'*' if ex else ''} | {fmt_r(s.ratio(l, 'power'))} | "
                   f"{fmt_r(s.ratio(l, other))} | {fmt_e(rel)}{'*' if rex else ''} | "
                   f"{fmt_r(rel / relp if relp else math.nan)} | {eff}"
                   f"{s.rays_per_point(l):.2f} | "
                   f"{tree_build:.3f} | {len(s.curves[l])} ({c['max_spp']}) |")
    out.append("")
    out.append(f"At equal shadow rays ({s.r_eq:.3g} per image, the most every curve reaches): " +
               ", ".join(f"{l} {fmt_e(s.eq_rays[l][0])}{'*' if s.eq_rays[l][1] else ''}"
                         for l in s.labels if l in s.eq_rays) + ".\n")
    out.append(f"![{s.name}: RMSE against time](results/{s.name}-time.png)\n")
    out.append(f"![{s.name}: RMSE against shadow rays](results/{s.name}-rays.png)\n")
    hm = os.path.join(docs, f"{s.name}-heatmap.png")
    if os.path.exists(hm):
        out.append(f"Shadow rays per shading point, tree-split at its default threshold (paper "
                   f"Fig. 18):\n\n![{s.name} heat map](results/{s.name}-heatmap.png)\n")
    else:
        out.append("Heat map: not produced (this build of `canopy render` has no `--heatmap`).\n")
    out.append(f"Data: [`{s.name}.csv`](results/{s.name}.csv) (every render), "
               f"[`{s.name}-median.csv`](results/{s.name}-median.csv) (medians of {s.seeds()} "
               f"seeds), "
               f"[`{s.name}-configs.csv`](results/{s.name}-configs.csv) (build and compile "
               f"times).\n")
    return "\n".join(out)


def glossy_summary(glossy):
    """The section of the glossy scenes (issue 11): equal-time RMSE of every light sampler with and
    without MIS, and of BSDF sampling alone; the baseline of issue 12."""
    o = ["## Glossy surfaces (issue 11): the baseline for issue 12\n"]
    o.append(
        "Glossy plastic and metal lit by thousands of small lights, after Liu, Xu & Yan 2019 "
        "(BRDF-oriented many-light sampling): [glossy-cornell](#glossy-cornell) (their Fig. 14) "
        "and [showroom](#showroom) (their Fig. 1). Each light sampler runs with MIS (power "
        "heuristic between its light samples and BSDF samples) and without (`/nomis`); `bsdf` "
        "samples the BSDF alone. RMSE at equal render time per image (the scene's equal time, "
        "given in its section), and MSE × time (inverse efficiency at the curve's last point; "
        "lower is better).\n")
    o.append(
        "**This is the baseline Liu et al.'s method must beat in issue 12**: BRDF-oriented light "
        "sampling, with its MIS, has to reach a lower equal-time RMSE on these two scenes than the "
        "best configuration below (marked **best**), measured by this same script.\n")
    if not glossy:
        o.append("Not run (neither glossy scene was rendered when the results were generated).\n")
        return "\n".join(o)
    o.append("| scene | light sampler | RMSE, MIS | RMSE, no MIS | no MIS / MIS | MSE × time, MIS "
             "| MSE × time, no MIS | vs tree-split (MIS) |")
    o.append("|---|---|---|---|---|---|---|---|")
    for name, _ in GLOSSY_SCENES:
        sc = glossy.get(name)
        if not sc:
            o.append(f"| {name} | | not run | | | | | |")
            continue
        best = min((l for l in ISSUE11_LABELS if l in sc.eq), key=lambda l: sc.eq[l][0],
                   default=None)

        def cell(label):
            if label not in sc.eq:
                return "not run"
            r, ex = sc.eq[label]
            txt = f"{fmt_e(r)}{'*' if ex else ''}"
            return f"**{txt}** (best)" if label == best else txt

        for ls in GLOSSY_LIGHT_SAMPLERS + ["bsdf"]:
            on, off = ls, ls + NOMIS
            if on not in sc.eq and off not in sc.eq:
                continue
            if ls == "bsdf":
                o.append(f"| {name} | bsdf (BSDF sampling only) | {cell(on)} | n/a | n/a | "
                         f"{fmt_e(sc.mse_time(on))} | n/a | {fmt_r(sc.ratio(on, GLOSSY_TREE))} |")
                continue
            o.append(f"| {name} | {ls} | {cell(on)} | {cell(off)} | "
                     f"{fmt_r(sc.ratio(off, on))} | {fmt_e(sc.mse_time(on))} | "
                     f"{fmt_e(sc.mse_time(off))} | {fmt_r(sc.ratio(on, GLOSSY_TREE))} |")
    o.append("")
    # One sentence per scene: what wins, and what MIS does for the tree.
    lines = []
    for name, _ in GLOSSY_SCENES:
        sc = glossy.get(name)
        if not sc or not sc.labels:
            continue
        cands = [l for l in ISSUE11_LABELS if l in sc.eq]
        if not cands:
            continue
        best = min(cands, key=lambda l: sc.eq[l][0])
        txt = f"{name}: best of these at equal time ({sc.t_eq:.3g} s per image) `{best}`"
        if GLOSSY_TREE in sc.eq and GLOSSY_TREE + NOMIS in sc.eq:
            r = sc.ratio(GLOSSY_TREE + NOMIS, GLOSSY_TREE)
            # A 5% margin: the seed-to-seed noise of the medians.
            effect = ("lowers" if r > 1.05 else "raises" if r < 0.95 else
                      "does not change (within 5%)")
            txt += f"; MIS {effect} tree-split's error (without / with MIS {r:.2f}×)"
        if "bsdf" in sc.eq and GLOSSY_TREE in sc.eq:
            txt += f"; BSDF sampling alone / tree-split {sc.ratio('bsdf', GLOSSY_TREE):.2f}×"
        lines.append("* " + txt + ".")
    o.append("\n".join(lines) + "\n")
    return "\n".join(o)


def met(ok):
    return "MET" if ok else "NOT MET"


def delta_of(label):
    """The BRDF split threshold delta of a brdf-mis configuration label, or None."""
    if label == BRDF_MIS:
        return BRDF_DEFAULT_DELTA
    if label.startswith(BRDF_MIS + ":") and "/" not in label:
        try:
            return float(label.split(":", 1)[1])
        except ValueError:
            return None
    return None


def read_scalability(docs):
    """{lights: {sampler: {"sec_per_spp": median over the repetitions, "reps": n, "spp": spp,
    "cut": ..., "samples": ..., "tree_build": s}}} from scalability-<lights>.csv."""
    out = {}
    for f in sorted(os.listdir(docs)) if os.path.isdir(docs) else []:
        if not (f.startswith("scalability-") and f.endswith(".csv")) or f.endswith("-configs.csv"):
            continue
        try:
            n = int(f[len("scalability-"):-len(".csv")])
        except ValueError:
            continue
        rows = read_csv(os.path.join(docs, f))
        cfg_path = os.path.join(docs, f"scalability-{n}-configs.csv")
        cfgs = {c["sampler"]: c for c in read_csv(cfg_path)} if os.path.exists(cfg_path) else {}
        per = {}
        for label in dict.fromkeys(r["sampler"] for r in rows):
            rr = [r for r in rows if r["sampler"] == label]
            secs = sorted(float(r["seconds"]) / int(r["spp"]) for r in rr)
            med = secs[len(secs) // 2] if len(secs) % 2 else 0.5 * (secs[len(secs) // 2 - 1] +
                                                                      secs[len(secs) // 2])
            pts = sum(int(r.get("glossy_points") or 0) for r in rr)
            per[label] = {
                "sec_per_spp": med, "reps": len(rr), "spp": int(rr[0]["spp"]),
                "cut": sum(int(r["brdf_cut_sum"]) for r in rr) / pts if pts else None,
                "samples": sum(int(r["brdf_samples_sum"]) for r in rr) / pts if pts else None,
                "tree_build": float(cfgs[label]["light_tree_seconds"]) if label in cfgs else None,
            }
        out[n] = per
    return out


def brdf_section(glossy, diffuse, scal, docs):
    """Issue 12: BRDF-oriented many-light sampling (Liu, Xu & Yan 2019) against the issue-11
    baseline, its delta sweep, allocation ablation, scalability, overhead on a diffuse scene, and
    the paper's claims. Every number comes from the CSVs."""
    o = ["## BRDF-oriented many-light sampling (issue 12)\n"]
    o.append(
        "Liu, Xu & Yan 2019, *Adaptive BRDF-oriented multiple importance sampling of many "
        "lights*. At a glossy shading point `brdf-oriented` selects a light cut by the BRDF's "
        "cap integral S_C (split a cluster while S_C > δ, their Eq. 5) and samples it by S_C; "
        "`brdf-mis` combines three techniques with MIS: tree light sampling with splitting "
        "([EK18], Canopy's `tree-split`), BRDF-oriented light sampling and BSDF sampling, "
        "with N = ⌈N_max I_B⌉ BRDF-aware samples (N_max 50, their Eq. 8-9) allocated "
        "adaptively between the last two (λ = 10, their Alg. 1); `brdf-mis/equal` allocates "
        "one sample to each (their Fig. 8 ablation); `brdf-mis:D` sets δ = D (default 0.5). "
        "Diffuse points use `tree-split` in every brdf-* configuration. Same method as above: "
        "equal render time per image (the scene's equal time, the longest time every curve of "
        "the scene reaches, * = extended with t^-1/2), medians of the seeds. Cut size and "
        "samples are means over glossy shading points of every render of the configuration "
        "(the paper's Table 1-2 columns).\n")
    if not glossy:
        o.append("Not run (neither glossy scene was rendered).\n")
    claims = []

    # (i) the samplers against the baseline
    o.append("### Equal-time error against the baseline\n")
    o.append("| scene | configuration | RMSE | vs tree-split [EK18] | MSE × time (s) "
             "| s per spp | cut / glossy point | BRDF-aware samples / glossy point |")
    o.append("|---|---|---|---|---|---|---|---|")
    target_rows = []
    for name, _ in GLOSSY_SCENES:
        sc = glossy.get(name)
        if not sc:
            o.append(f"| {name} | | not run | | | | | |")
            continue
        for label in (BRDF_MIS, BRDF_ORIENTED, BRDF_EQUAL, GLOSSY_TREE, GLOSSY_TREE + NOMIS, "bsdf",
                      "power"):
            if label not in sc.eq:
                o.append(f"| {name} | {label} | not run | | | | | |")
                continue
            r, ex = sc.eq[label]
            bm = sc.brdf_means(label)
            o.append(f"| {name} | {label} | {fmt_e(r)}{'*' if ex else ''} | "
                     f"{fmt_r(sc.ratio(label, GLOSSY_TREE))} | {fmt_e(sc.mse_time(label))} | "
                     f"{sc.seconds_per_spp(label):.3f} | "
                     f"{f'{bm[0]:.2f}' if bm else 'n/a'} | {f'{bm[1]:.2f}' if bm else 'n/a'} |")
        if BRDF_MIS in sc.eq and GLOSSY_TREE in sc.eq:
            target_rows.append((name, sc.ratio(BRDF_MIS, GLOSSY_TREE), sc.t_eq))
    o.append("")
    ok = len(target_rows) == len(GLOSSY_SCENES) and all(r <= TARGET_GLOSSY for _, r, _ in target_rows)
    o.append(f"**Target: brdf-mis ≤ {TARGET_GLOSSY} × tree-split at equal time on both glossy "
             f"scenes: {met(ok)}** (" + (
                 "; ".join(f"{n}: {r:.2f}× at {t:.3g} s" for n, r, t in target_rows)
                 if target_rows else "not measured") +
             (")." if len(target_rows) == len(GLOSSY_SCENES) else "; a scene is missing).") + "\n")
    # Issue 11 set a stricter bar: the best of its configurations, whatever it is.
    vs_best = []
    for name, _ in GLOSSY_SCENES:
        sc = glossy.get(name)
        cands = [l for l in ISSUE11_LABELS if sc and l in sc.eq]
        if sc and cands and BRDF_MIS in sc.eq:
            best = min(cands, key=lambda l: sc.eq[l][0])
            vs_best.append(f"{name}: brdf-mis / {best} {sc.ratio(BRDF_MIS, best):.2f}×")
    if vs_best:
        o.append("Against the best configuration of the issue-11 baseline (the bar set in the "
                 "section above): " + "; ".join(vs_best) + ".\n")

    # (ii) the delta sweep
    o.append("### The split threshold δ (the paper's Table 2)\n")
    o.append("| scene | δ | cut / glossy point | BRDF-aware samples / glossy point | RMSE "
             "| vs δ = 0.5 | s per spp |")
    o.append("|---|---|---|---|---|---|---|")
    sweeps = {}
    for name, _ in GLOSSY_SCENES:
        sc = glossy.get(name)
        if not sc:
            continue
        rows = sorted((delta_of(l), l) for l in sc.labels if delta_of(l) is not None)
        sweeps[name] = []
        for d, l in rows:
            bm = sc.brdf_means(l)
            r, ex = sc.eq[l]
            sweeps[name].append((d, bm, r, sc.seconds_per_spp(l)))
            o.append(f"| {name} | {d:g} | {f'{bm[0]:.2f}' if bm else 'n/a'} | "
                     f"{f'{bm[1]:.2f}' if bm else 'n/a'} | {fmt_e(r)}{'*' if ex else ''} | "
                     f"{fmt_r(sc.ratio(l, BRDF_MIS)) if BRDF_MIS in sc.eq else 'n/a'} | "
                     f"{sc.seconds_per_spp(l):.3f} |")
    o.append("")
    best_txt = []
    for name, rows in sweeps.items():
        if rows:
            bd = min(rows, key=lambda x: x[2])
            best_txt.append(f"{name}: lowest equal-time RMSE at δ = {bd[0]:g}")
    if best_txt:
        o.append("; ".join(best_txt) + " (the paper chooses 0.5 as its trade-off).\n")

    # (iii) equal against adaptive allocation
    o.append("### Equal against adaptive allocation (the paper's Fig. 8)\n")
    o.append("| scene | RMSE adaptive (brdf-mis) | RMSE equal (brdf-mis/equal) | equal / adaptive "
             "| samples / glossy point, adaptive | equal | s per spp, adaptive | equal |")
    o.append("|---|---|---|---|---|---|---|---|")
    alloc = []
    for name, _ in GLOSSY_SCENES:
        sc = glossy.get(name)
        if not sc or BRDF_MIS not in sc.eq or BRDF_EQUAL not in sc.eq:
            o.append(f"| {name} | not run | | | | | | |")
            continue
        ra, rq = sc.eq[BRDF_MIS][0], sc.eq[BRDF_EQUAL][0]
        ba, bq = sc.brdf_means(BRDF_MIS), sc.brdf_means(BRDF_EQUAL)
        alloc.append((name, rq / ra))
        o.append(f"| {name} | {fmt_e(ra)} | {fmt_e(rq)} | {rq / ra:.2f}× | "
                 f"{f'{ba[1]:.2f}' if ba else 'n/a'} | {f'{bq[1]:.2f}' if bq else 'n/a'} | "
                 f"{sc.seconds_per_spp(BRDF_MIS):.3f} | {sc.seconds_per_spp(BRDF_EQUAL):.3f} |")
    o.append("")

    # (iv) scalability
    o.append("### Scalability with the light count (the paper's Fig. 10)\n")
    scale_ok = scale_ratio = None
    if scal:
        counts = sorted(scal)
        samplers = list(dict.fromkeys(l for n in counts for l in scal[n]))
        any_n = scal[counts[0]]
        first = next(iter(any_n.values()))
        o.append(f"glossy-cornell regenerated with each light count (`scripts/gen-glossy-cornell.py "
                 f"--count N`, same seed and total power), {first['spp']} spp per render, the "
                 f"median of {first['reps']} renders (after an unrecorded warm-up render).\n")
        o.append("| lights | " + " | ".join(f"{l}: s per spp" for l in samplers) +
                 " | brdf-mis: cut / glossy point | brdf-mis: samples / glossy point "
                 "| light tree build (s) |")
        o.append("|---|" + "---|" * len(samplers) + "---|---|---|")
        for n in counts:
            cells = [f"{scal[n][l]['sec_per_spp']:.3f}" if l in scal[n] else "n/a"
                     for l in samplers]
            b = scal[n].get(BRDF_MIS, {})

            def num(v, f="{:.2f}"):
                return "n/a" if v is None else f.format(v)

            o.append(f"| {n:,} | " + " | ".join(cells) + f" | {num(b.get('cut'))} | "
                     f"{num(b.get('samples'))} | {num(b.get('tree_build'), '{:.3f}')} |")
        o.append("")
        lo, hi = counts[0], counts[-1]
        if BRDF_MIS in scal[lo] and BRDF_MIS in scal[hi] and hi > lo:
            ratio = scal[hi][BRDF_MIS]["sec_per_spp"] / scal[lo][BRDF_MIS]["sec_per_spp"]
            scale_ok, scale_ratio = ratio <= TARGET_SCALE, ratio
            o.append(f"**Target: brdf-mis render time per sample at {hi:,} lights ≤ {TARGET_SCALE} × "
                     f"at {lo:,}: {met(scale_ok)}** ({hi:,} / {lo:,}: {ratio:.2f}×; the paper: "
                     f"11 s → 20 s, 1.8×, from 1,000 to 100,000 lights).\n")
            scale_txt = f"brdf-mis s per spp {lo:,} → {hi:,} lights: {ratio:.2f}×"
            if GLOSSY_TREE in scal[lo] and GLOSSY_TREE in scal[hi]:
                rt = scal[hi][GLOSSY_TREE]["sec_per_spp"] / scal[lo][GLOSSY_TREE]["sec_per_spp"]
                scale_txt += f" (tree-split {rt:.2f}×)"
                o.append(f"tree-split, for comparison: {rt:.2f}× over the same range.\n")
        else:
            scale_txt = "brdf-mis not measured at both ends"
            o.append("**Target: ≤ 1.5× from 10^3 to 10^5 lights: NOT MET** (not measured at both "
                     "ends).\n")
    else:
        scale_txt = "not run"
        o.append("Not run.\n")

    # (v) the diffuse default scene
    o.append("### Overhead on a diffuse scene\n")
    dsc = diffuse.get("default")
    diffuse_ratio = None
    if dsc and BRDF_MIS in dsc.eq and GLOSSY_TREE in dsc.eq:
        diffuse_ratio = dsc.ratio(BRDF_MIS, GLOSSY_TREE)
        o.append(f"[default](#default) (no glossy material): equal-time RMSE at {dsc.t_eq:.3g} s, "
                 f"tree-split {fmt_e(dsc.eq[GLOSSY_TREE][0])}, brdf-mis "
                 f"{fmt_e(dsc.eq[BRDF_MIS][0])}; s per spp tree-split "
                 f"{dsc.seconds_per_spp(GLOSSY_TREE):.3f}, brdf-mis "
                 f"{dsc.seconds_per_spp(BRDF_MIS):.3f}.\n")
        o.append(f"**Target: brdf-mis ≤ {TARGET_DIFFUSE} × tree-split at equal time: "
                 f"{met(diffuse_ratio <= TARGET_DIFFUSE)}** ({diffuse_ratio:.2f}×).\n")
    else:
        o.append("Not run.\n")

    # (vi) the paper's claims
    def ratio_txt(sc, a, b):
        return f"{a}/{b} {sc.ratio(a, b):.2f}×"

    # 1. BRDF-oriented sampling beats tree light sampling on glossy scenes.
    txt, oks = [], []
    for name, sc in glossy.items():
        if BRDF_MIS in sc.eq and GLOSSY_TREE in sc.eq:
            r = sc.ratio(BRDF_MIS, GLOSSY_TREE)
            oks.append(r < 1 - NOISE_MARGIN)
            txt.append(f"{name}: {ratio_txt(sc, BRDF_MIS, GLOSSY_TREE)}")
            if BRDF_ORIENTED in sc.eq:
                txt[-1] += f", {ratio_txt(sc, BRDF_ORIENTED, GLOSSY_TREE)}"
    claims.append(("BRDF-oriented MIS beats tree light sampling [EK18] on glossy scenes at equal "
                   "time (Fig. 1, 11-14)", "; ".join(txt) or "not run", verdict(oks)))
    # 2. brdf-oriented alone beats each traditional technique and their MIS on the Cornell box.
    gc = glossy.get("glossy-cornell")
    if gc and BRDF_ORIENTED in gc.eq:
        others = [l for l in (GLOSSY_TREE + NOMIS, "bsdf", GLOSSY_TREE) if l in gc.eq]
        rs = [(l, gc.ratio(BRDF_ORIENTED, l)) for l in others]
        oks = [r < 1 - NOISE_MARGIN for _, r in rs]
        extra = ""
        if BRDF_MIS in gc.eq:
            extra = (f"; brdf-mis/brdf-oriented {gc.ratio(BRDF_MIS, BRDF_ORIENTED):.2f}× (the "
                     f"paper expects brdf-mis slightly worse than brdf-oriented here)")
        claims.append(("On the Cornell box, BRDF-oriented light sampling alone beats light "
                       "sampling alone, BSDF sampling alone and their MIS [EK18] (Fig. 14: "
                       "tree-split/nomis, bsdf, tree-split)",
                       "glossy-cornell: " + ", ".join(f"brdf-oriented/{l} {r:.2f}×" for l, r in rs)
                       + extra, verdict(oks if len(rs) == 3 else oks + [False])))
    else:
        claims.append(("On the Cornell box, BRDF-oriented light sampling alone beats each "
                       "traditional technique and their MIS (Fig. 14)", "not run", "not measured"))
    # 3. MIS makes it robust: never worse than [EK18] (tree-split), on glossy and diffuse scenes
    # alike (the paper's Fig. 13: "slightly better ... consistently robust" on a scene with few
    # lights); the ratio to the best single technique it combines is given for information.
    txt, oks = [], []
    for name, sc in glossy.items():
        if BRDF_MIS not in sc.eq or GLOSSY_TREE not in sc.eq:
            continue
        r = sc.ratio(BRDF_MIS, GLOSSY_TREE)
        oks.append(r <= 1 + NOISE_MARGIN)
        t = f"{name}: brdf-mis/tree-split {r:.2f}×"
        cands = [l for l in (GLOSSY_TREE, BRDF_ORIENTED, "bsdf") if l in sc.eq]
        best = min(cands, key=lambda l: sc.eq[l][0])
        t += f" (/ the best single technique, {best}, {sc.ratio(BRDF_MIS, best):.2f}×)"
        txt.append(t)
    if diffuse_ratio is not None:
        txt.append(f"default (diffuse): brdf-mis/tree-split {diffuse_ratio:.2f}×")
        oks.append(diffuse_ratio <= 1 + NOISE_MARGIN)
    claims.append(("MIS of the three techniques makes the method robust: never worse than "
                   f"[EK18] (tree-split; within {NOISE_MARGIN:.0%}) on any scene, glossy or not "
                   "(Fig. 13)", "; ".join(txt) or "not run", verdict(oks)))
    # 4. Adaptive beats equal allocation.
    claims.append(("Adaptive allocation beats equal allocation at equal time (Fig. 8, 11)",
                   "; ".join(f"{n}: equal/adaptive {r:.2f}×" for n, r in alloc) or "not run",
                   verdict([r > 1 + NOISE_MARGIN for _, r in alloc])))
    # 5. Larger delta: smaller cuts, more samples (two effects, judged separately: each scene
    # counts once for the cuts and once for the samples).
    txt, oks = [], []
    for name, rows in sweeps.items():
        rows = [x for x in rows if x[1]]
        if len(rows) < 2:
            continue
        cuts = [x[1][0] for x in rows]
        smp = [x[1][1] for x in rows]
        dec = all(b <= a for a, b in zip(cuts, cuts[1:]))
        inc = all(b >= a for a, b in zip(smp, smp[1:]))
        oks += [dec, inc]
        txt.append(f"{name}: δ " + ", ".join(f"{x[0]:g}" for x in rows) + " → cut " +
                   ", ".join(f"{c:.1f}" for c in cuts) + "; samples " +
                   ", ".join(f"{v:.1f}" for v in smp) +
                   f" (cut {'non-increasing' if dec else 'not monotone'}, samples "
                   f"{'non-decreasing' if inc else 'not monotone'})")
    claims.append(("A larger δ gives smaller cuts and more BRDF-aware samples (Table 2)",
                   "; ".join(txt) or "not run", verdict(oks)))
    # Reproduced: growth no steeper than the paper's 1.8x (within the noise margin); the issue's
    # own target (TARGET_SCALE) is stricter and reported above.
    claims.append(("Render time grows slowly with the light count: 1.8× from 10^3 to 10^5 lights "
                   "(Fig. 10)", scale_txt,
                   "not measured" if scale_ratio is None else
                   ("reproduced" if scale_ratio <= PAPER_SCALE * (1 + NOISE_MARGIN)
                    else "not reproduced")))
    o.append("### The paper's claims (issue 12)\n")
    o.append("“Reproduced” needs the effect beyond the seed-to-seed noise of the medians "
             f"({NOISE_MARGIN:.0%}) on every scene measured; “partly” means on some.\n")
    o.append("| claim | measured | verdict |")
    o.append("|---|---|---|")
    for c in claims:
        o.append("| " + " | ".join(c) + " |")
    o.append("")
    o.append(
        "Caveats: the paper renders direct illumination only, Canopy's scenes have 2-3 bounces "
        "(max depth 3), so indirect light, which every configuration samples the same way, "
        "dilutes the differences; the scenes are stand-ins for theirs (see the caveats above); "
        "the cap integral S_C is Canopy's fit (docs/cap-integral.md), not the paper's table.\n")
    return "\n".join(o)


def read_fog_stats(docs, name):
    """{"segment"|"midpoint"|"segment-0.25": the --stats-json of `canopy render` (tree-split at
    the scene's threshold, or at 0.25)} of a fog scene."""
    out = {}
    for vi in ("segment", "midpoint", "segment-0.25"):
        path = os.path.join(docs, f"{name}-stats-{vi}.json")
        if os.path.exists(path):
            with open(path) as f:
                out[vi] = json.load(f)
    return out


def fog_section(fog, docs):
    """Issue 13: participating media. Equal-time RMSE and relMSE of power, tree and tree-split
    (at the scene's threshold and at the default), each tree sampler with the segment importance
    (Conty Estevez & Kulla 2018, §5.2, Eq. 7) and with the surface importance at the segment's
    midpoint (/midpoint); shadow rays per ray segment and per surface point; the paper's media
    claims. Every number comes from the CSVs and stats JSONs."""
    o = ["## Participating media (issue 13)\n"]
    o.append(
        "Homogeneous fog (docs/scene-format.md, `medium`) in [spiral-fog](#spiral-fog) (the "
        "paper's Fig. 9: a long spiral mesh light in participating media, compared there against "
        "energy-based sampling) and [city-fog](#city-fog) (the city of Fig. 1 in ground fog). "
        "Direct light in the medium picks lights for each camera- or bounce-ray segment through "
        "the medium, samples a point on the segment equiangularly for each (Kulla & Fajardo "
        "2012), MIS'd with free-flight sampling. `tree` and `tree-split` rank light clusters for "
        "a segment by the segment importance (§5.2, Eq. 4-7: E cos(max(θmin − θo − θu, 0)) / "
        "dmin); `/midpoint` is the ablation that ranks them by the surface importance at the "
        "segment's midpoint (without a normal); `power` picks lights by emitted power alone "
        "(the paper's \"energy based sampling\"). `tree-split` splits at the scene's threshold "
        f"(0.85 in both scenes, as in city.json), `{FOG_DEFAULT_SPLIT}` at the renderer's default. "
        "Surface points are sampled by the configuration's light sampler (`/midpoint` changes "
        "segments only). RMSE and relMSE at equal render time per image (the scene's equal "
        "time, the longest time every curve reaches, * = extended with t^-1/2 for RMSE and "
        "t^-1 for relMSE), medians of the seeds.\n")
    if not fog:
        o.append("Not run (neither fog scene was rendered).\n")
        return "\n".join(o)
    labels = ["power", "tree", "tree" + MIDPOINT, "tree-split", "tree-split" + MIDPOINT,
              FOG_DEFAULT_SPLIT, FOG_DEFAULT_SPLIT + MIDPOINT]
    o.append("| scene | configuration | RMSE | vs power | vs tree | relMSE | vs power | vs tree "
             "| s per spp | shadow rays / shading point |")
    o.append("|---|---|---|---|---|---|---|---|---|---|")

    def rel_ratio(sc, a, b):
        ra, rb = sc.rel_eq.get(a, (math.nan,))[0], sc.rel_eq.get(b, (math.nan,))[0]
        return ra / rb if rb else math.nan

    for name, _ in FOG_SCENES:
        sc = fog.get(name)
        if not sc:
            o.append(f"| {name} | | not run | | | | | | | |")
            continue
        for label in labels + [l for l in sc.labels if l not in labels]:
            if label not in sc.eq:
                o.append(f"| {name} | {label} | not run | | | | | | | |")
                continue
            r, ex = sc.eq[label]
            rel, rex = sc.rel_eq[label]
            o.append(f"| {name} | {label} | {fmt_e(r)}{'*' if ex else ''} | "
                     f"{fmt_r(sc.ratio(label, 'power'))} | {fmt_r(sc.ratio(label, 'tree'))} | "
                     f"{fmt_e(rel)}{'*' if rex else ''} | {fmt_r(rel_ratio(sc, label, 'power'))} | "
                     f"{fmt_r(rel_ratio(sc, label, 'tree'))} | {sc.seconds_per_spp(label):.3f} | "
                     f"{sc.rays_per_point(label):.2f} |")
    o.append("")
    o.append("Equal time per image: " + "; ".join(f"{n} {sc.t_eq:.3g} s" for n, sc in
                                                  fog.items()) + ". Shadow rays / shading "
             "point counts every shadow ray (segments' and surface points') per surface point.\n")
    # The exact command lines of the run (written by make-results.sh).
    cmds = []
    for name, _ in FOG_SCENES:
        path = os.path.join(docs, f"{name}-commands.txt")
        if os.path.exists(path):
            with open(path) as f:
                cmds += [l.rstrip("\n") for l in f if l.strip()]
    if cmds:
        o.append("Commands of this run (`canopy` is build/canopy; the references and images go to "
                 "out/results/, the CSVs and JSONs to docs/results/):\n")
        o.append("```\n" + "\n".join(cmds) + "\n```\n")

    # Shadow rays per segment and per surface point (Fig. 1: 7 / 45).
    o.append("### Shadow rays per ray segment and per surface point (the paper's Fig. 1)\n")
    o.append("`canopy render SCENE --light-sampler tree-split --volume-importance V --stats-json "
             "...` at the scene's film, at the scene's threshold (0.85) and at the default (0.25). "
             "The paper's city: \"each shading point takes an average of 7 shadow rays (45 for "
             "the volume integral)\".\n")
    o.append("| scene | segment ranking (threshold) | shadow rays / segment "
             "| shadow rays / surface point | segments | surface points | spp | non-finite samples | render s |")
    o.append("|---|---|---|---|---|---|---|---|---|")
    ray_rows = {}
    for name, _ in FOG_SCENES:
        st = read_fog_stats(docs, name)
        if not st:
            o.append(f"| {name} | | not run | | | | | | |")
            continue
        for vi, j in st.items():
            seg, surf = j.get("shadow_rays_per_segment"), j.get("shadow_rays_per_surface_point")
            ray_rows.setdefault(name, {})[vi] = (seg, surf)
            o.append(f"| {name} | {vi.split('-')[0]} ({j.get('split_threshold', 0):.2g}) | "
                     f"{seg:.2f} | {surf:.2f} | {j.get('medium_segments', 0)} "
                     f"| {j.get('shading_points', 0)} | {j.get('spp', 'n/a')} | "
                     f"{j.get('nonfinite_samples', 'n/a')} | "
                     f"{float(j.get('wall_seconds', {}).get('render', math.nan)):.1f} |")
    o.append("")

    # The paper's claims.
    claims = []

    def ratios(a, b):
        return [(n, sc.ratio(a, b), rel_ratio(sc, a, b)) for n, sc in fog.items()
                if a in sc.eq and b in sc.eq]

    def judged(n, r, q):
        """The ratio the verdict uses and whether it is a gain beyond the noise margin (relMSE is
        an MSE: the margin is squared)."""
        if FOG_METRIC.get(n, "RMSE") == "relMSE":
            return q, q < (1 - NOISE_MARGIN) ** 2
        return r, r < 1 - NOISE_MARGIN

    def txt(rs, what):
        out = []
        for n, r, q in rs:
            rel = FOG_METRIC.get(n, "RMSE") == "relMSE"
            out.append(f"{n}: {what} RMSE {'' if rel else '**'}{r:.2f}×{'' if rel else '**'}, "
                       f"relMSE {'**' if rel else ''}{q:.2f}×{'**' if rel else ''}")
        return "; ".join(out)

    def join(*parts):
        return "; ".join(p for p in parts if p) or "not run"

    r1 = ratios("tree", "power")
    r1b = ratios("tree-split", "power")
    r1c = ratios(FOG_DEFAULT_SPLIT, "power")
    claims.append(("The light tree beats energy-based (power) sampling in participating media "
                   "(Fig. 9, equal time; verdict: tree)",
                   join(txt(r1, "tree/power"), txt(r1b, "tree-split/power"),
                        txt(r1c, f"{FOG_DEFAULT_SPLIT}/power")),
                   verdict([judged(*x)[1] for x in r1])))
    r2 = ratios("tree", "tree" + MIDPOINT)
    r2b = ratios("tree-split", "tree-split" + MIDPOINT)
    r2c = ratios(FOG_DEFAULT_SPLIT, FOG_DEFAULT_SPLIT + MIDPOINT)
    claims.append(("The segment importance (§5.2, Eq. 4-7) beats the surface importance at the "
                   "segment's midpoint (the issue's ablation: why §5.2 exists; verdict: every "
                   "pair)",
                   join(txt(r2, "tree/tree-midpoint"),
                        txt(r2b, "tree-split/tree-split-midpoint"),
                        txt(r2c, f"{FOG_DEFAULT_SPLIT}, segment/midpoint")),
                   verdict([judged(*x)[1] for x in r2 + r2b + r2c])))
    r3 = ratios("tree-split", "tree")
    r3c = ratios(FOG_DEFAULT_SPLIT, "tree")
    best = {}
    for x in r3 + r3c:
        best[x[0]] = best.get(x[0], False) or judged(*x)[1]
    claims.append(("\"Splitting always outperforms purely stochastic traversal\" at equal time "
                   "(§5.4, Fig. 14), here with media (verdict: either threshold per scene)",
                   join(txt(r3, "tree-split (0.85)/tree"),
                        txt(r3c, f"{FOG_DEFAULT_SPLIT}/tree")),
                   verdict(list(best.values()))))
    seg_txt, seg_ok = [], []
    for n, rows in ray_rows.items():
        for vi, thr in (("segment", "0.85"), ("segment-0.25", "0.25")):
            seg, surf = rows.get(vi, (None, None))
            if seg is None or not surf:
                continue
            seg_txt.append(f"{n}, threshold {thr}: {surf:.1f} per surface point, {seg:.1f} per "
                           f"segment ({seg / surf:.1f}×)")
            # "Several times": at least twice as many.
            seg_ok.append(seg >= 2 * surf)
    claims.append(("The volume integral takes several times (here: at least 2×) the shadow rays "
                   "of a surface point under adaptive splitting (Fig. 1: 7 per shading point, 45 "
                   "per volume segment, 6.4×)", "; ".join(seg_txt) or "not run",
                   verdict(seg_ok)))
    o.append("### The paper's claims (issue 13)\n")
    o.append("“Reproduced” needs the effect beyond the seed-to-seed noise of the medians "
             f"({NOISE_MARGIN:.0%} in RMSE, {1 - (1 - NOISE_MARGIN) ** 2:.1%} in relMSE) at "
             "equal time on every scene measured; “partly” means on some. Each scene is judged "
             "by the metric in bold: " + ", ".join(f"{n} by {m}" for n, m in FOG_METRIC.items()) +
             " (spiral-fog's emissive tube is in view: its anti-aliasing noise, the same for "
             "every light sampler, dominates the RMSE, so that power, tree and tree/midpoint "
             "have one RMSE curve there; relMSE weighs the fog about 30 times more than the "
             "clamped tube).\n")
    o.append("| claim | measured | verdict |")
    o.append("|---|---|---|")
    for c in claims:
        o.append("| " + " | ".join(c) + " |")
    o.append("")
    o.append(
        "Caveats: tree-split costs 10-25× tree per spp in these scenes (tens of shadow rays per "
        "segment, up to two per picked light: its equiangular and free-flight points), so "
        "within a short budget its curves have few points and one that ends before the equal "
        "time is extended (*); the references are tree-split renders whose own noise (each "
        "scene's section) is a floor under every curve; the paper's city is larger and its fog and split threshold are not "
        "given, so the shadow-ray counts compare in kind, not in value.\n")
    return "\n".join(o)

def verdict(oks):
    if not oks:
        return "not measured"
    return "reproduced" if all(oks) else ("partly" if any(oks) else "not reproduced")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--docs", default="docs/results")
    ap.add_argument("--command", default="./scripts/make-results.sh")
    ap.add_argument("--clamp", default="")
    ap.add_argument("--seeds", default="3")
    ap.add_argument("--note", default="", help="a line on the run (scenes, budgets, seeds)")
    a = ap.parse_args()

    scenes = {}
    for name, _ in SCENES:
        if os.path.exists(os.path.join(a.docs, f"{name}-median.csv")):
            scenes[name] = Scene(a.docs, name)
    glossy = {}
    for name, _ in GLOSSY_SCENES:
        if os.path.exists(os.path.join(a.docs, f"{name}-median.csv")):
            glossy[name] = Scene(a.docs, name)
    diffuse = {}
    for name, _ in DIFFUSE_SCENES:
        if os.path.exists(os.path.join(a.docs, f"{name}-median.csv")):
            diffuse[name] = Scene(a.docs, name)
    scal = read_scalability(a.docs)
    fog = {}
    for name, _ in FOG_SCENES:
        if os.path.exists(os.path.join(a.docs, f"{name}-median.csv")):
            fog[name] = Scene(a.docs, name)

    o = []
    o.append("# Results: error against render time\n")
    o.append(f"Regenerate everything on this page (text, tables, plots) with `{a.command}` "
             f"(about 45 minutes on 2 cores). Generated {datetime.date.today().isoformat()} at "
             f"commit `{git_commit()}` on {machine()}, OpenCL on PoCL's CPU device.\n")
    if a.note:
        o.append(a.note + "\n")
    o.append(
        "Method (DESIGN.md §8): `canopy converge` renders every sampler configuration at "
        "1, 2, 4, ... spp until its budget of render seconds is spent, "
        "several seeds per point (given in each scene's section), and measures each image "
        "against a reference with "
        "`canopy compare`'s metrics. The curves are medians over the seeds. Time is the "
        "renderer's wall time for the image (`RenderStats::render_seconds`: kernels, queues, "
        "host synchronisation), after one unrecorded warm-up render; scene loading, BVH and "
        "light tree builds and kernel compilation are reported separately. The configurations' "
        "renders interleave (level by level, seed by seed), so that load from other processes "
        "spreads over all curves. RMSE is over all pixels and RGB channels of the linear HDR "
        "images, unclamped except where a section says otherwise (clamping biases heavy-tailed "
        "estimators such as uniform sampling of the spiral, whose clamped error grows with spp)"
        +
        "; relMSE = mean (A - B)^2 / (B^2 + 0.01). Equal-time values interpolate the median "
        "curves in log-log. References are rendered by `canopy converge "
        "--reference-spp` with the sampler named in each section (an unbiased estimator at "
        "high spp, independent seeds); the exhaustive sampler would take hours per image for "
        "10^4-10^6 lights on this machine. Films are scaled down (`--film-scale`) so that "
        "every configuration reaches tens of spp within its budget. `tree-split:T` is adaptive "
        "splitting with threshold T (Canopy's dimensionless split measure, DESIGN.md §4; "
        "0 never splits); `tree-noorient` is the tree without the orientation terms of the "
        "importance (`canopy render --no-orientation`). On the glossy scenes (issue 11), "
        "`bsdf` samples the BSDF only (no light sampling) and a trailing `/nomis` is the same "
        "light sampler with multiple importance sampling off (`canopy render --no-mis`: light "
        "sampling alone for direct light at non-delta vertices); without the suffix, light "
        "and BSDF samples are combined with the power heuristic.\n")

    # ------------------------------------------------------------------ targets
    o.append("## Targets (issue 5)\n")
    o.append("| scene | target | measured | met |")
    o.append("|---|---|---|---|")
    s = scenes.get("spiral-10k")
    if s:
        best = s.best_split()
        r_best = s.ratio(best, "power")
        r_tree = s.ratio("tree", "power")
        o.append(f"| spiral-10k | tree-split at its best threshold ≤ 0.5 × power (equal time) | "
                 f"{best}: {r_best:.2f}× | {'yes' if r_best <= 0.5 else 'no'} |")
        o.append(f"| spiral-10k | tree ≤ 0.75 × power (equal time) | {r_tree:.2f}× | "
                 f"{'yes' if r_tree <= 0.75 else 'no'} |")
    else:
        o.append("| spiral-10k | | not run | no |")
    for name in ("cornell-1m", "city"):
        s = scenes.get(name)
        if not s:
            o.append(f"| {name} | tree-split beats power and uniform at every time | not run | no |")
            continue
        for label in ("tree-split:0.85", s.best_split()):
            ok, worst = s.beats_everywhere(label, ["power", "uniform"])
            o.append(f"| {name} | {label} beats power and uniform at every time on its curve | "
                     f"worst ratio {worst:.2f}× (max over its points of its RMSE / the others') "
                     f"| {'yes' if ok else 'no'} |")
            if label == s.best_split():
                break
    o.append("")

    # ------------------------------------------------------------------ issue 10
    o.append("## Targets (issue 10)\n")
    o.append("| scene | target | measured | met |")
    o.append("|---|---|---|---|")
    s = scenes.get("cornell-1m")
    if s:
        r = s.ratio("tree", "power")
        o.append(f"| cornell-1m | tree at least as good as power at equal time | tree/power "
                 f"{r:.2f}× | {'yes' if r <= 1.0 else 'no'} |")
    else:
        o.append("| cornell-1m | tree at least as good as power at equal time | not run | no |")
    # The default threshold: the one whose equal-time RMSE, relative to each scene's best
    # threshold, has the smallest geometric mean over the scenes.
    cands = [t for t in THRESHOLDS if all(t in sc.eq for sc in scenes.values())]
    if scenes and cands:
        def gmean_rel(t):
            logs = [math.log(sc.eq[t][0] / sc.eq[sc.best_split()][0]) for sc in scenes.values()]
            return math.exp(sum(logs) / len(logs))
        best = min(cands, key=gmean_rel)
        o.append(f"| all | the default threshold ({DEFAULT_THRESHOLD.split(':')[1]}) has the lowest "
                 f"equal-time RMSE over the scenes (geometric mean of RMSE / the scene's best "
                 f"threshold's) | " + ", ".join(f"{t.split(':')[1]}: {gmean_rel(t):.3f}"
                                                 for t in cands) +
                 f" | {'yes' if best == DEFAULT_THRESHOLD else 'no (best ' + best + ')'} |")
    o.append("")

    # ------------------------------------------------------------------ claims
    o.append("## The paper's claims\n")
    rows = []
    tb = [(n, sc.ratio("tree", "power")) for n, sc in scenes.items()]
    ok = all(r < 1 for _, r in tb)
    rows.append(("The light tree beats power sampling (Fig. 12, 16, 19)",
                 "; ".join(f"{n}: tree/power {r:.2f}×" for n, r in tb),
                 "reproduced" if ok and tb else ("partly" if any(r < 1 for _, r in tb) else "not reproduced"),
                 ", ".join(f"[{n}](#{n})" for n, _ in tb)))
    for axis, key, what in (("time", "eq", "equal render time"),
                            ("rays", "eq_rays", "equal shadow rays")):
        split_txt, split_ok = [], []
        for n, sc in scenes.items():
            eq = getattr(sc, key)
            vals = [(l.split(":")[1], eq[l][0]) for l in THRESHOLDS if l in eq]
            if not vals:
                continue
            best = min(vals, key=lambda v: v[1])
            # "Lowers" needs a margin beyond the seed-to-seed noise of the medians (5%).
            lowers = best[0] != "0.0" and best[1] < 0.95 * vals[0][1]
            oversplit = best[0] != vals[-1][0]
            split_ok.append(lowers and oversplit)
            split_txt.append(f"{n}: " + ", ".join(f"{t} → {v:.2e}" for t, v in vals) +
                             f" (best {best[0]}{'' if lowers or best[0] == '0.0' else ', within 5% of 0.0'}"
                             f"{'' if oversplit else ', still falling at 0.95'})")
        rows.append((f"Splitting lowers the error at {what} until over-splitting costs more than "
                     "it saves (Fig. 11-13)", "RMSE by threshold: " + "; ".join(split_txt),
                     "reproduced" if split_ok and all(split_ok) else
                     ("partly" if any(split_ok) else "not reproduced"),
                     "the `-time.png` plots" if axis == "time" else "the `-rays.png` plots"))
    # The ablation of Fig. 15-16: power (energy only) -> tree-noorient (+ distance) -> tree
    # (+ orientation). Gains in dB of PSNR at equal time, as in the paper's Fig. 16.
    abl = [(n, sc) for n, sc in scenes.items() if "tree-noorient" in sc.curves]

    def db(ratio):
        return -20.0 * math.log10(ratio) if ratio > 0 else math.nan

    if abl:
        txt = []
        for n, sc in abl:
            r_or = sc.ratio("tree", "tree-noorient")
            r_di = sc.ratio("tree-noorient", "power")
            txt.append(f"{n}: tree/tree-noorient {r_or:.2f}× ({db(r_or):+.1f} dB from orientation; "
                       f"tree-noorient/power {r_di:.2f}×, {db(r_di):+.1f} dB from distance)")
        ml = scenes.get("mesh-light")
        verdict = "not run"
        if ml and "tree-noorient" in ml.curves:
            verdict = ("reproduced" if ml.ratio("tree", "tree-noorient") < 0.95 else
                       "not reproduced")
        rows.append(("The orientation term helps mesh lights (Fig. 6, 15, 16; the paper: +5 dB "
                     "from distance, +3 dB from orientation)",
                     "equal-time RMSE, `tree-noorient` = the same tree ranking clusters by E/d^2 "
                     "only: " + "; ".join(txt), verdict, "[mesh-light](#mesh-light)"))
    elif scenes.get("mesh-light"):
        rows.append(("The orientation term helps mesh lights (Fig. 6, 15, 16)",
                     "tree-noorient was not among the configurations", "not measured",
                     "[mesh-light](#mesh-light)"))
    builds = []
    for n, sc in scenes.items():
        c = {x["sampler"]: x for x in sc.configs}.get("tree")
        if c:
            builds.append(f"{n}: {float(c['light_tree_seconds']):.3f} s")
    rows.append(("Building the tree is cheap (similar to a BVH build, §1)",
                 "light tree build: " + "; ".join(builds) +
                 " (`light_tree_seconds`, 2 cores, TBB), against render times of seconds to "
                 "minutes per image", "reproduced" if builds else "not run",
                 "the tables' build column"))
    o.append("| claim | measured | verdict | where |")
    o.append("|---|---|---|---|")
    for r in rows:
        o.append("| " + " | ".join(r) + " |")
    o.append("")

    o.append("### Caveats\n")
    o.append(
        "* Times are wall-clock on a 2-core machine that may be shared; the interleaved renders "
        "spread other load over all curves, but single points can still be slow (visible as "
        "kinks). The equal-time tables interpolate the medians.\n"
        "* References are high-spp renders with an unbiased sampler (named per scene), not the "
        "exhaustive sampler; their own noise (given per scene) is a floor under every curve and "
        "compresses ratios near the end of the best curves.\n"
        "* Canopy's split threshold is a dimensionless measure (DESIGN.md §4), so a threshold "
        "does not split exactly like the same number in the paper; the sweep includes 0.25 to "
        "locate the best value between 0 and 0.5.\n"
        "* `tree-noorient` drops the orientation terms from the importance only (emitter cone "
        "and receiver cosine, Eq. 3); its tree is the same SAOH tree, so the ablation isolates "
        "the importance measure as in the paper's Fig. 15-16, not the build heuristic.\n"
        "* The glossy scenes are stand-ins for Liu et al.'s (generated objects instead of their "
        "armadillo, bunny and car; fewer lights than the car's 43,486), so their numbers are "
        "not comparable with the paper's; they compare the samplers with each other on the same "
        "scenes, which is what issue 12 needs.\n")

    o.append(glossy_summary(glossy))
    o.append(brdf_section(glossy, diffuse, scal, a.docs))
    o.append(fog_section(fog, a.docs))

    # ------------------------------------------------------------------ scenes
    for group, loaded, is_glossy, other in ((SCENES, scenes, False, None),
                                            (GLOSSY_SCENES, glossy, True, None),
                                            (DIFFUSE_SCENES, diffuse, True, None),
                                            (FOG_SCENES, fog, False, "tree-split")):
        for name, title in group:
            o.append(f"## {name}\n")
            o.append(f"{title}: `scenes/{name}.json`.\n")
            if name in loaded:
                o.append(scene_section(loaded[name], a.clamp, a.seeds, a.docs, glossy=is_glossy,
                                       other=other))
            else:
                o.append("Not run (the scene file was missing when the results were generated).\n")
    print("\n".join(o))


if __name__ == "__main__":
    main()
