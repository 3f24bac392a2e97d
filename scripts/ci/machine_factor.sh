#!/usr/bin/env bash
# The machine factor: how much slower (> 1) or faster (< 1) this machine compiles and runs than the
# reference machine that CI's time budgets (.ci/run) and the README's figures were measured on.
#
# Workload: scripts/ci/machine_speed.cc (Eigen, standard containers; like driftlab's own sources)
# compiled at -O2, two compilations at once as the build runs them on the 2-core machines of this
# kind, three rounds (fewer when they take over 40 s: a loaded machine); the factor is the median
# round's wall time over the reference's. A machine with one core, a slower CPU or a CPU shared
# with another load shows it in the factor. About 21 s on the reference machine.
#
# Reference machine: 2-core AMD EPYC (family 25, AVX2, no AVX-512) under KVM, Debian 12, g++ 12.2,
# idle; the workload's median round took reference_round_s (below) there (measured 2026-11-28,
# rounds within 2 % of each other). Change both together.
#
# Prints `machine factor F (median round X s, reference Y s; rounds ...)` on stderr and F alone on
# stdout. DRIFTLAB_MACHINE_FACTOR=F skips the measurement and uses F.
set -euo pipefail
reference_round_s=7.00
here="$(cd "$(dirname "$0")" && pwd)"

if [ -n "${DRIFTLAB_MACHINE_FACTOR:-}" ]; then
  echo "machine factor ${DRIFTLAB_MACHINE_FACTOR} (from DRIFTLAB_MACHINE_FACTOR, not measured)" >&2
  echo "$DRIFTLAB_MACHINE_FACTOR"
  exit 0
fi
cxx="${CXX:-g++}"
eigen=/usr/include/eigen3
if ! command -v "$cxx" > /dev/null || [ ! -d "$eigen" ]; then
  echo "machine factor 1 (not measured: $cxx or Eigen's headers in $eigen missing)" >&2
  echo 1
  exit 0
fi
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
rounds=()
measure_start=$(date +%s)
for round in 1 2 3; do
  # On a heavily loaded machine a round takes minutes: after 40 s the rounds so far decide.
  if [ "${#rounds[@]}" -gt 0 ] && [ $(($(date +%s) - measure_start)) -gt 40 ]; then break; fi
  start=$(date +%s%N)
  for copy in 1 2; do
    "$cxx" -std=c++20 -O2 -I"$eigen" -c "$here/machine_speed.cc" -o "$scratch/$copy.o" &
  done
  wait
  rounds+=("$(awk -v ns="$(($(date +%s%N) - start))" 'BEGIN { printf "%.2f", ns / 1e9 }')")
done
median=$(printf '%s\n' "${rounds[@]}" | sort -g | sed -n "$(((${#rounds[@]} + 1) / 2))p")
factor=$(awk -v m="$median" -v r="$reference_round_s" 'BEGIN { printf "%.2f", m / r }')
echo "machine factor ${factor} (median round ${median} s, reference ${reference_round_s} s;" \
  "rounds ${rounds[*]} s)" >&2
echo "$factor"
