#!/usr/bin/env bash
# Regenerates docs/results.md and everything in docs/results/ from scratch: builds canopy, renders
# a reference per scene, runs `canopy converge` for every sampler configuration, renders the heat
# maps, and writes the report (scripts/results-report.py). About 45 minutes on 2 cores; not run
# by CI. Timings are only meaningful on an otherwise idle machine.
#
# Besides the scene files, SCENES may name two steps of issue 12 (BRDF-oriented many-light
# sampling, Liu, Xu & Yan 2019):
#   default      scenes/default.json (diffuse only): tree-split against brdf-mis at equal time
#                (without a glossy material brdf-mis renders as tree-split: its overhead must be nil)
#   scalability  glossy-cornell regenerated with 10^3, 10^4, 10^5 lights (their Fig. 10): render
#                seconds per spp of brdf-mis (and tree-split), SCALE_REPS repetitions each
#
#   ./scripts/make-results.sh                 # everything
#   SCENES="spiral-10k city" ./scripts/make-results.sh   # a subset (the report covers what exists)
#   SCENES="glossy-cornell showroom" ./scripts/make-results.sh   # the glossy scenes (issues 11-12)
#   SCENES="glossy-cornell showroom default scalability" ./scripts/make-results.sh   # issue 12
#   SCENES="spiral-fog city-fog" ./scripts/make-results.sh   # participating media (issue 13)
#   CANOPY=path/to/canopy SKIP_BUILD=1 ./scripts/make-results.sh
#   # A dry run of the machinery (meaningless numbers, nothing under docs/ touched):
#   BUDGET=1 REF_SPP=16 SEEDS=1 DOCS=/tmp/r REPORT=/tmp/r.md SCENES=plane-10k ./scripts/make-results.sh
#   BUDGET=1 REF_SPP=16 SEEDS=1 SCALE_COUNTS="1000 4000" SCALE_SPP=1 SCALE_REPS=1 DOCS=/tmp/r \
#     REPORT=/tmp/r.md SCENES="glossy-cornell default scalability" ./scripts/make-results.sh
#
# Environment: SCENES, BUILD, CANOPY, SKIP_BUILD; BUDGET and REF_SPP override every scene's budget
# and reference spp; SEEDS (3); WORK (out/results), DOCS (docs/results) and REPORT
# (docs/results.md) move the outputs; SAMPLERS_MANY, SAMPLERS_GLOSSY, SAMPLERS_DIFFUSE and
# SAMPLERS_FOG (the media scenes of issue 13) replace the sampler sets; REUSE_REFERENCE=1 keeps a
# reference already in $WORK (same scene, film scale and reference sampler: the caller's
# responsibility) instead of rendering it again. Scalability:
# SCALE_COUNTS (light counts, "1000 10000 100000"), SCALE_SPP (8), SCALE_REPS (3), SCALE_FILM
# (film scale, 0.5 = 128 x 128), SCALE_SAMPLERS ("brdf-mis,tree-split"). FOG_STATS_SPP (4): spp of
# the fog scenes' --stats renders (shadow rays per segment and per surface point).
#
# References and other large intermediates go to $WORK (not committed); $DOCS gets the CSVs and
# the small PNGs.
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
mkdir -p "$WORK" "$DOCS"

