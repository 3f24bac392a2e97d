#!/usr/bin/env bash
# Installs every package the tests need, builds driftlab with its tests and benchmarks, and runs
# every test: the README's test command. Prints the machine factor (scripts/ci/machine_factor.sh: how much slower
# than the reference machine this one is) and the time of each step, so a slow machine is visible.
# Usage: scripts/test.sh [BUILD_DIR] [--build-only]
#   extra CMake flags in $DRIFTLAB_CMAKE_FLAGS, extra ctest flags in $DRIFTLAB_CTEST_FLAGS.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=build
build_only=0
for arg in "$@"; do
  case "$arg" in
    --build-only) build_only=1 ;;
    *) build_dir="$arg" ;;
  esac
done
times=()
step_start=$(date +%s)
done_step() {
  times+=("$(printf '%-10s %5d s' "$1" $(($(date +%s) - step_start)))")
  step_start=$(date +%s)
}
report() {
  echo "=== test.sh: machine factor ${factor:-not measured}; times:"
  if [ "${#times[@]}" -gt 0 ]; then printf '  %s\n' "${times[@]}"; fi
}
trap report EXIT

# Every package a test needs, so that no test is skipped for a missing one: the build's and the
# tests' (bootstrap.sh --tests), and the ones CI's tests need (Slurm, clang-14, chromium, the arm64
# cross compiler and qemu; scripts/ci-packages.sh).
bash bootstrap.sh --tests
bash scripts/ci-packages.sh
done_step packages
factor=$(bash scripts/ci/machine_factor.sh)
done_step factor
# shellcheck disable=SC2086
cmake -S . -B "$build_dir" -G Ninja ${DRIFTLAB_CMAKE_FLAGS:-}
done_step configure
cmake --build "$build_dir" --parallel "$(nproc)"
done_step build
if [ "$build_only" -eq 1 ]; then exit 0; fi
# shellcheck disable=SC2086
ctest --test-dir "$build_dir" --output-on-failure --parallel "$(nproc)" ${DRIFTLAB_CTEST_FLAGS:-}
done_step test
