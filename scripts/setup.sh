#!/usr/bin/env bash
# Installs every Debian package Rocksteady needs, idempotently: only what is missing, sudo only when
# not root. Usage: scripts/setup.sh [--cross]   (--cross adds the aarch64 and bare-metal toolchains)
set -euo pipefail

packages=(
  cmake ninja-build g++ pkg-config git dpkg-dev fakeroot
  libeigen3-dev libgtest-dev libgmock-dev libbenchmark-dev
  liblcm-dev liblcm-bin liblcm-java libglib2.0-dev
  default-jdk-headless libjchart2d-java
  libyaml-cpp-dev libcli11-dev libsodium-dev
  coinor-libipopt-dev
  gnuplot-nox
  iproute2 util-linux
  stress-ng python3
  clang libclang-rt-14-dev
  libcpp-httplib-dev nlohmann-json3-dev chromium
  slurm-wlm munge
)
cross=0
if [[ "${1:-}" == "--cross" ]]; then
  cross=1
  # aarch64 target libraries are Debian multiarch (:arm64, needs `dpkg --add-architecture arm64`,
  # which scripts/cross.sh does); LCM is not multi-arch and is unpacked into a private sysroot.
  # IPOPT (rocksteady-planner) is not multi-arch either (cmake/toolchains/arm64-sysroot.sh); its
  # run-time libraries MUMPS (sequential), BLAS, LAPACK and gfortran are, and come from here.
  packages+=(g++-aarch64-linux-gnu qemu-user gcc-arm-none-eabi libstdc++-arm-none-eabi-newlib
             qemu-system-arm
             libstdc++6:arm64 libgtest-dev:arm64 libgmock-dev:arm64 libglib2.0-dev:arm64
             libsodium-dev:arm64
             libmumps-seq-5.5:arm64 libblas3:arm64 liblapack3:arm64 libgfortran5:arm64)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# The browser console's npm packages (NASA Open MCT; puppeteer-core for the browser test, which
# drives Debian's chromium: no browser is downloaded), from the checked-in package-lock.json.
npm_packages() {
  local dir
  dir="$(cd "$(dirname "$0")/.." && pwd)/ground/console"
  if [[ -f "$dir/node_modules/.package-lock.json" ]] &&
     cmp -s "$dir/package-lock.json" "$dir/node_modules/.package-lock.json.installed" 2>/dev/null; then
    return 0
  fi
  # Node 20 with npm is part of the machine image (ENVIRONMENT.md), not an apt package here.
  command -v npm >/dev/null || { echo "setup: npm not found: install Node.js 20 with npm" >&2; return 1; }
  echo "setup: npm ci in ground/console (Open MCT, puppeteer-core)"
  (cd "$dir" && PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-audit --no-fund --loglevel=error) &&
    cp "$dir/package-lock.json" "$dir/node_modules/.package-lock.json.installed"
}

if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  npm_packages
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
npm_packages