# Two sampler sets. "many": the many-light scenes of issues 5 and 10 (light samplers, split
# thresholds, the orientation ablation). "glossy": the glossy scenes of issue 11, the baseline of
# issue 12: tree-split at the scene's (default) threshold against power and BSDF-only sampling,
# each light sampler with MIS and without (/nomis; bsdf has no light samples, so no MIS variant);
# and for issue 12 the BRDF-oriented samplers of Liu et al. 2019: brdf-mis (three-technique MIS,
# adaptive allocation, delta 0.5), brdf-oriented alone, brdf-mis/equal (equal allocation, their
# Fig. 8) and brdf-mis:D, the sweep of the cut's split threshold delta (their Table 2).
# "diffuse": the default scene, where brdf-mis must cost nothing over tree-split.
# "fog": spiral-fog and city-fog (issue 13; SAMPLERS_FOG below). spiral-fog clamps for the same
# reason as cornell-1m (its emissive tube is in view, a few pixels wide); city-fog's lights are
# points (unseen). Their references are tree-split (the renderer's default); city-fog's film is
# quartered (its tree-split costs about 10 s per spp at full size with ~46 shadow rays per ray
# segment).
SAMPLERS_MANY=${SAMPLERS_MANY:-uniform,power,tree,tree-noorient,tree-split:0.0,tree-split:0.25,tree-split:0.5,tree-split:0.85,tree-split:0.95}
SAMPLERS_GLOSSY=${SAMPLERS_GLOSSY:-tree-split,tree-split/nomis,power,power/nomis,bsdf,brdf-mis,brdf-oriented,brdf-mis/equal,brdf-mis:0.005,brdf-mis:0.05,brdf-mis:0.1,brdf-mis:0.3,brdf-mis:0.7}
SAMPLERS_DIFFUSE=${SAMPLERS_DIFFUSE:-tree-split,brdf-mis}
# "fog": the participating-media scenes of issue 13 (Conty Estevez & Kulla 2018, §5.2): power
# sampling, the tree with and without splitting, each with the segment importance of ray
# segments (Eq. 7, the default) and with the surface importance at the segment's midpoint
# (/midpoint, the ablation).
# tree-split runs at the scene's threshold (0.85, as city.json) and at the default (0.25).
SAMPLERS_FOG=${SAMPLERS_FOG:-power,tree,tree/midpoint,tree-split,tree-split/midpoint,tree-split:0.25,tree-split:0.25/midpoint}
SCALE_COUNTS=${SCALE_COUNTS:-"1000 10000 100000"}
SCALE_SPP=${SCALE_SPP:-8}
SCALE_REPS=${SCALE_REPS:-3}
SCALE_FILM=${SCALE_FILM:-0.5}
SCALE_SAMPLERS=${SCALE_SAMPLERS:-brdf-mis,tree-split}
FOG_STATS_SPP=${FOG_STATS_SPP:-4}
SEEDS=${SEEDS:-3}
# Clamping (--clamp) biases heavy-tailed estimators (uniform sampling of the spiral, whose error
# would then grow with spp), so only cornell-1m clamps: its 10^6 sub-pixel ceiling lights are in
# view, and their anti-aliasing noise, which no light sampler changes, would otherwise dominate
# the RMSE. The other scenes keep emitters out of sight (points, spots; mesh-light's ring is just
# above the frame). glossy-cornell clamps for the same reason as cornell-1m (10^4 sub-pixel
# spheres on the side walls, in view); the showroom's lights are all above the frame. The default
# scene's 256 small ceiling quads are in view too (a few pixels each), so it clamps as well.

# The reference sampler is the most efficient one measured for the scene (any unbiased sampler
# converges to the same image; its seeds differ from the curves').
# The glossy scenes' references use MIS (unbiased for every material, including the
# near-specular ones); glossy-cornell's is power, which costs about a quarter of tree-split's time
# per spp there (tree-split splits to ~5 shadow rays per shading point among the 10^4 spheres) and
# had the lower equal-time error in a short trial run.
# name | film scale | budget (render s per configuration) | reference sampler | reference spp | clamp
#      | sampler set
SCENE_TABLE="
spiral-10k     | 0.25 | 20 | tree       | 1024 | 0 | many
cornell-1m     | 0.5  | 20 | power      | 2048 | 1 | many
city           | 0.5  | 20 | tree       | 1024 | 0 | many
mesh-light     | 0.75 | 20 | tree       | 768  | 0 | many
plane-10k      | 1    | 20 | tree       | 1024 | 0 | many
glossy-cornell | 0.5  | 20 | power      | 2048 | 1 | glossy
showroom       | 0.5  | 20 | tree-split | 1024 | 0 | glossy
default        | 0.5  | 20 | tree-split | 1024 | 1 | diffuse
spiral-fog     | 0.5  | 20 | tree-split | 256  | 1 | fog
city-fog       | 0.25 | 20 | tree-split | 256  | 0 | fog
"
SCENES=${SCENES:-"spiral-10k cornell-1m city mesh-light plane-10k glossy-cornell showroom default scalability spiral-fog city-fog"}

