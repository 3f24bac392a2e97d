#!/usr/bin/env bash
# no_warnings.sh COMMAND...: runs COMMAND (a build), passing its output through, and fails when
# the compiler or the linker warned (a line with ": warning: "), naming the warnings. CI's way of
# treating warnings as errors without -Werror on the command line, so CI's compile commands are
# the README's and share their compiler cache. A compilation served from the cache replays its
# warnings, so a warning is seen whether or not the file was compiled again.
set -uo pipefail
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
"$@" 2>&1 | tee "$log"
status="${PIPESTATUS[0]}"
if [ "$status" -ne 0 ]; then exit "$status"; fi
if grep -q ': warning: ' "$log"; then
  echo "no_warnings: FAILED: the build warned ($(grep -c ': warning: ' "$log") lines); warnings" \
    "are errors in CI:" >&2
  grep ': warning: ' "$log" | sort -u | head -20 >&2
  exit 1
fi
