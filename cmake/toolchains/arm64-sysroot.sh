#!/usr/bin/env bash
# Private aarch64 sysroot for the target libraries Debian does not ship multi-arch (LCM, yaml-cpp).
# `apt-get install liblcm-dev:arm64` would replace the host's LCM (lcm-gen, lcm.jar), and
# `libyaml-cpp-dev:arm64` the host's libyaml-cpp-dev (not Multi-Arch: same), so the arm64
# packages are downloaded and unpacked (dpkg -x, no root needed) into SYSROOT instead, and their
# pkg-config files are rewritten to point into it. Multi-arch dependencies (libglib2.0-dev:arm64)
# come from apt (scripts/setup.sh --cross). Needs `dpkg --add-architecture arm64` + apt-get update.
# Usage: arm64-sysroot.sh SYSROOT        (idempotent: does nothing when SYSROOT is complete)
set -euo pipefail
sysroot=${1:?usage: arm64-sysroot.sh SYSROOT}
# yaml-cpp: rocksteady-fsw's start-up configuration loader (fsw/main/CMakeLists.txt). Its CMake
# package files locate themselves (relative import prefix), so find_package works from here.
packages=(liblcm1:arm64 liblcm-dev:arm64 libyaml-cpp0.7:arm64 libyaml-cpp-dev:arm64)
stamp="$sysroot/.rocksteady-sysroot"
if [[ -f "$stamp" && "$(cat "$stamp")" == "${packages[*]}" ]]; then
  exit 0
fi
mkdir -p "$sysroot"
sysroot=$(cd "$sysroot" && pwd)
work=$(mktemp -d)
chmod 755 "$work"  # apt-get download runs as the _apt user where it can
trap 'rm -rf "$work"' EXIT
(cd "$work" && apt-get download -qq "${packages[@]}")
for deb in "$work"/*.deb; do
  dpkg -x "$deb" "$sysroot"
done
# pkg-config: prefix=/usr -> prefix=SYSROOT/usr (glib and the C library stay the multiarch ones).
for pc in "$sysroot"/usr/lib/aarch64-linux-gnu/pkgconfig/*.pc; do
  sed -i "s|^prefix=.*|prefix=$sysroot/usr|" "$pc"
done
# Development symlink liblcm.so -> liblcm.so.1 is absolute in some packagings: make it relative.
libdir="$sysroot/usr/lib/aarch64-linux-gnu"
for so in "$libdir"/*.so; do
  if [[ -L "$so" ]]; then
    ln -sfn "$(basename "$(readlink "$so")")" "$so"
  fi
done
echo "${packages[*]}" > "$stamp"
echo "arm64-sysroot: ${packages[*]} unpacked into $sysroot"
