#!/usr/bin/env python3
"""Writes docs/results.md (to stdout) from the outputs of `canopy converge --equal-time` in
docs/results/ (scripts/make-results.sh): per scene and depth tag (d1: direct light, --max-depth 1;
dfull: the scene's own depth) <scene>-<tag>-points.csv (per configuration: spp, seconds, mean MSE
and efficiency with 95% bootstrap intervals, top-0.1% share, worst pixel, over every pixel and
over the non-emitter pixels, resolved against the reference's floor), <scene>-<tag>-configs.csv,
<scene>-<tag>-reference.json (the reference's metadata) and <scene>-<tag>-commands.txt.
Standard library only.

The headline is efficiency = 1 / (mean MSE x mean render seconds) over the pixels whose camera
rays do not hit an emitter. Per table the best configuration is the one with the highest headline
efficiency among the resolved points (mean MSE > 10x the reference's floor); a configuration is
"close" when its efficiency is within 10% of the best's or its 95% interval overlaps the best's.
"""
import argparse
import csv
import datetime
import json
import math
import os
import platform
import subprocess

# (name, description): the order of the report.
SCENES = [
    ("default", "Canopy's default scene: a Cornell box lit by 256 small ceiling quads (in view)"),
    ("glossy-cornell", "Plastic objects in a Cornell box lit by 10^4 tiny sphere lights on the "
                       "side walls (Liu et al. 2019)"),
    ("showroom", "Glossy showroom, lights above the frame (Liu et al. 2019)"),
    ("cornell-1k", "Cornell box with 10^3 ceiling lights"),
    ("cornell-1m", "Cornell box with 10^6 ceiling lights (Conty Estevez & Kulla 2018, Fig. 17)"),
    ("plane-10k", "10,000 point lights over a diffuse plane (pbrt-v4's many-light test)"),
    ("spiral-10k", "Spiral of 10,000 point lights (Conty Estevez & Kulla 2018, Fig. 11-12)"),
    ("city", "Procedural city, about 3 x 10^5 lights (Conty Estevez & Kulla 2018, Fig. 1, 14)"),
    ("mesh-light", "Toroidal mesh light, 5,120 emissive triangles (Conty Estevez & Kulla 2018, "
                   "Fig. 6, 15, 16)"),
    ("spiral-fog", "The spiral in a homogeneous medium"),
    ("city-fog", "The city in fog"),
    ("outdoor", "Late afternoon: a sun, an image sky, 400 garden lamps, textured ground and a "
                "brushed gold box"),
]
TAGS = [("d1", "Direct light (`--max-depth 1`)"), ("dfull", "Full paths (the scene's depth)")]
CLOSE = 0.10  # within 10% of the best's efficiency


