#!/usr/bin/env bash
# Installs dependencies, builds driftlab with its tests and benchmarks, and runs every test: the
# README's test command.
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
bash bootstrap.sh
# shellcheck disable=SC2086
cmake -S . -B "$build_dir" -G Ninja ${DRIFTLAB_CMAKE_FLAGS:-}
cmake --build "$build_dir" --parallel "$(nproc)"
if [ "$build_only" -eq 1 ]; then exit 0; fi
# shellcheck disable=SC2086
ctest --test-dir "$build_dir" --output-on-failure --parallel "$(nproc)" ${DRIFTLAB_CTEST_FLAGS:-}
