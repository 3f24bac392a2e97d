#!/bin/sh
# Submits a driftlab job to Slurm by hand: a K-task array (one shard each) and a merge step that
# runs when every task succeeded. Prints both job ids.
#   deploy/slurm/submit.sh JOB K DIR RESULT [REPORT] [-- sbatch options, e.g. --partition=P]
# DIR must be on a filesystem the nodes share; $DRIFTLAB names the binary (default: driftlab).
set -eu
if [ $# -lt 4 ]; then
  echo "usage: $0 JOB K DIR RESULT [REPORT] [-- sbatch options]" >&2
  exit 2
fi
here="$(cd "$(dirname "$0")" && pwd)"
job="$1" k="$2" dir="$3" result="$4"
shift 4
report=""
if [ $# -gt 0 ] && [ "$1" != "--" ]; then report="$1"; shift; fi
if [ $# -gt 0 ] && [ "$1" = "--" ]; then shift; fi
mkdir -p "$dir"
array=$(sbatch --parsable "$@" --array="0-$((k - 1))" --output="$dir/shard-%a.log" \
  "$here/driftlab-shard.sbatch" "$job" "$dir")
array="${array%%;*}"
# shellcheck disable=SC2086
merge=$(sbatch --parsable "$@" --dependency="afterok:$array" --output="$dir/merge.log" \
  "$here/driftlab-merge.sbatch" "$dir" "$k" "$result" $report)
echo "array job $array ($k shards), merge job ${merge%%;*}"
