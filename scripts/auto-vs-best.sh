#!/usr/bin/env bash
# `auto` (render/auto_sampler.h) against the best configuration of each table of docs/results.md,
# in one converge run per table (both configurations alternate on the same machine state), with the
# references of scripts/make-results.sh (REUSE them: WORK as there). Writes docs/results/auto/ and
# prints one line per table: auto's choice, both non-emitter efficiencies with 95% intervals, their
# ratio and whether auto meets the rule (within 10% or overlapping intervals). About 20 minutes.
#
#   WORK=/path/to/references ./scripts/auto-vs-best.sh
#   TABLES="glossy-cornell-dfull showroom-d1" ./scripts/auto-vs-best.sh
set -euo pipefail
cd "$(dirname "$0")/.."
CANOPY=${CANOPY:-build/canopy}
WORK=${WORK:-out/results}
OUT=${OUT:-docs/results/auto}
mkdir -p "$OUT"
# The best configuration of each table (docs/results.md, Summary).
declare -A BEST=(
  [default-d1]=tree [default-dfull]=tree [glossy-cornell-d1]=tree [glossy-cornell-dfull]=tree
  [showroom-d1]=power [showroom-dfull]=power [cornell-1k-d1]=tree [cornell-1k-dfull]=tree
  [cornell-1m-d1]=tree [cornell-1m-dfull]=power [plane-10k-dfull]=tree-split
  [spiral-10k-d1]=tree-split:0.25 [spiral-10k-dfull]=tree-split:0.25 [city-d1]=tree-split:0.25
  [city-dfull]=brdf-mis/split=0.25 [mesh-light-dfull]=tree [spiral-fog-d1]=brdf-mis/split=0.25
  [spiral-fog-dfull]=tree [city-fog-d1]=tree-split:0.25 [city-fog-dfull]=tree-split:0.25
  [outdoor-d1]=tree [outdoor-dfull]=power)
for t in ${TABLES:-$(printf '%s\n' "${!BEST[@]}" | sort)}; do
  # The table's own command (docs/results/<table>-commands.txt) with its reference, other samplers.
  cmd=$(head -1 "docs/results/$t-commands.txt" |
    sed "s|^canopy|$CANOPY|; s|--samplers [^ ]*|--samplers auto,${BEST[$t]}|; s|--out [^ ]*|--out $OUT/$t|; s|--reference [^ ]*/\([^/ ]*\)|--reference $WORK/\1|")
  echo "== $t: $cmd" >&2
  $cmd >"$OUT/$t-converge.txt" 2>&1
done
python3 - "$OUT" <<'PY'
import csv, glob, os, re, sys
out = sys.argv[1]
for f in sorted(glob.glob(os.path.join(out, "*-points.csv"))):
    t = os.path.basename(f)[:-len("-points.csv")]
    e = {r["sampler"]: [float(r[k]) for k in ("efficiency_ne", "efficiency_lo_ne", "efficiency_hi_ne")]
         for r in csv.DictReader(open(f))}
    log = open(os.path.join(out, t + "-converge.txt")).read()
    m = re.search(r"auto: (\S+)", log)
    other = [k for k in e if k != "auto"][0]
    a, b = e["auto"], e[other]
    ratio = a[0] / b[0]
    ok = ratio >= 0.9 or (a[1] <= b[2] and b[1] <= a[2])
    print(f"| {t} | {m.group(1) if m else '?'} | {a[0]:.4g} [{a[1]:.4g}, {a[2]:.4g}] | {other} | "
          f"{b[0]:.4g} [{b[1]:.4g}, {b[2]:.4g}] | {ratio:.2f} | {'yes' if ok else 'no'} |")
PY
