#!/usr/bin/env bash
# One job, one answer on any CPU (DESIGN.md "Same bits everywhere"): glibc on x86-64 picks an FMA
# or an SSE2 variant of exp, log, sin, cos, atan2, ... by CPU at run time, and the two round some
# arguments differently; the engine uses its own functions (driftlab/elementary.h) so that its
# results do not depend on that choice. Each example job (8 runs) is run as this machine runs it
# and with glibc told that the CPU has no AVX, AVX2, AVX-512 or FMA (GLIBC_TUNABLES: glibc then
# takes its SSE2 variants, as on an older or a virtual CPU); the result files, but for their
# timing fields, must be the same bytes.
# Exits 77 (skipped) where the tunable changes nothing (a CPU without FMA, or a glibc that
# ignores it): there the comparison would show nothing.
# Usage: glibc_variants.sh DRIFTLAB SOURCE_DIR WORK_DIR
set -euo pipefail
driftlab="$1"
src="$2"
work="$3"
variant="glibc.cpu.hwcaps=-AVX2,-FMA,-AVX512F,-AVX"
mkdir -p "$work"
probe='import math, hashlib
h = hashlib.sha256()
for i in range(1, 200000):
    x = i * 0.7390851332151607
    h.update(math.sin(x).hex().encode()); h.update(math.exp(x % 700).hex().encode())
print(h.hexdigest())'
if [ "$(/usr/bin/python3 -c "$probe")" = "$(GLIBC_TUNABLES=$variant /usr/bin/python3 -c "$probe")" ]; then
  echo "skipped: glibc's math functions give the same bits with and without $variant here"
  exit 77
fi
echo "glibc's sin/exp differ between the machine's variant and the SSE2 one here: comparing"
strip_timing() { tr ',' '\n' < "$1" | grep -v '"wall_s"\|"cpu_s"\|"samples_per_s"'; }
failed=0
for job in car_drive.json car_drive_gnss.json aircraft_climb_turns.yaml seed002_zigzag.json \
  seed002_circle.json seed002_static.json ship_seaway.json static_alignment_navigation.yaml \
  gnss_ins_sim_import.json; do
  name="${job%.*}"
  "$driftlab" run "$src/examples/$job" --runs 8 --out "$work/$name.native.json" > /dev/null \
    2>> "$work/progress.log"
  GLIBC_TUNABLES="$variant" "$driftlab" run "$src/examples/$job" --runs 8 \
    --out "$work/$name.sse2.json" > /dev/null 2>> "$work/progress.log"
  differing=$( (diff <(strip_timing "$work/$name.native.json") \
    <(strip_timing "$work/$name.sse2.json") || true) | grep -c '^<' || true)
  if [ "$differing" -ne 0 ]; then
    echo "FAILED: $name: $differing lines of the result differ between glibc's variants" >&2
    failed=1
  else
    echo "$name: the same bytes"
  fi
done
exit "$failed"
