#!/usr/bin/env bash
# Regenerates docs/results.md and docs/results/ from scratch: builds canopy, and per scene of the
# table below, at two path depths (direct light, `--max-depth 1`, and the scene's own depth),
# renders a reference and runs `canopy converge --equal-time` for every sampler configuration;
# then writes the report (scripts/results-report.py). About 50 minutes on 2 cores (the
# estimate per scene is in the table's comment); not run by CI. Timings are only meaningful on an
# otherwise idle machine.
#
#   ./scripts/make-results.sh                                # every scene of the table
#   SCENES="default plane-10k" ./scripts/make-results.sh     # a subset (the report covers what exists)
#   CANOPY=path/to/canopy SKIP_BUILD=1 ./scripts/make-results.sh
#   # A dry run of the machinery (meaningless numbers, nothing under docs/ touched):
#   EQUAL_TIME=0.2 REF_TIME=4 SEEDS=3 ALLOW_FEW_SEEDS=1 DOCS=/tmp/r REPORT=/tmp/r.md WORK=/tmp/r/work \
#     SCENES="plane-10k default" ./scripts/make-results.sh
#
# Environment: SCENES; BUILD, CANOPY, SKIP_BUILD; EQUAL_TIME (seconds per render), REF_TIME
# (reference seconds) and REF_SAMPLER (the reference's configuration) override the table's; SEEDS
# (8: fewer is refused unless ALLOW_FEW_SEEDS=1); PROCESS_RUNS (whole-process runs per
# configuration, 3); SAMPLERS (the configurations compared); DEPTHS ("full 1": the scene's depth,
# then direct light); WORK (out/results: references and logs), DOCS (docs/results: CSVs, small PNGs)
# and REPORT (docs/results.md) move the outputs; REUSE_REFERENCE=1 keeps a reference already in
# $WORK (with its REF.mask.png; converge refuses one of another depth or film size, the sampler is
# the caller's responsibility) instead of rendering it again.
#
# Method. Per configuration, `canopy converge --equal-time T` builds and warms up the renderer
# (kernel builds are not timed), chooses the spp for which one render takes about T seconds from
# timing renders (checked by renders at it), then renders SEEDS independent seeds at that spp. Per point it reports the mean
# MSE over the seeds with a 95% bootstrap interval (2000 resamples, fixed RNG seed), the mean
# render seconds, efficiency = 1 / (mean MSE x mean seconds) with its bootstrap interval, the share
# of each image's squared error held by its top 0.1% of pixels (mean and max over seeds) and the
# worst pixel's squared error; all over every pixel and over the pixels whose camera rays do not
# hit an emitter directly (the reference's emitter mask).
#
# Whole process. Then scripts/process-seconds.py times `canopy render` as a fresh process at each
# configuration's spp (PROCESS_RUNS runs, 3 by default, after an untimed one that fills the kernel
# cache): start-up, auto's exploration and writing the images included. The report's whole-process
# efficiency is 1 / (mean MSE x mean process seconds): the seconds a user waits.
#
# References. Rendered by converge (--reference-time R: spp from a timing render) as two halves
# with independent seeds; their difference gives the reference's error floor, MSE_floor =
# MSE(A, B) / 4 (for independent halves of variance s^2 the mean has variance s^2 / 2 and
# E[MSE(A, B)] = 2 s^2). A point whose mean MSE is within 10x the floor is "unresolved" and gets
# no verdict. The reference estimator should differ from the ones it judges where feasible, or
# run at >= 64x their spp: here it is tree-split at threshold 0.5 (the judged tree-split runs at
# the scene's threshold, 0.85 or 0.25), for R >= 64 x T seconds, so that even for an estimator as
# efficient as the best judged one, the floor is about R / T times below its MSE.
set -euo pipefail
cd "$(dirname "$0")/.."

BUILD=${BUILD:-build}
CANOPY=${CANOPY:-$BUILD/canopy}
if [ -z "${SKIP_BUILD:-}" ]; then
  cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$BUILD" -j2 --target canopy
fi
WORK=${WORK:-out/results}
DOCS=${DOCS:-docs/results}
REPORT=${REPORT:-docs/results.md}
SEEDS=${SEEDS:-8}
DEPTHS=${DEPTHS:-"full 1"}
if [ "$SEEDS" -lt 8 ] && [ -z "${ALLOW_FEW_SEEDS:-}" ]; then
  echo "make-results: SEEDS=$SEEDS: at least 8 seeds per point (ALLOW_FEW_SEEDS=1 for a dry run)" >&2
  exit 2