has_heatmap=0
if "$CANOPY" render --help 2>/dev/null | grep -q -- "--heatmap"; then has_heatmap=1; fi

# Fig. 10 of Liu et al.: render time against the light count. glossy-cornell is regenerated with
# each count (same generator and seed as the committed scene; the total power is fixed, so only
# the noise changes). `canopy converge` measures the render seconds (after its unrecorded warm-up
# render, so kernel compilation is excluded) of SCALE_REPS renders at SCALE_SPP spp; its reference
# is a throw-away 2-spp image (the RMSE is not used here).
scalability() {
  local n scene
  for n in $SCALE_COUNTS; do
    scene=$WORK/glossy-cornell-$n.json
    python3 scripts/gen-glossy-cornell.py --count "$n" --no-mesh --out "$scene" >&2
    echo "== scalability: $n lights, $SCALE_SPP spp x $SCALE_REPS, $SCALE_SAMPLERS" >&2
    "$CANOPY" converge "$scene" --film-scale "$SCALE_FILM" --reference "$WORK/scale-$n-ref.exr" \
      --reference-sampler power --reference-spp 2 --samplers "$SCALE_SAMPLERS" \
      --spp-start "$SCALE_SPP" --max-spp "$SCALE_SPP" --budget 100000 --seeds "$SCALE_REPS" \
      --out "$WORK/scale-$n" | tee "$WORK/scale-$n-converge.txt"
    cp "$WORK/scale-$n.csv" "$DOCS/scalability-$n.csv"
    cp "$WORK/scale-$n-configs.csv" "$DOCS/scalability-$n-configs.csv"
  done
}