def read_csv(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def num(row, key):
    v = row.get(key, "")
    try:
        return float(v) if v != "" else math.nan
    except ValueError:
        return math.nan


def fe(v, digits=2):
    return "n/a" if not math.isfinite(v) else f"{v:.{digits}e}"


def ci(row, key):
    return f"{fe(num(row, key))} [{fe(num(row, key + '_lo' if not key.endswith('_ne') else key[:-3] + '_lo_ne'))}, " \
           f"{fe(num(row, key + '_hi' if not key.endswith('_ne') else key[:-3] + '_hi_ne'))}]"


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


def resolved(row, suffix):
    r = row.get("resolved" + suffix, "")
    return {"1": "yes", "0": "**unresolved**"}.get(r, "floor unknown")


def usable(row):
    # A verdict needs a resolved point (or, for an old reference, an unknown floor).
    return row.get("resolved_ne", "") != "0" and math.isfinite(num(row, "efficiency_ne"))


def whole_process(row, process, suffix):
    """1 / (mean MSE x mean process seconds) and its 95% interval from the MSE's (the seeds
    resampled; the process seconds' spread over runs is small beside it), or NaNs without a
    process time. suffix: '' (all pixels) or '_ne'."""
    p = process.get(row["sampler"])
    if not p:
        return math.nan, math.nan, math.nan
    w = num(p, "wall_seconds")
    mse = num(row, "mse" + suffix)
    lo, hi = num(row, "mse_lo" + suffix), num(row, "mse_hi" + suffix)
    return 1 / (mse * w), 1 / (hi * w), 1 / (lo * w)


def marks(rows):
    """Per configuration label: 'best', 'close' (within 10% or overlapping interval), 'no' or
    'unresolved', by the non-emitter efficiency."""
    ok = [r for r in rows if usable(r)]
    out = {r["sampler"]: "unresolved" for r in rows if not usable(r)}
    if not ok:
        return out, None
    best = max(ok, key=lambda r: num(r, "efficiency_ne"))
    b, blo = num(best, "efficiency_ne"), num(best, "efficiency_lo_ne")
    for r in ok:
        e, ehi = num(r, "efficiency_ne"), num(r, "efficiency_hi_ne")
        if r is best:
            out[r["sampler"]] = "best"
        elif e >= (1 - CLOSE) * b:
            out[r["sampler"]] = "within 10%"
        elif ehi >= blo:
            out[r["sampler"]] = "overlaps"
        else:
            out[r["sampler"]] = f"{b / e:.2g}x less"
    return out, best


def reference_line(docs, name, tag):
    path = os.path.join(docs, f"{name}-{tag}-reference.json")
    if not os.path.exists(path):
        return "reference: no metadata"
    with open(path) as f:
        j = json.load(f)
    a = j.get("reference", {}).get("metadata", {})
    g = lambda k: a.get("canopy:" + k, "?")
    return (f"Reference: `{g('sampler_config')}` ({g('light_sampler')}), {g('spp')} spp in "
            f"{g('render_seconds')} s, max depth {g('max_depth')}, film {g('film')}, two halves "
            f"(seeds {g('seed')}); error floor MSE(A, B) / 4: all pixels {g('reference_mse')}, "
            f"non-emitter pixels {g('reference_mse_nonemitter')}; {g('emitter_pixels')} emitter "
            f"pixels.")


def table(rows, process):
    m, best = marks(rows)
    lines = [
        "| configuration | spp | seconds | MSE non-emitter [95% CI] | efficiency non-emitter "
        "[95% CI] | MSE all [95% CI] | efficiency all [95% CI] | process seconds | whole-process "
        "efficiency non-emitter / all | top-0.1% share non-emitter "
        "(mean / max) | top-0.1% share all (mean / max) | worst pixel (non-emitter / all) | "
        "resolved (non-emitter / all) | verdict |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        verdict = m.get(r["sampler"], "")
        label = f"**{r['sampler']}**" if verdict == "best" else r["sampler"]
        p = process.get(r["sampler"])
        wall = f"{num(p, 'wall_seconds'):.2f}" if p else "-"
        lines.append(
            f"| {label} | {r['spp']} | {num(r, 'seconds'):.3f} | {ci(r, 'mse_ne')} | "
            f"{ci(r, 'efficiency_ne')} | {ci(r, 'mse')} | {ci(r, 'efficiency')} | {wall} | "
            f"{fe(whole_process(r, process, '_ne')[0])} / {fe(whole_process(r, process, '')[0])} | "
            f"{num(r, 'top_share_mean_ne'):.2f} / {num(r, 'top_share_max_ne'):.2f} | "
            f"{num(r, 'top_share_mean'):.2f} / {num(r, 'top_share_max'):.2f} | "
            f"{fe(num(r, 'worst_pixel_max_ne'))} / {fe(num(r, 'worst_pixel_max'))} | "
            f"{resolved(r, '_ne')} / {resolved(r, '')} | {verdict} |")
    return lines, m, best


def default_section(text_path, candidates, table_names):
    """The default estimator: the hand-written reasoning (text_path), then, generated, each
    configuration's non-emitter efficiency relative to each table's best and whether it meets the
    rule (best, within 10% or overlapping intervals) in every table."""
    out = ["## The default estimator", ""]
    if text_path and os.path.exists(text_path):
        out += [open(text_path).read().strip(), ""]
    out += ["Non-emitter efficiency over each table's best (1 = best; * within 10% or "
            "overlapping intervals; u unresolved; - not run):", ""]
    out.append("| configuration | " + " | ".join(table_names) +
               " | worst | meets the rule everywhere | tables run |")
    out.append("|---|" + "---|" * (len(table_names) + 3))
    for label, per in candidates.items():
        cells, every, worst, run = [], True, float("inf"), 0
        for t in table_names:
            ratio, verdict = per.get(t, (float("nan"), "-"))
            run += t in per
            if verdict == "unresolved":
                cells.append("u")
            elif not math.isfinite(ratio):
                cells.append("-")
                every = every and t not in per  # a table it was not run in is not a verdict
            else:
                ok = verdict in ("best", "within 10%", "overlaps")
                worst = min(worst, ratio)
                every = every and ok
                cells.append(f"{ratio:.2f}" + ("*" if ok and verdict != "best" else ""))
        worst_cell = f"{worst:.2f}" if math.isfinite(worst) else "-"
        verdict = ("yes" if every else "no") if run == len(table_names) else \
            ("yes, where run" if every else "no")
        out.append(f"| {label} | " + " | ".join(cells) +
                   f" | {worst_cell} | {verdict} | {run} of {len(table_names)} |")
    return out + [""]


FIXED_EXCLUDED = ("auto",)  # the default is judged against the fixed configurations


def wall_clock_rows(docs, names):
    """Per table of one budget: the default's whole-process efficiency against the best fixed
    configuration's, over all pixels (the verdict) and over the non-emitter pixels."""
    out = []
    for name in names:
        for tag, _ in TAGS:
            rows = read_csv(os.path.join(docs, f"{name}-{tag}-points.csv"))
            process = {p["sampler"]: p for p in
                       read_csv(os.path.join(docs, f"{name}-{tag}-process.csv"))}
            auto = next((r for r in rows if r["sampler"] == "auto"), None)
            if not rows or not process or not auto or "auto" not in process:
                continue
            depth = rows[0].get("max_depth", "?")
            cells = [name, "depth 1" if tag == "d1" else f"depth {depth}"]
            for suffix in ("", "_ne"):
                fixed = [r for r in rows if r["sampler"] not in FIXED_EXCLUDED and
                         r.get("resolved" + suffix, "") != "0" and r["sampler"] in process]
                a, alo, ahi = whole_process(auto, process, suffix)
                if not fixed or auto.get("resolved" + suffix, "") == "0":
                    cells += ["unresolved", "-", "-", "-"]
                    continue
                best = max(fixed, key=lambda r: whole_process(r, process, suffix)[0])
                b, blo, _ = whole_process(best, process, suffix)
                if a >= (1 - CLOSE) * b:
                    verdict = "within 10%" if a < b else "best"
                elif ahi >= blo:
                    verdict = "overlaps"
                else:
                    verdict = f"{b / a:.2g}x less"
                cells += [best["sampler"], f"{a / b:.2f}",
                          f"{fe(a)} [{fe(alo)}, {fe(ahi)}]", verdict]
            cells.insert(2, f"{num(process['auto'], 'wall_seconds'):.2f}")
            out.append("| " + " | ".join(cells) + " |")
    return out


def wall_clock_section(budgets, names):
    out = ["## At the user's wall clock", "",
           "Whole-process efficiency = 1 / (mean MSE x mean seconds of the whole `canopy render` "
           "process at the configuration's spp): start-up (scene load, light tree, kernel "
           "programs from the cache), auto's exploration and writing the images included "
           "(scripts/process-seconds.py, 3 runs per configuration after one that fills the kernel "
           "cache). The default, `auto`, against the fixed configuration of the highest "
           "whole-process efficiency, over all pixels (what the user looks at) and over the "
           "non-emitter pixels; auto / best is the ratio of their efficiencies (the default's 95% "
           "interval comes from its MSE's). The rule: within 10% of the best or overlapping "
           "intervals, over all pixels.", ""]
    for label, docs in budgets:
        rows = wall_clock_rows(docs, names)
        if not rows:
            continue
        out += [f"### {label}", "",
                "| scene | table | auto process seconds | best fixed, all pixels | auto / best | "
                "auto whole-process efficiency [95% CI] | verdict | best fixed, non-emitter | "
                "auto / best | auto [95% CI] | verdict |",
                "|---|---|---|---|---|---|---|---|---|---|---|"] + rows + [""]
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--docs", default="docs/results")
    ap.add_argument("--command", default="./scripts/make-results.sh")
    ap.add_argument("--note", default="", help="a line on the run (scenes, budgets, seeds)")
    ap.add_argument("--budget", action="append", default=[],
                    help="LABEL=DIR: another budget's converge and process CSVs, for the "
                         "wall-clock section (the first is --docs)")
    ap.add_argument("--budget-label", default="1 s per render",
                    help="the label of --docs' budget in the wall-clock section")
    ap.add_argument("--default-text", default="scripts/results-default.md",
                    help="the reasoning behind the default estimator (Markdown), quoted as is")
    ap.add_argument("--sampler-text", default="scripts/results-sampler.md",
                    help="the path sampler's measurements (Markdown, made by hand with the "
                         "commands it quotes), appended as is when the file exists")
    args = ap.parse_args()
    docs_rel = os.path.relpath(args.docs, "docs") if not os.path.isabs(args.docs) else args.docs

    out = ["# Results: efficiency at equal time", ""]
    out.append(f"Regenerate everything on this page with `{args.command}` (about 50 minutes on "
               f"2 cores; the scene table and budgets are in the script). Generated "
               f"{datetime.date.today().isoformat()} at commit `{git_commit()}` on {machine()}, "
               f"OpenCL on PoCL's CPU device.")
    out.append("")
    if args.note:
        out += [args.note, ""]
    out.append(
        "Method (`canopy converge --equal-time T`, docs/design.md \"Error against time\"): per "
        "configuration, after an unrecorded warm-up render, timing renders choose the spp for "
        "which one render takes about T seconds (and renders at it check that); then independent seeds (8 unless the note says "
        "otherwise) are rendered at that spp and measured against the reference. Per "
        "configuration: the mean MSE over the seeds with a 95% bootstrap interval (2000 "
        "resamples of the seeds, fixed RNG seed), the mean render seconds, and efficiency = 1 / "
        "(mean MSE x mean seconds) with its bootstrap interval (seeds resampled, the ratio "
        "recomputed): higher is better. Every metric is over all pixels and over the pixels none "
        "of whose camera rays hits an emitter directly (the reference's emitter mask): the "
        "headline is the latter, since the anti-aliasing noise of directly visible emitters is "
        "the same for every light sampler. The top-0.1% share is the part of an image's squared "
        "error held by its 0.1% worst pixels (fireflies show as a share near 1); the worst pixel "
        "is the largest per-pixel squared error over the seeds. The reference is the mean of two "
        "halves with independent seeds; its error floor is MSE(A, B) / 4 of the halves, and a "
        "point whose mean MSE is within 10x the floor is unresolved: it gets no verdict. Verdicts "
        "per table: **best** is the highest non-emitter efficiency among resolved points; "
        "\"within 10%\" and \"overlaps\" (95% intervals overlap the best's) mark configurations "
        "not distinguishable from it at this precision; \"Nx less\" gives the ratio otherwise. "
        "`tree-split` and `brdf-mis` (whose tree-split part splits) run at the scene's split "
        "threshold; `tree-split:0.25` and `brdf-mis/split=0.25` at the renderer's default "
        "threshold, on the scenes that set another (elsewhere the default-estimator table lists "
        "`tree-split` and `brdf-mis` in those rows too); `brdf-mis` renders as `tree-split` on "
        "scenes without a glossy material; `bsdf` samples the BSDF only. All configurations use "
        "MIS, and `max_depth` counts the vertices that sample lights (the last one also traces "
        "its BSDF ray for emission).")
    out.append("")

    summary = ["| scene | table | best (non-emitter efficiency) | within 10% or overlapping | "
               "unresolved |", "|---|---|---|---|---|"]
    # Per configuration, per table: its non-emitter efficiency over the best's and its verdict
    # (the choice of the default: within 10% of the best, or overlapping, in every table).
    candidates = {}  # label -> {table: (ratio, verdict)}
    table_names = []
    sections = []
    for name, desc in SCENES:
        tables = []
        for tag, title in TAGS:
            rows = read_csv(os.path.join(args.docs, f"{name}-{tag}-points.csv"))
            if not rows:
                continue
            depth = rows[0].get("max_depth", "?")
            process = {p["sampler"]: p for p in
                       read_csv(os.path.join(args.docs, f"{name}-{tag}-process.csv"))}
            lines, m, best = table(rows, process)
            cmd_path = os.path.join(args.docs, f"{name}-{tag}-commands.txt")
            cmd = open(cmd_path).read().strip() if os.path.exists(cmd_path) else ""
            tables.append((tag, title, depth, lines, m, best, cmd, rows))
        if not tables:
            continue
        sec = [f"## {name}", "", desc + ".", ""]
        if os.path.exists(os.path.join(args.docs, f"{name}.png")):
            sec += [f"![{name}]({docs_rel}/{name}.png) ![{name}: emitter pixels]"
                    f"({docs_rel}/{name}-mask.png)", ""]
        for tag, title, depth, lines, m, best, cmd, rows in tables:
            t = title if tag == "d1" else f"Full paths (the scene's depth, {depth})"
            if tag == "dfull" and depth == "1":
                t = "Direct light (the scene's depth is 1: one table)"
            sec += [f"### {t}", "", reference_line(args.docs, name, tag), ""]
            if cmd:
                sec += ["```sh", cmd, "```", ""]
            sec += lines + [""]
            close = [k for k, v in m.items() if v in ("within 10%", "overlaps")]
            unres = [k for k, v in m.items() if v == "unresolved"]
            tname = f"{name} {'d1' if tag == 'd1' else 'd' + depth}"
            table_names.append(tname)
            for r in rows:
                ratio = (num(r, "efficiency_ne") / num(best, "efficiency_ne")
                         if best and usable(r) else float("nan"))
                candidates.setdefault(r["sampler"], {})[tname] = (ratio, m.get(r["sampler"], ""))
                # tree-split at a scene's own threshold is also tree-split at that threshold: the
                # renderer's default (0.25) shows in one row across scenes.
                alias = {"tree-split": "tree-split:0.25", "brdf-mis": "brdf-mis/split=0.25"}
                if r["sampler"] in alias and num(r, "split_threshold") == 0.25:
                    candidates.setdefault(alias[r["sampler"]], {}).setdefault(
                        tname, (ratio, m.get(r["sampler"], "")))
            summary.append(f"| {name} | {'depth 1' if tag == 'd1' else 'depth ' + depth} | "
                           f"{best['sampler'] if best else 'none resolved'} | "
                           f"{', '.join(close) or '-'} | {', '.join(unres) or '-'} |")
        sections += sec
    out += ["## Summary", ""] + summary + [""]
    budgets = [(args.budget_label, args.docs)] + [tuple(b.split("=", 1)) for b in args.budget]
    out += wall_clock_section(budgets, [n for n, _ in SCENES])
    if table_names:
        out += default_section(args.default_text, candidates, table_names)
    out += sections
    if os.path.exists(args.sampler_text):
        with open(args.sampler_text) as f:
            out += ["", f.read().rstrip("\n")]
    print("\n".join(out))


if __name__ == "__main__":
    main()
