#!/usr/bin/env bash
# Installs dependencies, builds driftlab and runs every test: the README's test command.
# Usage: scripts/test.sh [BUILD_DIR]   (extra CMake flags in $DRIFTLAB_CMAKE_FLAGS,
#                                       extra ctest flags in $DRIFTLAB_CTEST_FLAGS)
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${1:-build}"
bash bootstrap.sh
# shellcheck disable=SC2086
cmake -S . -B "$build_dir" -G Ninja ${DRIFTLAB_CMAKE_FLAGS:-}
cmake --build "$build_dir" --parallel "$(nproc)"
# shellcheck disable=SC2086
ctest --test-dir "$build_dir" --output-on-failure --parallel "$(nproc)" ${DRIFTLAB_CTEST_FLAGS:-}