start=$(date +%s)
for name in $SCENES; do
  if [ "$name" = scalability ]; then
    rm -f "$DOCS"/scalability-*.csv
    scalability
    echo "== scalability done, $(( $(date +%s) - start )) s so far" >&2
    continue
  fi
  row=$(echo "$SCENE_TABLE" | awk -F'|' -v OFS='|' -v n="$name" '{gsub(/ /, "", $1)} $1 == n')
  if [ -z "$row" ]; then echo "make-results: unknown scene $name" >&2; exit 2; fi
  IFS='|' read -r _ scale budget ref_sampler ref_spp clamp set <<<"$(echo "$row" | tr -d ' ')"
  budget=${BUDGET:-$budget}
  ref_spp=${REF_SPP:-$ref_spp}
  case "$set" in
    many) samplers=$SAMPLERS_MANY ;;
    glossy) samplers=$SAMPLERS_GLOSSY ;;
    diffuse) samplers=$SAMPLERS_DIFFUSE ;;
    fog) samplers=$SAMPLERS_FOG ;;
    *) echo "make-results: scene $name: unknown sampler set '$set'" >&2; exit 2 ;;
  esac
  clamp_opt=()
  if [ "$clamp" != 0 ]; then clamp_opt=(--clamp "$clamp"); fi
  scene=scenes/$name.json
  if [ ! -f "$scene" ]; then
    echo "make-results: $scene does not exist, skipped" >&2
    continue
  fi
  ref_opt=(--reference-sampler "$ref_sampler" --reference-spp "$ref_spp")
  if [ -n "${REUSE_REFERENCE:-}" ] && [ -f "$WORK/$name-ref.exr" ]; then
    ref_opt=()
    echo "== $name: reusing the reference $WORK/$name-ref.exr" >&2
  fi
  echo "== $name: reference $ref_sampler x $ref_spp spp, film scale $scale, budget $budget s," \
    "samplers $samplers" >&2
  # The fog scenes' report quotes its exact command lines ($DOCS/$name-commands.txt).
  if [ "$set" = fog ]; then
    echo "canopy converge $scene --film-scale $scale ${clamp_opt[*]} --reference" \
      "$WORK/$name-ref.exr ${ref_opt[*]} --samplers $samplers --budget $budget --seeds $SEEDS" \
      "--out $DOCS/$name" | tr -s ' ' >"$DOCS/$name-commands.txt"
    if [ ${#ref_opt[@]} = 0 ]; then
      echo "# (REUSE_REFERENCE: $WORK/$name-ref.exr is from an earlier run of this script, made" \
        "with --reference-sampler $ref_sampler --reference-spp $ref_spp)" >>"$DOCS/$name-commands.txt"
    fi
  fi
  "$CANOPY" converge "$scene" --film-scale "$scale" "${clamp_opt[@]}" \
    --reference "$WORK/$name-ref.exr" "${ref_opt[@]}" --samplers "$samplers" \
    --budget "$budget" --seeds "$SEEDS" --out "$DOCS/$name" | tee "$WORK/$name-converge.txt"
  # The reference's metadata, for the report.
  "$CANOPY" compare "$WORK/$name-ref.exr" "$WORK/$name-ref.exr" --json >"$DOCS/$name-reference.json"
  cp "$WORK/$name-ref.png" "$DOCS/$name.png"
  # Heat map of shadow rays per shading point (paper Fig. 18) at the scene's own resolution.
  rm -f "$DOCS/$name-heatmap.png"
  if [ "$has_heatmap" = 1 ]; then
    "$CANOPY" render "$scene" --spp 1 --light-sampler tree-split --out "$WORK/$name-heat.exr" \
      --png "$WORK/$name-heat.png" --heatmap "$DOCS/$name-heatmap.png" >/dev/null
  fi
  # Media: shadow rays per ray segment and per surface point (the paper's Fig. 1: "7 shadow rays
  # per shading point, 45 for the volume integral"), tree-split with either segment ranking, at
  # the scene's film and FOG_STATS_SPP spp (averages over 10^5-10^6 segments: more spp would not
  # change them).
  # Both segment rankings at the scene's threshold, and the segment importance at the default
  # threshold (0.25; stats-segment-0.25.json).
  if [ "$set" = fog ]; then
    for run in segment midpoint segment:0.25; do
      vi=${run%%:*}
      thr_opt=() tag=$vi
      if [ "$run" != "$vi" ]; then thr_opt=(--split-threshold "${run#*:}") tag=$vi-${run#*:}; fi
      "$CANOPY" render "$scene" --spp "$FOG_STATS_SPP" --light-sampler tree-split "${thr_opt[@]}" \
        --volume-importance "$vi" --out "$WORK/$name-stats-$tag.exr" \
        --stats-json "$DOCS/$name-stats-$tag.json" >/dev/null
      echo "canopy render $scene --spp $FOG_STATS_SPP --light-sampler tree-split ${thr_opt[*]}" \
        "--volume-importance $vi --out $WORK/$name-stats-$tag.exr --stats-json" \
        "$DOCS/$name-stats-$tag.json" | tr -s ' ' >>"$DOCS/$name-commands.txt"
    done
  fi
  echo "== $name done, $(( $(date +%s) - start )) s so far" >&2
done

# A line on this run for the report: what was regenerated, and with which budgets.
note="Last run ($(date -u '+%Y-%m-%d %H:%M') UTC): \`SCENES=\"$SCENES\"\`; render budget per"
if [ -n "${BUDGET:-}" ]; then note+=" configuration $BUDGET s,"
else note+=" configuration as in the scene table of make-results.sh,"; fi
note+=" $SEEDS seeds per point, reference spp ${REF_SPP:-as in the scene table}"
case " $SCENES " in
  *" scalability "*) note+="; scalability: $SCALE_SPP spp x $SCALE_REPS renders at film scale $SCALE_FILM" ;;
esac
note+=". Sections of scenes not in SCENES come from the CSVs of an earlier run (their own seeds"
note+=" and budgets)."
python3 scripts/results-report.py --docs "$DOCS" --command "./scripts/make-results.sh" \
  --seeds "$SEEDS" --note "$note" >"$REPORT.tmp"
mv "$REPORT.tmp" "$REPORT"
echo "wrote $REPORT ($(( $(date +%s) - start )) s)" >&2