fi
mkdir -p "$WORK" "$DOCS"

# The configurations compared: power (alias table), the light tree without and with splitting
# (tree-split at the scene's threshold), Liu et al.'s BRDF-oriented sampling with MIS (on a
# scene without a glossy material it renders as tree-split), BSDF sampling alone, and the
# default, auto (a pilot picks power, tree or brdf-mis at threshold 0.25 per scene; its pilot's
# seconds are in -configs.csv, apart from the render seconds).
SAMPLERS=${SAMPLERS:-power,tree,tree-split,brdf-mis,bsdf,auto}

# Budgets. T: equal time, seconds per render (x SEEDS renders per configuration); R: reference
# seconds (per depth). Films are scaled (--film-scale) so that a render of T seconds holds a few
# spp or more: the metrics are per pixel. Per scene and depth the run costs about
#   5 configurations x (build + kernel compile + warm-up, ~2-4 s; timing renders ~0.75 T; SEEDS T)
#   + reference (warm-up + timing + R)  ~  5 x 13 s + 65 s  ~  2.3 min at T = 1 s, R = 60 s,
# so ~5 min per scene (both depths; plane-10k and mesh-light have depth 1 only): the 11 scenes
# took 47 minutes (2026-11-25, 5-7 configurations), scene loading and light tree builds
# included. R = 60 s keeps every reference's non-emitter floor >= 10x below the judged MSEs.
# clamp: 0 = none (the non-emitter metrics leave out directly visible emitters, so no scene needs
# a clamp; a clamp biases heavy-tailed estimators).
# name           | film scale | T (s) | reference      | R (s) | clamp
SCENE_TABLE="
default        | 0.5  | 1 | tree-split:0.5 | 60 | 0
glossy-cornell | 1    | 1 | tree-split:0.5 | 60 | 0
showroom       | 1    | 1 | tree-split:0.5 | 60 | 0
cornell-1k     | 1    | 1 | tree-split:0.5 | 60 | 0
cornell-1m     | 1    | 1 | tree-split:0.5 | 60 | 0
plane-10k      | 1    | 1 | tree-split:0.5 | 60 | 0
spiral-10k     | 0.25 | 1 | tree-split:0.5 | 60 | 0
city           | 0.5  | 1 | tree-split:0.5 | 60 | 0
mesh-light     | 0.5  | 1 | tree-split:0.5 | 60 | 0
spiral-fog     | 0.5  | 1 | tree-split:0.5 | 60 | 0
city-fog       | 0.25 | 1 | tree-split:0.5 | 60 | 0
outdoor        | 0.5  | 1 | tree-split:0.5 | 60 | 0
"
ALL_SCENES="default glossy-cornell showroom cornell-1k cornell-1m plane-10k spiral-10k city mesh-light spiral-fog city-fog outdoor"
SCENES=${SCENES:-$ALL_SCENES}

