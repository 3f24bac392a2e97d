#!/usr/bin/env bash
# The engine on arm64 (the default build runs on any x86-64 and builds on arm64; every path gives
# the same bits), with Debian's cross compiler and qemu-user (scripts/ci-packages.sh
# installs g++-aarch64-linux-gnu and qemu-user-static; without them this exits 77, skipped):
#  1. tests/arm64/lane_bits.cc (the lane code: the elementary functions, the deviates, the lockstep kernel's
#     sensor and mechanization steps, the statistics' error components) built for this machine and
#     for arm64 with the engine's options (-ffp-contract=off; the kernel files' -fno-math-errno
#     -fvect-cost-model=dynamic), the arm64 one run under qemu: both print the same digests, line
#     for line (the C library's results, which differ between x86-64 and arm64 for log, hypot,
#     exp2 and cbrt, are not used).
#  2. every engine source through the arm64 compiler with the engine's warnings as errors
#     (-fsyntax-only: parsing, templates instantiated; Eigen's and oneTBB's headers are
#     architecture-independent), and the three lockstep kernel files compiled to arm64 code.
# Usage: same_bits.sh SOURCE_DIR WORK_DIR [HOST_CXX]
set -euo pipefail
src="$1"
work="$2"
host_cxx="${3:-c++}"
cross=aarch64-linux-gnu-g++
for tool in "$cross" qemu-aarch64-static; do
  if ! command -v "$tool" > /dev/null; then
    echo "skipped: $tool not found (Debian: g++-aarch64-linux-gnu, qemu-user-static;" \
      "scripts/ci-packages.sh installs them)"
    exit 77
  fi
done
mkdir -p "$work/include"
# Eigen's and oneTBB's headers as system headers for the cross compiler (their own warnings are
# not ours), without the rest of the machine's /usr/include.
ln -sfn /usr/include/eigen3/Eigen "$work/include/Eigen"
ln -sfn /usr/include/eigen3/unsupported "$work/include/unsupported"
ln -sfn /usr/include/oneapi "$work/include/oneapi"
ln -sfn /usr/include/tbb "$work/include/tbb"
common=(-std=c++20 -ffp-contract=off -Wall -Wextra -Wpedantic -Werror -Wno-psabi
  "-I$src/engine/src" "-I$src/engine/include")
kernel_options=(-O2 -fno-math-errno -fvect-cost-model=dynamic)
# Compilations go through ccache when it is installed (CI's cache, with paths relative to the
# source tree as in the CMake build), so an unchanged engine costs seconds, not minutes.
launcher=()
if command -v ccache > /dev/null; then
  launcher=(env CCACHE_BASEDIR="$src" CCACHE_NOHASHDIR=1 ccache)
fi

"${launcher[@]}" "$host_cxx" "${common[@]}" "${kernel_options[@]}" -c \
  "$src/tests/arm64/lane_bits.cc" -o "$work/lane_bits_host.o"
"$host_cxx" "$work/lane_bits_host.o" -o "$work/lane_bits_host"
"${launcher[@]}" "$cross" "${common[@]}" "${kernel_options[@]}" -c \
  "$src/tests/arm64/lane_bits.cc" -o "$work/lane_bits_arm64.o"
"$cross" -static "$work/lane_bits_arm64.o" -o "$work/lane_bits_arm64"
"$work/lane_bits_host" > "$work/host.txt"
qemu-aarch64-static "$work/lane_bits_arm64" > "$work/arm64.txt"
echo "--- this machine ($(uname -m))"
cat "$work/host.txt"
echo "--- arm64 (qemu-aarch64-static)"
cat "$work/arm64.txt"
if [ "$(wc -l < "$work/host.txt")" -lt 10 ]; then
  echo "FAILED: lane_bits printed $(wc -l < "$work/host.txt") lines, expected 10 or more" >&2
  exit 1
fi
if ! diff "$work/host.txt" "$work/arm64.txt"; then
  echo "FAILED: the lane code gives different bits on arm64 (lines above)" >&2
  exit 1
fi

echo "--- engine sources through $cross"
failed=0
# Every source through the compiler's front end (-fsyntax-only: parsing, templates instantiated).
# A source whose preprocessed text, compiler and options were checked before is not checked again:
# its result is kept in a stamp file named by the hash of all three (what ccache does for object
# files, which it cannot do for -fsyntax-only), so an unchanged engine costs the preprocessing.
# Paths are taken out of the key, so clones of the same sources share the stamps.
stamps="${XDG_CACHE_HOME:-$HOME/.cache}/driftlab/arm64-syntax"
mkdir -p "$stamps"
export stamps src
# shellcheck disable=SC2016
find "$src/engine/src" -name '*.cc' | sort | xargs -P "$(nproc)" -I{} sh -c '
  set -- "$@"
  key=$( { "$0" --version; echo "$*"; "$0" "$@" -E -isystem "'"$work"'/include" \
    -DDRIFTLAB_VERSION=\"0\" {} | grep -v "^# "; } | sed "s|$src||g" | sha256sum | cut -c1-32)
  [ -f "$stamps/$key" ] && exit 0
  "$0" "$@" -fsyntax-only -isystem "'"$work"'/include" -DDRIFTLAB_VERSION=\"0\" {} ||
    { echo "FAILED: {}"; exit 1; }
  touch "$stamps/$key"' "$cross" "${common[@]}" || failed=1
for f in $(find "$src/engine/src" -name 'lockstep_ned_*.cc' ! -name '*kernel*' | sort); do
  "${launcher[@]}" "$cross" "${common[@]}" "${kernel_options[@]}" -isystem "$work/include" -c \
    "$f" -o "$work/$(basename "$f" .cc).o" || failed=1
done
if [ "$failed" -ne 0 ]; then
  echo "FAILED: the engine does not build for arm64 (errors above)" >&2
  exit 1
fi
echo "engine: $(find "$src/engine/src" -name '*.cc' | wc -l) sources pass the arm64 compiler;" \
  "the lockstep kernels compile to arm64 code"
echo "PASSED: the lane code gives the same bits on $(uname -m) and arm64"
