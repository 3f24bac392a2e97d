#!/usr/bin/env bash
# Installs the Debian 12 packages driftlab needs.
#   bash bootstrap.sh           what building and running `driftlab` and `driftlab-server` needs
#                               (the README's first command): compiler, CMake, the libraries
#   bash bootstrap.sh --tests   that and what the tests need (scripts/test.sh): the Python stack of
#                               clients/python and the test scripts, git, openssl, ccache,
#                               clang-format; CI's own packages are in scripts/ci-packages.sh
#   bash bootstrap.sh --only LABEL PACKAGE...   those packages the same way
# Non-interactive and idempotent: packages already installed are left alone. Prints the time it
# took when it installed something.
set -euo pipefail

label=bootstrap
build_packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libceres-dev libtbb-dev
  libprotobuf-dev protobuf-compiler libgrpc++-dev protobuf-compiler-grpc
  libyaml-cpp-dev libcli11-dev libfmt-dev libspdlog-dev libsqlite3-dev libssl-dev
  libcpp-httplib-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libjs-dygraphs
)
test_packages=(
  git ca-certificates openssl ccache clang-format
  python3-grpcio python3-protobuf python3-numpy python3-pandas python3-matplotlib python3-yaml
  python3-pip python3-setuptools python3-wheel python3-venv
)
case "${1:-}" in
  "") packages=("${build_packages[@]}") ;;
  --tests)
    label=bootstrap-tests
    packages=("${build_packages[@]}" "${test_packages[@]}")
    ;;
  --only)
    label="$2"
    shift 2
    packages=("$@")
    ;;
  *)
    echo "usage: bash bootstrap.sh [--tests | --only LABEL PACKAGE...]" >&2
    exit 2
    ;;
esac

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
start=$(date +%s)
echo "${label}: installing ${missing[*]}"
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "${label}: installed ${#missing[@]} packages (with their dependencies) in $(($(date +%s) - start)) s"
