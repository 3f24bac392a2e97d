#!/usr/bin/env bash
# A measured fuzzing campaign of one target: fuzz/measure.sh TARGET CPU_SECONDS
# Runs TARGET (built by fuzz/ci.sh or fuzz/run.sh) under `nice -n 19` in libFuzzer's fork mode
# (crashes, timeouts and memory blow-ups are recorded in build-fuzz/artifacts/TARGET/ and the run
# goes on) until the process tree has used CPU_SECONDS of CPU time, then prints one line: target,
# CPU seconds, executions, findings (artifact files), and libFuzzer's last cov:/ft: figures.
# The log is build-fuzz/logs/TARGET.measure.log.
set -euo pipefail
cd "$(dirname "$0")/.."
source fuzz/lib.sh

target="$1" cpu_budget_s="$2"
if [ ! -x "$fuzz_build_dir/fuzz/${target}_fuzzer" ]; then
  echo "fuzz/measure.sh: build the targets first (fuzz/ci.sh or fuzz/run.sh)" >&2
  exit 1
fi
logs="$fuzz_build_dir/logs"
mkdir -p "$logs"
log="$logs/$target.measure.log"
ticks_per_s=$(getconf CLK_TCK)

# CPU ticks of a process and its live descendants; each one's cutime/cstime holds its reaped
# children, so the sum is the whole tree's CPU time so far.
tree_ticks() {
  local total=0 p stat fields
  for p in $(descendants "$1") "$1"; do
    stat=$(cat "/proc/$p/stat" 2> /dev/null) || continue
    read -r -a fields <<< "${stat##*) }"
    total=$((total + fields[11] + fields[12] + fields[13] + fields[14]))
  done
  echo "$total"
}
descendants() {
  local c
  for c in $(pgrep -P "$1" || true); do
    echo "$c"
    descendants "$c"
  done
}

export -f fuzz_run
export fuzz_build_dir
setsid nice -n 19 bash -c "fuzz_run $target 86400 -fork=1 -ignore_crashes=1 -ignore_timeouts=1 \
  -ignore_ooms=1" > "$log" 2>&1 &
leader=$!
ticks=0
while kill -0 "$leader" 2> /dev/null; do
  ticks=$(tree_ticks "$leader")
  if [ "$ticks" -ge $((cpu_budget_s * ticks_per_s)) ]; then
    # libFuzzer's fork-mode parent outlives SIGINT and SIGTERM (LLVM 14): stop the group.
    kill -INT -- "-$leader" 2> /dev/null || true
    sleep 3
    kill -KILL -- "-$leader" 2> /dev/null || true
    break
  fi
  sleep 2
done
wait "$leader" 2> /dev/null || true
last=$(grep -E '^#[0-9]+: cov:' "$log" | tail -1)
execs=$(sed -n 's/^#\([0-9]*\):.*/\1/p' <<< "$last")
cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<< "$last")
ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<< "$last")
findings=$(find "$fuzz_build_dir/artifacts/$target" -type f | wc -l)
printf '%-20s cpu_s=%d execs=%s findings=%s cov=%s ft=%s\n' "$target" \
  $((ticks / ticks_per_s)) "${execs:-?}" "$findings" "${cov:-?}" "${ft:-?}"
