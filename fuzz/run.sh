#!/usr/bin/env bash
# Longer fuzzing on demand: fuzz/run.sh TARGET SECONDS [libFuzzer flags...]
# Builds the fuzz targets (fuzz/lib.sh) and fuzzes TARGET for SECONDS of wall time. The corpus it
# grows stays in build-fuzz/corpus/TARGET; a crashing input lands in build-fuzz/artifacts/TARGET/.
# fuzz/run.sh list prints the targets. Example, keep going after crashes:
#   fuzz/run.sh job_yaml 3600 -fork=1 -ignore_crashes=1
set -euo pipefail
cd "$(dirname "$0")/.."
source fuzz/lib.sh

if [ "${1:-}" = "list" ]; then
  fuzz_targets
  exit 0
fi
if [ $# -lt 2 ]; then
  echo "usage: fuzz/run.sh TARGET SECONDS [libFuzzer flags...]; targets:" $(fuzz_targets) >&2
  exit 2
fi
target="$1"
if ! fuzz_targets | grep -qx "$target"; then
  echo "fuzz/run.sh: unknown target '$target'; targets:" $(fuzz_targets) >&2
  exit 2
fi
if ! fuzz_toolchain_available; then
  echo "fuzz/run.sh: $fuzz_cxx with libFuzzer's runtime is not available" \
    "(Debian: apt-get install clang-14 libclang-rt-14-dev)" >&2
  exit 1
fi
fuzz_build
fuzz_run "$@"
