#!/usr/bin/env bash
# CI's bounded fuzzing (.ci/run's "fuzz" phase, budget 120 s): builds the libFuzzer targets
# (fuzz/lib.sh) and runs each for DRIFTLAB_FUZZ_SECONDS (default 8; in CI what the build left of
# the phase budget, 2 to 8) of wall time, as many at once as there are cores. Any crash, sanitizer
# report, leak, timeout or memory blow-up fails the phase and names the input; add it to
# fuzz/regressions/<target>/ with the fix. Without clang++-14 and libFuzzer's runtime the phase is
# skipped (exit 0) with a message saying so.
#
# Longer runs on demand: fuzz/run.sh TARGET SECONDS.
set -euo pipefail
cd "$(dirname "$0")/.."
source fuzz/lib.sh

if ! fuzz_toolchain_available; then
  echo "fuzz: SKIPPED: $fuzz_cxx with libFuzzer's runtime is not available" \
    "(Debian: apt-get install clang-14 libclang-rt-14-dev); the saved inputs still run in the" \
    "normal build's fuzz_regression_tests"
  exit 0
fi

start=$(date +%s)
fuzz_build
echo "fuzz: built in $(($(date +%s) - start)) s"

seconds="${DRIFTLAB_FUZZ_SECONDS:-8}"
# Inside CI's phase budget (DRIFTLAB_FUZZ_PHASE_S, set by .ci/run) the fuzzing gets what the build
# left: after a slow build (a partly cold compiler cache) each target runs shorter, down to 2 s,
# instead of the phase overrunning. An explicit DRIFTLAB_FUZZ_SECONDS wins.
if [ -n "${DRIFTLAB_FUZZ_PHASE_S:-}" ] && [ -z "${DRIFTLAB_FUZZ_SECONDS:-}" ]; then
  built=$(($(date +%s) - start))
  targets=$(fuzz_targets | wc -l)
  rounds=$(((targets + $(nproc) - 1) / $(nproc)))
  fit=$(((DRIFTLAB_FUZZ_PHASE_S - built - 15) / rounds))  # 15 s: start-up, summary, margin
  seconds=$((fit < 8 ? fit : 8))
  seconds=$((seconds < 2 ? 2 : seconds))
  echo "fuzz: ${seconds} s per target (phase budget ${DRIFTLAB_FUZZ_PHASE_S} s, built in ${built} s)"
fi
logs="$fuzz_build_dir/logs"
mkdir -p "$logs"
export -f fuzz_run
export fuzz_build_dir
# One target per core at a time; each run's log is kept, a failing run's tail is printed.
status=0
fuzz_targets | xargs -P "$(nproc)" -I{} bash -c \
  'fuzz_run {} '"$seconds"' > '"$logs"'/{}.log 2>&1 || { echo "fuzz: FAILED: {}"; exit 1; }' ||
  status=$?
for target in $(fuzz_targets); do
  summary=$(grep -E '^#[0-9]+.*(cov|DONE)' "$logs/$target.log" | tail -1 || true)
  printf 'fuzz: %-20s %s\n' "$target" "${summary:-no status line}"
done
if [ "$status" -ne 0 ]; then
  for target in $(fuzz_targets); do
    if grep -qE '^(==[0-9]+==ERROR|SUMMARY|.*runtime error|.*deadly signal|.*Test unit written)' \
      "$logs/$target.log"; then
      echo "=== fuzz: $target ($logs/$target.log):"
      grep -E 'ERROR|SUMMARY|runtime error|deadly signal|Test unit written|#[0-9]+ 0x' \
        "$logs/$target.log" | head -40
    fi
  done
  echo "fuzz: FAILED: a target crashed; its input is in $fuzz_build_dir/artifacts/<target>/." \
    "Reproduce with $fuzz_build_dir/fuzz/<target>_fuzzer FILE, fix it, and add FILE to" \
    "fuzz/regressions/<target>/." >&2
  exit 1
fi
echo "fuzz: all targets ran ${seconds} s without a finding ($(($(date +%s) - start)) s in all)"
