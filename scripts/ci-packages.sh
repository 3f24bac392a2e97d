#!/usr/bin/env bash
# Debian packages some tests need beyond bootstrap.sh --tests (scripts/test.sh installs them too, so
# that no test is skipped for a missing package): slurm-wlm and munge (tests/deploy/
# slurm_test.py starts a one-node Slurm cluster), clang-14 and libclang-rt-14-dev (libFuzzer
# targets, fuzz/ci.sh), chromium (tests/report/browser_test.py loads the HTML reports
# headless) and chromium-driver (tests/server/web_browser_test.py drives the server's web pages
# through WebDriver), g++-aarch64-linux-gnu and qemu-user-static (tests/arm64/same_bits.sh builds
# the lane code for arm64 and runs it).
# Non-interactive and idempotent, as bootstrap.sh.
set -euo pipefail
packages=(slurm-wlm munge clang-14 libclang-rt-14-dev chromium chromium-driver
  g++-aarch64-linux-gnu qemu-user-static)
bash "$(dirname "$0")/../bootstrap.sh" --only ci-packages "${packages[@]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
# The Debian packages start munge and Slurm's own daemons: the test starts its own, on other
# ports and sockets; stop the system ones so that nothing else runs jobs here.
for service in slurmctld slurmd munge; do
  if command -v systemctl > /dev/null && systemctl is-active --quiet "$service" 2> /dev/null; then
    $SUDO systemctl stop "$service" || true
  fi
done