start=$(date +%s)
elapsed() { echo "$(( ($(date +%s) - start) / 60 )) min $(( ($(date +%s) - start) % 60 )) s"; }
nscenes=$(echo $SCENES | wc -w)
i=0
for name in $SCENES; do
  i=$((i + 1))
  row=$(echo "$SCENE_TABLE" | awk -F'|' -v OFS='|' -v n="$name" '{gsub(/ /, "", $1)} $1 == n')
  if [ -z "$row" ]; then echo "make-results: unknown scene $name" >&2; exit 2; fi
  IFS='|' read -r _ scale eqt ref_sampler ref_time clamp <<<"$(echo "$row" | tr -d ' ')"
  eqt=${EQUAL_TIME:-$eqt}
  ref_time=${REF_TIME:-$ref_time}
  ref_sampler=${REF_SAMPLER:-$ref_sampler}
  scene=scenes/$name.json
  if [ ! -f "$scene" ]; then
    echo "make-results: $scene does not exist, skipped" >&2
    continue
  fi
  clamp_opt=()
  if [ "$clamp" != 0 ]; then clamp_opt=(--clamp "$clamp"); fi
  # tree-split (and brdf-mis' tree-split part) runs at the scene's own threshold; where the scene
  # sets another than the renderer's default (0.25), they are measured at the default too.
  samplers=$SAMPLERS
  thr=$(grep -o '"split_threshold": *[0-9.]*' "$scene" | grep -o '[0-9.]*$' || true)
  if [ -n "$thr" ] && [ "$thr" != 0.25 ] && [[ ",$samplers," == *",tree-split,"* ]] &&
    [[ ",$samplers," != *",tree-split:0.25,"* ]]; then
    samplers="$samplers,tree-split:0.25"
  fi
  if [ -n "$thr" ] && [ "$thr" != 0.25 ] && [[ ",$samplers," == *",brdf-mis,"* ]] &&
    [[ ",$samplers," != *",brdf-mis/split=0.25,"* ]]; then
    samplers="$samplers,brdf-mis/split=0.25"
  fi
  rm -f "$DOCS/$name"-d*.csv "$DOCS/$name"-d*-reference.json "$DOCS/$name"-d*-commands.txt
  full_depth=
  for depth in $DEPTHS; do
    depth_opt=() tag=d1
    if [ "$depth" = full ]; then
      tag=dfull
    else
      depth_opt=(--max-depth "$depth") tag=d$depth
    fi
    # A scene whose own depth is 1 has one table (its full-path run is the depth-1 run).
    if [ "$depth" = 1 ] && [ "$full_depth" = 1 ]; then
      echo "== [$i/$nscenes] $name: the scene's depth is 1, the full-path table is the direct-light one" >&2
      continue
    fi
    ref=$WORK/$name-$tag-ref.exr
    ref_opt=(--reference-sampler "$ref_sampler" --reference-time "$ref_time")
    if [ -n "${REUSE_REFERENCE:-}" ] && [ -f "$ref" ] && [ -f "${ref%.exr}.mask.png" ]; then
      ref_opt=()
      echo "== [$i/$nscenes] $name ($tag): reusing the reference $ref" >&2
    fi
    echo "== [$i/$nscenes] $name, depth $depth: film scale $scale, reference $ref_sampler ~${ref_time} s," \
      "equal time $eqt s x $SEEDS seeds, samplers $samplers ($(elapsed) so far)" >&2
    cmd=("$CANOPY" converge "$scene" --film-scale "$scale" "${depth_opt[@]}" "${clamp_opt[@]}"
      --reference "$ref" "${ref_opt[@]}" --samplers "$samplers" --equal-time "$eqt"
      --seeds "$SEEDS" --out "$DOCS/$name-$tag")
    echo "${cmd[*]}" | sed "s|^$CANOPY|canopy|" >"$DOCS/$name-$tag-commands.txt"
    if [ ${#ref_opt[@]} = 0 ]; then
      echo "# (REUSE_REFERENCE: $ref is from an earlier run of this script)" >>"$DOCS/$name-$tag-commands.txt"
    fi
    "${cmd[@]}" | tee "$WORK/$name-$tag-converge.txt"
    # The whole process at the chosen spp: start-up and auto's exploration included.
    depth_arg=()
    if [ ${#depth_opt[@]} -gt 0 ]; then depth_arg=(--max-depth "$depth"); fi
    python3 scripts/process-seconds.py --canopy "$CANOPY" --scene "$scene" --film-scale "$scale" \
      "${depth_arg[@]}" --points "$DOCS/$name-$tag-points.csv" --out "$DOCS/$name-$tag-process.csv" \
      --runs "${PROCESS_RUNS:-3}"
    # The reference's metadata (sampler, spp, seconds, error floors), for the report.
    "$CANOPY" compare "$ref" "$ref" --json >"$DOCS/$name-$tag-reference.json"
    if [ "$tag" = dfull ]; then
      cp "${ref%.exr}.png" "$DOCS/$name.png"
      cp "${ref%.exr}.mask.png" "$DOCS/$name-mask.png"
      full_depth=$(awk -F, 'NR == 2 { print $6 }' "$DOCS/$name-$tag-points.csv")
    fi
    echo "== [$i/$nscenes] $name, depth $depth done ($(elapsed) so far)" >&2
  done
done

note="Last run ($(date -u '+%Y-%m-%d %H:%M') UTC): \`SCENES=\"$SCENES\"\`, $SEEDS seeds per point"
if [ -n "${EQUAL_TIME:-}" ]; then note+=", equal time $EQUAL_TIME s per render"; fi
if [ -n "${REF_TIME:-}" ]; then note+=", references of $REF_TIME s"; fi
if [ -n "${REF_SAMPLER:-}" ]; then note+=" rendered with $REF_SAMPLER"; fi
note+=". Scenes not in SCENES come from the CSVs of an earlier run."
python3 scripts/results-report.py --docs "$DOCS" --command "./scripts/make-results.sh" \
  --note "$note" >"$REPORT.tmp"
mv "$REPORT.tmp" "$REPORT"
echo "wrote $REPORT ($(elapsed))" >&2
