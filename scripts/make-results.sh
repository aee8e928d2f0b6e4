#!/usr/bin/env bash
# Regenerates docs/results.md and everything in docs/results/ from scratch: builds canopy, renders
# a reference per scene, runs `canopy converge` for every sampler configuration, renders the heat
# maps, and writes the report (scripts/results-report.py). About 25 minutes on 2 cores; not run
# by CI. Timings are only meaningful on an otherwise idle machine.
#
#   ./scripts/make-results.sh                 # everything
#   SCENES="spiral-10k city" ./scripts/make-results.sh   # a subset (the report covers what exists)
#   SCENES="glossy-cornell showroom" ./scripts/make-results.sh   # the glossy scenes (issue 11)
#   CANOPY=path/to/canopy SKIP_BUILD=1 ./scripts/make-results.sh
#   # A dry run of the machinery (meaningless numbers, nothing under docs/ touched):
#   BUDGET=1 REF_SPP=16 SEEDS=1 DOCS=/tmp/r REPORT=/tmp/r.md SCENES=plane-10k ./scripts/make-results.sh
#
# Environment: SCENES, BUILD, CANOPY, SKIP_BUILD; BUDGET and REF_SPP override every scene's budget
# and reference spp; SEEDS (3); WORK (out/results), DOCS (docs/results) and REPORT
# (docs/results.md) move the outputs; SAMPLERS_MANY and SAMPLERS_GLOSSY replace the two sampler
# sets.
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
# each light sampler with MIS and without (/nomis; bsdf has no light samples, so no MIS variant).
SAMPLERS_MANY=${SAMPLERS_MANY:-uniform,power,tree,tree-noorient,tree-split:0.0,tree-split:0.25,tree-split:0.5,tree-split:0.85,tree-split:0.95}
SAMPLERS_GLOSSY=${SAMPLERS_GLOSSY:-tree-split,tree-split/nomis,power,power/nomis,bsdf}
SEEDS=${SEEDS:-3}
# Clamping (--clamp) biases heavy-tailed estimators (uniform sampling of the spiral, whose error
# would then grow with spp), so only cornell-1m clamps: its 10^6 sub-pixel ceiling lights are in
# view, and their anti-aliasing noise, which no light sampler changes, would otherwise dominate
# the RMSE. The other scenes keep emitters out of sight (points, spots; mesh-light's ring is just
# above the frame). glossy-cornell clamps for the same reason as cornell-1m (10^4 sub-pixel
# spheres on the side walls, in view); the showroom's lights are all above the frame.

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
"
SCENES=${SCENES:-"spiral-10k cornell-1m city mesh-light plane-10k glossy-cornell showroom"}

has_heatmap=0
if "$CANOPY" render --help 2>/dev/null | grep -q -- "--heatmap"; then has_heatmap=1; fi

start=$(date +%s)
for name in $SCENES; do
  row=$(echo "$SCENE_TABLE" | awk -F'|' -v OFS='|' -v n="$name" '{gsub(/ /, "", $1)} $1 == n')
  if [ -z "$row" ]; then echo "make-results: unknown scene $name" >&2; exit 2; fi
  IFS='|' read -r _ scale budget ref_sampler ref_spp clamp set <<<"$(echo "$row" | tr -d ' ')"
  budget=${BUDGET:-$budget}
  ref_spp=${REF_SPP:-$ref_spp}
  case "$set" in
    many) samplers=$SAMPLERS_MANY ;;
    glossy) samplers=$SAMPLERS_GLOSSY ;;
    *) echo "make-results: scene $name: unknown sampler set '$set'" >&2; exit 2 ;;
  esac
  clamp_opt=()
  if [ "$clamp" != 0 ]; then clamp_opt=(--clamp "$clamp"); fi
  scene=scenes/$name.json
  if [ ! -f "$scene" ]; then
    echo "make-results: $scene does not exist, skipped" >&2
    continue
  fi
  echo "== $name: reference $ref_sampler x $ref_spp spp, film scale $scale, budget $budget s," \
    "samplers $samplers" >&2
  "$CANOPY" converge "$scene" --film-scale "$scale" "${clamp_opt[@]}" \
    --reference "$WORK/$name-ref.exr" --reference-sampler "$ref_sampler" \
    --reference-spp "$ref_spp" --samplers "$samplers" --budget "$budget" --seeds "$SEEDS" \
    --out "$DOCS/$name" | tee "$WORK/$name-converge.txt"
  # The reference's metadata, for the report.
  "$CANOPY" compare "$WORK/$name-ref.exr" "$WORK/$name-ref.exr" --json >"$DOCS/$name-reference.json"
  cp "$WORK/$name-ref.png" "$DOCS/$name.png"
  # Heat map of shadow rays per shading point (paper Fig. 18) at the scene's own resolution.
  rm -f "$DOCS/$name-heatmap.png"
  if [ "$has_heatmap" = 1 ]; then
    "$CANOPY" render "$scene" --spp 1 --light-sampler tree-split --out "$WORK/$name-heat.exr" \
      --png "$WORK/$name-heat.png" --heatmap "$DOCS/$name-heatmap.png" >/dev/null
  fi
  echo "== $name done, $(( $(date +%s) - start )) s so far" >&2
done

python3 scripts/results-report.py --docs "$DOCS" --command "./scripts/make-results.sh" \
  --seeds "$SEEDS" >"$REPORT.tmp"
mv "$REPORT.tmp" "$REPORT"
echo "wrote $REPORT ($(( $(date +%s) - start )) s)" >&2
