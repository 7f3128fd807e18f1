#!/usr/bin/env bash
# Installs every Debian package Rocksteady needs, idempotently: only what is missing, sudo only when
# not root. Usage: scripts/setup.sh [--cross]   (--cross adds the aarch64 and bare-metal toolchains)
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config git
  libeigen3-dev libgtest-dev libgmock-dev libbenchmark-dev
  liblcm-dev liblcm-bin liblcm-java libglib2.0-dev
  default-jdk-headless libjchart2d-java
  libyaml-cpp-dev libcli11-dev
  coinor-libipopt-dev
  gnuplot-nox
  iproute2 util-linux
  clang libclang-rt-14-dev
  nlohmann-json3-dev
  slurm-wlm munge
)
cross=0
if [[ "${1:-}" == "--cross" ]]; then
  cross=1
  # aarch64 target libraries are Debian multiarch (:arm64, needs `dpkg --add-architecture arm64`,
  # which scripts/cross.sh does); LCM is not multi-arch and is unpacked into a private sysroot.
  packages+=(g++-aarch64-linux-gnu qemu-user gcc-arm-none-eabi libstdc++-arm-none-eabi-newlib
             qemu-system-arm
             libstdc++6:arm64 libgtest-dev:arm64 libgmock-dev:arm64 libglib2.0-dev:arm64)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
# The arm64 multiarch target libraries need the architecture enabled first.
if ((cross)) && ! dpkg --print-foreign-architectures | grep -qx arm64; then
  $SUDO dpkg --add-architecture arm64
fi
echo "setup: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
