#!/usr/bin/env bash
# Renders a scene on a Slurm cluster: a job array of TASKS sample ranges, then a merge job that
# depends on it (docs/distributed.md).
#
#   scripts/slurm/submit.sh SCENE SPP TASKS OUT.exr [canopy render flags...]
#
# Environment: CANOPY (default: canopy on PATH), PARTS (default: OUT's directory/OUT-parts),
# SBATCH_ARGS (more sbatch flags for both jobs, e.g. "--partition=render --time=2:00:00").
# Paths must be on storage every node sees. Prints the two job ids.
set -euo pipefail
if [ $# -lt 4 ]; then
  echo "usage: $0 SCENE SPP TASKS OUT.exr [canopy render flags...]" >&2
  exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
SCENE=$(realpath "$1") SPP=$2 TASKS=$3 OUT=$(realpath -m "$4")
shift 4
CANOPY=$(realpath "${CANOPY:-$(command -v canopy)}")
PARTS=$(realpath -m "${PARTS:-${OUT%.exr}-parts}")
case "$SPP$TASKS" in *[!0-9]*) echo "submit.sh: SPP and TASKS must be positive integers" >&2; exit 2 ;; esac
if [ "$TASKS" -lt 1 ] || [ "$SPP" -lt 1 ]; then echo "submit.sh: SPP and TASKS must be >= 1" >&2; exit 2; fi
mkdir -p "$PARTS"
rm -f "$PARTS"/part-*.exr
export CANOPY SCENE SPP PARTS OUT TASKS RENDER_ARGS="$*"
# shellcheck disable=SC2086 # SBATCH_ARGS is a list of flags
array=$(sbatch --parsable ${SBATCH_ARGS:-} --array=0-$((TASKS - 1)) --export=ALL \
  --output="$PARTS/range-%a.log" "$here/render-range.sbatch")
array=${array%%;*}
# shellcheck disable=SC2086
merge=$(sbatch --parsable ${SBATCH_ARGS:-} --dependency=afterany:"$array" --export=ALL \
  --output="$PARTS/merge.log" "$here/merge.sbatch")
merge=${merge%%;*}
echo "array job $array ($TASKS sample ranges of $SPP spp), merge job $merge -> $OUT"
echo "logs: $PARTS/range-<task>.log, $PARTS/merge.log"
echo "rerun one failed task i: sbatch --array=i --export=ALL $here/render-range.sbatch (same environment), then the merge"
