#!/usr/bin/env bash
# Private aarch64 sysroot for the target libraries Debian does not ship multi-arch (LCM, yaml-cpp,
# IPOPT).
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
# IPOPT 3.11 (coinor-libipopt1v5/-dev): the planner of rocksteady-planner (ground/planner). Debian
# installs it in /usr/lib, not in a multiarch directory, so the arm64 package replaces the host's
# (`apt-get -s install coinor-libipopt-dev:arm64` removes coinor-libipopt-dev, and through
# libmumps-seq-dev:arm64 -> libmumps-dev -> libscalapack-mpi-dev -> libopenmpi-dev:arm64 also g++,
# gfortran and slurm). Its run-time dependencies are multi-arch and come from apt (scripts/setup.sh
# --cross: libmumps-seq-5.5:arm64, libblas3:arm64, liblapack3:arm64, libgfortran5:arm64).
packages=(liblcm1:arm64 liblcm-dev:arm64 libyaml-cpp0.7:arm64 libyaml-cpp-dev:arm64
          coinor-libipopt1v5:arm64 coinor-libipopt-dev:arm64)
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
for pc in "$sysroot"/usr/lib/aarch64-linux-gnu/pkgconfig/*.pc "$sysroot"/usr/lib/pkgconfig/*.pc; do
  sed -i "s|^prefix=.*|prefix=$sysroot/usr|" "$pc"
done
# ipopt.pc lists the static link line (-ldmumps_seq -lblas -lgfortran ... and the build machine's
# -L/usr/lib/...): those need the unversioned development links of MUMPS/BLAS/gfortran, whose arm64
# -dev packages are the ones that would remove host packages. libipopt.so records its MUMPS, BLAS
# and LAPACK dependencies itself (DT_NEEDED, found by the linker in /usr/lib/aarch64-linux-gnu):
# link the shared library alone.
if [[ -f "$sysroot/usr/lib/pkgconfig/ipopt.pc" ]]; then
  sed -i 's|^Libs:.*|Libs: -L${libdir} -lipopt|' "$sysroot/usr/lib/pkgconfig/ipopt.pc"
fi
# Development symlink liblcm.so -> liblcm.so.1 is absolute in some packagings: make it relative.
for so in "$sysroot"/usr/lib/aarch64-linux-gnu/*.so "$sysroot"/usr/lib/*.so; do
  if [[ -L "$so" ]]; then
    ln -sfn "$(basename "$(readlink "$so")")" "$so"
  fi
done
echo "${packages[*]}" > "$stamp"
echo "arm64-sysroot: ${packages[*]} unpacked into $sysroot"
