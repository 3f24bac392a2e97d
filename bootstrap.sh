#!/usr/bin/env bash
# Installs every Debian 12 package driftlab's build, tests and clients need.
# Non-interactive and idempotent: packages already installed are left alone.
# `bash bootstrap.sh --only LABEL PACKAGE...` installs those packages the same way instead
# (scripts/ci-packages.sh: the packages only CI's tests need).
set -euo pipefail

label=bootstrap
packages=(
  build-essential cmake ninja-build pkg-config git ca-certificates
  libeigen3-dev libceres-dev libtbb-dev
  libprotobuf-dev protobuf-compiler libgrpc++-dev protobuf-compiler-grpc
  libyaml-cpp-dev libcli11-dev libfmt-dev libspdlog-dev libsqlite3-dev libssl-dev openssl
  libcpp-httplib-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3-grpcio python3-protobuf python3-matplotlib python3-numpy
  clang-format ccache
  libjs-dygraphs
)
if [ "${1:-}" = "--only" ]; then
  label="$2"
  shift 2
  packages=("$@")
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "${label}: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "${label}: installing ${missing[*]}"
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
